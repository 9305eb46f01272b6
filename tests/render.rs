//! Renders through the binary under validation, compared with committed golden images.
//! Set TRANSLUCENT_BLESS=1 to (re)write the goldens after checking the new images by eye.

mod common;

use common::{output_dir, repo_path, stderr, translucent};
use translucent::output;

/// Renders `args` at 96x96 to PNG with validation on and compares it with `tests/golden/{name}.png`.
fn render_and_compare(name: &str, args: &[&str]) {
    let actual_path = output_dir().join(format!("{name}.png"));
    let mut full = vec!["render", "--validation", "--width", "96", "--height", "96"];
    full.extend_from_slice(args);
    if !args.contains(&"--exposure") {
        full.extend_from_slice(&["--exposure", "0"]);
    }
    full.extend_from_slice(&["--out", actual_path.to_str().unwrap()]);
    let out = translucent(&full);
    assert!(out.status.success(), "render {name} failed:\n{}", stderr(&out));
    assert!(!stderr(&out).contains("vulkan"), "validation messages:\n{}", stderr(&out));

    let golden_path = repo_path(&format!("tests/golden/{name}.png"));
    let actual = image::open(&actual_path).unwrap().into_rgba8();
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

#[test]
fn sphere_matches_golden() {
    render_and_compare("sphere", &["--mesh", "sphere", "--light-dir", "-0.5,0.8,0.6"]);
}

#[test]
fn obj_file_matches_golden() {
    let mesh = repo_path("tests/data/irregular.obj");
    render_and_compare("irregular_obj", &["--mesh", mesh.to_str().unwrap(), "--light-dir", "0.3,1,0.4"]);
}

#[test]
fn bunny_renders_clean_when_installed() {
    let bunny = "/usr/share/glmark2/models/bunny.obj";
    if !std::path::Path::new(bunny).exists() {
        eprintln!("skipped: {bunny} is not installed (Debian package glmark2-data)");
        return;
    }
    // The default scene (back-lit marble bunny), brighter so that the translucency shows.
    render_and_compare("bunny", &["--mesh", bunny, "--exposure", "2.5"]);
}

#[test]
fn exr_output_is_linear_radiance() {
    let path = output_dir().join("sphere.exr");
    let out =
        translucent(&["render", "--validation", "--width", "32", "--height", "32", "--out", path.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let img = image::open(&path).unwrap().into_rgba32f();
    let centre = img.get_pixel(16, 16);
    assert_eq!(centre[3], 1.0, "the sphere covers the centre");
    assert!(centre[0] > 0.0 && centre[0].is_finite());
    assert_eq!(img.get_pixel(0, 0)[3], 0.0, "the corner is background");
}

#[test]
fn profile_json_has_every_pass() {
    let json_path = output_dir().join("profile.json");
    let png = output_dir().join("profile.png");
    let out = translucent(&[
        "render",
        "--validation",
        "--width",
        "64",
        "--height",
        "64",
        "--frames",
        "3",
        "--profile",
        "--profile-out",
        json_path.to_str().unwrap(),
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("shade") && table.contains("frame"), "table:\n{table}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let events = v["traceEvents"].as_array().unwrap();
    for pass in ["shade", "readback"] {
        let timed: Vec<_> = events.iter().filter(|e| e["name"] == pass).collect();
        assert_eq!(timed.len(), 3, "{pass}: one event per frame");
        assert!(timed.iter().all(|e| e["dur"].as_f64().unwrap() > 0.0), "{pass}: positive durations");
    }
}

/// `--frames N --spin-light DEG` with `{frame}` in `--out` writes every frame; the light turns
/// about the vertical axis and the hierarchy is rebuilt, so frames differ, and a whole turn comes
/// back to the first frame.
#[test]
fn spinning_light_writes_every_frame() {
    let dir = output_dir().join("spin");
    std::fs::create_dir_all(&dir).unwrap();
    for f in std::fs::read_dir(&dir).unwrap() {
        std::fs::remove_file(f.unwrap().path()).unwrap();
    }
    let pattern = dir.join("frame-{frame}.exr");
    let out = translucent(&[
        "render",
        "--validation",
        "--mesh",
        "torus",
        "--width",
        "32",
        "--height",
        "32",
        "--samples",
        "4096",
        "--light",
        "dir:1,0.5,0",
        "--frames",
        "5",
        "--spin-light",
        "90",
        "--out",
        pattern.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let frames: Vec<Vec<f32>> = (0..5)
        .map(|k| {
            let path = dir.join(format!("frame-{k:04}.exr"));
            image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgba32f().into_raw()
        })
        .collect();
    let relative_difference = |a: &[f32], b: &[f32]| {
        let num: f64 = a.iter().zip(b).map(|(x, y)| (*x as f64 - *y as f64).powi(2)).sum();
        let den: f64 = b.iter().map(|y| (*y as f64).powi(2)).sum();
        (num / den).sqrt()
    };
    let quarter = relative_difference(&frames[1], &frames[0]);
    let turn = relative_difference(&frames[4], &frames[0]);
    println!("spinning light: a quarter turn changes the image by {quarter:.3}, a whole turn by {turn:.2e}");
    assert!(quarter > 0.05, "the light did not move: {quarter}");
    assert!(turn < 1e-3, "a whole turn must come back to the first frame: {turn}");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 5, "one file per frame");
}

/// The PNG is tone-mapped on the GPU in the frame; it equals the CPU definition applied to the
/// EXR (linear radiance) of the same frame, with automatic and with fixed exposure.
#[test]
fn png_is_the_tone_mapped_exr() {
    for (name, exposure) in [("auto", None), ("fixed", Some("1.5"))] {
        let (png, exr) = (output_dir().join(format!("tm-{name}.png")), output_dir().join(format!("tm-{name}.exr")));
        for path in [&png, &exr] {
            let mut args = vec!["render", "--validation", "--mesh", "torus", "--width", "40", "--height", "24"];
            if let Some(e) = exposure {
                args.extend_from_slice(&["--exposure", e]);
            }
            args.extend_from_slice(&["--out", path.to_str().unwrap()]);
            let out = translucent(&args);
            assert!(out.status.success(), "{}", stderr(&out));
        }
        let hdr = image::open(&exr).unwrap().into_rgba32f();
        let hdr =
            output::HdrImage { width: hdr.width(), height: hdr.height(), pixels: hdr.pixels().map(|p| p.0).collect() };
        let stops = exposure.map(|e| output::Exposure::Stops(e.parse().unwrap())).unwrap_or(output::Exposure::Auto);
        let expected = output::tonemap(&hdr, stops);
        let actual = image::open(&png).unwrap().into_rgba8();
        let worst = actual.as_raw().iter().zip(expected.as_raw()).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
        println!("GPU tone mapping ({name} exposure) vs CPU: worst difference {worst}/255");
        assert!(worst <= 1, "{name}: {worst}");
    }
}

/// The layer forced from outside, as users and reviewers run it, with synchronization validation
/// and best practices: every kind of frame is clean (any message makes the exit code 1).
#[test]
fn forced_layer_with_best_practices_is_clean() {
    let out = output_dir().join("forced.png");
    let out = out.to_str().unwrap();
    let tree = output_dir().join("forced-tree.exr");
    #[rustfmt::skip]
    let cases: [&[&str]; 4] = [
        &["--frames", "2", "--spin-light", "30", "--profile"],
        &["--mesh", "torus", "--brute-force", "--samples", "9000", "--light", "point:2,2,2:3", "--light", "dir:0,1,0"],
        &["--mesh", "sphere", "--show", "samples", "--exposure", "1"],
        &["--mesh", "sphere", "--show", "tree", "--level", "3", "--out", tree.to_str().unwrap()],
    ];
    for extra in cases {
        let mut args = vec!["render", "--width", "40", "--height", "30"];
        args.extend_from_slice(extra);
        if !extra.contains(&"--out") {
            args.extend_from_slice(&["--out", out]);
        }
        let result = std::process::Command::new(env!("CARGO_BIN_EXE_translucent"))
            .args(&args)
            .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
            .env(
                "VK_LAYER_ENABLES",
                "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT:VK_VALIDATION_FEATURE_ENABLE_BEST_PRACTICES_EXT",
            )
            .output()
            .unwrap();
        let err = stderr(&result);
        assert!(result.status.success(), "{extra:?}: exit {:?}\n{err}", result.status.code());
        assert!(!err.contains("vulkan validation"), "{extra:?}:\n{err}");
    }
}
