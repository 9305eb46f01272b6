//! `translucent view` in a window on Xvfb (lavapipe, validation on): scripted runs, resizes,
//! screenshots against `render`, and the error without a window system.
//!
//! Each run starts its own virtual X server through `xvfb-run -a`; runs are serialised because
//! `xvfb-run -a` picks a free display number racily. Without `xvfb-run` (not CI: CI installs it
//! with scripts/setup-debian) the windowed tests print a note and pass.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Mutex;

use common::{output_dir, stderr, translucent};
use translucent::output;

static XVFB: Mutex<()> = Mutex::new(());

fn have_xvfb() -> bool {
    let found = std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|p| p.join("xvfb-run").is_file()))
        .unwrap_or(false);
    if !found {
        eprintln!("skipped: xvfb-run is not installed (Debian package xvfb; scripts/setup-debian installs it)");
    }
    found
}

/// The sphere at 96x96 with few samples and a fixed exposure, so that images compare.
const SCENE: &[&str] = &["--mesh", "sphere", "--width", "96", "--height", "96", "--samples", "4096", "--exposure", "0"];

/// Runs `translucent view --validation` under Xvfb with `args`, and the script `lines` if any.
fn view(name: &str, args: &[&str], lines: &[&str]) -> Output {
    let _one_at_a_time = XVFB.lock().unwrap_or_else(|e| e.into_inner());
    let mut cmd = Command::new("xvfb-run");
    cmd.args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_translucent"), "view", "--validation"]);
    cmd.args(args);
    if !lines.is_empty() {
        let script = output_dir().join(format!("{name}.script"));
        std::fs::write(&script, lines.join("\n")).unwrap();
        cmd.arg("--script").arg(&script);
    }
    let out = cmd.output().expect("run xvfb-run");
    let err = stderr(&out);
    assert!(!err.contains("vulkan validation"), "{name}: validation messages:\n{err}");
    assert!(!err.contains("panicked"), "{name}: panic:\n{err}");
    out
}

fn assert_ok(name: &str, out: &Output) {
    assert_eq!(out.status.code(), Some(0), "{name}: exit {:?}, stderr:\n{}", out.status.code(), stderr(out));
}

fn png(name: &str) -> PathBuf {
    output_dir().join(format!("view-{name}.png"))
}

fn load(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgba8()
}

/// Mean R, G, B over the pixels the object covers (alpha > 0).
fn mean_colour(img: &image::RgbaImage) -> [f64; 3] {
    let covered: Vec<_> = img.pixels().filter(|p| p[3] > 0).collect();
    assert!(!covered.is_empty(), "the object covers no pixel");
    let mean = |c: usize| covered.iter().map(|p| p[c] as f64).sum::<f64>() / covered.len() as f64;
    [mean(0), mean(1), mean(2)]
}

#[test]
fn open_resize_minimise_and_close_are_clean() {
    if !have_xvfb() {
        return;
    }
    let trace = output_dir().join("view-trace.json");
    let _ = std::fs::remove_file(&trace);
    let trace_line = format!("trace 2 {}", trace.display());
    let out = view(
        "resize",
        SCENE,
        &[
            &trace_line,
            "frames 2",
            "resize 128 80",
            "frames 2",
            "resize 0 0",
            "frames 2",
            "resize 96 112",
            "frames 1",
            "quit",
        ],
    );
    assert_ok("resize", &out);
    // The trace of the first two frames: Chrome trace events with the frame's passes.
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&trace).unwrap()).unwrap();
    let text = json.to_string();
    assert!(text.contains("tree build") && text.contains("shade"), "{text}");
}

#[test]
fn frames_flag_exits_after_that_many_frames_with_the_layer_forced_from_outside() {
    if !have_xvfb() {
        return;
    }
    let _one_at_a_time = XVFB.lock().unwrap_or_else(|e| e.into_inner());
    let shot = png("frames");
    let _ = std::fs::remove_file(&shot);
    // A resize and a minimise between the frames: swapchains rebuilt under the forced layer too.
    let script = output_dir().join("frames.script");
    std::fs::write(&script, "frames 1\nresize 120 90\nframes 1\nresize 0 0\nframes 1\nresize 96 96\n").unwrap();
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_translucent"), "view"])
        .args(SCENE)
        .args(["--frames", "3", "--screenshot", shot.to_str().unwrap(), "--script", script.to_str().unwrap()])
        .env("VK_INSTANCE_LAYERS", "VK_LAYER_KHRONOS_validation")
        .env(
            "VK_LAYER_ENABLES",
            "VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT:VK_VALIDATION_FEATURE_ENABLE_BEST_PRACTICES_EXT",
        )
        .output()
        .expect("run xvfb-run");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "stderr:\n{err}");
    assert!(!err.contains("vulkan validation"), "validation messages:\n{err}");
    assert!(shot.is_file(), "--screenshot {} was not written", shot.display());
}

#[test]
fn screenshot_equals_render_with_the_same_settings() {
    if !have_xvfb() {
        return;
    }
    let shot = png("screenshot");
    let mut args = SCENE.to_vec();
    args.extend_from_slice(&["--light-dir", "-0.5,0.8,0.6", "--frames", "1", "--screenshot", shot.to_str().unwrap()]);
    assert_ok("screenshot", &view("screenshot", &args, &[]));

    let rendered = png("screenshot-render");
    let mut render = vec!["render", "--validation"];
    render.extend_from_slice(SCENE);
    render.extend_from_slice(&["--light-dir", "-0.5,0.8,0.6", "--out", rendered.to_str().unwrap()]);
    assert_screenshot_equals_render(&shot, &render, &rendered);
}

#[test]
fn scripted_orbit_changes_the_image_and_orbiting_back_returns_it() {
    if !have_xvfb() {
        return;
    }
    // A light from the side, so that turning the camera turns the shading.
    let mut args = SCENE.to_vec();
    args.extend_from_slice(&["--light-dir", "1,0.3,0.2"]);
    let (a, b, c) = (png("orbit-a"), png("orbit-b"), png("orbit-c"));
    let lines = [
        format!("screenshot {}", a.display()),
        "orbit 60 0".into(),
        format!("screenshot {}", b.display()),
        "orbit -60 0".into(),
        format!("screenshot {}", c.display()),
        "quit".into(),
    ];
    let lines: Vec<&str> = lines.iter().map(|s| s.as_str()).collect();
    assert_ok("orbit", &view("orbit", &args, &lines));
    let (a, b, c) = (load(&a), load(&b), load(&c));
    let turned = output::compare(&a, &b).unwrap();
    assert!(turned.rmse > 5.0, "orbiting 60° should change the image: {turned:?}");
    let back = output::compare(&a, &c).unwrap();
    assert!(back.rmse < 1.0, "orbiting back should return the image: {back:?}");
}

#[test]
fn dragging_shows_previews_then_the_refined_frame() {
    if !have_xvfb() {
        return;
    }
    let _one_at_a_time = XVFB.lock().unwrap_or_else(|e| e.into_inner());
    let (a, c) = (png("drag-a"), png("drag-c"));
    let script = output_dir().join("drag.script");
    let lines = [
        format!("screenshot {}", a.display()),
        // As the mouse drags: interaction, so the frames right after are previews.
        "drag orbit -100 0".into(),
        "frames 2".into(),
        "drag orbit 100 0".into(),
        "frames 1".into(),
        format!("screenshot {}", c.display()),
        "quit".into(),
    ];
    std::fs::write(&script, lines.join("\n")).unwrap();
    let mut args = SCENE.to_vec();
    args.extend_from_slice(&["--light-dir", "1,0.3,0.2", "--script", script.to_str().unwrap()]);
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 640x480x24", env!("CARGO_BIN_EXE_translucent"), "view", "--validation"])
        .args(&args)
        .env("RUST_LOG", "translucent::view=info")
        .output()
        .expect("run xvfb-run");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "stderr:\n{err}");
    assert!(!err.contains("vulkan validation"), "validation messages:\n{err}");
    assert!(err.contains("preview frame 24x24"), "no preview at a quarter of 96x96:\n{err}");
    let back = output::compare(&load(&a), &load(&c)).unwrap();
    assert!(back.rmse < 1.0, "dragged there and back, refined: {back:?}");
}

#[test]
fn material_switch_changes_the_colour_balance_as_the_presets_predict() {
    if !have_xvfb() {
        return;
    }
    let (marble, skin) = (png("marble"), png("skin1"));
    let lines = [
        "material marble".to_string(),
        format!("screenshot {}", marble.display()),
        "material skin1".into(),
        format!("screenshot {}", skin.display()),
        "quit".into(),
    ];
    let lines: Vec<&str> = lines.iter().map(|s| s.as_str()).collect();
    assert_ok("material", &view("material", SCENE, &lines));
    let (m, s) = (mean_colour(&load(&marble)), mean_colour(&load(&skin)));
    // Diffuse reflectance Rd (`translucent materials`): marble 0.830 0.791 0.753, nearly grey;
    // skin1 0.436 0.227 0.131, red. The red-to-blue balance must follow.
    let (red_blue_marble, red_blue_skin) = (m[0] / m[2].max(1.0), s[0] / s[2].max(1.0));
    assert!(red_blue_skin > 1.5 * red_blue_marble, "marble {m:?}, skin1 {s:?}");
    assert!(s[0] > s[1] && s[1] > s[2], "skin1: R > G > B, got {s:?}");
}

#[test]
fn light_dragged_behind_the_object_brightens_its_rim() {
    if !have_xvfb() {
        return;
    }
    // Light from the camera's side, then turned 180° behind the sphere: the thin rim lets light
    // through and glows relative to the centre, which the light now reaches through the whole
    // sphere.
    let (front, back) = (png("light-front"), png("light-back"));
    let lines = [
        "light dir:0.3,0.3,1".to_string(),
        format!("screenshot {}", front.display()),
        "light turn 180 0".into(),
        format!("screenshot {}", back.display()),
        "quit".into(),
    ];
    let lines: Vec<&str> = lines.iter().map(|s| s.as_str()).collect();
    assert_ok("light", &view("light", SCENE, &lines));
    let rim_over_centre = |img: &image::RgbaImage| {
        let (w, h) = img.dimensions();
        let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
        let (mut rim, mut centre) = (Vec::new(), Vec::new());
        for (x, y, p) in img.enumerate_pixels() {
            if p[3] == 0 {
                continue;
            }
            let r = ((x as f64 + 0.5 - cx).powi(2) + (y as f64 + 0.5 - cy).powi(2)).sqrt() / (w as f64 / 2.0);
            let luma = p[0] as f64 + p[1] as f64 + p[2] as f64;
            if r > 0.8 {
                rim.push(luma);
            } else if r < 0.3 {
                centre.push(luma);
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        mean(&rim) / mean(&centre).max(1.0)
    };
    let (f, b) = (rim_over_centre(&load(&front)), rim_over_centre(&load(&back)));
    assert!(b > 1.5 * f, "rim / centre brightness: front-lit {f:.3}, back-lit {b:.3}");
}

#[test]
fn a_deforming_mesh_plays_pauses_and_matches_render() {
    if !have_xvfb() {
        return;
    }
    let (a, b, c) = (png("deform-a"), png("deform-b"), png("deform-c"));
    let mut args = vec!["--mesh", "box", "--deform", "twist:90", "--deform-period", "2"];
    args.extend_from_slice(&SCENE[2..]);
    let lines = [
        "pause".to_string(),
        format!("screenshot {}", a.display()),
        "pause".into(),
        // Steps 0 (the box) and 1 (twisted 90°), then held there.
        "frames 2".into(),
        "pause".into(),
        format!("screenshot {}", b.display()),
        "frames 2".into(),
        format!("screenshot {}", c.display()),
        "quit".into(),
    ];
    let lines: Vec<&str> = lines.iter().map(|s| s.as_str()).collect();
    assert_ok("deform", &view("deform", &args, &lines));
    let (a, b, c) = (load(&a), load(&b), load(&c));
    assert!(output::compare(&a, &b).unwrap().differing_fraction > 0.05, "the twist must show");
    let held = output::compare(&b, &c).unwrap();
    assert!(held.rmse < 0.5, "paused: the mesh must stay: {held:?}");

    // `render --frames 2` writes the same two steps.
    let out = output_dir().join("view-deform-render-{frame}.png");
    let mut render = vec!["render", "--validation"];
    render.extend_from_slice(&args);
    render.extend_from_slice(&["--frames", "2", "--out", out.to_str().unwrap()]);
    let result = translucent(&render);
    assert!(result.status.success(), "{}", stderr(&result));
    let rendered = load(&output_dir().join("view-deform-render-0001.png"));
    let same = output::compare(&b, &rendered).unwrap();
    assert!(same.rmse < 0.5 && same.differing_fraction < 0.001, "view and render differ: {same:?}");
}

#[test]
fn panel_settings_take_effect_on_the_next_frame() {
    if !have_xvfb() {
        return;
    }
    let shots: Vec<PathBuf> =
        ["plain", "samples", "brute", "dipole"].iter().map(|n| png(&format!("panel-{n}"))).collect();
    let lines = [
        "set samples 1024".to_string(),
        format!("screenshot {}", shots[0].display()),
        "set show samples".into(),
        format!("screenshot {}", shots[1].display()),
        "set show shading".into(),
        "set brute-force on".into(),
        format!("screenshot {}", shots[2].display()),
        "set brute-force off".into(),
        "set model dipole".into(),
        "set specular off".into(),
        "set eta 1.3".into(),
        "set epsilon 0.2".into(),
        "set exposure 1".into(),
        format!("screenshot {}", shots[3].display()),
        "quit".into(),
    ];
    let lines: Vec<&str> = lines.iter().map(|s| s.as_str()).collect();
    let out = view("panel", SCENE, &lines);
    assert_ok("panel", &out);
    let images: Vec<_> = shots.iter().map(|p| load(p)).collect();
    let differs = |i: usize| output::compare(&images[0], &images[i]).unwrap();
    assert!(differs(1).differing_fraction > 0.01, "the sample points must show: {:?}", differs(1));
    // Brute force and the tree agree closely (the tree's error at ε = 0.1 is about 1%).
    assert!(differs(2).rmse < 4.0, "brute force vs tree: {:?}", differs(2));
    assert!(differs(3).rmse > 5.0, "model, specular, η, ε and exposure changed: {:?}", differs(3));
    // Each full frame prints its per-pass GPU times.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.lines().any(|l| l.contains("1024 points") && l.contains("shade") && l.contains("tone mapping")),
        "{stdout}"
    );
}

#[test]
fn bad_script_line_exits_2_naming_the_line() {
    let script = output_dir().join("bad.script");
    std::fs::write(&script, "orbit 10 0\nzoom 1.2\norbitt 5 5\nquit\n").unwrap();
    // Checked before any window opens, so no X server is needed.
    let out = translucent(&["view", "--mesh", "sphere", "--script", script.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.lines().any(|l| l.starts_with("error:") && l.contains("line 3") && l.contains("orbitt")), "{err}");
}

#[test]
fn without_a_window_system_view_exits_2_suggesting_render() {
    let out = Command::new(env!("CARGO_BIN_EXE_translucent"))
        .args(["view", "--mesh", "sphere"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.lines().any(|l| l.starts_with("error:") && l.contains("translucent render")), "{err}");
}

/// Real key presses while a preview is shading (xdotool on a plain Xvfb, as a user's hands):
/// brute force on (a slow preview begins), then, while it shades, the model switched, ε halved
/// and brute force off again. The viewer goes on (it once exited 1 with "the pipeline for model 0
/// was not prepared") and its last image equals the same settings given before it started.
#[test]
fn keys_pressed_while_a_preview_shades_end_in_the_image_of_the_same_settings() {
    if !have_xvfb() {
        return;
    }
    let Some(xdotool) = ["/usr/bin/xdotool", "/usr/local/bin/xdotool"].into_iter().find(|p| Path::new(p).is_file())
    else {
        eprintln!("skipped: xdotool is not installed (scripts/setup-debian installs it)");
        return;
    };
    let one_at_a_time = XVFB.lock().unwrap_or_else(|e| e.into_inner());
    // A preview of brute force over 60k points takes about a second on lavapipe.
    let scene = ["--mesh", "sphere", "--width", "256", "--height", "192", "--samples", "60000", "--exposure", "0"];
    let shot = png("keys-during-preview");
    let xdo = |display: &str, args: &[&str]| {
        let mut cmd = Command::new("timeout");
        cmd.arg("20").arg(xdotool).args(args).env("DISPLAY", display);
        let out = cmd.output().expect("run xdotool");
        String::from_utf8_lossy(&out.stdout).trim().to_string()
    };
    // A fresh Xvfb and the viewer on it, until its window shows. A second try where the viewer
    // could not connect to a server that had answered xdotool (once in a CI run, after the other
    // tests' `xvfb-run -a` servers): the X server's doing, not the viewer's.
    let mut attempt = 0;
    let (mut xvfb, display, viewer, window) = loop {
        attempt += 1;
        let mut xvfb = Command::new("Xvfb")
            .args(["-displayfd", "1", "-screen", "0", "640x480x24", "-nolisten", "tcp"])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("start Xvfb");
        let display = {
            use std::io::BufRead;
            let mut line = String::new();
            std::io::BufReader::new(xvfb.stdout.take().unwrap()).read_line(&mut line).unwrap();
            format!(":{}", line.trim())
        };
        let _ = std::fs::remove_file(&shot);
        // The server takes connections (a viewer started before it did once failed to connect,
        // in a CI run under load): at most ten seconds.
        let ready = (0..100).any(|_| {
            let up = !xdo(&display, &["getdisplaygeometry"]).is_empty();
            if !up {
                std::thread::sleep(std::time::Duration::from_millis(100));
            }
            up
        });
        assert!(ready, "Xvfb on {display} takes no connections");
        // Bounded: a viewer that missed its `q` ends after three minutes, failing the test.
        let mut viewer = Command::new("timeout")
            .args(["180", env!("CARGO_BIN_EXE_translucent")])
            .args(["view", "--validation", "--no-panel", "--screenshot", shot.to_str().unwrap()])
            .args(scene)
            .env("DISPLAY", &display)
            .env("RUST_LOG", "translucent=debug")
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("start the viewer");
        let window = (0..600).find_map(|_| {
            let id = xdo(&display, &["search", "--name", "translucent"]);
            if id.is_empty() {
                if let Ok(Some(_)) = viewer.try_wait() {
                    return Some(None); // exited: no window will come
                }
                std::thread::sleep(std::time::Duration::from_millis(100));
                None
            } else {
                Some(Some(id.lines().next().unwrap_or_default().to_string()))
            }
        });
        if let Some(Some(window)) = window {
            break (xvfb, display, viewer, window);
        }
        // Say why: the viewer's status and what it printed (it may have exited at start).
        let _ = viewer.kill();
        let out = viewer.wait_with_output().expect("the viewer exits");
        let _ = xvfb.kill();
        let _ = xvfb.wait();
        let err = stderr(&out);
        if attempt < 2 && err.contains("Failed to open connection to X server") {
            eprintln!("the viewer could not connect to Xvfb on {display}; a fresh server:\n{err}");
            continue;
        }
        panic!("the viewer's window did not appear within a minute; exit {:?}:\n{err}", out.status.code());
    };
    let xdo = |args: &[&str]| xdo(&display, args);
    xdo(&["windowfocus", "--sync", &window]);
    // The first frame (full, 256x192) first; then the keys.
    std::thread::sleep(std::time::Duration::from_secs(4));
    xdo(&["key", "b"]);
    std::thread::sleep(std::time::Duration::from_millis(400));
    xdo(&["key", "d"]);
    xdo(&["key", "bracketleft"]);
    xdo(&["key", "b"]);
    std::thread::sleep(std::time::Duration::from_millis(300));
    xdo(&["key", "q"]);
    let out = viewer.wait_with_output().expect("the viewer exits");
    let _ = xvfb.kill();
    let _ = xvfb.wait();
    drop(one_at_a_time);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(0), "exit {:?}:\n{err}", out.status.code());
    assert!(!err.contains("vulkan validation"), "validation messages:\n{err}");
    assert!(err.contains("Preview frame begun"), "a preview was shading when the keys came:\n{err}");

    let reference = png("keys-reference");
    let mut args = scene.to_vec();
    args.extend_from_slice(&["--no-panel", "--model", "dipole", "--epsilon", "0.1"]);
    let lines = ["frames 1".to_string(), format!("screenshot {}", reference.display()), "quit".to_string()];
    assert_ok("keys-reference", &view("keys-reference", &args, &lines.each_ref().map(|l| l.as_str())));
    assert!(load(&shot) == load(&reference), "the last image differs from the same settings given at the start");
}

/// `view SCENE.pbrt` reads the scene as `render` does: the window takes the film's size, and its
/// screenshot equals `render SCENE.pbrt` (a translucent sphere on an opaque checker floor).
#[test]
fn a_scene_file_in_the_viewer_equals_its_render() {
    if !have_xvfb() {
        return;
    }
    let dir = output_dir().join("view-scene");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = r#"LookAt 0 2.5 5  0 0.4 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 120 ] "integer yresolution" [ 90 ]
WorldBegin
LightSource "distant" "point3 from" [ 0.3 1 0.2 ] "point3 to" [ 0 0 0 ] "rgb L" [ 2 2 2 ]
AttributeBegin
  Material "subsurface" "string name" "Skin1" "float scale" 10
  Translate 0 0.8 0
  Shape "sphere" "float radius" 0.8
AttributeEnd
Texture "checks" "spectrum" "checkerboard" "float uscale" [ 8 ] "float vscale" [ 8 ] "rgb tex1" [ .1 .1 .1 ] "rgb tex2" [ .8 .8 .8 ]
Material "diffuse" "texture reflectance" "checks"
Shape "trianglemesh" "integer indices" [ 0 2 1 0 3 2 ] "point3 P" [ -4 0 -4 4 0 -4 4 0 4 -4 0 4 ] "point2 uv" [ 0 0 1 0 1 1 0 1 ]
"#;
    let path = dir.join("scene.pbrt");
    std::fs::write(&path, scene).unwrap();
    let (shot, rendered) = (png("scene-file"), png("scene-file-render"));
    let line = format!("screenshot {}", shot.display());
    let args = [path.to_str().unwrap(), "--samples", "4096", "--exposure", "0", "--no-panel"];
    assert_ok("scene-file", &view("scene-file", &args, &["frames 1", &line, "quit"]));
    let out = translucent(&[
        "render",
        "--validation",
        path.to_str().unwrap(),
        "--samples",
        "4096",
        "--exposure",
        "0",
        "--out",
        rendered.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (load(&shot), load(&rendered));
    assert_eq!((a.width(), a.height()), (120, 90), "the window takes the film's size");
    assert!(a == b, "the viewer's screenshot differs from render's image");
}

/// `view SCENE.glb` reads a glTF scene as `render` does: the window takes the size its camera's
/// aspect ratio gives (4:3 at `--height 90`), and its screenshot equals `render SCENE.glb` (a
/// translucent box under a directional light, seen by the file's camera).
#[test]
fn a_gltf_scene_in_the_viewer_equals_its_render() {
    if !have_xvfb() {
        return;
    }
    let dir = output_dir().join("view-gltf");
    std::fs::create_dir_all(&dir).unwrap();
    let cube = translucent::mesh::Mesh::slab(0.05, 0.05, 0.05);
    let mut bin: Vec<u8> = cube.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
    let positions = bin.len();
    bin.extend(cube.indices.iter().flat_map(|i| i.to_le_bytes()));
    let json = serde_json::json!({
        "asset": {"version": "2.0"}, "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [{"mesh": 0, "rotation": [0.0, 0.3826834, 0.0, 0.9238795]},
                  {"camera": 0, "translation": [0.0, 0.06, 0.2], "rotation": [-0.1478094, 0.0, 0.0, 0.9890159]},
                  {"rotation": [-0.5, 0.0, 0.0, 0.8660254], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6, "aspectRatio": 1.3333334, "znear": 0.01}}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 2.0}]}},
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.6, 0.4, 1.0]},
                       "extensions": {"KHR_materials_volume": {"attenuationDistance": 0.002},
                                      "KHR_materials_transmission": {"transmissionFactor": 1.0}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "type": "VEC3", "count": cube.positions.len(),
                       "min": [-0.025, -0.025, -0.025], "max": [0.025, 0.025, 0.025]},
                      {"bufferView": 1, "componentType": 5125, "type": "SCALAR", "count": cube.indices.len()}],
        "bufferViews": [{"buffer": 0, "byteLength": positions}, {"buffer": 0, "byteOffset": positions, "byteLength": bin.len() - positions}],
        "buffers": [{"byteLength": bin.len(), "uri": "box.bin"}]
    });
    std::fs::write(dir.join("box.bin"), &bin).unwrap();
    let path = dir.join("box.gltf");
    std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
    let (shot, rendered) = (png("gltf-file"), png("gltf-file-render"));
    let line = format!("screenshot {}", shot.display());
    let args = [path.to_str().unwrap(), "--height", "90", "--samples", "4096", "--exposure", "0", "--no-panel"];
    assert_ok("gltf-file", &view("gltf-file", &args, &["frames 1", &line, "quit"]));
    let out = translucent(&[
        "render",
        "--validation",
        path.to_str().unwrap(),
        "--height",
        "90",
        "--samples",
        "4096",
        "--exposure",
        "0",
        "--out",
        rendered.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (load(&shot), load(&rendered));
    assert_eq!((a.width(), a.height()), (120, 90), "the window takes the camera's aspect ratio");
    assert!(a.pixels().filter(|p| p[3] > 0).count() > 500, "the box is in view");
    assert!(a == b, "the viewer's screenshot differs from render's image");
}

/// The environment and the lights are edited from a script as the panel edits them (issue #28):
/// a sky set, scaled, turned and sampled, a point light added and the first light moved give the
/// image `render` gives with the same flags.
#[test]
fn environment_and_lights_edited_in_the_viewer_equal_render() {
    if !have_xvfb() {
        return;
    }
    let shot = png("env-lights");
    let mut args = SCENE.to_vec();
    args.extend_from_slice(&["--light", "dir:0,1,0"]);
    let lines = [
        "env sky:20:90".to_string(),
        "env scale 0.5".into(),
        "env rotate 30".into(),
        "env samples 16".into(),
        "light add point:1.5,1,1:4".into(),
        "light 1 dir:-0.5,0.8,0.6".into(),
        format!("screenshot {}", shot.display()),
        "quit".into(),
    ];
    let lines: Vec<&str> = lines.iter().map(|s| s.as_str()).collect();
    assert_ok("env-lights", &view("env-lights", &args, &lines));
    let rendered = png("env-lights-render");
    let mut render = vec!["render", "--validation"];
    render.extend_from_slice(SCENE);
    render.extend_from_slice(&[
        "--light",
        "dir:-0.5,0.8,0.6",
        "--light",
        "point:1.5,1,1:4",
        "--env",
        "sky:20:90",
        "--env-scale",
        "0.5",
        "--env-rotate",
        "30",
        "--env-samples",
        "16",
        "--out",
        rendered.to_str().unwrap(),
    ]);
    assert_screenshot_equals_render(&shot, &render, &rendered);
}

/// A scene of `diffuse` shapes only (issue #28) in the viewer: the warning that nothing is
/// translucent, its screenshot equals its render, and a script's material edit is refused naming
/// the line (exit 2).
#[test]
fn a_scene_of_diffuse_shapes_only_in_the_viewer_equals_its_render() {
    if !have_xvfb() {
        return;
    }
    let dir = output_dir().join("view-diffuse-only");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = r#"LookAt 0 2.5 5  0 0.4 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "rgb" "integer xresolution" [ 80 ] "integer yresolution" [ 60 ]
WorldBegin
LightSource "distant" "point3 from" [ 0.3 1 0.2 ] "point3 to" [ 0 0 0 ] "rgb L" [ 2 2 2 ]
Material "diffuse" "rgb reflectance" [ 0.7 0.5 0.3 ]
AttributeBegin
  Translate 0 0.8 0
  Shape "sphere" "float radius" 0.8
AttributeEnd
Shape "trianglemesh" "integer indices" [ 0 2 1 0 3 2 ] "point3 P" [ -4 0 -4 4 0 -4 4 0 4 -4 0 4 ]
"#;
    let path = dir.join("diffuse.pbrt");
    std::fs::write(&path, scene).unwrap();
    let (shot, rendered) = (png("diffuse-only"), png("diffuse-only-render"));
    let line = format!("screenshot {}", shot.display());
    let args = [path.to_str().unwrap(), "--exposure", "0"];
    let out = view("diffuse-only", &args, &["frames 1", &line, "quit"]);
    assert_ok("diffuse-only", &out);
    assert!(stderr(&out).contains("nothing in the scene is translucent"), "{}", stderr(&out));
    let out = translucent(&[
        "render",
        "--validation",
        path.to_str().unwrap(),
        "--exposure",
        "0",
        "--out",
        rendered.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (load(&shot), load(&rendered));
    assert!(a == b, "the viewer's screenshot differs from render's image");
    assert!(mean_colour(&a)[0] > 20.0, "lit: {:?}", mean_colour(&a));
    let out = view("diffuse-only-material", &args, &["material marble", "quit"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("line 1") && err.contains("no translucent object"), "{err}");
}

/// Runs `render` (arguments writing `rendered`) and asserts the viewer's screenshot `shot` equals
/// it: the same frame code on the same device, equal but for nothing.
fn assert_screenshot_equals_render(shot: &Path, render: &[&str], rendered: &Path) {
    let out = translucent(render);
    assert!(out.status.success(), "{}", stderr(&out));
    let diff = output::compare(&load(shot), &load(rendered)).unwrap();
    assert!(diff.rmse < 0.5 && diff.differing_fraction < 0.001, "{diff:?}");
}

/// A textured translucent mesh (an OBJ's `map_Kd`) keeps its colour when the viewer's script
/// changes its material and model: the screenshot equals `render` with `--material` and
/// `--model` typed (the preset's mean free path, the texture's mean as its albedo, the texture
/// weighing it per point), and the two halves keep their colours.
#[test]
fn a_textured_mesh_edited_in_the_viewer_equals_render() {
    if !have_xvfb() {
        return;
    }
    let dir = output_dir().join("view-textured");
    std::fs::create_dir_all(&dir).unwrap();
    let obj = common::box_obj(1.0, 0.3, true);
    std::fs::write(dir.join("box.obj"), obj).unwrap();
    std::fs::write(dir.join("box.mtl"), "newmtl painted\nmap_Kd colours.png\n").unwrap();
    let map = image::RgbImage::from_fn(8, 1, |x, _| image::Rgb(if x < 4 { [230, 160, 120] } else { [90, 60, 200] }));
    map.save(dir.join("colours.png")).unwrap();
    let mesh = dir.join("box.obj");
    let common =
        ["--mesh", mesh.to_str().unwrap(), "--width", "96", "--height", "72", "--samples", "8192", "--exposure", "0"];
    let (shot, rendered) = (png("textured"), png("textured-render"));
    let line = format!("screenshot {}", shot.display());
    let mut args = common.to_vec();
    args.push("--no-panel");
    let script = ["material skin1", "set model dipole", "frames 1", &line, "quit"];
    assert_ok("textured", &view("textured", &args, &script));
    let mut render_args = vec!["render", "--validation"];
    render_args.extend(common);
    render_args.extend(["--material", "skin1", "--model", "dipole", "--out", rendered.to_str().unwrap()]);
    let out = translucent(&render_args);
    assert!(out.status.success(), "{}", stderr(&out));
    let (a, b) = (load(&shot), load(&rendered));
    assert!(a == b, "the viewer's screenshot differs from render's image");
    // The left half warm, the right half blue (the mean over each half's covered pixels).
    let w = a.width();
    let half = |left: bool| {
        let mut sum = [0.0f64; 3];
        for (_, _, p) in a.enumerate_pixels().filter(|(x, _, p)| p[3] > 0 && (*x < w / 2) == left) {
            (0..3).for_each(|c| sum[c] += p[c] as f64);
        }
        sum
    };
    let (l, r) = (half(true), half(false));
    assert!(l[0] > l[2] && r[2] > r[0], "the halves' colours: {l:?} {r:?}");
}
