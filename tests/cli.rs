//! Bad input through the binary: each case exits 2 with an `error:` line naming the problem, and
//! never panics or hangs.

mod common;

use common::{repo_path, stderr, translucent};

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
    assert_bad_input(&["--light", "spot:1,1,1"], "kind must be dir or point");
    assert_bad_input(&["--light", "dir:0,1,0:-2"], "--light");
    let nine: Vec<&str> = (0..9).flat_map(|_| ["--light", "dir:0,1,0"]).collect();
    assert_bad_input(&nine, "at most 8 lights");
}
