//! glTF 2.0 scenes: the default bunny written as glTF renders as the flags render it; node
//! hierarchies against meshes transformed by hand; GLB, external and embedded buffers give the
//! same world; materials (translucent by KHR_materials_volume + transmission, opaque otherwise,
//! textures, KHR_texture_transform), lights and cameras; every refusal class (exit 2, the file
//! and the JSON path named); property tests of the accessor reader and of the whole reader.

mod common;

use std::path::{Path, PathBuf};

use glam::{DMat4, DQuat, DVec3, Quat, Vec2, Vec3};
use proptest::prelude::*;
use serde_json::{json, Value};
use translucent::gltf::accessor::{self, Component, Layout};
use translucent::gltf::{self as tg};
use translucent::mesh::Mesh;
use translucent::scene::Light;
use translucent::world::Reflectance;

fn dir(name: &str) -> PathBuf {
    let d = common::output_dir().join("gltf").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A glTF document being written: its JSON and its one binary buffer.
struct Doc {
    json: Value,
    bin: Vec<u8>,
}

impl Doc {
    fn new() -> Doc {
        Doc {
            json: json!({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}], "nodes": [],
                "meshes": [], "accessors": [], "bufferViews": [], "buffers": [{"byteLength": 0}], "materials": []}),
            bin: Vec::new(),
        }
    }

    fn push(&mut self, key: &str, v: Value) -> usize {
        let a = self.json.as_object_mut().unwrap().entry(key).or_insert(json!([]));
        let a = a.as_array_mut().unwrap();
        a.push(v);
        a.len() - 1
    }

    /// A buffer view of `bytes` (4-byte aligned), with an optional stride.
    fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.json["buffers"][0]["byteLength"] = json!(self.bin.len());
        let mut v = json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()});
        if let Some(s) = stride {
            v["byteStride"] = json!(s);
        }
        self.push("bufferViews", v)
    }

    fn accessor(&mut self, bytes: &[u8], component: u32, kind: &str, count: usize) -> usize {
        let v = self.view(bytes, None);
        self.push("accessors", json!({"bufferView": v, "componentType": component, "type": kind, "count": count}))
    }

    fn vec3s(&mut self, ps: &[Vec3]) -> usize {
        let bytes: Vec<u8> = ps.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let a = self.accessor(&bytes, 5126, "VEC3", ps.len());
        let (lo, hi) = ps.iter().fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
        self.json["accessors"][a]["min"] = json!(lo.to_array());
        self.json["accessors"][a]["max"] = json!(hi.to_array());
        a
    }

    fn vec2s(&mut self, uvs: &[Vec2]) -> usize {
        let bytes: Vec<u8> = uvs.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        self.accessor(&bytes, 5126, "VEC2", uvs.len())
    }

    fn indices(&mut self, idx: &[u32]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        self.accessor(&bytes, 5125, "SCALAR", idx.len())
    }

    /// A mesh of one primitive: positions, indices, a material and optional uvs.
    fn mesh(&mut self, mesh: &Mesh, material: Option<usize>, uvs: Option<&[Vec2]>) -> usize {
        let p = self.vec3s(&mesh.positions);
        let i = self.indices(&mesh.indices);
        let mut prim = json!({"attributes": {"POSITION": p}, "indices": i});
        if let Some(uv) = uvs {
            let t = self.vec2s(uv);
            prim["attributes"]["TEXCOORD_0"] = json!(t);
        }
        if let Some(m) = material {
            prim["material"] = json!(m);
        }
        self.push("meshes", json!({"primitives": [prim]}))
    }

    /// A node, listed in the scene when `root`.
    fn node(&mut self, node: Value, root: bool) -> usize {
        let n = self.push("nodes", node);
        if root {
            self.json["scenes"][0]["nodes"].as_array_mut().unwrap().push(json!(n));
        }
        n
    }

    fn light(&mut self, light: Value) -> usize {
        let ext = self.json.as_object_mut().unwrap().entry("extensions").or_insert(json!({}));
        let lights = ext.as_object_mut().unwrap().entry("KHR_lights_punctual").or_insert(json!({"lights": []}));
        let a = lights["lights"].as_array_mut().unwrap();
        a.push(light);
        a.len() - 1
    }

    /// `.gltf` with the buffer in a file beside it.
    fn write_external(&self, dir: &Path, name: &str) -> PathBuf {
        let mut j = self.json.clone();
        j["buffers"][0]["uri"] = json!(format!("{name}.bin"));
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin).unwrap();
        let p = dir.join(format!("{name}.gltf"));
        std::fs::write(&p, serde_json::to_vec_pretty(&j).unwrap()).unwrap();
        p
    }

    /// `.gltf` as it is (the buffer's uri as the JSON gives it, no `.bin` written).
    fn write_raw(&self, dir: &Path, name: &str) -> PathBuf {
        let p = dir.join(format!("{name}.gltf"));
        std::fs::write(&p, serde_json::to_vec(&self.json).unwrap()).unwrap();
        p
    }

    /// `.gltf` with the buffer as a base64 data URI.
    fn write_embedded(&self, dir: &Path, name: &str) -> PathBuf {
        use base64::Engine;
        let mut j = self.json.clone();
        let data = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        j["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
        let p = dir.join(format!("{name}.gltf"));
        std::fs::write(&p, serde_json::to_vec(&j).unwrap()).unwrap();
        p
    }

    /// `.glb`: the JSON chunk and the buffer as its binary chunk.
    fn write_glb(&self, dir: &Path, name: &str) -> PathBuf {
        let p = dir.join(format!("{name}.glb"));
        std::fs::write(&p, glb(&serde_json::to_vec(&self.json).unwrap(), &self.bin)).unwrap();
        p
    }
}

fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut j = json.to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&b);
    out
}

/// `render_settings` for `translucent render PATH ARGS…`, as the command reads them.
fn settings_of(path: &Path, args: &[&str]) -> translucent::error::Result<translucent::settings::RenderSettings> {
    full_settings(path, args).map(|(_, s)| s)
}

fn error_of(path: &Path, args: &[&str]) -> translucent::error::Error {
    match settings_of(path, args) {
        Ok(_) => panic!("{}: accepted", path.display()),
        Err(e) => e,
    }
}

fn full_settings(
    path: &Path,
    args: &[&str],
) -> translucent::error::Result<(translucent::cli::RenderArgs, translucent::settings::RenderSettings)> {
    use clap::Parser;
    let argv: Vec<String> =
        ["translucent", "render", path.to_str().unwrap()].iter().chain(args).map(|s| s.to_string()).collect();
    let translucent::cli::Command::Render(r) = translucent::cli::Cli::try_parse_from(&argv).unwrap().command else {
        unreachable!()
    };
    translucent::settings::scene_file_settings(path, &r, &|f| translucent::pbrt::flag_given(&argv, f))
}

/// The default render's mesh: the bunny when installed, else the sphere.
fn default_mesh() -> (String, Mesh) {
    let spec = translucent::settings::SceneSettings::default().mesh_spec();
    let mesh = Mesh::from_spec(&spec).unwrap();
    (spec, mesh)
}

/// A rotation × scale whose z column is exactly `z` (so the direction a light's node gives is
/// `z` to the bit) and whose other columns are orthogonal to it.
fn frame_with_z(z: Vec3) -> [f32; 16] {
    let x = if z.x.abs() < 0.9 { Vec3::new(z.y, -z.x, 0.0) } else { Vec3::new(0.0, z.z, -z.y) };
    let y = z.cross(x);
    let m = glam::Mat4::from_cols(x.extend(0.0), y.extend(0.0), z.extend(0.0), glam::Vec4::W);
    m.to_cols_array()
}

fn render(args: &[&str]) -> std::process::Output {
    let mut full = vec!["render"];
    full.extend_from_slice(args);
    common::translucent(&full)
}

fn exr(path: &Path) -> image::Rgba32FImage {
    image::open(path).unwrap().into_rgba32f()
}

/// The default scene (the bunny, marble, the default light, the default framing) written as glTF
/// renders bit for bit as the flags render it; its camera written as a glTF camera node renders
/// within a bound (the node's quaternion is not the framing's direction to the bit).
#[test]
fn the_default_bunny_written_as_gltf_renders_as_the_flags_do() {
    let d = dir("bunny");
    let (spec, mesh) = default_mesh();
    let mut doc = Doc::new();
    let mat = doc.push("materials", json!({"name": "bunny", "pbrMetallicRoughness": {"roughnessFactor": 0.35}}));
    let m = doc.mesh(&mesh, Some(mat), None);
    doc.node(json!({"mesh": m}), true);
    // The default light: toward (−0.3, 0.7, −0.65), irradiance 1 (1 lux as 1 W/m²).
    let l = doc.light(json!({"type": "directional", "intensity": 1.0}));
    doc.node(json!({"matrix": frame_with_z(Vec3::new(-0.3, 0.7, -0.65)), "extensions": {"KHR_lights_punctual": {"light": l}}}), true);
    let path = doc.write_external(&d, "bunny");
    let small = ["--width", "64", "--height", "64", "--validation"];
    let (a, b) = (d.join("gltf.exr"), d.join("flags.exr"));
    let out = render(
        &[&[path.to_str().unwrap(), "--material", "marble", "--scale", "10", "-o", a.to_str().unwrap()][..], &small]
            .concat(),
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let out = render(&[&["--mesh", &spec, "-o", b.to_str().unwrap()][..], &small].concat());
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let (ia, ib) = (exr(&a), exr(&b));
    assert!(ia.pixels().filter(|p| p[3] > 0.0).count() > 400, "the bunny covers the image's middle");
    assert!(ia == ib, "the glTF bunny and the flags' bunny differ");

    // The framing as a camera node: at the eye, its −z toward the centre, yfov 40°.
    let (centre, radius) = translucent::scene::bounding_sphere(&mesh.positions);
    let cam = translucent::scene::Camera::framing(centre, radius, 40.0, Vec3::new(0.3, 0.3, 1.0));
    let back = (cam.eye - cam.target).as_dvec3().normalize();
    let x = DVec3::Y.cross(back).normalize();
    let q = DQuat::from_mat3(&glam::DMat3::from_cols(x, back.cross(x), back));
    let c = doc.push(
        "cameras",
        json!({"type": "perspective", "perspective": {"yfov": 40f64.to_radians(), "aspectRatio": 1.0, "znear": 0.01}}),
    );
    doc.node(json!({"camera": c, "translation": cam.eye.to_array(), "rotation": [q.x, q.y, q.z, q.w]}), true);
    let path = doc.write_glb(&d, "bunny-camera");
    let s = settings_of(&path, &["--material", "marble", "--scale", "10", "--width", "64", "--height", "64"]).unwrap();
    let got = &s.desc.camera;
    println!(
        "camera: eye {} vs {}, target {} vs {}, fov {} vs 40",
        got.eye, cam.eye, got.target, cam.target, got.fov_y_deg
    );
    assert!((got.eye - cam.eye).length() < 1e-5 * radius);
    let (fa, fb) = ((got.target - got.eye).normalize(), (cam.target - cam.eye).normalize());
    assert!((fa - fb).length() < 1e-6 && (got.fov_y_deg - 40.0).abs() < 1e-4, "{fa} vs {fb}");
    assert_eq!((s.desc.width, s.desc.height), (64, 64), "aspect ratio 1 keeps the typed size");
    let c_exr = d.join("camera.exr");
    let out = render(
        &[
            &[path.to_str().unwrap(), "--material", "marble", "--scale", "10", "-o", c_exr.to_str().unwrap()][..],
            &small,
        ]
        .concat(),
    );
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let ic = exr(&c_exr);
    let (mut worst, mut sum, mut differ, mut coverage) = (0f32, 0f64, 0, 0);
    for (p, q) in ic.pixels().zip(ib.pixels()) {
        if p[3] != q[3] {
            coverage += 1;
        }
        for k in 0..3 {
            let (x, y) = (p[k], q[k]);
            let rel = (x - y).abs() / y.abs().max(1e-3);
            worst = worst.max(rel);
            sum += (x - y).abs() as f64;
            differ += (x != y) as usize;
        }
    }
    let mean = ib.pixels().map(|p| (p[0] + p[1] + p[2]) as f64).sum::<f64>();
    println!(
        "the glTF camera against the framing: {differ} of {} channels differ, worst relative {worst:.2e}, total |difference| / total {:.2e}, {coverage} pixels of coverage differ",
        64 * 64 * 3,
        sum / mean
    );
    // Measured: 3345 of 12288 channels differ, worst 1.04e-4 relative, total 2.2e-6 of the image:
    // the camera's axis from the quaternion is the framing's within 1e-7 (f32 rounding), which
    // moves where each pixel meets the surface by as much; no pixel changes coverage.
    assert!(coverage == 0 && worst < 1e-3 && sum / mean < 2e-5, "the camera node's image is not the framing's");
}

/// The volume material mapping: a material whose base colour is marble's dipole reflectance
/// and whose attenuation gives marble's mean free path comes back as marble's coefficients.
#[test]
fn a_volume_material_inverts_to_the_coefficients_it_was_made_from() {
    let d = dir("volume");
    let marble = translucent::materials::Material::find("marble").unwrap();
    let eta = 1.5;
    let a = translucent::physics::Medium { sigma_a: 0.1, sigma_s: 1.0, g: 0.0, eta }
        .constants(translucent::physics::Diffusion::Classical)
        .a_dipole;
    let mut colour = [0.0; 3];
    let mut mfp_m = [0.0; 3];
    for ch in 0..3 {
        let st = marble.sigma_a[ch] + marble.sigma_s[ch] * (1.0 - marble.g[ch]);
        colour[ch] = translucent::physics::dipole::total_rd(marble.sigma_s[ch] * (1.0 - marble.g[ch]) / st, a);
        mfp_m[ch] = 1.0 / st / 1000.0; // mm → m
    }
    // mfp = d / (1 − ln c): d the largest mfp (its channel white), c = exp(1 − d/mfp).
    let dist = mfp_m.iter().cloned().fold(0.0, f64::max);
    let att = mfp_m.map(|m| (1.0 - dist / m).exp());
    let mut doc = Doc::new();
    let mat = doc.push(
        "materials",
        json!({"name": "marble", "pbrMetallicRoughness": {"baseColorFactor": [colour[0], colour[1], colour[2], 1.0]},
               "extensions": {"KHR_materials_volume": {"thicknessFactor": 0.01, "attenuationDistance": dist, "attenuationColor": att},
                              "KHR_materials_transmission": {"transmissionFactor": 1.0}}}),
    );
    let m = doc.mesh(&Mesh::sphere(0.05, 16), Some(mat), None);
    doc.node(json!({"mesh": m}), true);
    let s = settings_of(&doc.write_external(&d, "v"), &[]).unwrap();
    assert_eq!(s.world.objects.len(), 1);
    assert_eq!(s.world.mm_per_unit, 1000.0, "metres");
    let got = &s.world.objects[0].material;
    for ch in 0..3 {
        let (sa, ss) = (marble.sigma_a[ch], marble.sigma_s[ch] * (1.0 - marble.g[ch]));
        // f32 in the file (colour, distance): 1e-5 relative.
        assert!((got.sigma_a[ch] - sa).abs() < 1e-4 * sa.max(1e-3), "σa {ch}: {} vs {sa}", got.sigma_a[ch]);
        assert!((got.sigma_s[ch] - ss).abs() < 1e-5 * ss, "σs {ch}: {} vs {ss}", got.sigma_s[ch]);
    }
    assert_eq!(got.eta, 1.5, "KHR_materials_ior's default");
    // KHR_materials_volume_scatter's multiscatterColor gives the reflectance; ior and g read.
    doc.json["materials"][0]["extensions"]["KHR_materials_volume_scatter"] =
        json!({"multiscatterColor": [0.5, 0.4, 0.3], "scatterAnisotropy": 0.3});
    doc.json["materials"][0]["extensions"]["KHR_materials_ior"] = json!({"ior": 1.33});
    let s = settings_of(&doc.write_external(&d, "scatter"), &[]).unwrap();
    let got = &s.world.objects[0].material;
    assert_eq!((got.eta, got.g), (1.33f32 as f64, [0.3; 3]), "ior through the crate (f32), the raw JSON's g (f64)");
    let a = translucent::physics::Medium { sigma_a: 0.1, sigma_s: 1.0, g: 0.0, eta: got.eta }
        .constants(translucent::physics::Diffusion::Classical)
        .a_dipole;
    for (ch, want) in [0.5, 0.4, 0.3].into_iter().enumerate() {
        let reduced = got.sigma_s[ch] * (1.0 - got.g[ch]);
        let rd = translucent::physics::dipole::total_rd(reduced / (reduced + got.sigma_a[ch]), a);
        assert!((rd - want).abs() < 1e-9, "channel {ch}: Rd {rd} vs {want}");
    }
    // Without a transmission it is opaque; diffuse transmission (raw JSON) makes it translucent.
    doc.json["materials"][0]["extensions"].as_object_mut().unwrap().remove("KHR_materials_transmission");
    let s = settings_of(&doc.write_external(&d, "opaque"), &[]).unwrap();
    assert_eq!((s.world.objects.len(), s.world.opaque.len()), (0, 1));
    assert_eq!(s.world.opaque[0].reflectance, Reflectance::Constant(Vec3::from(colour.map(|c| c as f32))));
    doc.json["materials"][0]["extensions"]["KHR_materials_diffuse_transmission"] =
        json!({"diffuseTransmissionFactor": 0.5});
    let s = settings_of(&doc.write_external(&d, "diffuse"), &[]).unwrap();
    assert_eq!((s.world.objects.len(), s.world.opaque.len()), (1, 0));
    // --gltf-material NAME=PRESET and --material override the file.
    let s = settings_of(&doc.write_external(&d, "override"), &["--gltf-material", "marble=skin1"]).unwrap();
    assert_eq!(s.world.objects[0].material.sigma_a, translucent::materials::Material::find("skin1").unwrap().sigma_a);
    let s = settings_of(&doc.write_external(&d, "preset"), &["--material", "ketchup"]).unwrap();
    assert_eq!(s.world.objects[0].material.sigma_a, translucent::materials::Material::find("ketchup").unwrap().sigma_a);
}

/// Nested nodes (translation, rotation, scale, a matrix, a mirroring scale) against the mesh
/// transformed by hand: positions, normals by the inverse transpose, and the winding turned by
/// the mirror so that it agrees with the normals.
#[test]
fn a_node_hierarchy_matches_meshes_transformed_by_hand() {
    let d = dir("hierarchy");
    let tri = Mesh { positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y], normals: vec![Vec3::Z; 3], indices: vec![0, 1, 2] };
    let mut doc = Doc::new();
    let p = doc.vec3s(&tri.positions);
    let n = doc.vec3s(&tri.normals);
    let i = doc.indices(&tri.indices);
    let m = doc.push("meshes", json!({"primitives": [{"attributes": {"POSITION": p, "NORMAL": n}, "indices": i}]}));
    let q = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    let mirror = doc.node(json!({"mesh": m, "scale": [-1.0, 2.0, 1.0]}), false);
    let matrix = DMat4::from_cols_array(&[1., 0., 0., 0., 0., 0., 1., 0., 0., -1., 0., 0., 5., 0., 0., 1.]);
    let by_matrix = doc.node(json!({"mesh": m, "matrix": matrix.to_cols_array().map(|v| v as f32)}), false);
    let child = doc.node(
        json!({"mesh": m, "translation": [0.0, 0.0, 2.0], "scale": [2.0, 3.0, 4.0], "children": [mirror]}),
        false,
    );
    doc.node(
        json!({"mesh": m, "translation": [1.0, 2.0, 3.0], "rotation": [q.x, q.y, q.z, q.w], "children": [child, by_matrix]}),
        true,
    );
    let scene = tg::load(&doc.write_external(&d, "h"), None).unwrap();
    let parent = DMat4::from_rotation_translation(q.as_dquat(), DVec3::new(1.0, 2.0, 3.0));
    let c = parent * DMat4::from_scale_rotation_translation(DVec3::new(2.0, 3.0, 4.0), DQuat::IDENTITY, DVec3::Z * 2.0);
    let expected = [
        (parent, false),
        (c, false),
        (c * DMat4::from_scale(DVec3::new(-1.0, 2.0, 1.0)), true),
        (parent * matrix, false),
    ];
    assert_eq!(scene.objects.len(), 4);
    for (k, ((m, turned), o)) in expected.iter().zip(&scene.objects).enumerate() {
        let mesh = &o.mesh;
        let order = if *turned { [0, 2, 1] } else { [0, 1, 2] };
        for (corner, &v) in order.iter().enumerate() {
            let got = mesh.positions[mesh.indices[corner] as usize].as_dvec3();
            let want = m.transform_point3(tri.positions[v].as_dvec3());
            assert!((got - want).length() < 1e-5, "object {k} corner {corner}: {got} vs {want}");
        }
        let nrm = mesh.normals.as_ref().unwrap()[0].as_dvec3();
        let want = m.inverse().transpose().transform_vector3(DVec3::Z).normalize();
        assert!((nrm - want).length() < 1e-5, "object {k}: normal {nrm} vs {want}");
        let [a, b, c] = [0, 1, 2].map(|i| mesh.positions[mesh.indices[i] as usize]);
        assert!((b - a).cross(c - a).as_dvec3().dot(nrm) > 0.0, "object {k}: the winding against its normal");
    }
    assert!(
        scene.objects[2].path.starts_with("nodes[0] ") && scene.objects[2].path.contains("meshes[0].primitives[0]")
    );
    // The World render draws: the same triangles (opaque, glTF's default material), in its units.
    let s = settings_of(&d.join("h.gltf"), &[]).unwrap();
    assert_eq!(s.world.opaque.len(), 4);
    let f = 1000.0 / s.world.mm_per_unit;
    for (o, w) in scene.objects.iter().zip(&s.world.opaque) {
        assert_eq!(o.mesh.indices, w.mesh.indices, "{}", o.path);
        for (p, q) in o.mesh.positions.iter().zip(&w.mesh.positions) {
            assert!((*p * f - *q).length() < 1e-6 * f, "{}: {p} vs {q}", o.path);
        }
    }
}

/// Strips and fans become the triangles the specification forms; a mesh's several primitives,
/// indexed and not, each an object.
#[test]
fn strips_fans_and_several_primitives() {
    use translucent::gltf::read::triangles;
    let json_mode =
        |m: u32| serde_json::from_value::<gltf::json::validation::Checked<gltf::json::mesh::Mode>>(json!(m)).unwrap();
    let mode = |m: u32| match json_mode(m) {
        gltf::json::validation::Checked::Valid(m) => m,
        _ => unreachable!(),
    };
    assert_eq!(triangles(&[0, 1, 2, 3, 4], mode(5)).unwrap(), vec![0, 1, 2, 1, 3, 2, 2, 3, 4]);
    assert_eq!(triangles(&[0, 1, 2, 2, 3, 4], mode(5)).unwrap(), vec![0, 1, 2, 2, 4, 3], "degenerate joins dropped");
    assert_eq!(triangles(&[0, 1, 2, 3], mode(6)).unwrap(), vec![1, 2, 0, 2, 3, 0]);
    assert!(triangles(&[0, 1, 2, 3], mode(4)).unwrap_err().contains("multiple of 3"));

    let d = dir("primitives");
    let mut doc = Doc::new();
    let quad = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
    let p = doc.vec3s(&quad);
    let strip = doc.indices(&[0, 1, 3, 2]);
    let list = doc.vec3s(&[Vec3::ZERO, Vec3::X, Vec3::Y]);
    doc.push(
        "meshes",
        json!({"primitives": [
            {"attributes": {"POSITION": p}, "indices": strip, "mode": 5},
            {"attributes": {"POSITION": p}, "mode": 6},
            {"attributes": {"POSITION": list}}]}),
    );
    doc.node(json!({"mesh": 0}), true);
    let scene = tg::load(&doc.write_embedded(&d, "p"), None).unwrap();
    let tris: Vec<Vec<u32>> = scene.objects.iter().map(|o| o.mesh.indices.clone()).collect();
    assert_eq!(tris, vec![vec![0, 1, 3, 1, 2, 3], vec![1, 2, 0, 2, 3, 0], vec![0, 1, 2]]);
    // A sparse accessor: the list's third vertex replaced by (0, 2, 0).
    let idx = doc.view(&[2u8, 0, 0, 0], None);
    let val = doc.view(&[0.0f32, 2.0, 0.0].map(f32::to_le_bytes).concat(), None);
    doc.json["accessors"][list]["sparse"] =
        json!({"count": 1, "indices": {"bufferView": idx, "componentType": 5121}, "values": {"bufferView": val}});
    let sparse = tg::load(&doc.write_external(&d, "sparse"), None).unwrap();
    assert_eq!(sparse.objects[2].mesh.positions, vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, 2.0, 0.0)]);
    // Every one counter-clockwise seen from +z.
    for o in &scene.objects {
        for t in o.mesh.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| o.mesh.positions[t[k] as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "{}: {t:?}", o.path);
        }
    }
}

/// A small translucent box and an opaque textured floor under a point and a spot light.
fn box_scene(doc: &mut Doc, texture: Value) {
    let mat = doc.push(
        "materials",
        json!({"name": "jade", "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.7, 0.4, 1.0], "roughnessFactor": 0.5},
               "extensions": {"KHR_materials_volume": {"attenuationDistance": 0.002, "attenuationColor": [0.5, 0.9, 0.6]},
                              "KHR_materials_transmission": {"transmissionFactor": 1.0}}}),
    );
    let cube = Mesh::slab(0.05, 0.05, 0.05);
    let m = doc.mesh(&cube, Some(mat), None);
    doc.node(json!({"mesh": m, "rotation": [0.0, 0.3826834, 0.0, 0.9238795]}), true);
    let floor_mat = doc.push("materials", json!({"name": "floor", "pbrMetallicRoughness": {"baseColorTexture": texture, "baseColorFactor": [1.0, 0.5, 1.0, 1.0]}}));
    let floor = Mesh {
        positions: vec![
            Vec3::new(-0.2, -0.03, -0.2),
            Vec3::new(-0.2, -0.03, 0.2),
            Vec3::new(0.2, -0.03, 0.2),
            Vec3::new(0.2, -0.03, -0.2),
        ],
        normals: vec![Vec3::Y; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
    };
    let uvs = [Vec2::new(0.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0)];
    let fm = doc.mesh(&floor, Some(floor_mat), Some(&uvs));
    doc.node(json!({"mesh": fm}), true);
    let point = doc.light(json!({"type": "point", "intensity": 0.02, "color": [1.0, 0.9, 0.8]}));
    doc.node(json!({"translation": [0.1, 0.2, 0.1], "extensions": {"KHR_lights_punctual": {"light": point}}}), true);
    let spot =
        doc.light(json!({"type": "spot", "intensity": 0.05, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}}));
    // At (0, 0.3, 0.3), looking down −z turned toward the box's centre (the node's −z to −y·z).
    let q = Quat::from_rotation_arc(Vec3::NEG_Z, Vec3::new(0.0, -0.3, -0.3).normalize());
    doc.node(json!({"translation": [0.0, 0.3, 0.3], "rotation": [q.x, q.y, q.z, q.w], "extensions": {"KHR_lights_punctual": {"light": spot}}}), true);
    let cam = doc.push(
        "cameras",
        json!({"type": "perspective", "perspective": {"yfov": 0.6, "aspectRatio": 1.5, "znear": 0.01}}),
    );
    let q = Quat::from_rotation_arc(Vec3::NEG_Z, Vec3::new(0.0, -0.15, -0.3).normalize());
    doc.node(json!({"camera": cam, "translation": [0.0, 0.15, 0.3], "rotation": [q.x, q.y, q.z, q.w]}), true);
}

fn png_bytes(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(f(x, y)));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// GLB, `.gltf` with a `.bin` beside it and `.gltf` with a data URI (and the image in a buffer
/// view, a file and a data URI) give the same world and the same image; lights, camera, the
/// floor's texture × factor and its uvs as the file gives them.
#[test]
fn glb_external_and_embedded_buffers_give_the_same_world_and_image() {
    use base64::Engine;
    let d = dir("forms");
    let png = png_bytes(4, 2, |x, y| if (x + y) % 2 == 0 { [255, 255, 255] } else { [64, 128, 32] });
    std::fs::write(d.join("checker.png"), &png).unwrap();
    let mut forms = Vec::new();
    for form in ["external", "embedded", "glb"] {
        let mut doc = Doc::new();
        let image = match form {
            "external" => json!({"uri": "checker.png"}),
            "embedded" => {
                json!({"uri": format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(&png))})
            }
            _ => {
                let v = doc.view(&png, None);
                json!({"bufferView": v, "mimeType": "image/png"})
            }
        };
        doc.json["images"] = json!([image]);
        doc.json["textures"] = json!([{"source": 0}]);
        box_scene(&mut doc, json!({"index": 0}));
        forms.push(match form {
            "external" => doc.write_external(&d, form),
            "embedded" => doc.write_embedded(&d, form),
            _ => doc.write_glb(&d, form),
        });
    }
    let (args, first) = full_settings(&forms[0], &["--height", "32"]).unwrap();
    assert_eq!((args.width, args.height), (48, 32), "the camera's aspect ratio 1.5");
    for f in &forms[1..] {
        let s = settings_of(f, &["--height", "32"]).unwrap();
        assert!(s.world == first.world, "{} differs from {}", f.display(), forms[0].display());
        assert_eq!(s.desc.lights, first.desc.lights);
        assert_eq!(s.desc.camera, first.desc.camera);
    }
    let w = &first.world;
    assert_eq!((w.objects.len(), w.opaque.len(), w.mm_per_unit), (1, 1, 1000.0));
    assert_eq!(first.desc.roughness, 0.5, "the translucent material's roughnessFactor");
    // The floor: the texture decoded from sRGB, × (1, 0.5, 1); glTF's v turned up the image.
    let Reflectance::Image(t) = &w.opaque[0].reflectance else { panic!("{:?}", w.opaque[0].reflectance) };
    assert_eq!((t.width, t.height), (4, 2));
    let srgb = |c: f32| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
    assert_eq!(t.texels[0], [1.0, 0.5, 1.0, 1.0]);
    assert_eq!(t.texels[1], [srgb(64.0 / 255.0), srgb(128.0 / 255.0) * 0.5, srgb(32.0 / 255.0), 1.0]);
    assert_eq!(w.opaque[0].uvs.as_deref().unwrap()[1], Vec2::new(0.0, 0.0), "(0, 1) in glTF is (0, 0) here");
    // The lights: a point light (candela as W/sr) and a spot (outer 0.4 rad, falloff outer − inner).
    let [Light::Point { position, intensity }, Light::Spot { axis, cone_deg, delta_deg, .. }] = &first.desc.lights[..]
    else {
        panic!("{:?}", first.desc.lights)
    };
    let f = 1.0 / w.mm_per_unit * 1000.0; // the power-of-two rescale of positions
    assert!((*position - Vec3::new(0.1, 0.2, 0.1) * f).length() < 1e-5, "{position}");
    assert!((*intensity - Vec3::new(0.02, 0.018, 0.016)).length() < 1e-7);
    assert!(axis.dot(Vec3::new(0.0, -1.0, -1.0).normalize()) > 0.99999, "{axis}");
    assert!((cone_deg - 0.4f32.to_degrees()).abs() < 1e-4 && (delta_deg - 0.2f32.to_degrees()).abs() < 1e-4);
    // Rendered, as GLB and as .gltf: the same image.
    let (a, b) = (d.join("glb.exr"), d.join("external.exr"));
    for (path, out) in [(&forms[2], &a), (&forms[0], &b)] {
        let o = render(&[path.to_str().unwrap(), "--height", "32", "--validation", "-o", out.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    }
    let (ia, ib) = (exr(&a), exr(&b));
    assert_eq!(ia.dimensions(), (48, 32));
    assert!(ia == ib, "GLB and .gltf render differently");
    assert!(ia.pixels().filter(|p| p[3] > 0.0).count() > 200, "the box and the floor are in view");
}

/// Flags typed on the command line override the file: the camera's parts, its aspect ratio's
/// size, the lights, the scale, the roughness.
#[test]
fn flags_override_the_file() {
    let d = dir("flags");
    let png = png_bytes(2, 2, |_, _| [200, 200, 200]);
    std::fs::write(d.join("grey.png"), &png).unwrap();
    let mut doc = Doc::new();
    doc.json["images"] = json!([{"uri": "grey.png"}]);
    doc.json["textures"] = json!([{"source": 0}]);
    box_scene(&mut doc, json!({"index": 0}));
    let path = doc.write_external(&d, "box");
    let (args, file) = full_settings(&path, &["--width", "300"]).unwrap();
    assert_eq!((args.width, args.height), (300, 200), "--width typed: the height from the aspect ratio 1.5");
    assert!((file.desc.camera.fov_y_deg - 0.6f32.to_degrees()).abs() < 1e-4);
    let typed = [
        "--eye",
        "1,2,3",
        "--target",
        "0,0.1,0",
        "--up",
        "0,0,1",
        "--fov",
        "25",
        "--light",
        "dir:0,1,0:2",
        "--scale",
        "100",
        "--roughness",
        "0.8",
        "--width",
        "40",
        "--height",
        "40",
    ];
    let (args, s) = full_settings(&path, &typed).unwrap();
    assert_eq!((args.width, args.height), (40, 40));
    let c = &s.desc.camera;
    let f = 100.0 / s.world.mm_per_unit; // positions × the power-of-two rescale
    assert_eq!(
        (c.eye / f, c.target / f, c.up, c.fov_y_deg),
        (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.1, 0.0), Vec3::Z, 25.0)
    );
    assert_eq!(s.desc.lights, vec![Light::Directional { toward: Vec3::Y, irradiance: Vec3::splat(2.0) }]);
    assert_eq!((s.desc.roughness, s.world.mm_per_unit * f), (0.8, 100.0));
    // An environment typed replaces the file's lights.
    let s = settings_of(&path, &["--env", "const:0.5", "--env-samples", "4"]).unwrap();
    assert!(s.desc.environment.is_some() && s.desc.lights.iter().all(|l| matches!(l, Light::Directional { .. })));
}

/// A translucent material's base colour texture: carried on the object (texels × factor, uvs
/// through KHR_texture_transform and v turned), its material the inversion of the texture's mean.
#[test]
fn a_translucent_texture_is_carried_with_its_uvs_and_its_mean() {
    let d = dir("texture");
    let mut doc = Doc::new();
    let jpeg = {
        let img =
            image::RgbImage::from_fn(8, 8, |x, _| image::Rgb(if x < 4 { [200, 100, 50] } else { [100, 150, 200] }));
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Jpeg).unwrap();
        out.into_inner()
    };
    let v = doc.view(&jpeg, None);
    doc.json["images"] = json!([{"bufferView": v, "mimeType": "image/jpeg"}]);
    doc.json["textures"] = json!([{"source": 0}]);
    let mat = doc.push(
        "materials",
        json!({"name": "skin", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.7, 1.0],
                 "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0.25], "rotation": 1.5707964, "scale": [2.0, 3.0]}}}},
               "extensions": {"KHR_materials_volume": {"thicknessFactor": 0.001},
                              "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0}}}),
    );
    let sphere = Mesh::sphere(0.05, 8);
    let uvs: Vec<Vec2> = (0..sphere.positions.len()).map(|k| Vec2::new(k as f32 / 100.0, 0.5)).collect();
    let m = doc.mesh(&sphere, Some(mat), Some(&uvs));
    doc.node(json!({"mesh": m}), true);
    let s = settings_of(&doc.write_glb(&d, "t"), &[]).unwrap();
    let o = &s.world.objects[0];
    let Some(Reflectance::Image(t)) = &o.texture else { panic!("{:?}", o.texture) };
    let img = image::load_from_memory(&jpeg).unwrap().into_rgb8();
    let srgb = |c: u8| {
        let c = c as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    let p = img.get_pixel(1, 1);
    assert_eq!(t.texels[8 + 1], [srgb(p[0]) * 0.9, srgb(p[1]) * 0.8, srgb(p[2]) * 0.7, 1.0], "texels × factor");
    // uv' = T R S uv: (u, v) = (k/100, 0.5) → (2u, 1.5) → rotated by π/2 (u' = v, v' = −u) → + offset; v turned.
    let got = o.uvs.as_ref().unwrap();
    assert_eq!(got.len(), o.mesh.positions.len());
    for (k, uv) in got.iter().enumerate() {
        let (u, v) = (2.0 * k as f32 / 100.0, 1.5);
        let want = Vec2::new(v + 0.5, 1.0 - (-u + 0.25));
        assert!((*uv - want).length() < 1e-5, "vertex {k}: {uv} vs {want}");
    }
    // The material: the mean texel's reflectance with the thickness as the mean free path.
    let mean = t.mean();
    let (sa, ss) = translucent::pbrt::from_reflectance(mean, [1.0; 3], 0.0, 1.5).unwrap();
    for ch in 0..3 {
        // The thickness is an f32 in the file: 1e-3 m is 1.0000000475 mm.
        assert!(
            (o.material.sigma_a[ch] - sa[ch]).abs() < 1e-6 * sa[ch],
            "σa {ch}: {} vs {}",
            o.material.sigma_a[ch],
            sa[ch]
        );
        assert!(
            (o.material.sigma_s[ch] - ss[ch]).abs() < 1e-6 * ss[ch],
            "σs {ch}: {} vs {}",
            o.material.sigma_s[ch],
            ss[ch]
        );
    }
    s.world.validate().unwrap();
    // It renders (the texture carried) under validation.
    let out = render(&[
        d.join("t.glb").to_str().unwrap(),
        "--width",
        "24",
        "--height",
        "24",
        "--validation",
        "-o",
        d.join("t.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
}

/// A glTF material with a base colour texture and a pbrt-v4 `subsurface` with the same texture
/// as its `"texture reflectance"` (and the same mean free path, η and mesh) make the same
/// translucent object (material, texture, uvs) and, under the same typed camera and light, the
/// same image bit for bit: the hand-off to the textured shading is the pbrt reader's.
#[test]
fn a_textured_gltf_material_is_pbrts_texture_reflectance() {
    let d = dir("pbrt-twin");
    let png = png_bytes(8, 4, |x, y| [40 + 25 * x as u8, 200 - 40 * y as u8, 90 + 10 * (x + y) as u8]);
    std::fs::write(d.join("tex.png"), &png).unwrap();
    let mut sphere = Mesh::sphere(0.5, 12);
    // −0 as +0 (the glTF reader's f64 transform makes it so; normals are summed per position's bits).
    sphere.positions.iter_mut().for_each(|p| *p += Vec3::ZERO);
    // Dyadic uvs: exact in f32 through glTF's v turned twice.
    let uvs: Vec<Vec2> =
        (0..sphere.positions.len()).map(|k| Vec2::new((k % 8) as f32 / 8.0, (k % 5) as f32 / 8.0)).collect();
    let flat = |v: &mut dyn Iterator<Item = f32>| v.map(|x| format!("{x}")).collect::<Vec<_>>().join(" ");
    let pbrt = format!(
        "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nWorldBegin\n\
         Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"tex.png\"\n\
         Material \"subsurface\" \"texture reflectance\" \"t\" \"rgb mfp\" [1 1 1] \"float eta\" 1.5 \"float scale\" 8\n\
         Shape \"trianglemesh\" \"point3 P\" [{}] \"integer indices\" [{}] \"point2 uv\" [{}]\n",
        flat(&mut sphere.positions.iter().flat_map(|p| p.to_array())),
        sphere.indices.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" "),
        flat(&mut uvs.iter().flat_map(|p| p.to_array())),
    );
    let pbrt_path = d.join("twin.pbrt");
    std::fs::write(&pbrt_path, pbrt).unwrap();
    let mut doc = Doc::new();
    doc.json["images"] = json!([{"uri": "tex.png"}]);
    doc.json["textures"] = json!([{"source": 0}]);
    // mfp 1 mm at 8 mm per unit: an attenuation distance of 0.125, white.
    let mat = doc.push(
        "materials",
        json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
               "extensions": {"KHR_materials_volume": {"attenuationDistance": 0.125},
                              "KHR_materials_transmission": {"transmissionFactor": 1.0}}}),
    );
    let gl_uvs: Vec<Vec2> = uvs.iter().map(|uv| Vec2::new(uv.x, 1.0 - uv.y)).collect();
    let m = doc.mesh(&sphere, Some(mat), Some(&gl_uvs));
    doc.node(json!({"mesh": m}), true);
    let gltf_path = doc.write_glb(&d, "twin");
    let typed = [
        "--scale",
        "8",
        "--eye",
        "0,0.5,4",
        "--target",
        "0,0,0",
        "--fov",
        "30",
        "--light",
        "dir:0.3,0.5,-1:2",
        "--width",
        "40",
        "--height",
        "40",
        "--roughness",
        "0.4",
    ];
    let (a, b) = (settings_of(&pbrt_path, &typed).unwrap(), settings_of(&gltf_path, &typed).unwrap());
    let (oa, ob) = (&a.world.objects[0], &b.world.objects[0]);
    let diff = |x: &[Vec3], y: &[Vec3]| x.iter().zip(y).filter(|(a, b)| a != b).count() + x.len().abs_diff(y.len());
    let (dp, dn) = (diff(&oa.mesh.positions, &ob.mesh.positions), diff(&oa.mesh.normals, &ob.mesh.normals));
    let first = oa.mesh.normals.iter().zip(&ob.mesh.normals).position(|(a, b)| a != b);
    assert!(
        (dp, dn, oa.mesh.indices == ob.mesh.indices) == (0, 0, true),
        "positions {dp}, normals {dn} differ (first {first:?}: {:?}), indices equal: {}",
        first.map(|k| (oa.mesh.normals[k], ob.mesh.normals[k])),
        oa.mesh.indices == ob.mesh.indices
    );
    assert_eq!((oa.uvs.as_ref(), oa.texture.as_ref()), (ob.uvs.as_ref(), ob.texture.as_ref()));
    assert!(oa.texture.is_some());
    let (ma, mb) = (&oa.material, &ob.material);
    assert_eq!((ma.sigma_a, ma.sigma_s, ma.g, ma.eta), (mb.sigma_a, mb.sigma_s, mb.g, mb.eta), "{ma:?} vs {mb:?}");
    assert_eq!(a.world.mm_per_unit, b.world.mm_per_unit);
    let (ia, ib) = (d.join("pbrt.exr"), d.join("gltf.exr"));
    for (path, out) in [(&pbrt_path, &ia), (&gltf_path, &ib)] {
        let o = render(&[&[path.to_str().unwrap(), "--validation", "-o", out.to_str().unwrap()][..], &typed].concat());
        assert_eq!(o.status.code(), Some(0), "{}", common::stderr(&o));
    }
    let (ia, ib) = (exr(&ia), exr(&ib));
    assert!(ia.pixels().filter(|p| p[3] > 0.0).count() > 150, "the sphere is in view");
    assert!(ia == ib, "the glTF twin renders differently from the pbrt scene");
}

/// glTF's metres: a 0.1 m bunny is 100 mm across at 1000 mm per unit (`--scale` replaces it),
/// framed by the default camera when the file has none, under the default light.
#[test]
fn metres_are_millimetres_times_a_thousand() {
    let d = dir("metres");
    let (_, mesh) = default_mesh();
    let (lo, hi) = mesh.bounds();
    let fit = 0.1 / (hi - lo).max_element();
    let mut doc = Doc::new();
    let mat = doc.push("materials", json!({"extensions": {"KHR_materials_volume": {"attenuationDistance": 0.001}, "KHR_materials_transmission": {"transmissionFactor": 1}}}));
    let m = doc.mesh(&mesh.clone().scaled(fit), Some(mat), None);
    doc.node(json!({"mesh": m}), true);
    let path = doc.write_embedded(&d, "bunny");
    let s = settings_of(&path, &[]).unwrap();
    let w = &s.world;
    let (lo, hi) = w.objects[0].mesh.bounds();
    let across_mm = (hi - lo).max_element() * w.mm_per_unit;
    assert!((across_mm - 100.0).abs() < 1e-3, "{across_mm} mm");
    assert_eq!(w.mm_per_unit, 1000.0);
    let s = settings_of(&path, &["--scale", "10"]).unwrap();
    assert_eq!(s.world.mm_per_unit, 10.0, "--scale replaces the metres");
    // The default light and the default material's white base colour (held below the dipole's top).
    assert_eq!(s.desc.lights.len(), 1);
}

/// Loads `path` through `render_settings` and asserts a refusal (exit 2) starting with
/// `FILE: PATH` and containing `needle`.
fn refused(path: &Path, args: &[&str], json_path: &str, needle: &str) {
    let err = error_of(path, args);
    assert_eq!(err.exit_code(), 2, "{err}");
    let msg = err.to_string();
    let at = format!("{}: {json_path}", path.display());
    assert!(msg.starts_with(&at), "{msg:?} does not start with {at:?}");
    assert!(msg.contains(needle), "{msg:?} lacks {needle:?}");
}

/// A valid scene: one triangle, for the refusals to break.
fn triangle() -> Doc {
    let mut doc = Doc::new();
    let m = doc.mesh(
        &Mesh { positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y], normals: vec![Vec3::Z; 3], indices: vec![0, 1, 2] },
        None,
        None,
    );
    doc.node(json!({"mesh": m}), true);
    doc
}

#[test]
fn every_refusal_names_the_file_and_the_json_path() {
    let d = dir("refusals");
    type Edit = fn(&mut Doc);
    let cases: Vec<(&str, Edit, &str, &str)> = vec![
        (
            "draco",
            |doc| doc.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]),
            "extensionsRequired[0]",
            "KHR_draco_mesh_compression: Draco-compressed meshes are not read",
        ),
        (
            "meshopt",
            |doc| doc.json["extensionsRequired"] = json!(["KHR_lights_punctual", "EXT_meshopt_compression"]),
            "extensionsRequired[1]",
            "EXT_meshopt_compression: meshopt-compressed",
        ),
        (
            "required",
            |doc| doc.json["extensionsRequired"] = json!(["KHR_materials_clearcoat"]),
            "extensionsRequired[0]",
            "KHR_materials_clearcoat: a required extension that is not read",
        ),
        (
            "points",
            |doc| doc.json["meshes"][0]["primitives"][0]["mode"] = json!(0),
            "meshes[0].primitives[0].mode",
            "POINTS (0): only TRIANGLES",
        ),
        (
            "lines",
            |doc| doc.json["meshes"][0]["primitives"][0]["mode"] = json!(1),
            "meshes[0].primitives[0].mode",
            "LINES (1)",
        ),
        (
            "count",
            |doc| doc.json["accessors"][0]["count"] = json!(4),
            "meshes[0].primitives[0].attributes.POSITION (accessors[0])",
            "4 elements of 12 bytes every 12 bytes from byte 0 need 48 bytes; the buffer view has 36",
        ),
        (
            "offset",
            |doc| doc.json["accessors"][1]["byteOffset"] = json!(4),
            "meshes[0].primitives[0].indices (accessors[1])",
            "need 16 bytes; the buffer view has 12",
        ),
        (
            "stride",
            |doc| doc.json["bufferViews"][0]["byteStride"] = json!(8),
            "meshes[0].primitives[0].attributes.POSITION (accessors[0])",
            "byteStride 8: must be at least the element's 12 bytes",
        ),
        (
            "view",
            |doc| doc.json["bufferViews"][1]["byteLength"] = json!(400),
            "bufferViews[1]",
            "runs past buffers[0]'s",
        ),
        (
            "index",
            |doc| doc.json["meshes"][0]["primitives"][0]["indices"] = json!(7),
            "meshes[0].primitives[0].indices",
            "Index out of bounds",
        ),
        (
            "vertex",
            |doc| {
                let i = doc.indices(&[0, 1, 9]);
                doc.json["meshes"][0]["primitives"][0]["indices"] = json!(i);
            },
            "meshes[0].primitives[0].indices",
            "index 9 is out of range (POSITION has 3 vertices)",
        ),
        (
            "normal",
            |doc| {
                let n = doc.vec3s(&[Vec3::Z; 2]);
                doc.json["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(n);
            },
            "meshes[0].primitives[0].attributes.NORMAL",
            "2 normals for 3 positions",
        ),
        (
            "normal-type",
            |doc| {
                let n = doc.accessor(&[0; 12], 5121, "VEC3", 3);
                doc.json["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = json!(n);
            },
            "meshes[0].primitives[0].attributes.NORMAL",
            "VEC3 of FLOAT expected (3 components of UNSIGNED_BYTE given)",
        ),
        (
            "huge",
            |doc| doc.json["accessors"][0]["count"] = json!(1u64 << 40),
            "meshes[0].primitives[0].attributes.POSITION (accessors[0])",
            "count 1099511627776 must be between 1 and 33554432",
        ),
        (
            "missing-bin",
            |doc| doc.json["buffers"][0]["uri"] = json!("nowhere.bin"),
            "buffers[0].uri",
            "nowhere.bin: cannot read the file",
        ),
        (
            "scheme",
            |doc| doc.json["buffers"][0]["uri"] = json!("https://example.com/a.bin"),
            "buffers[0].uri",
            "only data: URIs and paths relative to the file",
        ),
        (
            "base64",
            |doc| doc.json["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@"),
            "buffers[0].uri",
            "not base64",
        ),
        (
            "short-buffer",
            |doc| doc.json["buffers"][0]["byteLength"] = json!(1000),
            "buffers[0]",
            "byteLength 1000, but its data has 48 bytes",
        ),
        (
            "missing-image",
            |doc| {
                doc.json["images"] = json!([{"uri": "nowhere.png"}]);
                doc.json["textures"] = json!([{"source": 0}]);
                doc.json["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
                doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
            },
            "images[0].uri",
            "nowhere.png: cannot read the file",
        ),
        (
            "no-uv",
            |doc| {
                doc.json["images"] = json!([{"uri": "tiny.png"}]);
                doc.json["textures"] = json!([{"source": 0}]);
                doc.json["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
                doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
            },
            "meshes[0].primitives[0].attributes",
            "no TEXCOORD_0, which the base colour texture of materials[0] needs",
        ),
        (
            "cycle",
            |doc| doc.json["nodes"][0]["children"] = json!([0]),
            "nodes[0]",
            "reached again from nodes[0].children[0]",
        ),
        (
            "scene",
            |doc| {
                doc.json["scenes"] = json!([]);
                doc.json.as_object_mut().unwrap().remove("scene");
            },
            "scenes",
            "no scene",
        ),
        (
            "colour",
            |doc| doc.json["materials"] = json!([{"pbrMetallicRoughness": {"baseColorFactor": [2, 0, 0, 1]}}]),
            "",
            "",
        ),
        (
            "spot",
            |doc| {
                let l = doc.light(json!({"type": "spot", "spot": {"innerConeAngle": 0.5, "outerConeAngle": 0.4}}));
                doc.node(json!({"extensions": {"KHR_lights_punctual": {"light": l}}}), true);
            },
            "extensions.KHR_lights_punctual.lights[0].spot",
            "falloff width",
        ),
        (
            "attenuation",
            |doc| {
                doc.json["materials"] = json!([{"extensions": {"KHR_materials_volume": {"attenuationDistance": -1}, "KHR_materials_transmission": {"transmissionFactor": 1}}}]);
                doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
            },
            "materials[0].extensions.KHR_materials_volume.attenuationDistance",
            "-1: must be positive",
        ),
        (
            "ior",
            |doc| {
                doc.json["materials"] = json!([{"extensions": {"KHR_materials_volume": {"attenuationDistance": 1}, "KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 20}}}]);
                doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
            },
            "materials[0]",
            "eta = 20 must be within",
        ),
        ("zero-scale", |doc| doc.json["nodes"][0]["scale"] = json!([0, 1, 1]), "nodes[0]", "singular"),
        (
            "draco-primitive",
            |doc| {
                doc.json["meshes"][0]["primitives"][0]["extensions"] =
                    json!({"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}});
                doc.json["accessors"][0].as_object_mut().unwrap().remove("bufferView");
            },
            "meshes[0].primitives[0].extensions.KHR_draco_mesh_compression",
            "Draco-compressed meshes are not read",
        ),
    ];
    std::fs::write(d.join("tiny.png"), png_bytes(1, 1, |_, _| [9, 9, 9])).unwrap();
    for (name, edit, json_path, needle) in cases {
        let mut doc = triangle();
        edit(&mut doc);
        if name == "colour" {
            doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
            refused(
                &doc.write_embedded(&d, name),
                &[],
                "materials[0].pbrMetallicRoughness.baseColorFactor",
                "each component must be within [0, 1]",
            );
            continue;
        }
        let path = match name {
            "missing-bin" | "scheme" | "base64" => doc.write_raw(&d, name),
            "missing-image" => doc.write_embedded(&d, name),
            _ => doc.write_external(&d, name),
        };
        if name == "missing-bin" {
            let err = error_of(&path, &[]).to_string();
            assert!(
                err.starts_with(&format!("{}: buffers[0].uri: {}", path.display(), d.join("nowhere.bin").display())),
                "{err}"
            );
            continue;
        }
        refused(&path, &[], json_path, needle);
    }
    // Flags naming what the file lacks.
    let path = triangle().write_glb(&d, "flags");
    let err = error_of(&path, &["--gltf-scene", "3"]);
    assert!(err.to_string().contains("--gltf-scene 3: ") && err.to_string().contains("has 1 scene(s)"), "{err}");
    let err = error_of(&path, &["--gltf-material", "nope=marble"]);
    assert!(err.to_string().contains("has no material named \"nope\""), "{err}");
    // The container and the sizes: checked before anything is allocated or decoded.
    let bad_glb = d.join("bad.glb");
    let mut bytes = glb(b"{}", b"");
    bytes[8..12].copy_from_slice(&10_000u32.to_le_bytes());
    std::fs::write(&bad_glb, &bytes).unwrap();
    refused(&bad_glb, &[], "GLB container", "its header gives a length of 10000 bytes");
    let big = d.join("big.gltf");
    std::fs::File::create(&big).unwrap().set_len(tg::MAX_FILE_BYTES + 1).unwrap();
    refused(&big, &[], "larger than the limit of 512 MiB", "");
    let not_json = d.join("text.gltf");
    std::fs::write(&not_json, "solid cube\n").unwrap();
    refused(&not_json, &[], "not a glTF 2.0 document", "");
    // An image whose header claims 20000×20000: refused from the header, before decoding.
    let mut doc = triangle();
    let png = png_bytes(1, 1, |_, _| [0, 0, 0]);
    let mut huge = png.clone();
    huge[16..20].copy_from_slice(&20000u32.to_be_bytes());
    huge[20..24].copy_from_slice(&20000u32.to_be_bytes());
    let mut crc = flate2::Crc::new();
    crc.update(&huge[12..29]);
    huge[29..33].copy_from_slice(&crc.sum().to_be_bytes());
    std::fs::write(d.join("huge.png"), &huge).unwrap();
    doc.json["images"] = json!([{"uri": "huge.png"}]);
    doc.json["textures"] = json!([{"source": 0}]);
    doc.json["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]);
    doc.json["meshes"][0]["primitives"][0]["material"] = json!(0);
    let path = doc.write_external(&d, "huge");
    refused(&path, &[], "images[0]: 20000x20000", "at most 16777216 texels");
    // The glTF flags without a glTF file.
    let out = render(&["--gltf-scene", "1"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(common::stderr(&out).contains("--gltf-scene: only for a glTF scene file"), "{}", common::stderr(&out));
    // Through the binary: exit 2, `error: FILE: PATH: …`.
    let mut doc = triangle();
    doc.json["meshes"][0]["primitives"][0]["mode"] = json!(3);
    let path = doc.write_glb(&d, "cli");
    let out = render(&[path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = common::stderr(&out);
    assert!(
        err.starts_with(&format!("error: {}: meshes[0].primitives[0].mode: LINE_STRIP (3)", path.display())),
        "{err}"
    );
}

fn count_numbers(v: &Value) -> usize {
    match v {
        Value::Number(_) => 1,
        Value::Array(a) => a.iter().map(count_numbers).sum(),
        Value::Object(o) => o.values().map(count_numbers).sum(),
        _ => 0,
    }
}

/// The `n`th number of a JSON tree, depth first.
fn nth_number<'a>(v: &'a mut Value, n: &mut usize) -> Option<&'a mut Value> {
    if v.is_number() {
        if *n == 0 {
            return Some(v);
        }
        *n -= 1;
        return None;
    }
    match v {
        Value::Array(a) => a.iter_mut().find_map(|x| nth_number(x, n)),
        Value::Object(o) => o.values_mut().find_map(|x| nth_number(x, n)),
        _ => None,
    }
}

/// The reference decoder: the spec's rules written out element by element.
fn reference(view: &[u8], l: &Layout) -> Option<Vec<f32>> {
    let size = l.component.size() as u64;
    let element = size * l.width as u64;
    if l.count == 0 || l.count > 1 << 25 || !(1..=4).contains(&l.width) || !l.offset.is_multiple_of(size) {
        return None;
    }
    if l.normalized && matches!(l.component, Component::U32 | Component::F32) {
        return None;
    }
    let step = match l.stride {
        Some(s) if s < element || s > 252 || !s.is_multiple_of(size) => return None,
        Some(s) => s,
        None => element,
    };
    let mut out = Vec::new();
    for e in 0..l.count {
        for k in 0..l.width as u64 {
            let at = (l.offset + e * step + k * size) as usize;
            let b = view.get(at..at + size as usize)?;
            let v = match (l.component, l.normalized) {
                (Component::I8, false) => b[0] as i8 as f32,
                (Component::I8, true) => f32::max(b[0] as i8 as f32 / 127.0, -1.0),
                (Component::U8, false) => b[0] as f32,
                (Component::U8, true) => b[0] as f32 / 255.0,
                (Component::I16, n) => {
                    let c = i16::from_le_bytes([b[0], b[1]]) as f32;
                    if n {
                        f32::max(c / 32767.0, -1.0)
                    } else {
                        c
                    }
                }
                (Component::U16, n) => {
                    let c = u16::from_le_bytes([b[0], b[1]]) as f32;
                    if n {
                        c / 65535.0
                    } else {
                        c
                    }
                }
                (Component::U32, _) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
                (Component::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            };
            out.push(v);
        }
    }
    Some(out)
}

fn layout() -> impl Strategy<Value = Layout> {
    (
        0..6usize,
        0..6usize,
        any::<bool>(),
        prop_oneof![0..80u64, Just(1u64 << 25), Just(u64::MAX), Just((1u64 << 25) + 1)],
        prop_oneof![0..64u64, Just(u64::MAX - 3)],
        prop_oneof![Just(None), (0..260u64).prop_map(Some)],
    )
        .prop_map(|(c, width, normalized, count, offset, stride)| Layout {
            component: Component::ALL[c],
            width,
            normalized,
            count,
            offset,
            stride,
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// Any layout over any bytes: never a panic; what is read equals the reference decoder, and
    /// what the reference can read is read.
    #[test]
    fn the_accessor_reader_equals_a_reference_decoder(l in layout(), view in proptest::collection::vec(any::<u8>(), 0..700)) {
        let got = accessor::read_floats(&view, &l);
        let want = reference(&view, &l);
        match (&got, &want) {
            (Ok(g), Some(w)) => prop_assert_eq!(g.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), w.iter().map(|v| v.to_bits()).collect::<Vec<_>>()),
            (Err(_), None) => {}
            _ => prop_assert!(false, "reader {:?} vs reference {:?} for {:?}", got.as_ref().map(|v| v.len()), want.as_ref().map(|v| v.len()), l),
        }
        let idx = accessor::read_indices(&view, &l);
        let index_ok = matches!(l.component, Component::U8 | Component::U16 | Component::U32) && l.width == 1 && !l.normalized;
        match (idx, want) {
            (Ok(i), Some(w)) => {
                prop_assert!(index_ok);
                prop_assert_eq!(i.iter().map(|&v| v as f32).collect::<Vec<_>>(), w);
            }
            (Err(_), w) => prop_assert!(!index_ok || w.is_none()),
            (Ok(_), None) => prop_assert!(false, "indices read where the reference refuses"),
        }
    }

}

/// A scene with something of everything (meshes, a texture, lights, a camera), as fuzzing starts.
fn fuzz_doc() -> Doc {
    let mut doc = triangle();
    box_scene(&mut doc, json!({"index": 0}));
    doc.json["images"] = json!([{"uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGP4//8/AAX+Av4N70a4AAAAAElFTkSuQmCC"}]);
    doc.json["textures"] = json!([{"source": 0}]);
    doc
}

/// An edit of the JSON tree: the `n`th number replaced, or the `n`th value (any) removed from
/// its object or array.
#[derive(Clone, Debug)]
enum JsonEdit {
    Number(prop::sample::Index, Value),
    Remove(prop::sample::Index),
}

fn json_edits() -> impl Strategy<Value = Vec<JsonEdit>> {
    let value = prop_oneof![
        Just(json!(0)),
        Just(json!(1)),
        Just(json!(-1)),
        Just(json!(3)),
        Just(json!(4)),
        Just(json!(255)),
        Just(json!(5121)),
        Just(json!(5126)),
        Just(json!(4294967295u64)),
        Just(json!(1u64 << 40)),
        Just(json!(1e30)),
        Just(json!(-1e30)),
        Just(json!(0.5)),
        Just(json!(1e-30)),
        Just(json!(18446744073709551615u64)),
        Just(json!("VEC3")),
        Just(json!([])),
        Just(json!({})),
    ];
    let edit = prop_oneof![
        4 => (any::<prop::sample::Index>(), value).prop_map(|(i, v)| JsonEdit::Number(i, v)),
        1 => any::<prop::sample::Index>().prop_map(JsonEdit::Remove),
    ];
    proptest::collection::vec(edit, 1..5)
}

fn count_values(v: &Value) -> usize {
    1 + match v {
        Value::Array(a) => a.iter().map(count_values).sum(),
        Value::Object(o) => o.values().map(count_values).sum(),
        _ => 0,
    }
}

/// Removes the `n`th value below the root, depth first (`true` when done).
fn remove_nth(v: &mut Value, n: &mut usize) -> bool {
    match v {
        Value::Array(a) => {
            for k in 0..a.len() {
                if *n == 0 {
                    a.remove(k);
                    return true;
                }
                *n -= 1;
                if remove_nth(&mut a[k], n) {
                    return true;
                }
            }
            false
        }
        Value::Object(o) => {
            let keys: Vec<String> = o.keys().cloned().collect();
            for k in keys {
                if *n == 0 {
                    o.remove(&k);
                    return true;
                }
                *n -= 1;
                if remove_nth(o.get_mut(&k).unwrap(), n) {
                    return true;
                }
            }
            false
        }
        _ => false,
    }
}

/// The whole reader on the fuzzing scene with its JSON edited: a result or a refusal, never a panic.
fn check_json_edits(edits: Vec<JsonEdit>) {
    let d = dir("numbers");
    let mut doc = fuzz_doc();
    for edit in edits {
        match edit {
            JsonEdit::Number(at, new) => {
                let count = count_numbers(&doc.json);
                if let Some(v) = nth_number(&mut doc.json, &mut at.index(count)) {
                    *v = new;
                }
            }
            JsonEdit::Remove(at) => {
                let count = count_values(&doc.json) - 1;
                remove_nth(&mut doc.json, &mut at.index(count.max(1)));
            }
        }
    }
    let path = doc.write_glb(&d, "n");
    let _ = tg::load(&path, None);
    let _ = settings_of(&path, &[]);
}

/// The whole reader on the fuzzing scene (GLB, or `.gltf` with a data URI) with bytes changed.
fn check_byte_edits(edits: Vec<(prop::sample::Index, u8)>, glb_form: bool) {
    use base64::Engine;
    let d = dir("fuzz");
    let doc = fuzz_doc();
    let mut bytes = if glb_form {
        glb(&serde_json::to_vec(&doc.json).unwrap(), &doc.bin)
    } else {
        let mut j = doc.json.clone();
        let data = base64::engine::general_purpose::STANDARD.encode(&doc.bin);
        j["buffers"][0]["uri"] = json!(format!("data:application/octet-stream;base64,{data}"));
        serde_json::to_vec(&j).unwrap()
    };
    for (at, b) in edits {
        let i = at.index(bytes.len());
        bytes[i] = b;
    }
    let path = d.join(if glb_form { "f.glb" } else { "f.gltf" });
    std::fs::write(&path, &bytes).unwrap();
    let _ = tg::load(&path, None);
    let _ = settings_of(&path, &[]);
}

fn byte_edits() -> impl Strategy<Value = (Vec<(prop::sample::Index, u8)>, bool)> {
    (proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6), any::<bool>())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    /// The whole reader on a valid file with its JSON edited (numbers changed to values a file
    /// may hold: counts, offsets, strides, indices, factors; values removed).
    #[test]
    fn the_reader_never_panics_on_an_edited_json(edits in json_edits()) {
        check_json_edits(edits);
    }

    /// The whole reader on a valid file with bytes changed: a result or a refusal, never a panic.
    #[test]
    fn the_reader_never_panics_on_a_damaged_file((edits, glb_form) in byte_edits()) {
        check_byte_edits(edits, glb_form);
    }
}

/// `scripts/fuzz`: the two whole-reader properties for FUZZ_SECONDS each (default 60).
#[test]
#[ignore]
fn fuzz_gltf_reader() {
    use proptest::test_runner::{Config, TestRunner};
    let seconds: u64 = std::env::var("FUZZ_SECONDS").ok().and_then(|s| s.parse().ok()).unwrap_or(60);
    for (name, edits) in [("JSON edits", true), ("byte edits", false)] {
        let start = std::time::Instant::now();
        let mut total = 0u64;
        while start.elapsed().as_secs() < seconds {
            let mut runner = TestRunner::new(Config { cases: 256, failure_persistence: None, ..Config::default() });
            let outcome = if edits {
                runner
                    .run(&json_edits(), |e| {
                        check_json_edits(e);
                        Ok(())
                    })
                    .map_err(|e| e.to_string())
            } else {
                runner
                    .run(&byte_edits(), |(e, g)| {
                        check_byte_edits(e, g);
                        Ok(())
                    })
                    .map_err(|e| e.to_string())
            };
            if let Err(e) = outcome {
                panic!("fuzz glTF reader ({name}): {e}");
            }
            total += 256;
        }
        println!("fuzz glTF reader ({name}): {total} inputs in {:.0} s, no failure", start.elapsed().as_secs_f64());
    }
}
