//! The command line itself, through the binary: bad input (each case exits 2 with an `error:` line
//! naming the problem, and never panics or hangs), the output files and flags of `render`, and
//! that its flags make the same settings, hence the same frame, as the library's defaults. The
//! physics and rendering tests (tests/subsurface.rs, tests/render.rs) build frames through the
//! library.

mod common;

use common::{output_dir, repo_path, stderr, translucent};

/// Runs `render` with `args` and asserts exit code 2 and an `error:` line containing `needle`.
fn assert_bad_input(args: &[&str], needle: &str) {
    let out = common::output_dir().join("bad-input.png");
    // Validation on: several of these cases create a device before they are refused.
    let mut full = vec!["render", "--validation", "--out", out.to_str().unwrap()];
    // Small images of the sphere unless the case is about the size or the mesh itself.
    for flag in ["--width", "--height"] {
        if !args.contains(&flag) {
            full.extend_from_slice(&[flag, "16"]);
        }
    }
    if !args.contains(&"--mesh") {
        full.extend_from_slice(&["--mesh", "sphere"]);
    }
    full.extend_from_slice(args);
    let result = translucent(&full);
    let err = stderr(&result);
    assert_eq!(result.status.code(), Some(2), "args {args:?}: expected exit 2, stderr:\n{err}");
    assert!(err.lines().any(|l| l.starts_with("error:")), "args {args:?}: no `error:` line in:\n{err}");
    assert!(err.contains(needle), "args {args:?}: stderr does not mention {needle:?}:\n{err}");
    assert!(!err.contains("panicked"), "args {args:?}: panic:\n{err}");
}

fn fixture(name: &str) -> String {
    repo_path(&format!("tests/data/{name}")).to_string_lossy().into_owned()
}

#[test]
fn missing_mesh_file() {
    assert_bad_input(&["--mesh", "/nonexistent/mesh.obj"], "/nonexistent/mesh.obj");
}

#[test]
fn malformed_obj_files() {
    for (file, needle) in [
        ("garbage.obj", "garbage.obj"),
        ("truncated_face.obj", "truncated_face.obj"),
        ("index_out_of_range.obj", "index_out_of_range.obj"),
        ("empty.obj", "empty.obj"),
        ("nan_vertex.obj", "nan_vertex.obj"),
        ("zero_area.obj", "zero_area.obj"),
    ] {
        assert_bad_input(&["--mesh", &fixture(file)], needle);
    }
}

#[test]
fn bad_flag_values() {
    assert_bad_input(&["--width", "0"], "--width");
    assert_bad_input(&["--height", "-3"], "--height");
    assert_bad_input(&["--width", "100000"], "100000");
    assert_bad_input(&["--fov", "nan"], "--fov");
    assert_bad_input(&["--fov", "180"], "--fov");
    assert_bad_input(&["--eye", "1,2"], "--eye");
    assert_bad_input(&["--light-dir", "0,0,0"], "light direction");
    assert_bad_input(&["--light-intensity", "-1"], "--light-intensity");
    assert_bad_input(&["--scale", "0"], "--scale");
    assert_bad_input(&["--frames", "0"], "--frames");
    assert_bad_input(&["--device", "no-such-device"], "no-such-device");
    assert_bad_input(&["--no-such-flag"], "--no-such-flag");
    assert_bad_input(&["--roughness", "0"], "--roughness");
    assert_bad_input(&["--roughness", "-0.5"], "--roughness");
    assert_bad_input(&["--roughness", "1.5"], "--roughness");
    assert_bad_input(&["--roughness", "nan"], "--roughness");
    assert_bad_input(&["--spin-light", "inf"], "--spin-light");
    assert_bad_input(&["--epsilon", "-1"], "--epsilon");
    assert_bad_input(&["--model", "pbd", "--scattering", "single"], "--scattering");
    assert_bad_input(&["--scattering", "twice"], "--scattering");
    assert_bad_input(&["--model", "directional", "--reentry"], "--reentry");
    assert_bad_input(&["--model", "mc", "--reentry", "--brute-force"], "--brute-force");
}

#[test]
fn output_folder_must_exist() {
    let result = translucent(&["render", "--width", "8", "--height", "8", "--out", "/nonexistent/dir/x.png"]);
    assert_eq!(result.status.code(), Some(2), "{}", stderr(&result));
    assert!(stderr(&result).contains("/nonexistent/dir"), "{}", stderr(&result));
    let result = translucent(&["render", "--width", "8", "--height", "8", "--profile-out", "/nonexistent/p.json"]);
    assert_eq!(result.status.code(), Some(2), "{}", stderr(&result));
}

#[test]
fn bad_output_extension() {
    let result = translucent(&["render", "--validation", "--width", "8", "--height", "8", "--out", "picture.bmp"]);
    assert_eq!(result.status.code(), Some(2));
    assert!(stderr(&result).contains("picture.bmp"));
}

#[test]
fn bad_hierarchy_input() {
    assert_bad_input(&["--samples", "0"], "--samples 0");
    assert_bad_input(&["--samples", "4000000000"], "more than this device can hold");
    assert_bad_input(&["--light", "point:0,0,0:5"], "inside the mesh");
    assert_bad_input(&["--light", "dir:nan,1,0"], "--light");
    assert_bad_input(&["--light", "point:1,nan,0"], "--light");
    assert_bad_input(&["--light", "spot:1,1,1"], "expected spot:X,Y,Z:TX,TY,TZ:ANGLE[:DELTA[:I]]");
    assert_bad_input(&["--light", "cone:1,1,1"], "kind must be dir, point or spot");
    assert_bad_input(&["--light", "dir:0,1,0:-2"], "--light");
    // As many lights as the device has shadow-map layers (lavapipe: 2048; 6 per point light).
    let many: Vec<&str> = (0..400).flat_map(|_| ["--light", "point:3,3,3"]).collect();
    assert_bad_input(&many, "shadow-map layers");
}

/// `--light spot:…` refuses each part that is out of range, naming the flag and the value.
#[test]
fn bad_spot_lights() {
    for (spec, needle) in [
        ("spot:0,3,0:0,0,0:0", "cone angle 0°: must be in (0, 180]"),
        ("spot:0,3,0:0,0,0:-10", "cone angle -10°"),
        ("spot:0,3,0:0,0,0:180.5", "cone angle 180.5°"),
        ("spot:0,3,0:0,0,0:30:40", "falloff width 40°: must be in [0, 30]"),
        ("spot:0,3,0:0,0,0:30:-1", "falloff width -1°"),
        ("spot:0,3,0:0,3,0:30", "are the same point"),
        ("spot:0,nan,0:0,0,0:30", "'nan' is not finite"),
        ("spot:0,3,0:0,0,inf:30", "'inf' is not finite"),
        ("spot:0,3,0:0,0,0:inf", "cone angle: 'inf' is not finite"),
        ("spot:0,3,0:0,0,0:30:5:-1", "must not be negative"),
        ("spot:0,3,0:0,0,0:30:5:1:2", "expected spot:X,Y,Z"),
        ("spot:0,3,0:0,0:30", "X,Y,Z"),
        ("spot:1e16,0,0:0,0,0:30", "coordinates must be within"),
    ] {
        // Each names the flag (clap's "invalid value … for '--light …'", or check_lights').
        assert_bad_input(&["--light", spec], needle);
        let out = translucent(&["render", "--mesh", "sphere", "--light", spec]);
        assert!(stderr(&out).starts_with("error:") && stderr(&out).contains("--light"), "{spec}: {}", stderr(&out));
    }
    // Found once the mesh is known: the light is inside it.
    assert_bad_input(&["--light", "spot:0,0,0:0,1,0:30"], "spot light at [0, 0, 0] is inside the mesh");
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

/// `render`'s defaults are the library's: the settings its flags make without any flag are
/// `SceneSettings::default()` and `RenderSettings::new` with the default material.
#[test]
fn render_flags_default_to_the_library_settings() {
    use clap::Parser;
    use translucent::cli::{Cli, Command};
    use translucent::settings::{RenderSettings, SceneSettings};
    let Command::Render(args) = Cli::try_parse_from(["translucent", "render", "--mesh", "sphere"]).unwrap().command
    else {
        panic!("not render")
    };
    let scene = SceneSettings { mesh: Some("sphere".into()), ..Default::default() };
    assert_eq!(SceneSettings::from_args(&args), scene);
    let flags = RenderSettings::from_args(&args).unwrap();
    let code = RenderSettings::new(scene.build().unwrap(), translucent::materials::Material::find("marble").unwrap());
    let (a, b) = (&flags.desc, &code.desc);
    let material = |s: &RenderSettings| s.world.objects[0].material.clone();
    let (ai, bi) = (a.integration, b.integration);
    assert_eq!((material(&flags), ai.model, ai.diffusion), (material(&code), bi.model, bi.diffusion));
    assert_eq!(
        (ai.epsilon, ai.brute_force, a.specular, a.roughness),
        (bi.epsilon, bi.brute_force, b.specular, b.roughness)
    );
    assert_eq!(
        (flags.desc.width, flags.desc.height, flags.world.objects[0].samples),
        (code.desc.width, code.desc.height, code.world.objects[0].samples)
    );
    assert_eq!(
        (flags.desc.shadow_resolution, flags.desc.show, flags.desc.exposure),
        (code.desc.shadow_resolution, code.desc.show, code.desc.exposure)
    );
    assert_eq!((flags.profile, flags.desc.count_work), (code.profile, code.desc.count_work));
}

/// The binary renders exactly what the library renders from the same settings: the EXR of
/// `translucent render` and the library's frame are bit-identical.
#[test]
fn render_writes_the_library_frame() {
    use translucent::settings::{RenderSettings, SceneSettings};
    let path = output_dir().join("cli-vs-library.exr");
    #[rustfmt::skip]
    let out = translucent(&[
        "render", "--validation", "--mesh", "torus", "--width", "24", "--height", "20", "--samples", "3000",
        "--light", "dir:0.2,1,0.4:2", "--model", "dipole", "--epsilon", "0.1", "--out", path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let cli = image::open(&path).unwrap().into_rgba32f();
    let scene = SceneSettings {
        mesh: Some("torus".into()),
        lights: vec![common::dir_light([0.2, 1.0, 0.4], [2.0; 3])],
        ..Default::default()
    };
    let mut s = RenderSettings::new(scene.build().unwrap(), translucent::materials::Material::find("marble").unwrap());
    (s.desc.width, s.desc.height, s.world.objects[0].samples) = (24, 20, Some(3000));
    (s.desc.integration.model, s.desc.integration.epsilon) = (translucent::physics::Model::Dipole, 0.1);
    let library = common::render_hdr(&s);
    assert_eq!((cli.width(), cli.height()), (library.width, library.height));
    let differing =
        cli.pixels().zip(&library.pixels).filter(|(p, q)| p.0.map(f32::to_bits) != q.map(f32::to_bits)).count();
    assert_eq!(differing, 0, "pixels differing between the binary and the library");
}
