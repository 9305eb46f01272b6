//! Renders through the library (settings and renderer, as `translucent render` builds its frames)
//! under validation, compared with committed golden images. Set TRANSLUCENT_BLESS=1 to (re)write
//! the goldens after checking the new images by eye. tests/cli.rs covers the command line.

mod common;

use common::{assert_clean, output_dir, render_frame, repo_path};
use glam::Vec3;
use translucent::materials::Material;
use translucent::output::{self, Exposure};
use translucent::settings::{RenderSettings, SceneSettings, BUNNY};

/// `scene` in marble at 96x96 with the command line's defaults otherwise.
fn settings(scene: SceneSettings, exposure: Exposure) -> RenderSettings {
    let mut s = RenderSettings::new(scene.build().expect("scene"), Material::find("marble").unwrap());
    (s.desc.width, s.desc.height, s.desc.exposure) = (96, 96, exposure);
    s
}

/// Renders `scene` at 96x96 with validation on (exposure 0 stops unless given), tone-mapped on
/// the GPU, and compares it with `tests/golden/{name}.png`.
fn render_and_compare(name: &str, scene: SceneSettings, exposure: Option<f32>) {
    let actual_path = output_dir().join(format!("{name}.png"));
    let (renderer, counts) = render_frame(&settings(scene, Exposure::Stops(exposure.unwrap_or(0.0))));
    let actual = renderer.tone_mapped_image().unwrap();
    drop(renderer);
    assert_clean(&counts);
    actual.save(&actual_path).unwrap();

    let golden_path = repo_path(&format!("tests/golden/{name}.png"));
    if std::env::var_os("TRANSLUCENT_BLESS").is_some() {
        actual.save(&golden_path).unwrap();
        return;
    }
    let golden = image::open(&golden_path).unwrap_or_else(|e| panic!("{}: {e}", golden_path.display())).into_rgba8();
    let diff = output::compare(&actual, &golden).unwrap();
    // Rasterisation differs slightly between drivers; a wrong shading or camera moves far more.
    if diff.rmse > 2.0 || diff.differing_fraction > 0.01 {
        let diff_path = output_dir().join(format!("{name}.diff.png"));
        output::difference_image(&actual, &golden).save(&diff_path).unwrap();
        panic!(
            "{name}: differs from the golden image ({diff:?}); actual {}, difference {}",
            actual_path.display(),
            diff_path.display()
        );
    }
}

/// The default scene's set-up with `mesh` and the default light toward `light_dir`.
fn scene(mesh: &str, light_dir: Option<[f32; 3]>) -> SceneSettings {
    let mut scene = SceneSettings { mesh: Some(mesh.to_string()), ..Default::default() };
    if let Some(d) = light_dir {
        scene.light_dir = Vec3::from(d);
    }
    scene
}

#[test]
fn sphere_matches_golden() {
    render_and_compare("sphere", scene("sphere", Some([-0.5, 0.8, 0.6])), None);
}

#[test]
fn obj_file_matches_golden() {
    let mesh = repo_path("tests/data/irregular.obj");
    render_and_compare("irregular_obj", scene(mesh.to_str().unwrap(), Some([0.3, 1.0, 0.4])), None);
}

#[test]
fn bunny_renders_clean_when_installed() {
    if !std::path::Path::new(BUNNY).exists() {
        eprintln!("skipped: {BUNNY} is not installed (Debian package glmark2-data)");
        return;
    }
    // The default scene (back-lit marble bunny), brighter so that the translucency shows.
    render_and_compare("bunny", scene(BUNNY, None), Some(2.5));
}

/// The PNG is tone-mapped on the GPU in the frame; it equals the CPU definition applied to the
/// linear radiance of the same frame, with automatic and with fixed exposure.
#[test]
fn png_is_the_tone_mapped_exr() {
    for (name, exposure) in [("auto", None), ("fixed", Some(1.5))] {
        let stops = exposure.map(Exposure::Stops).unwrap_or(Exposure::Auto);
        let mut s = settings(scene("torus", None), stops);
        (s.desc.width, s.desc.height) = (40, 24);
        let (renderer, counts) = render_frame(&s);
        let (actual, hdr) = (renderer.tone_mapped_image().unwrap(), renderer.image().unwrap());
        drop(renderer);
        assert_clean(&counts);
        let expected = output::tonemap(&hdr, stops);
        let worst = actual.as_raw().iter().zip(expected.as_raw()).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
        println!("GPU tone mapping ({name} exposure) vs CPU: worst difference {worst}/255");
        assert!(worst <= 1, "{name}: {worst}");
    }
}
