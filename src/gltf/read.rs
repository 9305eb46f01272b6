//! A glTF 2.0 file (`.gltf` with its buffers and images, or `.glb`) into a [`GltfScene`]: the
//! JSON through the `gltf` crate's types and validation, everything else here: the GLB
//! container, buffers (GLB chunk, data URIs, files), accessors ([`super::accessor`]), images
//! (decoded by [`Texture::from_bytes`] after their size is checked), the node hierarchy.
//! Every refusal names the file and the JSON path of what is wrong.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use ::gltf::json;
use glam::{DMat3, DMat4, DQuat, DVec3, Vec2, Vec3};
use json::validation::Checked;

use super::accessor::{self, Component, Layout};
use super::{CameraDesc, GltfScene, LightDesc, MaterialDesc, Object, Volume};
use crate::bad_input;
use crate::error::{Error, Result};
use crate::mesh::{RawMesh, MAX_ELEMENTS};
use crate::world::Texture;

/// The largest file read: the `.gltf` or `.glb` itself, each external buffer and each image
/// file (as a mesh file may be).
pub const MAX_FILE_BYTES: u64 = crate::mesh::MAX_MESH_BYTES;
/// The largest JSON document (a `.gltf` file or a GLB's JSON chunk).
pub const MAX_JSON_BYTES: u64 = 64 << 20;

/// The extensions read (any other in `extensionsRequired` is refused by name).
pub const SUPPORTED_EXTENSIONS: [&str; 7] = [
    "KHR_materials_volume",
    "KHR_materials_transmission",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_volume_scatter",
    "KHR_materials_ior",
    "KHR_texture_transform",
    "KHR_lights_punctual",
];

/// Reads a glTF 2.0 file: `scene` (`--gltf-scene`) or the file's default scene.
pub fn load(path: &Path, scene: Option<usize>) -> Result<GltfScene> {
    let shown = path.display().to_string();
    let bytes = read_file(path, &shown, MAX_FILE_BYTES)?;
    let (json_bytes, bin) = if bytes.starts_with(b"glTF") {
        let (j, b) = split_glb(&bytes).map_err(|e| bad_input!("{shown}: GLB container: {e}"))?;
        (j.to_vec(), b.map(<[u8]>::to_vec))
    } else {
        (bytes, None)
    };
    if json_bytes.len() as u64 > MAX_JSON_BYTES {
        return Err(bad_input!("{shown}: its JSON is larger than the limit of {} MiB", MAX_JSON_BYTES >> 20));
    }
    let text = json_bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&json_bytes);
    let mut root: json::Root =
        json::deserialize::from_slice(text).map_err(|e| bad_input!("{shown}: not a glTF 2.0 document: {e}"))?;
    if !root.asset.version.starts_with("2.") {
        return Err(bad_input!("{shown}: asset.version: \"{}\": only glTF 2.x is read", root.asset.version));
    }
    for (i, ext) in root.extensions_required.iter().enumerate() {
        if !SUPPORTED_EXTENSIONS.contains(&ext.as_str()) {
            let what = match ext.as_str() {
                "KHR_draco_mesh_compression" => "Draco-compressed meshes are not read".to_string(),
                "EXT_meshopt_compression" | "KHR_meshopt_compression" => {
                    "meshopt-compressed buffers are not read".to_string()
                }
                "KHR_mesh_quantization" => "quantized (integer) positions and normals are not read".to_string(),
                _ => "a required extension that is not read".to_string(),
            };
            return Err(bad_input!(
                "{shown}: extensionsRequired[{i}]: {ext}: {what} (supported: {})",
                SUPPORTED_EXTENSIONS.join(", ")
            ));
        }
    }
    // The crate's validation indexes the accessors by POSITION without a check (gltf-json
    // 1.4.1, mesh.rs): an index out of range is refused here first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let position = prim.attributes.get(&Checked::Valid(json::mesh::Semantic::Positions));
            if let Some(a) = position.filter(|a| a.value() >= root.accessors.len()) {
                return Err(bad_input!(
                    "{shown}: meshes[{m}].primitives[{p}].attributes.POSITION: accessor {} does not exist ({} accessors)",
                    a.value(),
                    root.accessors.len()
                ));
            }
        }
    }
    // Draco-compressed primitives whose accessors have no data of their own (the crate's
    // validation would call them a missing bufferView): refused by name.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let draco = prim.extensions.as_ref().is_some_and(|e| e.others.contains_key("KHR_draco_mesh_compression"));
            let no_data = prim
                .attributes
                .values()
                .any(|a| root.accessors.get(a.value()).is_some_and(|a| a.buffer_view.is_none()));
            if draco && no_data {
                return Err(bad_input!(
                    "{shown}: meshes[{m}].primitives[{p}].extensions.KHR_draco_mesh_compression: Draco-compressed meshes are not read (the file has no uncompressed copy)"
                ));
            }
        }
    }
    // The crate's own check of required extensions knows fewer than we read: ours is above.
    root.extensions_required.clear();
    let document = ::gltf::Document::from_json(root).map_err(|e| match e {
        ::gltf::Error::Validation(errors) => {
            let (p, why) = &errors[0];
            let more = match errors.len() {
                1 => String::new(),
                n => format!(" (and {} more)", n - 1),
            };
            bad_input!("{shown}: {p}: {why}{more}")
        }
        e => bad_input!("{shown}: {e}"),
    })?;
    let root = document.into_json();
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut reader = Reader {
        shown,
        dir,
        root: &root,
        bin,
        buffers: HashMap::new(),
        images: HashMap::new(),
        primitives: HashMap::new(),
        materials: HashMap::new(),
        scene: GltfScene::default(),
        elements: [0; 2],
    };
    reader.read_scene(scene)?;
    let unread: Vec<&str> =
        root.extensions_used.iter().map(String::as_str).filter(|e| !SUPPORTED_EXTENSIONS.contains(e)).collect();
    if !unread.is_empty() {
        reader.warn("extensionsUsed", format!("{}: not read (the scene is rendered without them)", unread.join(", ")));
    }
    reader.scene.material_names = root.materials.iter().filter_map(|m| m.name.clone()).collect();
    Ok(reader.scene)
}

/// A regular file of at most `cap` bytes (a FIFO or a device is refused before it is opened).
fn read_file(path: &Path, shown: &str, cap: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|e| bad_input!("{shown}: cannot read the file: {e}"))?;
    if !meta.is_file() {
        return Err(bad_input!("{shown}: not a regular file"));
    }
    let too_big = || bad_input!("{shown}: larger than the limit of {} MiB", cap >> 20);
    if meta.len() > cap {
        return Err(too_big());
    }
    let file = std::fs::File::open(path).map_err(|e| bad_input!("{shown}: cannot read the file: {e}"))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(cap + 1).read_to_end(&mut bytes).map_err(|e| bad_input!("{shown}: cannot read the file: {e}"))?;
    if bytes.len() as u64 > cap {
        return Err(too_big());
    }
    Ok(bytes)
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    bytes.get(at..at.checked_add(4)?).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// A GLB's JSON chunk and its binary chunk, when it has one (chunks of other types are skipped,
/// as the specification asks).
pub fn split_glb(bytes: &[u8]) -> std::result::Result<(&[u8], Option<&[u8]>), String> {
    let version = u32_at(bytes, 4).ok_or("shorter than its 12-byte header")?;
    let length = u32_at(bytes, 8).ok_or("shorter than its 12-byte header")? as usize;
    if version != 2 {
        return Err(format!("version {version}: only GLB version 2 is read"));
    }
    if length < 12 || length > bytes.len() {
        return Err(format!("its header gives a length of {length} bytes; the file has {}", bytes.len()));
    }
    let bytes = &bytes[..length];
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    let mut k = 0;
    while at < length {
        let len = u32_at(bytes, at).ok_or_else(|| format!("chunk {k}: truncated header at byte {at}"))? as usize;
        let kind = bytes.get(at + 4..at + 8).ok_or_else(|| format!("chunk {k}: truncated header at byte {at}"))?;
        let start = at + 8;
        let end = start
            .checked_add(len)
            .filter(|&e| e <= length)
            .ok_or_else(|| format!("chunk {k}: {len} bytes from byte {start} run past the file's {length}"))?;
        match (k, kind) {
            (0, b"JSON") => json = Some(&bytes[start..end]),
            (0, _) => return Err("the first chunk is not JSON".into()),
            (1, b"BIN\0") => bin = Some(&bytes[start..end]),
            _ => {}
        }
        // Chunks start on 4-byte boundaries.
        at = end.checked_add(3).map(|e| e & !3).unwrap_or(usize::MAX);
        k += 1;
    }
    Ok((json.ok_or("no JSON chunk")?, bin))
}

/// Decodes a `data:` URI's payload (base64 only); `None` when `uri` is not a data URI.
fn data_uri(uri: &str, cap: u64) -> Option<std::result::Result<Vec<u8>, String>> {
    use base64::Engine;
    let rest = uri.strip_prefix("data:")?;
    let Some((meta, data)) = rest.split_once(',') else {
        return Some(Err("a data URI without a ',' before its data".into()));
    };
    if !meta.ends_with(";base64") {
        return Some(Err("a data URI that is not base64 (\";base64,\")".into()));
    }
    if data.len() as u64 / 4 * 3 > cap {
        return Some(Err(format!("its data is larger than the limit of {} MiB", cap >> 20)));
    }
    let engine = base64::engine::GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        base64::engine::GeneralPurposeConfig::new()
            .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
    );
    Some(engine.decode(data.trim_end()).map_err(|e| format!("not base64: {e}")))
}

/// A URI reference as a path: percent-decoded, relative to the glTF file's folder (or absolute);
/// a URI with a scheme (`http:`, `file:`, …) other than `data:` is refused.
fn uri_path(dir: &Path, uri: &str) -> std::result::Result<PathBuf, String> {
    let scheme = uri
        .split_once(':')
        .map(|(s, _)| s)
        .filter(|s| s.len() > 1 && s.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c)));
    if let Some(s) = scheme {
        return Err(format!("\"{uri}\": a {s}: URI; only data: URIs and paths relative to the file are read"));
    }
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = uri.get(i + 1..i + 3).and_then(|h| u8::from_str_radix(h, 16).ok());
            let byte = hex.ok_or_else(|| format!("\"{uri}\": a '%' not followed by two hexadecimal digits"))?;
            out.push(byte);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    let decoded = String::from_utf8(out).map_err(|_| format!("\"{uri}\": not UTF-8 once percent-decoded"))?;
    Ok(dir.join(decoded))
}

/// A buffer view: its buffer's bytes, its range in them, its stride.
type View = (Rc<Vec<u8>>, std::ops::Range<usize>, Option<u64>);

/// A primitive's vertices and triangles as its file gives them (before any node's transform).
struct Primitive {
    positions: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    /// The base colour texture's coordinates (its texCoord set, KHR_texture_transform applied,
    /// v turned to run up the image), when its material has a texture.
    uvs: Option<Vec<Vec2>>,
    indices: Vec<u32>,
    /// Index into [`GltfScene::materials`].
    material: usize,
}

struct Reader<'a> {
    shown: String,
    dir: PathBuf,
    root: &'a json::Root,
    bin: Option<Vec<u8>>,
    buffers: HashMap<usize, Rc<Vec<u8>>>,
    images: HashMap<usize, Texture>,
    primitives: HashMap<(usize, usize), Rc<Primitive>>,
    /// `materials[i]` (`None`: the default material) → index into the scene's materials.
    materials: HashMap<Option<usize>, usize>,
    scene: GltfScene,
    /// Vertices and triangles of every mesh instance so far.
    elements: [u64; 2],
}

/// A node's own transform: its matrix, or translation × rotation × scale.
fn local_transform(node: &json::scene::Node) -> std::result::Result<DMat4, String> {
    if let Some(m) = node.matrix {
        let cols: [f64; 16] = m.map(|v| v as f64);
        return Ok(DMat4::from_cols_array(&cols));
    }
    let t = node.translation.unwrap_or([0.0; 3]).map(|v| v as f64);
    let s = node.scale.unwrap_or([1.0; 3]).map(|v| v as f64);
    let r = node.rotation.as_ref().map(|q| q.0).unwrap_or([0.0, 0.0, 0.0, 1.0]).map(|v| v as f64);
    let q = DQuat::from_xyzw(r[0], r[1], r[2], r[3]);
    let len = q.length();
    if !(len.is_finite() && len > 0.0) {
        return Err(format!("rotation {r:?} is not a unit quaternion"));
    }
    Ok(DMat4::from_scale_rotation_translation(DVec3::from(s), q / len, DVec3::from(t)))
}

impl Reader<'_> {
    fn err(&self, path: &str, why: impl std::fmt::Display) -> Error {
        bad_input!("{}: {path}: {why}", self.shown)
    }

    fn warn(&mut self, path: &str, why: impl std::fmt::Display) {
        let line = format!("{}: {path}: {why}", self.shown);
        if !self.scene.warnings.contains(&line) {
            self.scene.warnings.push(line);
        }
    }

    fn read_scene(&mut self, wanted: Option<usize>) -> Result<()> {
        let root = self.root;
        if root.scenes.is_empty() {
            return Err(self.err("scenes", "the file has no scene (nothing to render)"));
        }
        let index = match wanted {
            Some(n) if n >= root.scenes.len() => {
                return Err(bad_input!(
                    "--gltf-scene {n}: {} has {} scene(s), numbered from 0",
                    self.shown,
                    root.scenes.len()
                ))
            }
            Some(n) => n,
            None => root.scene.map(|s| s.value()).unwrap_or(0),
        };
        let scene = root.scenes.get(index).ok_or_else(|| self.err("scene", "out of range"))?;
        if !root.skins.is_empty() || !root.animations.is_empty() {
            self.warn("skins/animations", "not animated: meshes are read in their rest pose");
        }
        // Depth first, as the nodes are listed; each node reached once (glTF's nodes form trees).
        let mut reached = vec![false; root.nodes.len()];
        let mut stack: Vec<(usize, DMat4, String)> = scene
            .nodes
            .iter()
            .rev()
            .enumerate()
            .map(|(k, n)| (n.value(), DMat4::IDENTITY, format!("scenes[{index}].nodes[{}]", scene.nodes.len() - 1 - k)))
            .collect();
        while let Some((n, parent, from)) = stack.pop() {
            let path = format!("nodes[{n}]");
            let node = root.nodes.get(n).ok_or_else(|| self.err(&from, format!("node {n} does not exist")))?;
            if std::mem::replace(&mut reached[n], true) {
                return Err(self.err(
                    &path,
                    format!("reached again from {from}: a node must have one parent, and the hierarchy no cycle"),
                ));
            }
            let local = local_transform(node).map_err(|e| self.err(&path, e))?;
            let world = parent * local;
            if !world.is_finite() {
                return Err(self.err(&path, "its transform is not finite"));
            }
            if let Some(c) = node.camera {
                self.camera(c.value(), &world, &path)?;
            }
            if let Some(l) = node.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) {
                self.light(l.light.value(), &world, &path)?;
            }
            if let Some(m) = node.mesh {
                if node.weights.is_some() || node.skin.is_some() {
                    self.warn(&path, "morph weights and skins are ignored (the rest pose is read)");
                }
                self.mesh(m.value(), &world, &path)?;
            }
            for (k, child) in node.children.as_deref().unwrap_or_default().iter().enumerate().rev() {
                stack.push((child.value(), world, format!("{path}.children[{k}]")));
            }
        }
        Ok(())
    }

    fn camera(&mut self, index: usize, world: &DMat4, node: &str) -> Result<()> {
        let path = format!("cameras[{index}]");
        let camera = self.root.cameras.get(index).ok_or_else(|| self.err(node, "camera out of range"))?;
        let Some(p) =
            camera.perspective.as_ref().filter(|_| camera.type_ == Checked::Valid(json::camera::Type::Perspective))
        else {
            self.warn(&path, "an orthographic camera is not read (only perspective ones)");
            return Ok(());
        };
        if self.scene.camera.is_some() {
            self.warn(&path, "only the first perspective camera is used");
            return Ok(());
        }
        let yfov = p.yfov as f64;
        if !(yfov > 0.0 && yfov < std::f64::consts::PI) {
            return Err(self.err(&format!("{path}.perspective.yfov"), format!("{yfov}: must be in (0, π) radians")));
        }
        let aspect = p.aspect_ratio.map(|a| a as f64);
        if let Some(a) = aspect.filter(|a| !(a.is_finite() && *a > 0.0)) {
            return Err(self.err(&format!("{path}.perspective.aspectRatio"), format!("{a}: must be positive")));
        }
        let eye = world.transform_point3(DVec3::ZERO);
        let forward = world.transform_vector3(DVec3::NEG_Z);
        let up = world.transform_vector3(DVec3::Y);
        let (Some(forward), Some(up)) = (forward.try_normalize(), up.try_normalize()) else {
            return Err(self.err(node, "a camera's transform must not be singular"));
        };
        self.scene.camera = Some(CameraDesc {
            eye,
            forward,
            up,
            yfov_deg: yfov.to_degrees(),
            aspect,
            path: format!("{path} ({node})"),
        });
        Ok(())
    }

    fn light(&mut self, index: usize, world: &DMat4, node: &str) -> Result<()> {
        use json::extensions::scene::khr_lights_punctual::Type;
        let path = format!("extensions.KHR_lights_punctual.lights[{index}]");
        let light = self
            .root
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
            .and_then(|l| l.lights.get(index))
            .ok_or_else(|| self.err(node, format!("light {index} does not exist")))?;
        let colour = light.color.map(|c| c as f64);
        let intensity = light.intensity as f64;
        let finite = colour.iter().all(|c| c.is_finite() && *c >= 0.0) && intensity.is_finite() && intensity >= 0.0;
        if !finite {
            return Err(self.err(&path, "color and intensity must be finite and not negative"));
        }
        let power = Vec3::from(colour.map(|c| (c * intensity) as f32));
        if light.range.is_some() {
            self.warn(
                &format!("{path}.range"),
                "ignored: the light falls off with the squared distance, without a cutoff",
            );
        }
        let position = world.transform_point3(DVec3::ZERO).as_vec3();
        // Lights shine down their node's −z: the direction toward a directional light is +z.
        let toward = world.transform_vector3(DVec3::Z).as_vec3();
        let shown = format!("{path} ({node})");
        let desc = match light.type_ {
            Checked::Valid(Type::Directional) => {
                let toward = crate::mesh::safe_normalize(toward)
                    .ok_or_else(|| self.err(node, "a directional light's transform must not be singular"))?;
                LightDesc { light: crate::scene::Light::Directional { toward, irradiance: power }, path: shown }
            }
            Checked::Valid(Type::Point) => {
                LightDesc { light: crate::scene::Light::Point { position, intensity: power }, path: shown }
            }
            Checked::Valid(Type::Spot) => {
                let spot = light.spot.as_ref().ok_or_else(|| self.err(&format!("{path}.spot"), "missing"))?;
                let (inner, outer) = (spot.inner_cone_angle.to_degrees(), spot.outer_cone_angle.to_degrees());
                let toward = crate::mesh::safe_normalize(toward)
                    .ok_or_else(|| self.err(node, "a spot light's transform must not be singular"))?;
                let light = crate::scene::Light::spot(position, position - toward, outer, outer - inner, power)
                    .map_err(|e| self.err(&format!("{path}.spot"), e))?;
                LightDesc { light, path: shown }
            }
            Checked::Invalid => return Err(self.err(&format!("{path}.type"), "not directional, point or spot")),
        };
        self.scene.lights.push(desc);
        Ok(())
    }

    fn mesh(&mut self, index: usize, world: &DMat4, node: &str) -> Result<()> {
        let mesh = self.root.meshes.get(index).ok_or_else(|| self.err(node, format!("mesh {index} does not exist")))?;
        let normal_matrix = DMat3::from_mat4(*world);
        let det = normal_matrix.determinant();
        if !(det.is_finite() && det != 0.0) {
            return Err(self.err(node, "a mesh's transform is singular (a zero scale)"));
        }
        let normal_matrix = normal_matrix.inverse().transpose();
        for p in 0..mesh.primitives.len() {
            let prim = self.primitive(index, p)?;
            let path = format!("meshes[{index}].primitives[{p}]");
            self.elements[0] += prim.positions.len() as u64;
            self.elements[1] += prim.indices.len() as u64 / 3;
            if self.elements.iter().any(|&e| e > MAX_ELEMENTS as u64) {
                return Err(self.err(
                    &format!("{path} ({node})"),
                    format!("the scene's mesh instances exceed {MAX_ELEMENTS} vertices or triangles in all"),
                ));
            }
            let positions = prim.positions.iter().map(|p| world.transform_point3(p.as_dvec3()).as_vec3()).collect();
            let normals = prim
                .normals
                .as_ref()
                .map(|ns| ns.iter().map(|n| (normal_matrix * n.as_dvec3()).normalize_or_zero().as_vec3()).collect());
            let mut indices = prim.indices.clone();
            if det < 0.0 {
                // A mirroring transform: turned so triangles stay counter-clockwise seen from outside.
                for t in indices.chunks_exact_mut(3) {
                    t.swap(1, 2);
                }
            }
            let raw = RawMesh { positions, normals, uvs: prim.uvs.clone(), indices };
            self.scene.objects.push(Object { mesh: raw, material: prim.material, path: format!("{node} ({path})") });
        }
        Ok(())
    }

    /// A primitive as its file gives it, read once however many nodes instance its mesh.
    fn primitive(&mut self, m: usize, p: usize) -> Result<Rc<Primitive>> {
        use json::mesh::{Mode, Semantic};
        if let Some(prim) = self.primitives.get(&(m, p)) {
            return Ok(prim.clone());
        }
        let path = format!("meshes[{m}].primitives[{p}]");
        let prim = &self.root.meshes[m].primitives[p];
        let mode = match prim.mode {
            Checked::Valid(mode) => mode,
            Checked::Invalid => return Err(self.err(&format!("{path}.mode"), "not a glTF primitive mode")),
        };
        let name = match mode {
            Mode::Points => Some("POINTS (0)"),
            Mode::Lines => Some("LINES (1)"),
            Mode::LineLoop => Some("LINE_LOOP (2)"),
            Mode::LineStrip => Some("LINE_STRIP (3)"),
            _ => None,
        };
        if let Some(name) = name {
            return Err(self.err(
                &format!("{path}.mode"),
                format!("{name}: only TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN primitives are read"),
            ));
        }
        let compressed = |ext: &str| prim.extensions.as_ref().is_some_and(|e| e.others.contains_key(ext));
        let attribute = |s: Semantic| prim.attributes.get(&Checked::Valid(s)).map(|a| a.value());
        let Some(position) = attribute(Semantic::Positions) else {
            if compressed("KHR_draco_mesh_compression") {
                return Err(self.err(
                    &format!("{path}.extensions.KHR_draco_mesh_compression"),
                    "Draco-compressed meshes are not read",
                ));
            }
            return Err(self.err(&format!("{path}.attributes"), "no POSITION"));
        };
        if compressed("KHR_draco_mesh_compression")
            && self.root.accessors.get(position).is_some_and(|a| a.buffer_view.is_none())
        {
            return Err(self.err(
                &format!("{path}.extensions.KHR_draco_mesh_compression"),
                "Draco-compressed meshes are not read (the file has no uncompressed copy)",
            ));
        }
        let pos_path = format!("{path}.attributes.POSITION");
        let positions = self.vec3s(position, &pos_path)?;
        let n = positions.len();
        let normals = match attribute(Semantic::Normals) {
            Some(a) => {
                let np = format!("{path}.attributes.NORMAL");
                let normals = self.vec3s(a, &np)?;
                if normals.len() != n {
                    return Err(self.err(&np, format!("{} normals for {n} positions", normals.len())));
                }
                Some(normals)
            }
            None => None,
        };
        let material = self.material(prim.material.map(|i| i.value()))?;
        let uvs = match self.scene.materials[material].uv_set {
            Some((set, transform)) => {
                let up = format!("{path}.attributes.TEXCOORD_{set}");
                let Some(a) = attribute(Semantic::TexCoords(set)) else {
                    return Err(self.err(
                        &format!("{path}.attributes"),
                        format!(
                            "no TEXCOORD_{set}, which the base colour texture of {} needs",
                            self.scene.materials[material].path
                        ),
                    ));
                };
                let uv = self.vec2s(a, &up)?;
                if uv.len() != n {
                    return Err(self.err(&up, format!("{} coordinates for {n} positions", uv.len())));
                }
                if let Some(bad) = uv.iter().find(|v| !v.is_finite()) {
                    return Err(self.err(&up, format!("({}, {}) is not finite", bad.x, bad.y)));
                }
                // KHR_texture_transform, then glTF's v (down from the image's top) turned to ours (up).
                Some(uv.iter().map(|&v| transform.apply(v)).map(|v| Vec2::new(v.x, 1.0 - v.y)).collect())
            }
            None => None,
        };
        let ip = format!("{path}.indices");
        let corners = match prim.indices {
            Some(a) => {
                let idx = self.indices(a.value(), &ip)?;
                if let Some(&bad) = idx.iter().find(|&&i| i as usize >= n) {
                    return Err(self.err(&ip, format!("index {bad} is out of range (POSITION has {n} vertices)")));
                }
                idx
            }
            None => (0..n as u32).collect(),
        };
        let indices = triangles(&corners, mode).map_err(|e| self.err(&ip, e))?;
        if indices.is_empty() {
            return Err(self.err(&path, "no triangles"));
        }
        let prim = Rc::new(Primitive { positions, normals, uvs, indices, material });
        self.primitives.insert((m, p), prim.clone());
        Ok(prim)
    }

    fn vec3s(&mut self, a: usize, path: &str) -> Result<Vec<Vec3>> {
        let (values, layout) = self.accessor(a, path)?;
        if layout.width != 3 || layout.component != Component::F32 {
            return Err(self.err(
                path,
                format!("VEC3 of FLOAT expected ({} components of {} given)", layout.width, layout.component.name()),
            ));
        }
        Ok(values.chunks_exact(3).map(|v| Vec3::new(v[0], v[1], v[2])).collect())
    }

    fn vec2s(&mut self, a: usize, path: &str) -> Result<Vec<Vec2>> {
        let (values, layout) = self.accessor(a, path)?;
        let ok = layout.width == 2
            && match layout.component {
                Component::F32 => true,
                Component::U8 | Component::U16 => layout.normalized,
                _ => false,
            };
        if !ok {
            return Err(self.err(
                path,
                format!(
                    "VEC2 of FLOAT, or of normalized UNSIGNED_BYTE or UNSIGNED_SHORT, expected ({} components of {}{} given)",
                    layout.width,
                    if layout.normalized { "normalized " } else { "" },
                    layout.component.name()
                ),
            ));
        }
        Ok(values.chunks_exact(2).map(|v| Vec2::new(v[0], v[1])).collect())
    }

    fn indices(&mut self, a: usize, path: &str) -> Result<Vec<u32>> {
        let acc = self.root.accessors.get(a).ok_or_else(|| self.err(path, format!("accessor {a} does not exist")))?;
        let at = format!("{path} (accessors[{a}])");
        if acc.sparse.is_some() {
            return Err(self.err(&at, "sparse index accessors are not read"));
        }
        let layout = self.layout(acc, &at)?;
        let view = acc.buffer_view.ok_or_else(|| self.err(&at, "indices without a bufferView"))?;
        let (bytes, range, stride) = self.view(view.value(), &at)?;
        let layout = Layout { stride, ..layout };
        accessor::read_indices(&bytes[range], &layout).map_err(|e| self.err(&at, e))
    }

    /// An accessor's layout from its JSON (the view's stride filled in by the caller).
    fn layout(&self, acc: &json::Accessor, at: &str) -> Result<Layout> {
        use json::accessor::{ComponentType, Type};
        let component = match acc.component_type {
            Checked::Valid(json::accessor::GenericComponentType(c)) => match c {
                ComponentType::I8 => Component::I8,
                ComponentType::U8 => Component::U8,
                ComponentType::I16 => Component::I16,
                ComponentType::U16 => Component::U16,
                ComponentType::U32 => Component::U32,
                ComponentType::F32 => Component::F32,
            },
            Checked::Invalid => return Err(self.err(at, "componentType is not a glTF component type")),
        };
        let width = match acc.type_ {
            Checked::Valid(Type::Scalar) => 1,
            Checked::Valid(Type::Vec2) => 2,
            Checked::Valid(Type::Vec3) => 3,
            Checked::Valid(Type::Vec4) => 4,
            _ => return Err(self.err(at, "type: only SCALAR, VEC2, VEC3 and VEC4 accessors are read")),
        };
        Ok(Layout {
            component,
            width,
            normalized: acc.normalized,
            count: acc.count.0,
            offset: acc.byte_offset.map(|o| o.0).unwrap_or(0),
            stride: None,
        })
    }

    /// Every component of an accessor (zeros without a bufferView, sparse values substituted).
    fn accessor(&mut self, a: usize, path: &str) -> Result<(Vec<f32>, Layout)> {
        let acc = self.root.accessors.get(a).ok_or_else(|| self.err(path, format!("accessor {a} does not exist")))?;
        let at = format!("{path} (accessors[{a}])");
        let mut layout = self.layout(acc, &at)?;
        let mut values = match acc.buffer_view {
            Some(v) => {
                let (bytes, range, stride) = self.view(v.value(), &at)?;
                layout.stride = stride;
                accessor::read_floats(&bytes[range], &layout).map_err(|e| self.err(&at, e))?
            }
            None => {
                // No data: zeros (sparse values may follow); the count is still bounded.
                layout.check(u64::MAX).map_err(|e| self.err(&at, e))?;
                vec![0.0; layout.count as usize * layout.width]
            }
        };
        if let Some(sparse) = &acc.sparse {
            let sp = format!("{at}.sparse");
            let count = sparse.count.0;
            if count > layout.count {
                return Err(self.err(&sp, format!("count {count} exceeds the accessor's {}", layout.count)));
            }
            let ic = match sparse.indices.component_type {
                Checked::Valid(json::accessor::IndexComponentType(c)) => match c {
                    json::accessor::ComponentType::U8 => Component::U8,
                    json::accessor::ComponentType::U16 => Component::U16,
                    _ => Component::U32,
                },
                Checked::Invalid => return Err(self.err(&format!("{sp}.indices"), "not an index component type")),
            };
            let (bytes, range, _) = self.view(sparse.indices.buffer_view.value(), &format!("{sp}.indices"))?;
            let il = Layout {
                component: ic,
                width: 1,
                normalized: false,
                count,
                offset: sparse.indices.byte_offset.0,
                stride: None,
            };
            let idx = accessor::read_indices(&bytes[range], &il).map_err(|e| self.err(&format!("{sp}.indices"), e))?;
            let (bytes, range, _) = self.view(sparse.values.buffer_view.value(), &format!("{sp}.values"))?;
            let vl = Layout { count, offset: sparse.values.byte_offset.0, stride: None, ..layout.clone() };
            let vals = accessor::read_floats(&bytes[range], &vl).map_err(|e| self.err(&format!("{sp}.values"), e))?;
            let w = layout.width;
            for (k, &i) in idx.iter().enumerate() {
                if i as u64 >= layout.count {
                    return Err(self.err(&format!("{sp}.indices"), format!("index {i} is out of range")));
                }
                values[i as usize * w..(i as usize + 1) * w].copy_from_slice(&vals[k * w..(k + 1) * w]);
            }
        }
        Ok((values, layout))
    }

    /// A buffer view: its buffer's bytes, the view's range in them (checked against the buffer)
    /// and its stride.
    fn view(&mut self, v: usize, from: &str) -> Result<View> {
        let path = format!("bufferViews[{v}]");
        let view =
            self.root.buffer_views.get(v).ok_or_else(|| self.err(from, format!("buffer view {v} does not exist")))?;
        let b = view.buffer.value();
        let data = self.buffer(b, &path)?;
        let start = view.byte_offset.map(|o| o.0).unwrap_or(0);
        let len = view.byte_length.0;
        let end = start.checked_add(len);
        let declared = self.root.buffers[b].byte_length.0;
        match end {
            Some(end) if end <= declared && end <= data.len() as u64 => {}
            _ => {
                return Err(self.err(
                    &path,
                    format!("byteOffset {start} + byteLength {len} runs past buffers[{b}]'s {declared} bytes"),
                ))
            }
        }
        let stride = view.byte_stride.map(|s| s.0 as u64);
        Ok((data, start as usize..(start + len) as usize, stride))
    }

    /// A buffer's bytes: the GLB's binary chunk, a data URI or a file beside the glTF; read once.
    fn buffer(&mut self, b: usize, from: &str) -> Result<Rc<Vec<u8>>> {
        if let Some(d) = self.buffers.get(&b) {
            return Ok(d.clone());
        }
        let path = format!("buffers[{b}]");
        let buffer = self.root.buffers.get(b).ok_or_else(|| self.err(from, format!("buffer {b} does not exist")))?;
        let data = match &buffer.uri {
            None if b == 0 && self.bin.is_some() => self.bin.take().unwrap_or_default(),
            None => {
                let meshopt =
                    buffer.extensions.as_ref().is_some_and(|e| e.others.contains_key("EXT_meshopt_compression"));
                return Err(self.err(
                    &path,
                    if meshopt {
                        "no uri: a meshopt-compressed file's fallback buffer, which has no data (EXT_meshopt_compression is not read)"
                    } else {
                        "no uri, and it is not the first buffer of a .glb with a binary chunk"
                    },
                ));
            }
            Some(uri) => self.uri_bytes(uri, &path)?,
        };
        let declared = buffer.byte_length.0;
        if (data.len() as u64) < declared {
            return Err(self.err(&path, format!("byteLength {declared}, but its data has {} bytes", data.len())));
        }
        let data = Rc::new(data);
        self.buffers.insert(b, data.clone());
        Ok(data)
    }

    /// A URI's bytes: a base64 data URI or a file relative to the glTF file.
    fn uri_bytes(&self, uri: &str, path: &str) -> Result<Vec<u8>> {
        if let Some(decoded) = data_uri(uri, MAX_FILE_BYTES) {
            return decoded.map_err(|e| self.err(&format!("{path}.uri"), e));
        }
        let file = uri_path(&self.dir, uri).map_err(|e| self.err(&format!("{path}.uri"), e))?;
        read_file(&file, &format!("{}: {path}.uri: {}", self.shown, file.display()), MAX_FILE_BYTES)
    }

    /// An image decoded (sRGB to linear), size checked first; read once.
    fn image(&mut self, i: usize, from: &str) -> Result<Texture> {
        if let Some(t) = self.images.get(&i) {
            return Ok(t.clone());
        }
        let path = format!("images[{i}]");
        let image = self.root.images.get(i).ok_or_else(|| self.err(from, format!("image {i} does not exist")))?;
        let bytes = match (&image.uri, image.buffer_view) {
            (Some(uri), _) => self.uri_bytes(uri, &path)?,
            (None, Some(v)) => {
                let (data, range, _) = self.view(v.value(), &path)?;
                data[range].to_vec()
            }
            (None, None) => return Err(self.err(&path, "neither a uri nor a bufferView")),
        };
        let texture = Texture::from_bytes(&bytes, false, &format!("{}: {path}", self.shown))?;
        self.images.insert(i, texture.clone());
        Ok(texture)
    }

    /// A material (`None`: glTF's default material), read once: index into the scene's materials.
    fn material(&mut self, index: Option<usize>) -> Result<usize> {
        if let Some(&k) = self.materials.get(&index) {
            return Ok(k);
        }
        let desc = match index {
            None => MaterialDesc::default(),
            Some(i) => self.read_material(i)?,
        };
        self.scene.materials.push(desc);
        let k = self.scene.materials.len() - 1;
        self.materials.insert(index, k);
        Ok(k)
    }

    fn read_material(&mut self, i: usize) -> Result<MaterialDesc> {
        let path = format!("materials[{i}]");
        let m = self.root.materials.get(i).ok_or_else(|| self.err(&path, "does not exist"))?;
        let pbr = &m.pbr_metallic_roughness;
        let factor = pbr.base_color_factor.0.map(|c| c as f64);
        if !factor.iter().all(|c| (0.0..=1.0).contains(c)) {
            return Err(self.err(
                &format!("{path}.pbrMetallicRoughness.baseColorFactor"),
                format!("{factor:?}: each component must be within [0, 1]"),
            ));
        }
        let roughness = pbr.roughness_factor.0 as f64;
        if !(0.0..=1.0).contains(&roughness) {
            return Err(self.err(
                &format!("{path}.pbrMetallicRoughness.roughnessFactor"),
                format!("{roughness}: must be within [0, 1]"),
            ));
        }
        let mut desc = MaterialDesc {
            index: Some(i),
            name: m.name.clone(),
            path: match &m.name {
                Some(n) => format!("{path} (\"{n}\")"),
                None => path.clone(),
            },
            base_color: [factor[0], factor[1], factor[2]],
            roughness,
            ..MaterialDesc::default()
        };
        if let Some(info) = &pbr.base_color_texture {
            let tp = format!("{path}.pbrMetallicRoughness.baseColorTexture");
            let t = info.index.value();
            let texture =
                self.root.textures.get(t).ok_or_else(|| self.err(&tp, format!("texture {t} does not exist")))?;
            if let Some(s) = texture.sampler.and_then(|s| self.root.samplers.get(s.value())) {
                let repeat = Checked::Valid(json::texture::WrappingMode::Repeat);
                if s.wrap_s != repeat || s.wrap_t != repeat {
                    self.warn(
                        &format!("samplers[{}]", texture.sampler.map(|s| s.value()).unwrap_or(0)),
                        "wrapping modes other than REPEAT are rendered repeated",
                    );
                }
            }
            let mut image = self.image(texture.source.value(), &format!("textures[{t}].source"))?;
            let transform = info.extensions.as_ref().and_then(|e| e.texture_transform.as_ref());
            let set = transform.and_then(|t| t.tex_coord).unwrap_or(info.tex_coord);
            let transform = match transform {
                Some(t) => {
                    let tt = UvTransform { offset: t.offset.0, rotation: t.rotation.0, scale: t.scale.0 };
                    if !tt.is_finite() {
                        return Err(self.err(&format!("{tp}.extensions.KHR_texture_transform"), "must be finite"));
                    }
                    tt
                }
                None => UvTransform::IDENTITY,
            };
            if factor[..3] != [1.0; 3] {
                // The factor multiplies the texture: multiplied into the texels on load.
                let f = [factor[0] as f32, factor[1] as f32, factor[2] as f32];
                let texels = image.texels.iter().map(|t| [t[0] * f[0], t[1] * f[1], t[2] * f[2], 1.0]).collect();
                image = Texture { texels: std::sync::Arc::new(texels), ..image };
            }
            desc.texture = Some(image);
            desc.uv_set = Some((set, transform));
        }
        let ext = m.extensions.as_ref();
        if let Some(v) = ext.and_then(|e| e.volume.as_ref()) {
            let vp = format!("{path}.extensions.KHR_materials_volume");
            let volume = Volume {
                thickness: v.thickness_factor.0 as f64,
                attenuation_distance: v.attenuation_distance.0 as f64,
                attenuation_color: v.attenuation_color.0.map(|c| c as f64),
            };
            if !(volume.thickness.is_finite() && volume.thickness >= 0.0) {
                return Err(
                    self.err(&format!("{vp}.thicknessFactor"), format!("{}: must not be negative", volume.thickness))
                );
            }
            if volume.attenuation_distance.is_nan() || volume.attenuation_distance <= 0.0 {
                return Err(self.err(
                    &format!("{vp}.attenuationDistance"),
                    format!("{}: must be positive", volume.attenuation_distance),
                ));
            }
            if !volume.attenuation_color.iter().all(|c| (0.0..=1.0).contains(c)) {
                return Err(self.err(
                    &format!("{vp}.attenuationColor"),
                    format!("{:?}: each component must be within [0, 1]", volume.attenuation_color),
                ));
            }
            desc.volume = Some(volume);
        }
        if let Some(t) = ext.and_then(|e| e.transmission.as_ref()) {
            let f = t.transmission_factor.0 as f64;
            desc.transmission = Some(if t.transmission_texture.is_some() { f.max(f64::MIN_POSITIVE) } else { f });
        }
        if let Some(ior) = ext.and_then(|e| e.ior.as_ref()) {
            desc.ior = ior.ior.0 as f64;
        }
        let others = ext.map(|e| &e.others);
        if let Some(d) = others.and_then(|o| o.get("KHR_materials_diffuse_transmission")) {
            let dp = format!("{path}.extensions.KHR_materials_diffuse_transmission");
            let f = number(d, "diffuseTransmissionFactor", 0.0).map_err(|e| self.err(&dp, e))?;
            let textured = d.get("diffuseTransmissionTexture").is_some();
            desc.diffuse_transmission = Some(if textured { f.max(f64::MIN_POSITIVE) } else { f });
        }
        if let Some(s) = others.and_then(|o| o.get("KHR_materials_volume_scatter")) {
            let sp = format!("{path}.extensions.KHR_materials_volume_scatter");
            let colour = match s.get("multiscatterColor") {
                None => [0.0; 3],
                Some(c) => rgb(c).ok_or_else(|| {
                    self.err(&format!("{sp}.multiscatterColor"), "must be 3 numbers, each within [0, 1]")
                })?,
            };
            desc.multiscatter = Some(colour);
            desc.anisotropy = number(s, "scatterAnisotropy", 0.0).map_err(|e| self.err(&sp, e))?;
        }
        Ok(desc)
    }
}

/// `value[key]` as a number (`default` when absent).
fn number(value: &serde_json::Value, key: &str, default: f64) -> std::result::Result<f64, String> {
    match value.get(key) {
        None => Ok(default),
        Some(v) => v.as_f64().filter(|v| v.is_finite()).ok_or_else(|| format!("{key}: {v} is not a number")),
    }
}

fn rgb(value: &serde_json::Value) -> Option<[f64; 3]> {
    let a = value.as_array().filter(|a| a.len() == 3)?;
    let c = [a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?];
    c.iter().all(|v| (0.0..=1.0).contains(v)).then_some(c)
}

/// KHR_texture_transform: uv' = T(offset) · R(rotation) · S(scale) · uv, as the extension's
/// specification writes it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    pub offset: [f32; 2],
    pub rotation: f32,
    pub scale: [f32; 2],
}

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform { offset: [0.0; 2], rotation: 0.0, scale: [1.0; 2] };

    fn is_finite(&self) -> bool {
        self.offset.iter().chain(&self.scale).chain([&self.rotation]).all(|v| v.is_finite())
    }

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        if *self == UvTransform::IDENTITY {
            return uv;
        }
        let (s, c) = (self.rotation as f64).sin_cos();
        let (u, v) = (uv.x as f64 * self.scale[0] as f64, uv.y as f64 * self.scale[1] as f64);
        Vec2::new((c * u + s * v + self.offset[0] as f64) as f32, (-s * u + c * v + self.offset[1] as f64) as f32)
    }
}

/// Triangles (three indices each) from a primitive's corners: a list as it is, a strip's and a
/// fan's as the glTF specification forms them (a strip's triangles with a repeated index, its
/// joins, dropped).
pub fn triangles(corners: &[u32], mode: json::mesh::Mode) -> std::result::Result<Vec<u32>, String> {
    use json::mesh::Mode;
    let n = corners.len();
    match mode {
        Mode::Triangles => {
            if !n.is_multiple_of(3) {
                return Err(format!("{n} corners: TRIANGLES needs a multiple of 3"));
            }
            Ok(corners.to_vec())
        }
        Mode::TriangleStrip | Mode::TriangleFan if n < 3 => Err(format!("{n} corners: a strip or fan needs 3 or more")),
        Mode::TriangleStrip => Ok((0..n - 2)
            .map(|i| {
                if i % 2 == 0 {
                    [corners[i], corners[i + 1], corners[i + 2]]
                } else {
                    [corners[i], corners[i + 2], corners[i + 1]]
                }
            })
            .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
            .flatten()
            .collect()),
        Mode::TriangleFan => Ok((1..n - 1).flat_map(|i| [corners[i], corners[i + 1], corners[0]]).collect()),
        _ => Err("not a triangle mode".into()),
    }
}
