//! Triangle meshes: OBJ files through tobj (with the checks tobj does not make), PLY files
//! through ply-rs-bw ([`ply`]), OFF files ([`off`]), any of them gzip-compressed, and procedural
//! shapes. One index stream is shared by positions and normals.

pub mod curvature;
pub mod occupancy;
pub mod off;
pub mod ply;

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use crate::bad_input;
use crate::error::Result;

#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    /// Triangle list, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

/// A mesh as a file gives it, before the checks and repairs every format shares
/// ([`Mesh::from_raw`]): triangles (polygons already fanned), indices into the vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawMesh {
    pub positions: Vec<Vec3>,
    /// Per vertex, when the file gives them (for every vertex).
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates per vertex, when the file gives them.
    pub uvs: Option<Vec<Vec2>>,
    pub indices: Vec<u32>,
}

/// The mesh file formats, chosen by the file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    Obj,
    Ply,
    Off,
}

impl MeshFormat {
    /// The format named by a path's extension (`.ply`, `.off`, anything else OBJ), and whether
    /// the file is gzip-compressed (`.gz` after it: `bunny.ply.gz`).
    pub fn of(path: &Path) -> (MeshFormat, bool) {
        let name = path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        let (name, gz) = match name.strip_suffix(".gz") {
            Some(inner) => (inner.to_string(), true),
            None => (name, false),
        };
        let format = if name.ends_with(".ply") {
            MeshFormat::Ply
        } else if name.ends_with(".off") {
            MeshFormat::Off
        } else {
            MeshFormat::Obj
        };
        (format, gz)
    }
}

/// The largest number of vertices, faces or triangles read from a PLY or OFF file: past any real
/// scan (Lucy has 14M vertices and 28M triangles), and a bound on what a header's counts may make
/// the reader allocate.
pub const MAX_ELEMENTS: usize = 1 << 25;

/// Reads a mesh file as its format gives it (by extension, gunzipped first for `.gz`), checked
/// as [`Mesh::load`] checks it but not yet validated or repaired: for callers that transform it
/// first (scene files).
pub fn read_raw(path: &Path) -> Result<RawMesh> {
    let shown = path.display().to_string();
    let (format, gz) = MeshFormat::of(path);
    let mut bytes = read_mesh_file(path)?;
    if gz {
        bytes = gunzip(&bytes, &shown)?;
    }
    raw_from_bytes(&bytes, format, &shown)
}

/// The file's triangles as its format gives them; errors name `shown` and the line.
pub fn raw_from_bytes(bytes: &[u8], format: MeshFormat, shown: &str) -> Result<RawMesh> {
    match format {
        MeshFormat::Obj => Mesh::raw_from_obj_bytes(bytes, shown),
        MeshFormat::Ply => ply::read(bytes).map_err(|why| bad_input!("mesh {shown}: {why}")),
        MeshFormat::Off => off::read(bytes).map_err(|why| bad_input!("mesh {shown}: {why}")),
    }
}

/// The diffuse colour map (`map_Kd`, times `Kd` when the material gives one) of the first
/// material an OBJ file uses that has one, through its `mtllib` (relative to the OBJ file, at most
/// [`MAX_MESH_BYTES`], read by tobj): what colours a translucent OBJ (README "Textured translucent
/// materials"). `None` when the file names no library or no material with a map; a library or map
/// that cannot be read is an error naming it. Later materials' maps are left out with a warning
/// (one texture per object).
pub fn obj_diffuse_map(path: &Path) -> Result<Option<(PathBuf, Vec3)>> {
    let shown = path.display();
    let text = String::from_utf8_lossy(&read_mesh_file(path)?).into_owned();
    let dir = path.parent().unwrap_or(Path::new("."));
    let words = |key: &'static str| {
        text.lines()
            .filter_map(move |l| l.trim().strip_prefix(key).filter(|r| r.starts_with([' ', '\t'])).map(str::trim))
    };
    let used: Vec<&str> = words("usemtl").collect();
    let mut maps = Vec::new();
    for lib in words("mtllib") {
        let lib_path = dir.join(lib);
        let bytes = read_mesh_file(&lib_path).map_err(|e| bad_input!("mesh {shown}: mtllib {lib}: {e}"))?;
        // tobj 4.0.5 panics on a colour with fewer than three numbers (parse_float3's unwrap):
        // refused here first, naming the line.
        for (n, line) in String::from_utf8_lossy(&bytes).lines().enumerate() {
            let mut words = line.split_whitespace();
            if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
                if words.count() < 3 {
                    return Err(bad_input!("mesh {shown}: mtllib {lib}: line {}: {key} takes three numbers", n + 1));
                }
            }
        }
        let (materials, _) = tobj::load_mtl_buf(&mut std::io::BufReader::new(bytes.as_slice()))
            .map_err(|e| bad_input!("mesh {shown}: mtllib {lib}: not a readable MTL file: {e}"))?;
        for m in materials {
            if let Some(map) = m.diffuse_texture.as_ref().filter(|_| used.is_empty() || used.contains(&m.name.as_str()))
            {
                let factor = m.diffuse.map_or(Vec3::ONE, Vec3::from);
                let map_dir = lib_path.parent().unwrap_or(dir);
                maps.push((m.name.clone(), map_dir.join(map.trim()), factor));
            }
        }
    }
    // In the order the file uses them.
    maps.sort_by_key(|(name, _, _)| used.iter().position(|u| u == name).unwrap_or(usize::MAX));
    if maps.len() > 1 {
        crate::note!(
            "warning: mesh {shown}: {} materials have a map_Kd; the object takes the first, {} (one texture per object)",
            maps.len(),
            maps[0].1.display()
        );
    }
    Ok(maps.into_iter().next().map(|(_, map, factor)| (map, factor)))
}

/// Decompresses a gzip file, bounded like an uncompressed one (a small file that inflates past
/// [`MAX_MESH_BYTES`] is refused as it is read, not after).
pub fn gunzip(bytes: &[u8], shown: &str) -> Result<Vec<u8>> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::MultiGzDecoder::new(bytes)
        .take(MAX_MESH_BYTES + 1)
        .read_to_end(&mut out)
        .map_err(|e| bad_input!("mesh {shown}: not a readable gzip file: {e}"))?;
    if out.len() as u64 > MAX_MESH_BYTES {
        return Err(bad_input!("mesh {shown}: decompresses to more than the limit of {} MiB", MAX_MESH_BYTES >> 20));
    }
    Ok(out)
}

impl Mesh {
    /// `sphere`, `box`, `slab`, `torus`, or the path of a mesh file (OBJ, PLY, OFF; see [`Mesh::load`]).
    pub fn from_spec(spec: &str) -> Result<Mesh> {
        match spec {
            "sphere" => Ok(Mesh::sphere(1.0, 48)),
            "box" => Ok(Mesh::slab(1.0, 1.0, 1.0)),
            "slab" => Ok(Mesh::slab(4.0, 4.0, 1.0)),
            "torus" => Ok(Mesh::torus(1.0, 0.35, 64, 32)),
            path => Mesh::load(Path::new(path)),
        }
    }

    /// Loads a mesh file, its format chosen by the extension: `.ply`, `.off`, anything else OBJ,
    /// each optionally gzip-compressed (`.ply.gz`). The same checks and repairs for every format
    /// ([`Mesh::from_raw`]).
    pub fn load(path: &Path) -> Result<Mesh> {
        let (format, _) = MeshFormat::of(path);
        let raw = read_raw(path)?;
        Mesh::from_raw(raw, &path.display().to_string(), format)
    }

    /// Mesh bytes of a format (uncompressed); errors name `shown`.
    pub fn from_bytes(bytes: &[u8], format: MeshFormat, shown: &str) -> Result<Mesh> {
        Mesh::from_raw(raw_from_bytes(bytes, format, shown)?, shown, format)
    }

    /// Loads every object of an OBJ file into one mesh (triangulated, single index). Computes smooth
    /// area-weighted normals when the file has none or has unusable ones.
    pub fn load_obj(path: &Path) -> Result<Mesh> {
        Mesh::from_obj_bytes(&read_mesh_file(path)?, &path.display().to_string())
    }

    /// Parses OBJ text (`shown` names it in errors). A UTF-8 byte-order mark is skipped and
    /// old-Mac CR-only line endings are read as line ends, like LF and CRLF.
    pub fn from_obj_bytes(bytes: &[u8], shown: &str) -> Result<Mesh> {
        Mesh::from_raw(Mesh::raw_from_obj_bytes(bytes, shown)?, shown, MeshFormat::Obj)
    }

    /// OBJ text as triangles, checked line by line but not yet validated.
    fn raw_from_obj_bytes(bytes: &[u8], shown: &str) -> Result<RawMesh> {
        let text = std::str::from_utf8(bytes).map_err(|e| {
            bad_input!("mesh {shown}: not an OBJ file (not UTF-8 text: byte {} is invalid)", e.valid_up_to() + 1)
        })?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let converted;
        let text = if text.contains('\r') {
            converted = text.replace("\r\n", "\n").replace('\r', "\n");
            converted.as_str()
        } else {
            text
        };
        check_obj_text(text).map_err(|why| bad_input!("mesh {shown}: {why}"))?;

        let options =
            tobj::LoadOptions { triangulate: true, single_index: true, ignore_points: true, ignore_lines: true };
        let mut reader = std::io::BufReader::new(text.as_bytes());
        let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| bad_input!("mesh {shown}: malformed OBJ: {e}"))?;

        let mut mesh = Mesh { positions: Vec::new(), normals: Vec::new(), indices: Vec::new() };
        let mut have_normals = true;
        let mut uvs = Some(Vec::new());
        for model in &models {
            let m = &model.mesh;
            let base = mesh.positions.len() as u32;
            let count = m.positions.len() / 3;
            mesh.positions.extend(m.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
            if m.normals.len() == m.positions.len() {
                mesh.normals.extend(m.normals.chunks_exact(3).map(|n| Vec3::new(n[0], n[1], n[2])));
            } else {
                have_normals = false;
                mesh.normals.extend(std::iter::repeat_n(Vec3::ZERO, count));
            }
            // `vt` for every vertex of every object, or no uv at all.
            match (&mut uvs, m.texcoords.len() == 2 * count) {
                (Some(uvs), true) => uvs.extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1]))),
                _ => uvs = None,
            }
            for &i in &m.indices {
                if i as usize >= count {
                    return Err(bad_input!("mesh {shown}: object '{}' has a vertex index out of range", model.name));
                }
                mesh.indices.push(base + i);
            }
        }
        Ok(RawMesh {
            positions: mesh.positions,
            normals: have_normals.then_some(mesh.normals),
            uvs: uvs.filter(|uvs| !uvs.is_empty()),
            indices: mesh.indices,
        })
    }

    /// The checks and repairs every file format shares: [`Mesh::validate`]; a closed mesh wound
    /// inside out turned outward; the file's normals normalised (computed when it has none or an
    /// unusable one), and turned outward when they point inward on a closed mesh. Each repair
    /// prints a warning naming `shown`.
    pub fn from_raw(raw: RawMesh, shown: &str, format: MeshFormat) -> Result<Mesh> {
        let what = match format {
            MeshFormat::Obj => "vn normals",
            MeshFormat::Ply | MeshFormat::Off => "normals",
        };
        let have_normals = raw.normals.as_ref().is_some_and(|n| n.len() == raw.positions.len());
        let normals = match raw.normals {
            Some(n) if have_normals => n,
            _ => vec![Vec3::ZERO; raw.positions.len()],
        };
        let mut mesh = Mesh { positions: raw.positions, normals, indices: raw.indices };
        mesh.validate().map_err(|e| bad_input!("mesh {shown}: {e}"))?;
        // Inside-out meshes render dark: a closed mesh enclosing negative volume is wound inward.
        if mesh.is_closed() && mesh.signed_volume() < 0.0 {
            mesh.flip_winding();
            crate::note!(
                "warning: mesh {shown}: its triangles are wound inward (clockwise seen from outside); turned outward"
            );
        }
        // Normalised safely: a normal such as (1e38, 1e38, 1e38) overflows f32 when squared.
        let normalised: Option<Vec<Vec3>> =
            if have_normals { mesh.normals.iter().map(|n| safe_normalize(*n)).collect() } else { None };
        match normalised {
            Some(n) => mesh.normals = n,
            None => mesh.compute_normals(),
        }
        if mesh.normal_agreement() < 0.0 {
            if mesh.is_closed() {
                for n in &mut mesh.normals {
                    *n = -*n;
                }
                crate::note!("warning: mesh {shown}: its {what} point inward; turned outward");
            } else {
                crate::note!(
                    "warning: mesh {shown}: most {what} point against the triangles' winding; the surface may render dark"
                );
            }
        }
        Ok(mesh)
    }

    /// Whether every edge is shared by exactly two triangles, once in each direction (welded by
    /// position, so duplicated vertices count as one): a closed, consistently wound surface.
    pub fn is_closed(&self) -> bool {
        // Welded on a grid a millionth of the mesh's size: a seam's two copies of a vertex
        // (cos 0 and cos 2π) differ in the last bits. Each vertex takes the rank of its grid
        // cell among the cells in use.
        let (lo, hi) = self.bounds();
        let cell = ((hi - lo).max_element() as f64 * 1e-6).max(f64::MIN_POSITIVE);
        let keys: Vec<[i64; 3]> = (self.positions.iter())
            .map(|&p| {
                let p = (p - lo).as_dvec3() / cell;
                [p.x.round() as i64, p.y.round() as i64, p.z.round() as i64]
            })
            .collect();
        let mut order: Vec<u32> = (0..keys.len() as u32).collect();
        order.sort_unstable_by_key(|&i| keys[i as usize]);
        let mut welded = vec![0u32; keys.len()];
        for k in 1..order.len() {
            let (previous, this) = (order[k - 1] as usize, order[k] as usize);
            welded[this] = welded[previous] + u32::from(keys[this] != keys[previous]);
        }
        // Closed and consistently wound: every edge is crossed as often from a to b as from b to
        // a, that is, the directed edges sorted are the reversed ones sorted. (Sorted vectors
        // rather than a map of edges: 0.1 s rather than 1.8 s for two million triangles.)
        let mut forward: Vec<u64> = Vec::with_capacity(self.indices.len());
        for t in self.indices.chunks_exact(3) {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let (a, b) = (welded[a as usize], welded[b as usize]);
                if a != b {
                    forward.push((u64::from(a) << 32) | u64::from(b));
                }
            }
        }
        let mut backward: Vec<u64> = forward.iter().map(|e| e.rotate_left(32)).collect();
        std::thread::scope(|s| {
            s.spawn(|| backward.sort_unstable());
            forward.sort_unstable();
        });
        !forward.is_empty() && forward == backward
    }

    /// The volume enclosed (positive when wound counter-clockwise seen from outside), about the
    /// bounding box's centre; meaningful for a closed mesh.
    pub fn signed_volume(&self) -> f64 {
        let (lo, hi) = self.bounds();
        let c = ((lo + hi) * 0.5).as_dvec3();
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, d] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize].as_dvec3() - c);
                a.dot(b.cross(d)) / 6.0
            })
            .sum()
    }

    /// Σ over triangles of the area-weighted agreement between the winding's normal and the
    /// vertex normals: negative when the normals mostly point against the winding.
    pub fn normal_agreement(&self) -> f64 {
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize].as_dvec3());
                let n: glam::DVec3 = [t[0], t[1], t[2]].iter().map(|&i| self.normals[i as usize].as_dvec3()).sum();
                let g = (b - a).cross(c - a);
                let m = g.abs().max_element();
                if m > 0.0 {
                    (g / m).dot(n).signum() * (g / m).length()
                } else {
                    0.0
                }
            })
            .sum()
    }

    /// Reverses every triangle's winding (normals are left as they are).
    pub fn flip_winding(&mut self) {
        for t in self.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
    }

    /// Smooth vertex normals: each the area-weighted sum of the normals of the triangles that touch
    /// its position. Summing per position, not per vertex, keeps normals smooth where objects (or
    /// texture seams) made tobj duplicate a vertex.
    pub fn compute_normals(&mut self) {
        let key = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        let mut sums: std::collections::HashMap<[u32; 3], Vec3> = std::collections::HashMap::new();
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
            // The cross product's length is twice the area: it weights by area for free.
            let n = (b - a).cross(c - a);
            for p in [a, b, c] {
                *sums.entry(key(p)).or_insert(Vec3::ZERO) += n;
            }
        }
        // A vertex used only by degenerate triangles gets an arbitrary but valid normal.
        self.normals = self
            .positions
            .iter()
            .map(|p| sums.get(&key(*p)).and_then(|n| n.try_normalize()).unwrap_or(Vec3::Z))
            .collect();
    }

    /// A UV sphere with exact outward normals; `rings` latitude bands, 2·rings longitude segments.
    pub fn sphere(radius: f32, rings: u32) -> Mesh {
        let rings = rings.max(3);
        let segments = rings * 2;
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        for i in 0..=rings {
            let theta = PI * i as f32 / rings as f32;
            for j in 0..=segments {
                let phi = 2.0 * PI * j as f32 / segments as f32;
                let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin());
                positions.push(n * radius);
                normals.push(n);
            }
        }
        let mut indices = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let a = i * (segments + 1) + j;
                let b = a + segments + 1;
                // Skip the zero-area triangles at the poles.
                if i != 0 {
                    indices.extend_from_slice(&[a, b, a + 1]);
                }
                if i != rings - 1 {
                    indices.extend_from_slice(&[a + 1, b, b + 1]);
                }
            }
        }
        Mesh { positions, normals, indices }
    }

    /// An axis-aligned box centred at the origin (x by y by z), flat normals per face; the top
    /// face is at y = +size_y/2 (a slab seen from above).
    pub fn slab(size_x: f32, size_z: f32, thickness: f32) -> Mesh {
        let h = Vec3::new(size_x, thickness, size_z) * 0.5;
        let mut mesh = Mesh { positions: Vec::new(), normals: Vec::new(), indices: Vec::new() };
        // For each face: its normal and two tangents u, v with u × v = n (counter-clockwise).
        let faces = [
            (Vec3::X, Vec3::NEG_Z, Vec3::Y),
            (Vec3::NEG_X, Vec3::Z, Vec3::Y),
            (Vec3::Y, Vec3::Z, Vec3::X),
            (Vec3::NEG_Y, Vec3::X, Vec3::Z),
            (Vec3::Z, Vec3::X, Vec3::Y),
            (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
        ];
        for (n, u, v) in faces {
            let base = mesh.positions.len() as u32;
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                mesh.positions.push((n + u * su + v * sv) * h);
                mesh.normals.push(n);
            }
            mesh.indices.extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
        }
        mesh
    }

    /// A torus around the y axis: ring radius `major`, tube radius `minor`.
    pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Mesh {
        let (segments, sides) = (segments.max(3), sides.max(3));
        let mut mesh = Mesh { positions: Vec::new(), normals: Vec::new(), indices: Vec::new() };
        for i in 0..=segments {
            let phi = 2.0 * PI * i as f32 / segments as f32;
            let ring = Vec3::new(phi.cos(), 0.0, -phi.sin());
            for j in 0..=sides {
                let theta = 2.0 * PI * j as f32 / sides as f32;
                let n = ring * theta.cos() + Vec3::Y * theta.sin();
                mesh.positions.push(ring * major + n * minor);
                mesh.normals.push(n);
            }
        }
        for i in 0..segments {
            for j in 0..sides {
                let a = i * (sides + 1) + j;
                let b = a + sides + 1;
                mesh.indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
            }
        }
        mesh
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    }

    /// Area of each triangle.
    pub fn triangle_areas(&self) -> Vec<f32> {
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .collect()
    }

    pub fn surface_area(&self) -> f32 {
        self.triangle_areas().iter().map(|&a| a as f64).sum::<f64>() as f32
    }

    /// Checks what the renderer relies on: triangles, finite positions, indices in range, area > 0.
    pub fn validate(&self) -> Result<()> {
        if self.indices.len() < 3 || self.positions.is_empty() {
            return Err(bad_input!("the mesh has no triangles"));
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(bad_input!("the index count {} is not a multiple of 3", self.indices.len()));
        }
        if self.normals.len() != self.positions.len() {
            return Err(bad_input!("{} normals for {} positions", self.normals.len(), self.positions.len()));
        }
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(bad_input!("vertex {} has a position that is not finite: {}", i + 1, self.positions[i]));
        }
        if let Some(&i) = self.indices.iter().find(|&&i| i as usize >= self.positions.len()) {
            return Err(bad_input!("vertex index {} is out of range ({} vertices)", i + 1, self.positions.len()));
        }
        let (lo, hi) = self.bounds();
        let largest = lo.abs().max(hi.abs()).max_element();
        if largest > MAX_COORDINATE {
            return Err(bad_input!(
                "vertex coordinates reach {largest:e}: beyond ±{MAX_COORDINATE:e} squared areas overflow f32"
            ));
        }
        if (hi - lo).max_element() < MIN_EXTENT {
            return Err(bad_input!(
                "the mesh is {:e} units across: below {MIN_EXTENT:e} squared areas underflow f32 (scale the file's \
                 coordinates up and --scale down)",
                (hi - lo).max_element()
            ));
        }
        let area = self.surface_area();
        let scale = (hi - lo).max_element();
        if area.is_nan() || area <= 1e-12 * scale * scale || !area.is_finite() {
            return Err(bad_input!("the mesh has zero surface area (every triangle is degenerate)"));
        }
        Ok(())
    }

    /// Interleaved vertex data for the vertex buffer: `[px, py, pz, nx, ny, nz]` (24 bytes).
    pub fn vertex_data(&self) -> Vec<[f32; 6]> {
        self.positions.iter().zip(&self.normals).map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z]).collect()
    }

    pub fn scaled(mut self, factor: f32) -> Mesh {
        for p in &mut self.positions {
            *p *= factor;
        }
        self
    }
}

/// The largest vertex coordinate: a triangle's doubled area vector squared (an edge to the fourth
/// power) must stay finite in f32.
pub const MAX_COORDINATE: f32 = 1e9;
/// The smallest extent of a mesh: the same fourth power must stay a normal f32.
pub const MIN_EXTENT: f32 = 1e-9;

/// The largest mesh file read (bytes): far above any real scan (the bunny is 3 MB), far below
/// what would exhaust memory while parsing.
pub const MAX_MESH_BYTES: u64 = 512 << 20;

/// Reads a mesh file: a regular file of at most [`MAX_MESH_BYTES`]. A FIFO, a device such as
/// /dev/zero or a folder is refused before it is opened, so nothing can block or read forever.
fn read_mesh_file(path: &Path) -> Result<Vec<u8>> {
    use std::io::Read;
    let shown = path.display();
    let meta = std::fs::metadata(path).map_err(|e| bad_input!("--mesh {shown}: cannot read the file: {e}"))?;
    if !meta.is_file() {
        return Err(bad_input!("--mesh {shown}: not a regular file (a folder, FIFO or device cannot be a mesh)"));
    }
    let too_big =
        || bad_input!("--mesh {shown}: larger than the limit of {} MiB for a mesh file", MAX_MESH_BYTES >> 20);
    if meta.len() > MAX_MESH_BYTES {
        return Err(too_big());
    }
    let file = std::fs::File::open(path).map_err(|e| bad_input!("--mesh {shown}: cannot read the file: {e}"))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // Bounded even when the file grows while it is read.
    file.take(MAX_MESH_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| bad_input!("--mesh {shown}: cannot read the file: {e}"))?;
    if bytes.len() as u64 > MAX_MESH_BYTES {
        return Err(too_big());
    }
    Ok(bytes)
}

/// `v` scaled to unit length, or `None` when it is zero or not finite. Divides by the largest
/// component first, so vectors whose squared length overflows f32 (1e20, 1e20, 1e20) or
/// underflows it (1e-30, 0, 0) normalise correctly.
pub fn safe_normalize(v: Vec3) -> Option<Vec3> {
    if !v.is_finite() {
        return None;
    }
    let m = v.abs().max_element();
    if m == 0.0 {
        return None;
    }
    (v / m).try_normalize()
}

/// Checks tobj is lenient about: unknown statements are skipped silently (so garbage loads as an
/// empty mesh), and faces with fewer than 3 vertices are dropped. Also names the line.
fn check_obj_text(text: &str) -> std::result::Result<(), String> {
    let mut vertices = 0i64;
    let mut texcoords = 0i64;
    let mut normals = 0i64;
    let mut faces = 0usize;
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        let at = number + 1;
        match keyword {
            "v" => {
                let coords: Vec<&str> = words.collect();
                if coords.len() < 3 {
                    return Err(format!("line {at}: a vertex needs 3 coordinates: '{line}'"));
                }
                for c in &coords[..3] {
                    let value: f32 = c.parse().map_err(|_| format!("line {at}: '{c}' is not a number"))?;
                    if !value.is_finite() {
                        return Err(format!("line {at}: vertex coordinate '{c}' is not finite"));
                    }
                }
                vertices += 1;
            }
            "f" => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(format!("line {at}: a face needs at least 3 vertices (truncated face?): '{line}'"));
                }
                for corner in corners {
                    // v, v/vt, v//vn or v/vt/vn. tobj drops bad vt/vn references silently (and
                    // overflows on negative ones in debug builds), so all three are checked here.
                    let mut parts = corner.split('/');
                    for (kind, defined) in
                        [("vertex", vertices), ("texture coordinate", texcoords), ("normal", normals)]
                    {
                        let Some(index) = parts.next() else { break };
                        if index.is_empty() && kind != "vertex" {
                            continue;
                        }
                        let i: i64 =
                            index.parse().map_err(|_| format!("line {at}: '{corner}' is not a valid face corner"))?;
                        // OBJ indices are 1-based; negative ones count back from the last one so far.
                        let resolved = if i < 0 { defined + 1 + i } else { i };
                        if i == 0 || resolved < 1 || resolved > defined {
                            return Err(format!(
                                "line {at}: {kind} index {i} is out of range ({defined} defined so far)"
                            ));
                        }
                    }
                    if parts.next().is_some() {
                        return Err(format!("line {at}: '{corner}' has more than three indices"));
                    }
                }
                faces += 1;
            }
            "vt" => texcoords += 1,
            "vn" => normals += 1,
            "vp" | "o" | "g" | "s" | "usemtl" | "mtllib" | "l" | "p" => {}
            k if k.starts_with('#') => {}
            _ => return Err(format!("line {at}: not an OBJ statement: '{}'", truncate(line))),
        }
    }
    if faces == 0 {
        return Err("no faces: the file holds no triangles (empty mesh)".to_string());
    }
    Ok(())
}

fn truncate(s: &str) -> String {
    if s.chars().count() > 40 {
        format!("{}…", s.chars().take(40).collect::<String>())
    } else {
        s.to_string()
    }
}

impl Mesh {
    /// Whether `p` is inside the closed mesh: parity of the crossings of a ray from `p`
    /// (Möller–Trumbore; an irrational-ish direction avoids edges and vertices of regular meshes).
    pub fn contains_point(&self, p: Vec3) -> bool {
        let dir = Vec3::new(0.5773, 0.5774, 0.5772).normalize();
        let mut crossings = 0;
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.positions[i as usize]);
            let (e1, e2) = (b - a, c - a);
            let h = dir.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-12 {
                continue;
            }
            let s = p - a;
            let u = s.dot(h) / det;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let q = s.cross(e1);
            let v = dir.dot(q) / det;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            if e2.dot(q) / det > 0.0 {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }
}
