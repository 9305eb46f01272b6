//! The reliability contract through the binary (issue #12): exit 0 on success; 2 with an
//! `error:` line naming the flag or file for bad input; 1 for a failure at run time (a full disk,
//! a closed pipe, a validation message); never a panic, a hang, a NaN image or unbounded memory.
//! One section per class of the issue.

mod common;

use std::io::{Read, Write};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{output_dir, repo_path, stderr};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_translucent"))
}

/// Runs with a deadline: a hang fails the test instead of blocking the suite.
fn run_with_timeout(mut cmd: Command, seconds: u64) -> Output {
    let mut child = cmd.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > Duration::from_secs(seconds) {
            child.kill().ok();
            let out = child.wait_with_output().unwrap();
            panic!("{cmd:?} did not finish in {seconds} s (hang); stderr:\n{}", stderr(&out));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn run(args: &[&str], seconds: u64) -> Output {
    let mut cmd = bin();
    cmd.args(args);
    run_with_timeout(cmd, seconds)
}

/// Exit 2, an `error:` line mentioning `needle`, no panic.
fn assert_bad_input(out: &Output, needle: &str, what: &str) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(2), "{what}: expected exit 2, stderr:\n{err}");
    assert!(
        err.lines().any(|l| l.starts_with("error:") && err.contains(needle)),
        "{what}: no `error:` naming {needle:?}:\n{err}"
    );
    assert!(!err.contains("panicked"), "{what}: {err}");
}

fn assert_runtime_failure(out: &Output, needle: &str, what: &str) {
    let err = stderr(out);
    assert_eq!(out.status.code(), Some(1), "{what}: expected exit 1, stderr:\n{err}");
    assert!(err.contains("error:") && err.contains(needle), "{what}: no `error:` naming {needle:?}:\n{err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
}

fn tmp(name: &str) -> String {
    output_dir().join(name).to_string_lossy().into_owned()
}

fn csv_header() -> String {
    translucent::bssrdf_csv::COLUMNS.join(",")
}

const GOOD_ROW: &str = "0.01,1,0,1.3,0,0,0,0,0,1,0,0,1,1,0,0,0,0,1";

fn bssrdf(args: &[&str], input: Vec<u8>) -> Output {
    let mut child = common::spawn_bssrdf(args);
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().ok();
    out
}

// 1. Hangs.

#[test]
fn class1_profile_with_nothing_positive_or_absurd_ranges_ends() {
    let png = tmp("hang.png");
    for args in [
        vec!["--sigma-s", "0"],
        vec!["--sigma-s", "0", "--sigma-a", "0"],
        vec!["--sigma-s", "1e-300", "--sigma-a", "1e-300"],
        vec!["--r-min", "1e-300", "--r-max", "1e300"],
    ] {
        let mut full = vec!["profile", "--out", &png];
        full.extend(&args);
        let out = run(&full, 60);
        assert_bad_input(&out, "--", &format!("{args:?}"));
    }
    // The same material to CSV has values to list: it works.
    let csv = tmp("hang.csv");
    let out = run(&["profile", "--sigma-s", "0", "--out", &csv], 60);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn class1_and_4_mesh_that_is_not_a_regular_file_is_refused_at_once() {
    let fifo = tmp("mesh.fifo");
    std::fs::remove_file(&fifo).ok();
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    for mesh in [fifo.as_str(), "/dev/zero", "/tmp"] {
        let out = run(&["render", "--mesh", mesh, "--width", "8", "--height", "8", "--out", &tmp("x.png")], 30);
        assert_bad_input(&out, mesh, mesh);
        assert!(stderr(&out).contains("not a regular file"), "{}", stderr(&out));
    }
    std::fs::remove_file(&fifo).ok();
}

// 2. Output that cannot be written.

#[test]
fn class2_full_or_closed_stdout_and_stderr_never_panic() {
    // stdout on a full disk: exit 1, named.
    let full = std::fs::File::create("/dev/full").unwrap();
    let out = bin().arg("materials").stdout(full).stderr(Stdio::piped()).output().unwrap();
    assert_runtime_failure(&out, "stdout", "materials > /dev/full");
    // A closed pipe (the reader is gone before anything is written): exit 1, named.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = bin().arg("materials").stdout(writer).stderr(Stdio::piped()).output().unwrap();
    assert_runtime_failure(&out, "stdout", "materials | (closed)");
    // render's profile report on a closed pipe.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let png = tmp("pipe.png");
    let out = bin()
        .args(["render", "--mesh", "sphere", "--width", "8", "--height", "8", "--out", &png])
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert_runtime_failure(&out, "stdout", "render | (closed)");
    // stderr on a full disk: the exit code still tells, no panic (101).
    for (args, code) in [(vec!["profile", "--sigma-s", "nan"], 2), (vec!["materials"], 0), (vec![], 2)] {
        let full = std::fs::File::create("/dev/full").unwrap();
        let out = bin().args(&args).stdout(Stdio::null()).stderr(full).output().unwrap();
        assert_eq!(out.status.code(), Some(code), "{args:?} 2>/dev/full");
    }
    // --help and --version to a full stdout are failures too, named as every other command's.
    for args in [vec!["--help"], vec!["--version"], vec!["render", "--help"], vec!["bench", "-h"], vec!["help", "view"]]
    {
        let full = std::fs::File::create("/dev/full").unwrap();
        let out = bin().args(&args).stdout(full).stderr(Stdio::piped()).output().unwrap();
        assert_runtime_failure(&out, "stdout", &format!("{args:?} > /dev/full"));
        assert!(stderr(&out).contains("error: stdout: No space left on device"), "{args:?}: {}", stderr(&out));
    }
}

// 3. Silently wrong output: a full disk.

#[test]
fn class3_a_full_disk_is_an_error_not_success() {
    for ext in ["png", "svg", "csv"] {
        let link = tmp(&format!("full.{ext}"));
        std::fs::remove_file(&link).ok();
        std::os::unix::fs::symlink("/dev/full", &link).unwrap();
        let out = run(&["profile", "--out", &link], 60);
        assert_runtime_failure(&out, "No space left", &format!("profile --out {link}"));
        std::fs::remove_file(&link).ok();
    }
    // A render to a full disk, small enough to fit any write buffer: exit 1, not 0.
    for (flag, name) in [("--out", "full-render.png"), ("--out", "full-render.exr"), ("--profile-out", "full.json")] {
        let link = tmp(name);
        std::fs::remove_file(&link).ok();
        std::os::unix::fs::symlink("/dev/full", &link).unwrap();
        let mut args = vec!["render", "--mesh", "sphere", "--width", "8", "--height", "8", flag, &link];
        let other = tmp("full-other.png");
        if flag == "--profile-out" {
            args.extend(["--out", &other]);
        }
        let out = run(&args, 120);
        assert_runtime_failure(&out, "No space left", &format!("render {flag} {link}"));
        std::fs::remove_file(&link).ok();
    }
}

#[test]
fn class3_bssrdf_gpu_refuses_rows_beyond_f32() {
    let input = format!("{}\n{GOOD_ROW}\n1e30,1e30,0,1.3,0,0,0,0,0,1,0,0,1,1e-30,0,0,0,0,1\n", csv_header());
    let out = bssrdf(&["--gpu", "--validation"], input.into_bytes());
    assert_bad_input(&out, "line 3", "sigma 1e30 on the GPU");
    assert!(stderr(&out).contains("f32"), "{}", stderr(&out));
}

// 4. Unbounded memory: bssrdf streams.

#[test]
fn class4_bssrdf_writes_output_before_the_input_ends() {
    for args in [&[][..], &["--gpu", "--validation"][..]] {
        bssrdf_streams(args);
    }
}

fn bssrdf_streams(args: &[&str]) {
    let rows = translucent::bssrdf_csv::BATCH_ROWS + 10;
    let mut child = common::spawn_bssrdf(args);
    let mut stdin = child.stdin.take().unwrap();
    let mut input = csv_header() + "\n";
    for _ in 0..rows {
        input += GOOD_ROW;
        input += "\n";
    }
    stdin.write_all(input.as_bytes()).unwrap();
    // stdin stays open: a first batch of results must come out all the same.
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut seen = Vec::new();
        let mut buf = [0u8; 1 << 16];
        while seen.iter().filter(|&&b| b == b'\n').count() < translucent::bssrdf_csv::BATCH_ROWS {
            let n = stdout.read(&mut buf).unwrap();
            assert!(n > 0, "stdout closed early");
            seen.extend_from_slice(&buf[..n]);
        }
        stdout
    });
    let start = Instant::now();
    while !reader.is_finished() {
        assert!(start.elapsed() < Duration::from_secs(60), "no output while the input is still open");
        std::thread::sleep(Duration::from_millis(20));
    }
    let mut stdout = reader.join().unwrap();
    drop(stdin);
    let mut rest = Vec::new();
    stdout.read_to_end(&mut rest).unwrap();
    assert!(child.wait().unwrap().success(), "{args:?}");
}

#[test]
fn class4_a_line_without_end_is_refused_with_bounded_memory() {
    let out = bssrdf(&[], vec![b'1'; 4 << 20]);
    assert_bad_input(&out, "line 1", "4 MiB without a line end");
}

// 6. Exit codes and flags named.

#[test]
fn class6_usage_errors_name_the_flag() {
    let out = run(&[], 10);
    assert_bad_input(&out, "command", "bare translucent");
    for (flag, value) in [("--shadow-resolution", "-1"), ("--level", "-1"), ("--device", "-1")] {
        let out = run(
            &["render", flag, value, "--mesh", "sphere", "--width", "8", "--height", "8", "--out", &tmp("n.png")],
            60,
        );
        assert_bad_input(&out, flag, flag);
    }
    let out = run(&["bench", "--samples", "0"], 30);
    assert_bad_input(&out, "--samples", "bench --samples 0");
    let out = run(&["bench", "--device", "99", "--meshes", "sphere", "--samples", "64", "--accuracy-size", "0"], 60);
    assert_bad_input(&out, "--device 99", "bench --device 99");
}

#[test]
fn class6_output_paths_are_checked_first() {
    let dir = output_dir().to_string_lossy().into_owned();
    let folder_png = tmp("folder.png");
    std::fs::create_dir_all(&folder_png).unwrap();
    let start = Instant::now();
    let out = run(&["render", "--out", &folder_png, "--mesh", "sphere"], 30);
    assert_bad_input(&out, "--out", "--out a folder");
    let out = run(&["render", "--profile-out", &dir, "--mesh", "sphere"], 30);
    assert_bad_input(&out, "--profile-out", "--profile-out a folder");
    assert!(start.elapsed() < Duration::from_secs(20), "refused only after rendering");
    let out = run(&["profile", "--out", "/missing/p.png"], 30);
    assert_bad_input(&out, "--out /missing/p.png", "profile into a missing folder");
    assert!(!stderr(&out).contains("BackendError"));
    // A place that cannot take a file (procfs refuses to create one, even for root).
    let out = run(&["profile", "--out", "/proc/p.csv"], 30);
    assert_bad_input(&out, "cannot be written", "profile into /proc");
    let out = run(&["render", "--out", "/proc/r.png", "--mesh", "sphere"], 30);
    assert_bad_input(&out, "--out /proc/r.png: cannot be written", "render into /proc");
}

#[test]
fn class6_csv_encoding_and_line_ends() {
    let header = csv_header();
    let mut latin1 = format!("{header}\n").into_bytes();
    latin1.extend_from_slice(b"0.01,\xff\n");
    let out = bssrdf(&[], latin1);
    assert_bad_input(&out, "line 2: not UTF-8", "non-UTF-8 row");
    // A byte-order mark is skipped; CRLF works; CR-only is refused, saying so.
    let out = bssrdf(&[], format!("\u{feff}{header}\r\n{GOOD_ROW}\r\n").into_bytes());
    assert!(out.status.success(), "{}", stderr(&out));
    let out = bssrdf(&[], format!("{header}\r{GOOD_ROW}\r").into_bytes());
    assert_bad_input(&out, "CR-only", "CR line ends");
    // Long but valid vectors are directions, not "zero length".
    let out = bssrdf(&[], format!("{header}\n0.01,1,0,1.3,0,0,0,0,0,1e308,0,1e308,1e308,1,0,0,0,0,1\n").into_bytes());
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn class6_obj_encoding_and_line_ends() {
    let text = std::fs::read_to_string(repo_path("tests/data/tetra_two_objects.obj")).unwrap();
    let lf = translucent::mesh::Mesh::from_obj_bytes(text.as_bytes(), "lf").unwrap();
    for (name, bytes) in [
        ("bom", format!("\u{feff}{text}").into_bytes()),
        ("crlf", text.replace('\n', "\r\n").into_bytes()),
        ("cr", text.replace('\n', "\r").into_bytes()),
    ] {
        let mesh = translucent::mesh::Mesh::from_obj_bytes(&bytes, name).unwrap();
        assert_eq!(mesh.indices, lf.indices, "{name}");
    }
    let err = translucent::mesh::Mesh::from_obj_bytes(b"v 0 0 0\xff\n", "latin1.obj").unwrap_err();
    assert_eq!(err.exit_code(), 2);
    assert!(err.to_string().contains("latin1.obj") && err.to_string().contains("UTF-8"), "{err}");
}

// 3. No NaN reaches an output file; vectors that overflow f32 are normalised safely or refused.

/// Renders a small EXR of the sphere and returns its pixels, or the failed output.
fn render_exr(name: &str, args: &[&str]) -> Result<Vec<[f32; 4]>, Output> {
    let exr = tmp(&format!("{name}.exr"));
    std::fs::remove_file(&exr).ok();
    let mut full = vec!["render", "--validation", "--width", "24", "--height", "24", "--out", &exr];
    if !args.contains(&"--mesh") {
        full.extend(["--mesh", "sphere"]);
    }
    full.extend(args);
    let out = run(&full, 120);
    if !out.status.success() {
        assert!(!std::path::Path::new(&exr).exists(), "{name}: a failed render left {exr}");
        return Err(out);
    }
    let img = image::open(&exr).unwrap().into_rgba32f();
    Ok(img.pixels().map(|p| p.0).collect())
}

fn covered_and_lit(pixels: &[[f32; 4]]) -> (usize, usize) {
    let covered = pixels.iter().filter(|p| p[3] > 0.0).count();
    let lit = pixels.iter().filter(|p| p[3] > 0.0 && p[0] + p[1] + p[2] > 0.0).count();
    (covered, lit)
}

#[test]
fn class3_huge_vectors_render_finite_images_or_are_refused() {
    let obj = tmp("huge-normals.obj");
    let sphere = translucent::mesh::Mesh::sphere(1.0, 8);
    let mut text = String::new();
    for (p, n) in sphere.positions.iter().zip(&sphere.normals) {
        text += &format!("v {} {} {}\nvn {} {} {}\n", p.x, p.y, p.z, n.x * 1e38, n.y * 1e38, n.z * 1e38);
    }
    for t in sphere.indices.chunks_exact(3) {
        text += &format!("f {a}//{a} {b}//{b} {c}//{c}\n", a = t[0] + 1, b = t[1] + 1, c = t[2] + 1);
    }
    std::fs::write(&obj, text).unwrap();
    let reference = render_exr("reference", &[]).unwrap();
    for (name, args) in [
        ("light-dir", vec!["--light-dir", "1e20,1e20,1e20"]),
        ("light-spec", vec!["--light", "dir:1e30,1e30,0"]),
        ("up", vec!["--up", "1e20,1e20,0"]),
        ("normals", vec!["--mesh", obj.as_str()]),
    ] {
        let pixels = render_exr(name, &args).unwrap_or_else(|out| panic!("{name}: {}", stderr(&out)));
        assert!(pixels.iter().flatten().all(|v| v.is_finite()), "{name}: non-finite pixels");
        let (covered, lit) = covered_and_lit(&pixels);
        assert!(covered > 100 && lit > covered / 3, "{name}: {covered} covered, {lit} lit");
    }
    let (covered, _) = covered_and_lit(&reference);
    assert!(covered > 100);
    for (flag, value) in [("--scale", "1e20"), ("--eye", "1e20,0,0"), ("--light", "point:1e20,0,0")] {
        let out = render_exr("refused", &[flag, value]).unwrap_err();
        assert_bad_input(&out, flag, flag);
    }
}

#[test]
fn class3_gpu_output_guard_fails_a_frame_with_non_finite_radiance() {
    // Irradiance near f32's largest value: the tree's power sums overflow on the GPU.
    let out = render_exr("overflow", &["--light-intensity", "3e38"]).unwrap_err();
    assert_runtime_failure(&out, "non-finite radiance", "overflowing light");
    let mut cmd = bin();
    cmd.env("TRANSLUCENT_CHECK_PASSES", "1").args([
        "render",
        "--mesh",
        "sphere",
        "--width",
        "24",
        "--height",
        "24",
        "--light-intensity",
        "3e38",
        "--out",
        &tmp("overflow.png"),
    ]);
    let out = run_with_timeout(cmd, 120);
    assert_runtime_failure(&out, "first pass with a non-finite output: tree summaries", "debug flag names the pass");
    assert!(!std::path::Path::new(&tmp("overflow.png")).exists());
}

// 7. Dark images without a word: inside-out meshes and tiny ones.

fn cube_obj(size: f64, inward: bool) -> String {
    let v: Vec<[f64; 3]> =
        (0..8).map(|i| [(i >> 2 & 1) as f64 * size, (i >> 1 & 1) as f64 * size, (i & 1) as f64 * size]).collect();
    // Counter-clockwise seen from outside.
    let faces = [[1, 2, 4, 3], [5, 7, 8, 6], [1, 5, 6, 2], [3, 4, 8, 7], [1, 3, 7, 5], [2, 6, 8, 4]];
    let mut text: String = v.iter().map(|p| format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2])).collect();
    for f in faces {
        let f: Vec<i32> = if inward { f.iter().rev().copied().collect() } else { f.to_vec() };
        text += &format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]);
    }
    text
}

#[test]
fn class7_inside_out_meshes_are_turned_outward_with_a_warning() {
    use translucent::mesh::Mesh;
    let outward = Mesh::from_obj_bytes(cube_obj(1.0, false).as_bytes(), "out.obj").unwrap();
    assert!(outward.signed_volume() > 0.9);
    let turned = Mesh::from_obj_bytes(cube_obj(1.0, true).as_bytes(), "in.obj").unwrap();
    assert!(turned.signed_volume() > 0.9, "winding turned outward");
    assert!(turned.normal_agreement() > 0.0);
    // Inward vn on an outward-wound sphere: turned.
    let sphere = Mesh::sphere(1.0, 8);
    let mut text = String::new();
    for (p, n) in sphere.positions.iter().zip(&sphere.normals) {
        text += &format!("v {} {} {}\nvn {} {} {}\n", p.x, p.y, p.z, -n.x, -n.y, -n.z);
    }
    for t in sphere.indices.chunks_exact(3) {
        text += &format!("f {a}//{a} {b}//{b} {c}//{c}\n", a = t[0] + 1, b = t[1] + 1, c = t[2] + 1);
    }
    let loaded = Mesh::from_obj_bytes(text.as_bytes(), "inward-vn.obj").unwrap();
    for (p, n) in loaded.positions.iter().zip(&loaded.normals) {
        assert!(p.dot(*n) > 0.0, "normal at {p} points inward");
    }
    // Through the binary: a warning, and the same light as the right-way-out cube.
    let (good, bad) = (tmp("cube-out.obj"), tmp("cube-in.obj"));
    std::fs::write(&good, cube_obj(1.0, false)).unwrap();
    std::fs::write(&bad, cube_obj(1.0, true)).unwrap();
    let mean = |p: &[[f32; 4]]| p.iter().map(|p| p[0] + p[1] + p[2]).sum::<f32>() / p.len() as f32;
    let a = render_exr("cube-out", &["--mesh", &good]).unwrap();
    let out = run(&["render", "--mesh", &bad, "--width", "24", "--height", "24", "--out", &tmp("cube-in.exr")], 120);
    assert!(out.status.success() && stderr(&out).contains("warning: mesh") && stderr(&out).contains("inward"));
    let b = render_exr("cube-in", &["--mesh", &bad]).unwrap();
    // (The quads split along the other diagonal once turned, so the sampling differs a little;
    // before the fix the inside-out cube was about 5% lit.)
    let ratio = mean(&b) / mean(&a);
    assert!((0.7..1.4).contains(&ratio), "inside-out cube {} vs {}", mean(&b), mean(&a));
}

#[test]
fn class7_tiny_meshes_are_framed() {
    let (tiny, unit) = (tmp("cube-tiny.obj"), tmp("cube-unit.obj"));
    std::fs::write(&tiny, cube_obj(1e-9, false)).unwrap();
    std::fs::write(&unit, cube_obj(1.0, false)).unwrap();
    let a = render_exr("cube-unit", &["--mesh", &unit, "--scale", "10"]).unwrap();
    let b = render_exr("cube-tiny", &["--mesh", &tiny, "--scale", "1e10"]).unwrap();
    let ((ca, la), (cb, lb)) = (covered_and_lit(&a), covered_and_lit(&b));
    assert!(ca > 100 && la > ca / 2, "{ca} {la}");
    assert!((cb as f32 / ca as f32 - 1.0).abs() < 0.1 && lb > cb / 2, "tiny cube: {cb} covered, {lb} lit; unit {ca}");
}

// 1. Coincident triangles: each pixel is shaded once whatever the mesh.

#[test]
fn class1_repeated_triangles_shade_each_pixel_once() {
    let mut results = Vec::new();
    for copies in [1, 300] {
        let obj = tmp(&format!("repeated-{copies}.obj"));
        let mut text = String::from("v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv 0 0 -1\n");
        for _ in 0..copies {
            text += "f 1 2 3\nf 1 4 2\n";
        }
        std::fs::write(&obj, text).unwrap();
        let exr = tmp(&format!("repeated-{copies}.exr"));
        let start = Instant::now();
        let out = run(
            &["render", "--validation", "--profile", "--mesh", &obj, "--width", "32", "--height", "32", "--out", &exr],
            120,
        );
        assert!(out.status.success(), "{copies} copies: {}", stderr(&out));
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let pixels = text
            .lines()
            .find_map(|l| l.strip_prefix("work per pixel (last frame, "))
            .and_then(|l| l.split(' ').next())
            .unwrap_or_else(|| panic!("no work line in:\n{text}"))
            .to_string();
        results.push((pixels, std::fs::read(&exr).unwrap(), start.elapsed()));
    }
    assert_eq!(results[0].0, results[1].0, "shaded pixels: one copy vs 300 copies");
    assert!(results[0].1 == results[1].1, "300 copies must give the same image as one");
    println!("one copy {:?}, 300 copies {:?}", results[0].2, results[1].2);
}

// 5. Sizes inside the flags' ranges that this device cannot hold: refused before anything is
// created, naming the flag (before, the validation layer reported vkCreateImage).

#[test]
fn class5_images_beyond_the_device_are_refused_by_flag() {
    let png = tmp("huge.png");
    let start = Instant::now();
    let out = run(
        &["render", "--validation", "--mesh", "sphere", "--width", "16384", "--height", "16384", "--out", &png],
        60,
    );
    assert_bad_input(&out, "--width/--height", "16384x16384");
    let mut args = vec!["render", "--validation", "--mesh", "sphere", "--width", "16", "--height", "16"];
    args.extend(["--shadow-resolution", "8192", "--out", &png]);
    for p in ["point:3,3,3", "point:-3,3,3", "point:3,-3,3"] {
        args.extend(["--light", p]);
    }
    let out = run(&args, 60);
    assert_bad_input(&out, "--shadow-resolution", "three point lights at 8192");
    assert!(!stderr(&out).contains("vulkan validation"), "{}", stderr(&out));
    assert!(start.elapsed() < Duration::from_secs(30));
}

// 8. A debug view costs what it draws.

#[test]
fn class8_debug_views_skip_the_subsurface_pass() {
    let png = tmp("samples.png");
    for view in [&["--show", "samples"][..], &["--show", "tree", "--level", "2"][..]] {
        let mut args =
            vec!["render", "--validation", "--mesh", "sphere", "--width", "64", "--height", "64", "--out", &png];
        args.extend(view);
        let out = run(&args, 120);
        assert!(out.status.success(), "{}", stderr(&out));
        let table = String::from_utf8_lossy(&out.stdout);
        assert!(table.contains("surface"), "{table}");
        assert!(!table.lines().any(|l| l.starts_with("shade ")), "{view:?} ran the shade pass:\n{table}");
    }
}
