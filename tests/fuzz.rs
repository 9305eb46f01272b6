//! Property tests of the readers and the flag parsers with generated inputs (proptest): no panic,
//! and every input either loads into something the renderer can use or is refused as bad input
//! (exit code 2) with a message naming the file or flag.
//!
//! The plain tests run a bounded number of cases (seconds, in CI). The `#[ignore]`d `fuzz_*`
//! tests run for FUZZ_SECONDS (default 60) each and print how many inputs they tried:
//! `scripts/fuzz` or `cargo test --release --test fuzz -- --ignored fuzz`.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

use translucent::bssrdf_csv::{self, Reader};
use translucent::cli::{Cli, Command};
use translucent::mesh::Mesh;

// ---------- generators ----------

/// Numbers as a hostile user types them.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|v| format!("{v}")),
        any::<f32>().prop_map(|v| format!("{v:e}")),
        (-3i32..3).prop_map(|v| v.to_string()),
        (-320i32..320).prop_map(|e| format!("1e{e}")),
        (-320i32..320).prop_map(|e| format!("-3.5e{e}")),
        prop::sample::select(vec![
            "nan",
            "NaN",
            "inf",
            "-inf",
            "infinity",
            "-0",
            "0",
            "",
            " ",
            "1e",
            "--1",
            "0x10",
            "1,2",
            "1.5.2",
            "١",
            "4294967296",
            "-2147483649",
            "18446744073709551616",
            "1e400",
            "-1e-400",
            "+5",
        ])
        .prop_map(str::to_string),
    ]
}

fn triple() -> impl Strategy<Value = String> {
    prop_oneof![
        (number(), number(), number()).prop_map(|(a, b, c)| format!("{a},{b},{c}")),
        number(),
        (number(), number()).prop_map(|(a, b)| format!("{a},{b}")),
        (number(), number(), number(), number()).prop_map(|(a, b, c, d)| format!("{a},{b},{c},{d}")),
    ]
}

fn obj_index() -> impl Strategy<Value = String> {
    prop_oneof![(-12i64..12).prop_map(|i| i.to_string()), any::<i64>().prop_map(|i| i.to_string()), Just(String::new())]
}

fn obj_line() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (number(), number(), number()).prop_map(|(a, b, c)| format!("v {a} {b} {c}")),
        4 => (-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0).prop_map(|(a, b, c)| format!("v {a} {b} {c}")),
        2 => (number(), number(), number()).prop_map(|(a, b, c)| format!("vn {a} {b} {c}")),
        1 => (number(), number()).prop_map(|(a, b)| format!("vt {a} {b}")),
        4 => prop::collection::vec(1i64..10, 3..6)
            .prop_map(|v| format!("f {}", v.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" "))),
        3 => prop::collection::vec((obj_index(), obj_index(), obj_index(), 0usize..4), 0..6).prop_map(|v| {
            let corners: Vec<String> = v
                .iter()
                .map(|(a, b, c, form)| match form {
                    0 => a.clone(),
                    1 => format!("{a}/{b}"),
                    2 => format!("{a}//{c}"),
                    _ => format!("{a}/{b}/{c}"),
                })
                .collect();
            format!("f {}", corners.join(" "))
        }),
        1 => prop::sample::select(vec!["o a", "g", "s off", "# c", "usemtl x", "mtllib x.mtl", "l 1 2", "p 1", "", "   "])
            .prop_map(str::to_string),
        1 => "[ -~]{0,20}",
    ]
}

/// OBJ text from the grammar above, with random line ends and an optional BOM.
fn obj_text() -> impl Strategy<Value = Vec<u8>> {
    (prop::collection::vec(obj_line(), 0..40), prop::sample::select(vec!["\n", "\r\n", "\r"]), any::<bool>()).prop_map(
        |(lines, end, bom)| {
            let mut text = if bom { "\u{feff}".to_string() } else { String::new() };
            text += &lines.join(end);
            text.into_bytes()
        },
    )
}

fn csv_row() -> impl Strategy<Value = String> {
    prop_oneof![
        // Plausible rows with hostile values in random columns.
        (prop::collection::vec(prop_oneof![3 => (-2.0f64..2.0).prop_map(|v| v.to_string()), 1 => number()], 19..21))
            .prop_map(|v| v.join(",")),
        // Mostly valid rows (physical ranges), including extreme scales.
        (-6i32..31, -6i32..31, -0.99f64..0.99, 0.5f64..2.5, prop::collection::vec(-10.0f64..10.0, 15), -300i32..300)
            .prop_map(|(a, s, g, eta, geometry, e)| {
                let scale = 10f64.powi(e);
                let g3: Vec<String> = geometry.iter().map(|v| (v * scale).to_string()).collect();
                format!("1e{a},1e{s},{g},{eta},{}", g3.join(","))
            }),
        prop::collection::vec(number(), 0..22).prop_map(|v| v.join(",")),
        "[ -~]{0,60}",
    ]
}

fn csv_text() -> impl Strategy<Value = Vec<u8>> {
    (
        prop::collection::vec(csv_row(), 0..12),
        prop::sample::select(vec!["\n", "\r\n", "\r"]),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(|(rows, end, bom, good_header)| {
            let mut text = if bom { "\u{feff}".to_string() } else { String::new() };
            if good_header {
                text += &bssrdf_csv::COLUMNS.join(",");
                text += end;
            }
            text += &rows.join(end);
            text.into_bytes()
        })
}

/// A command line: a command and flags with generated values.
fn argv() -> impl Strategy<Value = Vec<String>> {
    let render_flags = prop::sample::select(vec![
        "--width",
        "--height",
        "--frames",
        "--spin-light",
        "--scale",
        "--eye",
        "--target",
        "--up",
        "--fov",
        "--light-dir",
        "--light-intensity",
        "--light",
        "--samples",
        "--shadow-resolution",
        "--show",
        "--level",
        "--material",
        "--sigma-a",
        "--sigma-s",
        "--g",
        "--eta",
        "--model",
        "--diffusion",
        "--epsilon",
        "--roughness",
        "--exposure",
        "--mesh",
        "--out",
        "--profile-out",
        "--device",
    ]);
    let value = prop_oneof![
        4 => triple(),
        1 => prop::sample::select(vec![
            "sphere", "box", "slab", "torus", "marble", "skin1", "KETCHUP", "dir:0,1,0", "point:3,3,3:5",
            "dir:1e30,1e30,0", "point:0,0,0", "spot:1,1,1", "dir:", "point:1,2,3:1,2", "samples", "tree",
            "dipole", "alternative", "x.png", "x.exr", "x.bmp", "{frame}.png", "-",
        ])
        .prop_map(str::to_string),
        1 => "[ -~]{0,12}",
    ];
    let command = prop::sample::select(vec!["render", "profile", "bssrdf", "bench", "materials", "devices", "nope"]);
    (command, prop::collection::vec((render_flags, value, any::<bool>()), 0..8)).prop_map(|(command, flags)| {
        let mut argv = vec!["translucent".to_string(), command.to_string()];
        for (flag, value, joined) in flags {
            if joined {
                argv.push(format!("{flag}={value}"));
            } else {
                argv.push(flag.to_string());
                argv.push(value);
            }
        }
        argv
    })
}

// ---------- properties ----------

fn check_obj(bytes: &[u8]) -> Result<(), TestCaseError> {
    match Mesh::from_obj_bytes(bytes, "fuzz.obj") {
        Ok(mesh) => {
            prop_assert!(mesh.validate().is_ok(), "loaded but invalid: {:?}", mesh.validate().err());
            prop_assert!(mesh.positions.iter().all(|p| p.is_finite()));
            for n in &mesh.normals {
                prop_assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-3, "normal {n}");
            }
            prop_assert!(mesh.surface_area().is_finite() && mesh.surface_area() > 0.0);
            let (centre, radius) = translucent::scene::bounding_sphere(&mesh.positions);
            prop_assert!(centre.is_finite() && radius.is_finite());
        }
        Err(e) => {
            prop_assert_eq!(e.exit_code(), 2, "{}", e);
            prop_assert!(e.to_string().contains("fuzz.obj"), "error does not name the file: {}", e);
        }
    }
    Ok(())
}

fn check_csv(bytes: &[u8]) -> Result<(), TestCaseError> {
    let mut reader = Reader::new(bytes);
    loop {
        match reader.next_batch(4) {
            Ok(batch) if batch.is_empty() => return Ok(()),
            Ok(batch) => {
                for (line, q) in batch {
                    for v in [q.ni, q.wi, q.no] {
                        prop_assert!(v.is_finite() && (v.length() - 1.0).abs() < 1e-9, "line {line}: {v}");
                    }
                    for model in [translucent::physics::Model::Directional, translucent::physics::Model::Dipole] {
                        let sd = q.sd(model, translucent::physics::Diffusion::Classical);
                        prop_assert!(!sd.is_nan(), "line {line}: Sd is NaN for {q:?}");
                    }
                }
            }
            Err(e) => {
                prop_assert_eq!(e.exit_code(), 2, "{}", e);
                prop_assert!(
                    e.to_string().starts_with("bssrdf: line ") || e.to_string().starts_with("bssrdf: empty input"),
                    "error does not name the line: {}",
                    e
                );
                return Ok(());
            }
        }
    }
}

fn check_argv(argv: &[String]) -> Result<(), TestCaseError> {
    use clap::Parser;
    let cli = match Cli::try_parse_from(argv) {
        Ok(cli) => cli,
        Err(e) => {
            // A usage error is exit 2 and names what was wrong.
            let code = e.exit_code();
            prop_assert!(code == 2 || code == 0, "{argv:?}: clap exit {code}");
            return Ok(());
        }
    };
    match cli.command {
        Command::Render(args) => {
            if args.mesh.as_deref().is_some_and(|m| !["sphere", "box", "slab", "torus"].contains(&m)) {
                return Ok(()); // files are the OBJ property's business
            }
            match translucent::settings::SceneSettings::from_args(&args).build() {
                Ok(scene) => {
                    let c = scene.camera;
                    prop_assert!(c.eye.is_finite() && c.target.is_finite() && c.up.is_finite());
                    prop_assert!((c.up.length() - 1.0).abs() < 1e-4, "{argv:?}: up {}", c.up);
                    let vp = c.view_projection(1.0, scene.mesh.bounds());
                    prop_assert!(vp.is_finite(), "{argv:?}: view-projection {vp}");
                    for l in &scene.lights {
                        if let translucent::scene::Light::Directional { toward, .. } = l {
                            prop_assert!((toward.length() - 1.0).abs() < 1e-4, "{argv:?}: light {toward}");
                        }
                    }
                    let mm = scene.mm_per_unit as f64;
                    let area = scene.mesh.surface_area() as f64 * mm * mm;
                    prop_assert!(area.is_finite() && area > 0.0 && (area as f32).is_finite(), "{argv:?}: area {area}");
                }
                Err(e) => prop_assert_eq!(e.exit_code(), 2, "{:?}: {}", argv, e),
            }
            if let Err(e) = args.material.material() {
                prop_assert_eq!(e.exit_code(), 2, "{:?}: {}", argv, e);
            }
        }
        Command::Profile(args) => {
            if let Ok(material) = args.material.material() {
                let spec = translucent::plot::ProfileSpec {
                    material,
                    models: args.model.clone(),
                    angles_deg: args.angles.clone(),
                    r_min_mm: args.r_min,
                    r_max_mm: args.r_max.unwrap_or(100.0),
                    diffusion: args.diffusion.into(),
                    samples: args.samples.min(20),
                };
                if spec.validate().is_ok() {
                    for c in spec.curves() {
                        prop_assert!(c.points.iter().all(|p| !p.1.is_nan()), "{argv:?}: NaN in a profile");
                    }
                }
            }
        }
        _ => {}
    }
    Ok(())
}

// ---------- runners ----------

/// Runs `check` on `cases` inputs from `strategy`, with a seed per round; panics with the smallest
/// failing input proptest finds.
fn run_cases<S: Strategy>(strategy: &S, cases: u32, seed: u64, check: impl Fn(S::Value) -> Result<(), TestCaseError>)
where
    S::Value: std::fmt::Debug,
{
    let config = Config { cases, failure_persistence: None, ..Config::default() };
    let mut seed_bytes = [0u8; 16];
    seed_bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::XorShift, &seed_bytes));
    if let Err(e) = runner.run(strategy, check) {
        panic!("seed {seed}: {e}");
    }
}

/// Runs rounds of 256 cases until FUZZ_SECONDS (default 60) have passed; prints the total.
fn fuzz_for<S: Strategy>(name: &str, strategy: S, check: impl Fn(S::Value) -> Result<(), TestCaseError> + Copy)
where
    S::Value: std::fmt::Debug,
{
    let seconds: u64 = std::env::var("FUZZ_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(60);
    let start = std::time::Instant::now();
    let base: u64 = std::env::var("FUZZ_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or_else(|| {
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos() as u64
    });
    let mut total = 0u64;
    let mut round = 0u64;
    while start.elapsed().as_secs() < seconds {
        let seed = base.wrapping_add(round);
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run_cases(&strategy, 256, seed, check)));
        if let Err(panic) = outcome {
            println!(
                "fuzz {name}: FAILED after about {total} inputs in {:.0} s (seed {seed})",
                start.elapsed().as_secs_f64()
            );
            std::panic::resume_unwind(panic);
        }
        total += 256;
        round += 1;
    }
    println!(
        "fuzz {name}: {total} inputs in {:.0} s, no failure (seeds {base}..+{round})",
        start.elapsed().as_secs_f64()
    );
}

const CI_CASES: u32 = 1500;

/// Inputs the long fuzz runs found failing, kept as regression cases.
#[test]
fn fuzz_findings_stay_fixed() {
    let header = bssrdf_csv::COLUMNS.join(",");
    for row in [
        "1,1,0,1.3,0,0,0,0,0,-1,0,0,-1,0,0,1.6460873221073073e154,0,0,1", // position 1.6e154 mm
        "0,0.76,0.1,1e-104,0,0,0,0,0,-1,0,0,1,0,0,0,0,0,-1",              // η = 1e-104
        "1e154,1.65,0,0.44,0,0,0,0,0,-1,0,0,-1,0,0,0,0,0,-1",             // σa = 1e154
        "-0.0,1e-154,0,1.05,0,0,0,0,0,1,0,0,1,0,0,0,0,0,-1",              // σs = 1e-154
    ] {
        check_csv(format!("{header}\n{row}\n").as_bytes()).unwrap();
    }
    for args in [["--eye", "0,-3.5e0,4294967296"], ["--fov", "1e-37"]] {
        let argv: Vec<String> = ["translucent", "render"].iter().chain(&args).map(|s| s.to_string()).collect();
        check_argv(&argv).unwrap();
    }
}

#[test]
fn obj_reader_properties() {
    run_cases(&obj_text(), CI_CASES, 1, |b| check_obj(&b));
    run_cases(&prop::collection::vec(any::<u8>(), 0..400), CI_CASES, 2, |b| check_obj(&b));
}

#[test]
fn csv_reader_properties() {
    run_cases(&csv_text(), CI_CASES, 3, |b| check_csv(&b));
    run_cases(&prop::collection::vec(any::<u8>(), 0..400), CI_CASES, 4, |b| check_csv(&b));
}

#[test]
fn flag_parser_properties() {
    run_cases(&argv(), CI_CASES, 5, |a| check_argv(&a));
}

#[test]
#[ignore]
fn fuzz_obj_reader() {
    fuzz_for("OBJ reader (grammar)", obj_text(), |b| check_obj(&b));
    fuzz_for("OBJ reader (bytes)", prop::collection::vec(any::<u8>(), 0..2000), |b| check_obj(&b));
}

#[test]
#[ignore]
fn fuzz_csv_reader() {
    fuzz_for("CSV reader (grammar)", csv_text(), |b| check_csv(&b));
    fuzz_for("CSV reader (bytes)", prop::collection::vec(any::<u8>(), 0..2000), |b| check_csv(&b));
}

#[test]
#[ignore]
fn fuzz_flag_parsers() {
    fuzz_for("flag parsers", argv(), |a| check_argv(&a));
}
