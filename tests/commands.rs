//! The `bssrdf`, `materials` and `profile` commands through the binary.

mod common;

use std::io::Write;

use common::{output_dir, repo_path, stderr, translucent};

fn bssrdf(args: &[&str], input: &str) -> std::process::Output {
    let mut child = common::spawn_bssrdf(args);
    let mut stdin = child.stdin.take().unwrap();
    let input = input.to_string();
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().ok();
    out
}

fn sd_column(stdout: &[u8]) -> Vec<f64> {
    let text = String::from_utf8_lossy(stdout);
    let mut lines = text.lines();
    assert!(lines.next().unwrap().ends_with(",no_z,sd"));
    lines.map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect()
}

#[test]
fn bssrdf_cpu_and_gpu_agree_on_the_reference_file() {
    let reference = std::fs::read_to_string(repo_path("tests/data/dirpole-check.csv")).unwrap();
    let cpu = bssrdf(&[], &reference);
    assert!(cpu.status.success(), "{}", stderr(&cpu));
    let gpu = bssrdf(&["--gpu", "--validation"], &reference);
    assert!(gpu.status.success(), "{}", stderr(&gpu));
    let (cpu, gpu) = (sd_column(&cpu.stdout), sd_column(&gpu.stdout));
    assert_eq!(cpu.len(), 400);
    let expected: Vec<f64> =
        reference.lines().skip(1).map(|l| l.split(',').nth(19).unwrap().parse().unwrap()).collect();
    for (i, ((c, g), e)) in cpu.iter().zip(&gpu).zip(&expected).enumerate() {
        if *e > 1e-12 {
            assert!((c - e).abs() <= 1e-6 * e, "line {}: cpu {c} vs reference {e}", i + 2);
        }
        assert!(g.is_finite());
    }
    let dipole = bssrdf(&["--model", "dipole"], &reference);
    let expected: Vec<f64> =
        reference.lines().skip(1).map(|l| l.split(',').nth(20).unwrap().parse().unwrap()).collect();
    for (c, e) in sd_column(&dipole.stdout).iter().zip(&expected) {
        assert!((c - e).abs() <= 1e-6 * e);
    }
}

#[test]
fn bssrdf_bad_rows_name_line_and_column() {
    let header = translucent::bssrdf_csv::COLUMNS.join(",");
    let good = "0.01,1,0,1.3,0,0,0,0,0,1,0,0,1,1,0,0,0,0,1";
    for (row, needle) in [
        ("0.01,1,0,1.3,0,0,0,0,0,1,0,0,1,1,0,0,0,0", "missing column no_z"),
        ("0.01,abc,0,1.3,0,0,0,0,0,1,0,0,1,1,0,0,0,0,1", "column sigma_s"),
        ("-0.01,1,0,1.3,0,0,0,0,0,1,0,0,1,1,0,0,0,0,1", "column sigma_a"),
        ("0.01,1,0,nan,0,0,0,0,0,1,0,0,1,1,0,0,0,0,1", "column eta"),
        ("0.01,1,0,1.3,0,0,0,0,0,0,0,0,1,1,0,0,0,0,1", "column ni_x"),
        ("0.01,1,1.5,1.3,0,0,0,0,0,1,0,0,1,1,0,0,0,0,1", "column g"),
    ] {
        let out = bssrdf(&[], &format!("{header}\n{good}\n{row}\n"));
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{row}: {err}");
        assert!(err.contains("line 3") && err.contains(needle), "{row}: {err}");
    }
    let out = bssrdf(&[], "a,b,c\n");
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("header"));
}

#[test]
fn bssrdf_handles_100k_rows_quickly() {
    let header = translucent::bssrdf_csv::COLUMNS.join(",");
    let mut input = header + "\n";
    for q in common::random_queries(100_000, 3) {
        let m = q.medium;
        let f = |v: glam::DVec3| format!("{},{},{}", v.x, v.y, v.z);
        input += &format!(
            "{},{},{},{},{},{},{},{},{}\n",
            m.sigma_a,
            m.sigma_s,
            m.g,
            m.eta,
            f(q.xi),
            f(q.ni),
            f(q.wi),
            f(q.xo),
            f(q.no)
        );
    }
    for args in [&[][..], &["--gpu", "--validation"][..]] {
        let start = std::time::Instant::now();
        let out = bssrdf(args, &input);
        assert!(out.status.success(), "{}", stderr(&out));
        let seconds = start.elapsed().as_secs_f64();
        println!("bssrdf {args:?}: 100000 rows in {seconds:.2} s");
        assert_eq!(sd_column(&out.stdout).len(), 100_000);
        assert!(seconds < 30.0, "{seconds} s");
    }
}

#[test]
fn materials_lists_every_preset() {
    let out = translucent(&["materials"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for name in ["Marble", "Skin1", "Ketchup", "Spectralon", "Regular Milk", "Pacific Ocean Surface Water"] {
        assert!(text.contains(name), "{name} missing");
    }
    assert_eq!(text.lines().count(), 1 + 12 + 35);
}

#[test]
fn profile_writes_png_svg_and_csv() {
    for ext in ["png", "svg", "csv"] {
        let path = output_dir().join(format!("profile.{ext}"));
        let out = translucent(&["profile", "--material", "Skin1", "--out", path.to_str().unwrap()]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(std::fs::metadata(&path).unwrap().len() > 1000, "{ext}");
    }
}

#[test]
fn bad_material_values_exit_2_naming_the_value() {
    let png = output_dir().join("bad.png");
    for (args, needle) in [
        (vec!["--sigma-a", "-1"], "sigma_a = -1"),
        (vec!["--sigma-s", "nan"], "sigma_s = NaN"),
        (vec!["--eta", "0"], "eta = 0"),
        (vec!["--g", "1"], "g = 1"),
        (vec!["--material", "unobtainium"], "unobtainium"),
    ] {
        let mut full = vec!["profile", "--out", png.to_str().unwrap()];
        full.extend(args.iter());
        let out = translucent(&full);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
}

/// A bench asked to be small is small (issue #28): the lights table has only the counts asked for
/// (the sky in as many directions as the most of them), and the size typed for the frame sizes the
/// pbrt-v2 comparison and the scene of several objects too.
#[test]
fn a_small_bench_keeps_every_table_small() {
    let started = std::time::Instant::now();
    let args = [
        "bench",
        "--validation",
        "--meshes",
        "sphere",
        "--samples",
        "1024",
        "--accuracy-size",
        "16",
        "--accuracy-samples",
        "1024",
        "--epsilons",
        "0.2",
        "--width",
        "32",
        "--height",
        "32",
        "--frames",
        "2",
        "--lights",
        "1,8",
    ];
    let out = common::translucent(&args);
    let wall = started.elapsed().as_secs_f64();
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let lights = text.split("### Lights").nth(1).expect("a lights table").split("###").next().unwrap();
    let rows: Vec<&str> = lights.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| lights")).collect();
    assert_eq!(rows.len(), 3, "{lights}");
    assert!(
        rows[0].starts_with("| 1 |") && rows[1].starts_with("| 8 |") && rows[2].starts_with("| sky, 8 directions |"),
        "{lights}"
    );
    assert!(text.contains("| 32² |"), "the pbrt-v2 comparison at the typed size:\n{text}");
    assert!(text.contains("32x32: sphere in marble"), "the scene of objects at the typed size:\n{text}");
    eprintln!("small bench: {wall:.1} s");
}
