//! Property tests of the readers (OBJ, PLY, OFF, CSV) and the flag parsers with generated inputs (proptest): no panic,
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
use translucent::mesh::{Mesh, MeshFormat};

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

/// A PLY header from parts a writer (or an attacker) might use, then a body of number lines
/// (ASCII) or bytes (binary): counts, types and names both valid and hostile.
fn ply_text() -> impl Strategy<Value = Vec<u8>> {
    let format = prop::sample::select(vec!["ascii", "binary_little_endian", "binary_big_endian", "binary", ""]);
    let count = prop_oneof![4 => 0u64..6, 1 => any::<u64>(), 1 => Just(1u64 << 40)];
    let scalar = prop::sample::select(vec![
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "float32", "list",
    ]);
    let name = prop::sample::select(vec![
        "x",
        "y",
        "z",
        "nx",
        "ny",
        "nz",
        "u",
        "v",
        "s",
        "t",
        "confidence",
        "intensity",
        "vertex_indices",
        "vertex_index",
        "red",
    ]);
    let property = prop_oneof![
        3 => (scalar.clone(), name.clone()).prop_map(|(t, n)| format!("property {t} {n}")),
        1 => (scalar.clone(), scalar, name).prop_map(|(c, t, n)| format!("property list {c} {t} {n}")),
    ];
    let element = (
        prop::sample::select(vec!["vertex", "face", "edge", "material", "vertex"]),
        count,
        prop::collection::vec(property, 0..6),
    )
        .prop_map(|(e, n, props)| format!("element {e} {n}\n{}", props.join("\n")));
    let extra = prop::sample::select(vec![
        "comment made by hand",
        "obj_info scanner 1",
        "",
        "end_header",
        "ply",
        "format ascii 2.0",
    ]);
    let body_line = prop::collection::vec(prop_oneof![number(), (-3i64..8).prop_map(|i| i.to_string())], 0..8)
        .prop_map(|v| v.join(" "));
    (
        format,
        prop::collection::vec(element, 0..4),
        prop::collection::vec(extra, 0..2),
        prop::collection::vec(body_line, 0..12),
        prop::collection::vec(any::<u8>(), 0..200),
    )
        .prop_map(|(format, elements, extra, lines, bytes)| {
            let mut out =
                format!("ply\nformat {format} 1.0\n{}\n{}\nend_header\n", extra.join("\n"), elements.join("\n"))
                    .replace("\n\n", "\n")
                    .into_bytes();
            if format == "ascii" {
                out.extend(lines.join("\n").into_bytes());
            } else {
                out.extend(bytes);
            }
            out
        })
}

/// pbrt-v4 scene text: directives (known and not), parameter lists with declared types and
/// values of every kind, brackets, strings with escapes, comments; valid and hostile.
fn pbrt_text() -> impl Strategy<Value = Vec<u8>> {
    let directive = prop::sample::select(vec![
        "LookAt",
        "Camera",
        "Film",
        "Scale",
        "Translate",
        "Rotate",
        "Transform",
        "ConcatTransform",
        "Identity",
        "CoordinateSystem",
        "CoordSysTransform",
        "ReverseOrientation",
        "AttributeBegin",
        "AttributeEnd",
        "WorldBegin",
        "MakeNamedMaterial",
        "NamedMaterial",
        "Material",
        "Texture",
        "Shape",
        "LightSource",
        "Sampler",
        "Option",
        "Include",
        "ObjectBegin",
        "Frobnicate",
        "TransformBegin",
        "TransformEnd",
    ]);
    let word = prop::sample::select(vec![
        "\"perspective\"",
        "\"subsurface\"",
        "\"diffuse\"",
        "\"sphere\"",
        "\"trianglemesh\"",
        "\"distant\"",
        "\"point\"",
        "\"spot\"",
        "\"infinite\"",
        "\"checkerboard\"",
        "\"spectrum\"",
        "\"rgb\"",
        "\"camera\"",
        "\"a\\\"b\"",
        "\"x.pbrt\"",
        "\"\"",
        "[",
        "]",
        "true",
        "#c\n",
        "\"Skin1\"",
    ]);
    let decl = (
        prop::sample::select(vec![
            "float",
            "integer",
            "rgb",
            "spectrum",
            "point3",
            "normal",
            "point2",
            "string",
            "texture",
            "bool",
            "blackbody",
            "quaternion",
        ]),
        prop::sample::select(vec![
            "fov",
            "P",
            "indices",
            "N",
            "uv",
            "radius",
            "name",
            "sigma_a",
            "sigma_s",
            "reflectance",
            "mfp",
            "L",
            "from",
            "to",
            "scale",
            "xresolution",
            "type",
            "filename",
            "tex1",
        ]),
    )
        .prop_map(|(t, n)| format!("\"{t} {n}\""));
    let value = prop_oneof![
        number(),
        (-3i64..12).prop_map(|i| i.to_string()),
        prop::collection::vec((-3i64..12).prop_map(|i| i.to_string()), 0..10)
            .prop_map(|v| format!("[ {} ]", v.join(" "))),
        word.clone().prop_map(str::to_string),
    ];
    let item = prop_oneof![
        3 => directive.prop_map(str::to_string),
        2 => word.prop_map(str::to_string),
        3 => (decl, value.clone()).prop_map(|(d, v)| format!("{d} {v}")),
        2 => value,
        1 => "[ -~]{0,12}",
    ];
    prop::collection::vec(item, 0..40).prop_map(|v| v.join(" ").into_bytes())
}

/// OFF text: keyword, counts and records, valid and hostile, with comments and blank lines.
fn off_text() -> impl Strategy<Value = Vec<u8>> {
    let keyword = prop::sample::select(vec!["OFF", "NOFF", "COFF", "STOFF", "CNOFF", "4OFF", "nOFF", "off", ""]);
    let count = prop_oneof![4 => (0u64..6).prop_map(|v| v.to_string()), 1 => any::<u64>().prop_map(|v| v.to_string()), 1 => number()];
    let line = prop_oneof![
        3 => (number(), number(), number()).prop_map(|(a, b, c)| format!("{a} {b} {c}")),
        3 => (-2.0f32..2.0, -2.0f32..2.0, -2.0f32..2.0).prop_map(|(a, b, c)| format!("{a} {b} {c}")),
        3 => prop::collection::vec(-2i64..8, 1..7).prop_map(|v| v.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" ")),
        1 => Just("# a comment".to_string()),
        1 => Just(String::new()),
        1 => "[ -~]{0,20}",
    ];
    (keyword, count.clone(), count, any::<bool>(), prop::collection::vec(line, 0..20)).prop_map(
        |(keyword, nv, nf, same_line, lines)| {
            let counts = format!("{nv} {nf} 0");
            let head = if same_line { format!("{keyword} {counts}") } else { format!("{keyword}\n{counts}") };
            format!("{head}\n{}\n", lines.join("\n")).into_bytes()
        },
    )
}

/// A valid mesh's data: positions, and polygons (3 to 5 corners) indexing them.
fn polygon_mesh() -> impl Strategy<Value = (Vec<[f32; 3]>, Vec<Vec<u32>>)> {
    prop::collection::vec(prop::array::uniform3(-1e3f32..1e3), 3..30).prop_flat_map(|positions| {
        let n = positions.len() as u32;
        (Just(positions), prop::collection::vec(prop::collection::vec(0..n, 3..6), 1..30))
    })
}

/// The mesh as PLY (encoding 0 ASCII, 1 little, 2 big endian) or, for encoding 3, OFF.
fn write_mesh(positions: &[[f32; 3]], faces: &[Vec<u32>], encoding: usize) -> Vec<u8> {
    if encoding == 3 {
        let mut s = format!("OFF\n{} {} 0\n", positions.len(), faces.len());
        for p in positions {
            s += &format!("{} {} {}\n", p[0], p[1], p[2]);
        }
        for f in faces {
            s += &format!("{} {}\n", f.len(), f.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" "));
        }
        return s.into_bytes();
    }
    let format = ["ascii", "binary_little_endian", "binary_big_endian"][encoding];
    let mut out = format!(
        "ply\nformat {format} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        positions.len(),
        faces.len()
    )
    .into_bytes();
    let big = encoding == 2;
    for p in positions {
        if encoding == 0 {
            out.extend(format!("{} {} {}\n", p[0], p[1], p[2]).into_bytes());
        } else {
            p.iter().for_each(|c| out.extend(if big { c.to_be_bytes() } else { c.to_le_bytes() }));
        }
    }
    for f in faces {
        if encoding == 0 {
            out.extend(
                format!("{} {}\n", f.len(), f.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" ")).into_bytes(),
            );
        } else {
            out.push(f.len() as u8);
            f.iter().for_each(|i| out.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() }));
        }
    }
    out
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
    check_mesh(bytes, MeshFormat::Obj)
}

/// Any bytes either load into a valid mesh or are refused as bad input naming the file.
fn check_mesh(bytes: &[u8], format: MeshFormat) -> Result<(), TestCaseError> {
    let shown = match format {
        MeshFormat::Obj => "fuzz.obj",
        MeshFormat::Ply => "fuzz.ply",
        MeshFormat::Off => "fuzz.off",
    };
    let loaded = match format {
        MeshFormat::Obj => Mesh::from_obj_bytes(bytes, shown),
        _ => Mesh::from_bytes(bytes, format, shown),
    };
    match loaded {
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
            prop_assert!(e.to_string().contains(shown), "error does not name the file: {}", e);
        }
    }
    Ok(())
}

/// A generated mesh written as PLY or OFF reads back to exactly its positions and fanned polygons.
fn check_round_trip(positions: &[[f32; 3]], faces: &[Vec<u32>], encoding: usize) -> Result<(), TestCaseError> {
    let format = if encoding == 3 { MeshFormat::Off } else { MeshFormat::Ply };
    let raw = translucent::mesh::raw_from_bytes(&write_mesh(positions, faces, encoding), format, "round-trip")
        .map_err(|e| TestCaseError::fail(e.to_string()))?;
    let expected: Vec<glam::Vec3> = positions.iter().map(|p| glam::Vec3::from(*p)).collect();
    prop_assert_eq!(&raw.positions, &expected);
    let fanned: Vec<u32> =
        faces.iter().flat_map(|f| (1..f.len() - 1).flat_map(move |k| [f[0], f[k], f[k + 1]])).collect();
    prop_assert_eq!(&raw.indices, &fanned);
    Ok(())
}

/// A scene file either loads (every object's vertices finite, indices in range) or is refused as
/// bad input whose message begins with the file's path (FILE:LINE:COLUMN).
fn check_pbrt(bytes: &[u8]) -> Result<(), TestCaseError> {
    thread_local!(static DIR: std::path::PathBuf = {
        let d = std::env::temp_dir().join(format!("translucent-fuzz-pbrt-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    });
    let path = DIR.with(|d| d.join(format!("fuzz-{:?}.pbrt", std::thread::current().id())));
    std::fs::write(&path, bytes).unwrap();
    match translucent::pbrt::load(&path) {
        Ok(scene) => {
            for o in &scene.objects {
                prop_assert!(o.mesh.positions.iter().all(|p| p.is_finite()));
                prop_assert!(o.mesh.indices.iter().all(|&i| (i as usize) < o.mesh.positions.len()));
            }
        }
        Err(e) => {
            prop_assert_eq!(e.exit_code(), 2, "{}", e);
            prop_assert!(
                e.to_string().starts_with(&*path.parent().unwrap().to_string_lossy()),
                "error does not name the file: {}",
                e
            );
        }
    }
    // The tokenizer alone, on the same text as a string: never a panic, errors located.
    if let Ok(text) = std::str::from_utf8(bytes) {
        if let Err(e) = translucent::pbrt::tokenizer::tokenize(text, "t") {
            prop_assert!(e.starts_with("t:"), "{}", e);
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

/// An OBJ's material library, any text: its colour map is found, or the file refused as bad input
/// naming the library, never a panic (tobj's MTL parser on what users write).
fn mtl_text() -> impl Strategy<Value = String> {
    let line = prop_oneof![
        "newmtl [a-z]{0,3}".prop_map(|s| s),
        "map_Kd [a-z./ ]{0,12}".prop_map(|s| s),
        (triple()).prop_map(|t| format!("Kd {t}")),
        "[A-Za-z_]{1,8} [ -~]{0,20}".prop_map(|s| s),
        Just(String::new()),
    ];
    prop::collection::vec(line, 0..12).prop_map(|lines| lines.join("\n"))
}

fn check_mtl((obj, mtl): (String, String)) -> Result<(), TestCaseError> {
    let dir = std::env::temp_dir().join(format!("translucent-fuzz-mtl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| TestCaseError::fail(e.to_string()))?;
    let (obj_path, mtl_path) = (dir.join("m.obj"), dir.join("m.mtl"));
    std::fs::write(&obj_path, format!("mtllib m.mtl\n{obj}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")).unwrap();
    std::fs::write(&mtl_path, &mtl).unwrap();
    match translucent::mesh::obj_diffuse_map(&obj_path) {
        Ok(_) => Ok(()),
        Err(e) if e.exit_code() == 2 && e.to_string().contains("m.obj") => Ok(()),
        Err(e) => Err(TestCaseError::fail(format!("{e}"))),
    }
}

#[test]
fn obj_material_library_properties() {
    run_cases(&("(usemtl [a-z]{0,3}\n){0,2}", mtl_text()), 400, 31, check_mtl);
    let _ = std::fs::remove_dir_all(std::env::temp_dir().join(format!("translucent-fuzz-mtl-{}", std::process::id())));
}

#[test]
fn obj_reader_properties() {
    run_cases(&obj_text(), CI_CASES, 1, |b| check_obj(&b));
    run_cases(&prop::collection::vec(any::<u8>(), 0..400), CI_CASES, 2, |b| check_obj(&b));
}

#[test]
fn ply_and_off_reader_properties() {
    run_cases(&ply_text(), CI_CASES, 6, |b| check_mesh(&b, MeshFormat::Ply));
    run_cases(&prop::collection::vec(any::<u8>(), 0..400), CI_CASES, 7, |b| check_mesh(&b, MeshFormat::Ply));
    run_cases(&off_text(), CI_CASES, 8, |b| check_mesh(&b, MeshFormat::Off));
    run_cases(&prop::collection::vec(any::<u8>(), 0..400), CI_CASES, 9, |b| check_mesh(&b, MeshFormat::Off));
    run_cases(&(polygon_mesh(), 0usize..4), 400, 10, |((p, f), e)| check_round_trip(&p, &f, e));
    // A valid file with a few bytes changed: near-valid input reaches the deep checks.
    let mutated = (polygon_mesh(), 0usize..4, prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4));
    run_cases(&mutated, CI_CASES, 11, |((p, f), e, edits)| {
        let mut bytes = write_mesh(&p, &f, e);
        for (at, b) in edits {
            let i = at.index(bytes.len());
            bytes[i] = b;
        }
        check_mesh(&bytes, if e == 3 { MeshFormat::Off } else { MeshFormat::Ply })
    });
}

#[test]
fn pbrt_reader_properties() {
    run_cases(&pbrt_text(), CI_CASES, 12, |b| check_pbrt(&b));
    run_cases(&prop::collection::vec(any::<u8>(), 0..400), 500, 13, |b| check_pbrt(&b));
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
fn fuzz_ply_and_off_readers() {
    fuzz_for("PLY reader (grammar)", ply_text(), |b| check_mesh(&b, MeshFormat::Ply));
    fuzz_for("PLY reader (bytes)", prop::collection::vec(any::<u8>(), 0..2000), |b| check_mesh(&b, MeshFormat::Ply));
    fuzz_for("OFF reader (grammar)", off_text(), |b| check_mesh(&b, MeshFormat::Off));
    fuzz_for("mesh round trip", (polygon_mesh(), 0usize..4), |((p, f), e)| check_round_trip(&p, &f, e));
}

#[test]
#[ignore]
fn fuzz_pbrt_reader() {
    fuzz_for("pbrt-v4 reader (grammar)", pbrt_text(), |b| check_pbrt(&b));
    fuzz_for("pbrt-v4 reader (bytes)", prop::collection::vec(any::<u8>(), 0..2000), |b| check_pbrt(&b));
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
