//! The mesh formats: one mesh written as OBJ, PLY (ASCII, binary little and big endian, gzip) and
//! OFF loads to the same triangles and renders the same image bit for bit; malformed files are
//! refused (exit 2) naming the file and the line (or, in binary PLY, the element and its byte).

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use translucent::materials::Material;
use translucent::mesh::{Mesh, MeshFormat};
use translucent::output::Exposure;
use translucent::settings::{RenderSettings, SceneSettings};

/// A torus of quads (polygons, to test fan triangulation) with unit normals and texture coordinates.
struct Quads {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    faces: Vec<[u32; 4]>,
}

fn quad_torus(segments: u32, sides: u32) -> Quads {
    let mut q = Quads { positions: vec![], normals: vec![], uvs: vec![], faces: vec![] };
    for i in 0..segments {
        let phi = std::f32::consts::TAU * i as f32 / segments as f32;
        let ring = Vec3::new(phi.cos(), 0.0, -phi.sin());
        for j in 0..sides {
            let theta = std::f32::consts::TAU * j as f32 / sides as f32;
            let n = (ring * theta.cos() + Vec3::Y * theta.sin()).normalize();
            q.positions.push(ring + n * 0.4);
            q.normals.push(n);
            q.uvs.push(Vec2::new(i as f32 / segments as f32, j as f32 / sides as f32));
        }
    }
    for i in 0..segments {
        for j in 0..sides {
            let at = |a: u32, b: u32| (a % segments) * sides + b % sides;
            q.faces.push([at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    q
}

fn obj(q: &Quads, normals: bool) -> Vec<u8> {
    let mut s = String::from("# a torus of quads\no torus\n");
    for p in &q.positions {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    if normals {
        for n in &q.normals {
            s += &format!("vn {} {} {}\n", n.x, n.y, n.z);
        }
    }
    for f in &q.faces {
        let c: Vec<String> =
            f.iter().map(|i| if normals { format!("{0}//{0}", i + 1) } else { format!("{}", i + 1) }).collect();
        s += &format!("f {}\n", c.join(" "));
    }
    s.into_bytes()
}

#[derive(Clone, Copy, PartialEq)]
enum Ply {
    Ascii,
    Little,
    Big,
}

/// A PLY file the way scanners write them: `obj_info` and comments, extra vertex properties
/// (confidence, intensity) before the normals, doubles for positions in binary, an extra element
/// between the vertices and the faces, an extra face property after the index list.
fn ply(q: &Quads, encoding: Ply) -> Vec<u8> {
    let format = match encoding {
        Ply::Ascii => "ascii",
        Ply::Little => "binary_little_endian",
        Ply::Big => "binary_big_endian",
    };
    let position_type = if encoding == Ply::Ascii { "float" } else { "double" };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment written by tests/mesh_formats.rs\nobj_info a torus of quads\n\
         element vertex {}\nproperty {position_type} x\nproperty {position_type} y\nproperty {position_type} z\n\
         property float confidence\nproperty float intensity\nproperty float nx\nproperty float ny\nproperty float nz\n\
         property float s\nproperty float t\nelement marker 2\nproperty int id\nproperty list uchar float values\n\
         element face {}\nproperty list uchar int vertex_indices\nproperty uchar flags\nend_header\n",
        q.positions.len(),
        q.faces.len()
    )
    .into_bytes();
    let big = encoding == Ply::Big;
    let f32b = |v: f32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
    let f64b = |v: f64| if big { v.to_be_bytes() } else { v.to_le_bytes() };
    let i32b = |v: i32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
    for ((p, n), uv) in q.positions.iter().zip(&q.normals).zip(&q.uvs) {
        if encoding == Ply::Ascii {
            writeln!(out, "{} {} {} 0.5 0.25 {} {} {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y).unwrap();
        } else {
            for c in [p.x, p.y, p.z] {
                out.extend(f64b(c as f64));
            }
            for c in [0.5, 0.25, n.x, n.y, n.z, uv.x, uv.y] {
                out.extend(f32b(c));
            }
        }
    }
    for id in 0..2 {
        if encoding == Ply::Ascii {
            writeln!(out, "{id} 2 1.5 2.5").unwrap();
        } else {
            out.extend(i32b(id));
            out.push(2);
            out.extend(f32b(1.5));
            out.extend(f32b(2.5));
        }
    }
    for f in &q.faces {
        if encoding == Ply::Ascii {
            writeln!(out, "4 {} {} {} {} 7", f[0], f[1], f[2], f[3]).unwrap();
        } else {
            out.push(4);
            for i in f {
                out.extend(i32b(*i as i32));
            }
            out.push(7);
        }
    }
    out
}

fn off(q: &Quads, normals: bool) -> Vec<u8> {
    let mut s = format!(
        "{}OFF\n# a torus of quads\n{} {} 0\n\n",
        if normals { "N" } else { "" },
        q.positions.len(),
        q.faces.len()
    );
    for (p, n) in q.positions.iter().zip(&q.normals) {
        if normals {
            s += &format!("{} {} {} {} {} {}\n", p.x, p.y, p.z, n.x, n.y, n.z);
        } else {
            s += &format!("{} {} {}\n", p.x, p.y, p.z);
        }
    }
    for f in &q.faces {
        // A colour after the indices, as CGAL writes for coloured faces.
        s += &format!("4 {} {} {} {} 0.5 0.5 0.5\n", f[0], f[1], f[2], f[3]);
    }
    s.into_bytes()
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = common::output_dir().join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The torus in every format (with normals), as files: (label, path).
fn torus_files(dir: &Path) -> Vec<(&'static str, PathBuf)> {
    let q = quad_torus(24, 12);
    let files: Vec<(&'static str, &str, Vec<u8>)> = vec![
        ("obj", "torus.obj", obj(&q, true)),
        ("ply ascii", "torus-ascii.ply", ply(&q, Ply::Ascii)),
        ("ply little endian", "torus-le.ply", ply(&q, Ply::Little)),
        ("ply big endian", "torus-be.ply", ply(&q, Ply::Big)),
        ("ply big endian, gzip", "torus-be.ply.gz", gzip(&ply(&q, Ply::Big))),
        ("noff", "torus.off", off(&q, true)),
    ];
    files
        .into_iter()
        .map(|(label, name, bytes)| {
            let path = dir.join(name);
            std::fs::write(&path, bytes).unwrap();
            (label, path)
        })
        .collect()
}

/// The triangles as (position, normal) corners, in order: what the renderer sees, whatever the
/// vertex numbering.
fn corners(mesh: &Mesh) -> Vec<[u32; 6]> {
    mesh.indices
        .iter()
        .map(|&i| {
            let (p, n) = (mesh.positions[i as usize], mesh.normals[i as usize]);
            [p.x, p.y, p.z, n.x, n.y, n.z].map(f32::to_bits)
        })
        .collect()
}

#[test]
fn every_format_loads_the_same_triangles() {
    let dir = temp_dir("mesh-formats-load");
    let files = torus_files(&dir);
    let reference = Mesh::load(&files[0].1).unwrap();
    assert_eq!(reference.triangle_count(), 24 * 12 * 2);
    for (label, path) in &files[1..] {
        let mesh = Mesh::load(path).unwrap_or_else(|e| panic!("{label}: {e}"));
        assert_eq!(corners(&mesh), corners(&reference), "{label}");
        // PLY and OFF keep the file's numbering: the vertices are the file's, in order.
        let q = quad_torus(24, 12);
        assert_eq!(mesh.positions, q.positions, "{label}");
        assert_eq!(&mesh.indices[..6], &[0, 12, 13, 0, 13, 1], "{label}: fan triangulation");
    }
    // Without normals they are computed the same way for every format.
    let q = quad_torus(24, 12);
    let plain_obj = Mesh::from_bytes(&obj(&q, false), MeshFormat::Obj, "plain.obj").unwrap();
    let plain_off = Mesh::from_bytes(&off(&q, false), MeshFormat::Off, "plain.off").unwrap();
    assert_eq!(corners(&plain_off), corners(&plain_obj));
    // The PLY reader keeps the texture coordinates (s t here) for scene files.
    let raw = translucent::mesh::read_raw(&files[3].1).unwrap();
    assert_eq!(raw.uvs.as_deref(), Some(&q.uvs[..]));
}

#[test]
fn every_format_renders_the_same_image() {
    let dir = temp_dir("mesh-formats-render");
    let mut images = Vec::new();
    for (label, path) in torus_files(&dir) {
        let scene = SceneSettings {
            mesh: Some(path.to_string_lossy().into_owned()),
            light_dir: Vec3::new(-0.4, 0.8, 0.5),
            ..Default::default()
        };
        let mut s = RenderSettings::new(scene.build().unwrap(), Material::find("skin1").unwrap());
        (s.desc.width, s.desc.height, s.world.objects[0].samples, s.desc.exposure) =
            (40, 40, Some(4096), Exposure::Stops(0.0));
        let image = common::render_hdr(&s);
        assert!(image.pixels.iter().any(|p| p[0] > 0.0), "{label}: black image");
        images.push((label, image.pixels));
    }
    for (label, pixels) in &images[1..] {
        assert!(pixels == &images[0].1, "{label}: differs from the OBJ's image");
    }
}

#[test]
fn the_cgal_and_glmark2_meshes_load_when_installed() {
    let archive = Path::new("/usr/share/doc/libcgal-dev/data.tar.gz");
    if !archive.exists() {
        eprintln!("skipped: {} is not installed (Debian package libcgal-demo)", archive.display());
        return;
    }
    let dir = temp_dir("cgal");
    let status = std::process::Command::new("tar")
        .args(["xzf", archive.to_str().unwrap(), "-C", dir.to_str().unwrap(), "data/meshes/elephant.off"])
        .args(["data/meshes/sphere.ply", "data/meshes/colored_tetra.ply"])
        .status()
        .unwrap();
    assert!(status.success());
    let elephant = Mesh::load(&dir.join("data/meshes/elephant.off")).unwrap();
    assert_eq!((elephant.positions.len(), elephant.triangle_count()), (2775, 5558));
    let sphere = Mesh::load(&dir.join("data/meshes/sphere.ply")).unwrap();
    assert_eq!((sphere.positions.len(), sphere.triangle_count()), (162, 320));
    // Normals, colours, an id and an extra `edge` element.
    let tetra = Mesh::load(&dir.join("data/meshes/colored_tetra.ply")).unwrap();
    assert_eq!(tetra.triangle_count(), 4);
}

/// Writes `bytes` as `name` and loads it: the error, which must be bad input (exit 2) naming the
/// file and containing every one of `needles`.
fn refused(dir: &Path, name: &str, bytes: &[u8], needles: &[&str]) {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    let err = Mesh::load(&path).expect_err(name);
    assert_eq!(err.exit_code(), 2, "{name}: {err}");
    let msg = err.to_string();
    assert!(msg.contains(&path.display().to_string()), "{name}: {msg}");
    for needle in needles {
        assert!(msg.contains(needle), "{name}: {msg:?} lacks {needle:?}");
    }
}

#[test]
fn malformed_ply_and_off_files_are_refused_naming_the_line() {
    let dir = temp_dir("mesh-formats-refused");
    let head = |format: &str, vertices: u64, faces: u64| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {vertices}\nproperty float x\nproperty float y\nproperty float z\n\
             element face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
        )
    };
    let tri = "0 0 0\n1 0 0\n0 1 0\n";
    for (name, text, needles) in [
        ("not-ply.ply", "solid cube\n".to_string(), &["line 1", "not a PLY file"][..]),
        ("bad-format.ply", "ply\nformat cubes 1.0\nend_header\n".into(), &["line 2", "malformed PLY header"]),
        ("no-header-end.ply", "ply\nformat ascii 1.0\nelement vertex 3\n".into(), &["end_header"]),
        ("no-z.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0\n".into(), &["line 3", "'z'"]),
        ("no-faces.ply", head("ascii", 3, 0) + tri, &["no faces"]),
        ("no-index-list.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty int a\nend_header\n0 0 0\n1 0 0\n0 1 0\n7\n".into(), &["line 7", "vertex_indices"]),
        ("index-out-of-range.ply", head("ascii", 3, 1) + tri + "3 0 1 3\n", &["line 13", "vertex index 3 is out of range"]),
        ("negative-index.ply", head("ascii", 3, 1) + tri + "3 0 -1 2\n", &["line 13"]),
        ("two-corners.ply", head("ascii", 3, 1) + tri + "2 0 1\n", &["line 13", "at least 3"]),
        ("nan.ply", head("ascii", 3, 1) + "0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", &["line 11", "not numbers"]),
        ("inf.ply", head("ascii", 3, 1) + "0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n", &["line 11", "not finite"]),
        ("bad-number.ply", head("ascii", 3, 1) + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", &["line 11"]),
        ("truncated.ply", head("ascii", 3, 1) + tri, &["line 7", "declares 1 'face'"]),
        ("huge-count.ply", head("ascii", 1 << 40, 1) + tri, &["line 3", "at most"]),
        ("trailing.ply", head("ascii", 3, 1) + tri + "3 0 1 2\n9 9 9\n", &["line 14", "after the last element"]),
        ("zero-area.ply", head("ascii", 3, 1) + "0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n", &["zero surface area"]),
        ("not-off.off", "ply\n".into(), &["line 1", "not an OFF file"]),
        ("4off.off", "4OFF\n1 1 0\n".into(), &["line 1", "4OFF"]),
        ("off-counts.off", "OFF\n# comment\nthree 1 0\n".into(), &["line 3", "not a whole number"]),
        ("off-huge.off", "OFF\n100000000000 1 0\n".into(), &["line 2", "at most"]),
        ("off-truncated.off", format!("OFF\n3 2 0\n{tri}3 0 1 2\n"), &["line 6", "after 1 of the 2 faces declared on line 2"]),
        ("off-index.off", format!("OFF\n3 1 0\n{tri}3 0 1 5\n"), &["line 6", "vertex index 5 is out of range"]),
        ("off-short-face.off", format!("OFF\n3 1 0\n{tri}4 0 1 2\n"), &["line 6", "declares 4 vertices but lists 3"]),
        ("off-vertex.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n".into(), &["line 4", "needs 3 numbers"]),
        ("off-inf.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n".to_string(), &["line 4", "not finite"]),
    ] {
        refused(&dir, name, text.as_bytes(), needles);
    }

    // Binary: the element's index and byte offset. Header is 158 bytes; 12 bytes per vertex.
    let mut b = head("binary_little_endian", 3, 1).into_bytes();
    let header_len = b.len();
    for v in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        v.iter().for_each(|c| b.extend(c.to_le_bytes()));
    }
    let mut bad = b.clone();
    bad.push(3);
    [0i32, 1, 9].iter().for_each(|i| bad.extend(i.to_le_bytes()));
    let offset = format!("element 0 at byte {}", header_len + 36);
    refused(&dir, "binary-index.ply", &bad, &[&offset, "vertex index 9"]);
    refused(&dir, "binary-no-faces.ply", &b, &["line 7", "declares 1 'face'", "0 bytes"]);
    let mut cut = b.clone();
    cut.extend([3u8, 0, 0]);
    refused(&dir, "binary-truncated.ply", &cut, &["'face' element 0 at byte", "ends inside it"]);
    let mut cut_list = b.clone();
    cut_list.extend([200u8, 0, 0, 0, 0]);
    refused(&dir, "binary-truncated-list.ply", &cut_list, &["ends inside it"]);
    // A header claiming 2^40 faces is refused before anything is allocated.
    let mut huge = head("binary_big_endian", 3, 1 << 40).into_bytes();
    huge.extend([0u8; 36]);
    refused(&dir, "binary-huge.ply", &huge, &["at most"]);
    let mut zero_props =
        head("binary_little_endian", 3, 1).replace("end_header", "element empty 99999999999\nend_header").into_bytes();
    zero_props.extend(&b[header_len..]);
    zero_props.push(3);
    [0i32, 1, 2].iter().for_each(|i| zero_props.extend(i.to_le_bytes()));
    refused(&dir, "binary-empty-element.ply", &zero_props, &["'empty'"]);

    // gzip: not gzip at all, and a bomb is bounded (checked by reading, not by allocating).
    refused(&dir, "plain.ply.gz", b"ply\n", &["gzip"]);
}

#[test]
fn the_command_line_reads_every_format_and_refuses_naming_file_and_line() {
    let dir = temp_dir("mesh-formats-cli");
    let bad = dir.join("bad.ply");
    std::fs::write(&bad, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n").unwrap();
    let out = dir.join("out.png");
    let result = common::translucent(&["render", "--mesh", bad.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    let err = common::stderr(&result);
    assert_eq!(result.status.code(), Some(2), "{err}");
    assert!(err.starts_with("error:") && err.contains("bad.ply: line 13"), "{err}");
    // A FIFO is refused unopened, as for OBJ files.
    let fifo = dir.join("pipe.ply");
    let _ = std::fs::remove_file(&fifo);
    if std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success()) {
        let result = common::translucent(&["render", "--mesh", fifo.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        assert_eq!(result.status.code(), Some(2));
        assert!(common::stderr(&result).contains("not a regular file"));
    }
}

#[test]
fn a_frame_sequence_of_ply_files_loads_through_the_same_reader() {
    let dir = temp_dir("mesh-formats-sequence");
    let q = quad_torus(8, 6);
    for i in 0..3 {
        std::fs::write(dir.join(format!("frame-{i}.ply")), ply(&q, Ply::Little)).unwrap();
    }
    let pattern = dir.join("frame-{frame}.ply").to_string_lossy().into_owned();
    let mesh = translucent::deform::first_mesh(&pattern).unwrap();
    assert_eq!(mesh.triangle_count(), 8 * 6 * 2);
}
