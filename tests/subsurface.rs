//! The subsurface shading pass: the tree against brute force, under validation.

mod common;

use common::{output_dir, stderr, translucent};

/// Renders to EXR (validation on) and returns the linear RGBA pixels.
fn render(name: &str, args: &[&str]) -> Vec<[f32; 4]> {
    let path = output_dir().join(format!("{name}.exr"));
    let mut full = vec!["render", "--validation", "--width", "64", "--height", "64", "--samples", "4096"];
    full.extend_from_slice(args);
    full.extend_from_slice(&["--out", path.to_str().unwrap()]);
    let out = translucent(&full);
    assert!(out.status.success(), "{name}: {}", stderr(&out));
    let img = image::open(&path).unwrap().into_rgba32f();
    img.pixels().map(|p| p.0).collect()
}

/// sqrt(Σ(a − b)² / Σ b²) over the pixels the object covers, all channels.
fn relative_rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (p, q) in a.iter().zip(b) {
        if q[3] > 0.0 {
            for c in 0..3 {
                num += (p[c] as f64 - q[c] as f64).powi(2);
                den += (q[c] as f64).powi(2);
            }
        }
    }
    (num / den).sqrt()
}

fn meshes() -> Vec<String> {
    let mut m = vec!["sphere".to_string()];
    let bunny = "/usr/share/glmark2/models/bunny.obj";
    // An irregular mesh: the bunny when installed, else the committed irregular octahedron.
    if std::path::Path::new(bunny).exists() {
        m.push(bunny.to_string());
    } else {
        m.push(common::repo_path("tests/data/irregular.obj").to_string_lossy().into_owned());
    }
    m
}

#[test]
fn tree_matches_brute_force_within_one_percent() {
    let light = "dir:0.3,1,-0.5";
    for mesh in meshes() {
        for model in ["directional", "dipole"] {
            let name = format!("{}-{model}", std::path::Path::new(&mesh).file_stem().unwrap().to_string_lossy());
            let args = ["--mesh", mesh.as_str(), "--light", light, "--model", model];
            let reference = render(&format!("{name}-brute"), &[&args[..], &["--brute-force"]].concat());
            let mut errors = Vec::new();
            for eps in ["0.2", "0.05", "0.01"] {
                let tree = render(&format!("{name}-eps{eps}"), &[&args[..], &["--epsilon", eps]].concat());
                errors.push(relative_rmse(&tree, &reference));
            }
            let default = render(&format!("{name}-default"), &args);
            let error = relative_rmse(&default, &reference);
            println!("{name}: relative RMSE at epsilon 0.2, 0.05, 0.01: {errors:.5?}; default {error:.5}");
            assert!(error <= 0.01, "{name}: {error}");
            assert!(errors[2] < errors[0], "{name}: error must fall with epsilon: {errors:?}");
        }
    }
}
