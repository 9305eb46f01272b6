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
    let mut child = bin()
        .arg("bssrdf")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
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
    // stderr on a full disk: the exit code still tells, no panic (101).
    for (args, code) in [(vec!["profile", "--sigma-s", "nan"], 2), (vec!["materials"], 0), (vec![], 2)] {
        let full = std::fs::File::create("/dev/full").unwrap();
        let out = bin().args(&args).stdout(Stdio::null()).stderr(full).output().unwrap();
        assert_eq!(out.status.code(), Some(code), "{args:?} 2>/dev/full");
    }
    // --help to a full stdout is a failure too.
    let full = std::fs::File::create("/dev/full").unwrap();
    let out = bin().arg("--help").stdout(full).stderr(Stdio::null()).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
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
    let rows = translucent::bssrdf_csv::BATCH_ROWS + 10;
    let mut child =
        bin().arg("bssrdf").stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
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
    assert!(child.wait().unwrap().success());
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
