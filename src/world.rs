//! What is drawn: objects, each a mesh of one material placed by a transform, and the world's
//! scale in millimetres. A plain value: the viewer, `render` and the tests edit it, and
//! [`crate::gpu_world::GpuWorld::sync`] makes the GPU's copy follow it when a frame begins.

use std::borrow::Cow;

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::bad_input;
use crate::error::Result;
use crate::materials::Material;
use crate::mesh::Mesh;

/// The sizes (mm across) a mesh may have once --scale is applied: from a micrometre to a thousand
/// kilometres, so that areas in mm² and the powers summed over them stay finite in f32.
pub const SIZE_MM_LIMITS: (f64, f64) = (1e-3, 1e9);

/// One translucent object.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// In the object's own coordinates.
    pub mesh: Mesh,
    pub material: Material,
    /// Object to world coordinates.
    pub transform: Mat4,
    /// Sample points over its surface (`None`: from the material's length scales and its area).
    pub samples: Option<u32>,
    /// A colour over the surface: the total diffuse reflectance per channel (linear, in [0, 1])
    /// at each uv, which sets the material's albedo there (the material keeps its mean free
    /// path). `None`: the material alone, the same everywhere. A checkerboard or an image needs
    /// `uvs`.
    pub texture: Option<Reflectance>,
    /// One per vertex of `mesh`, when it has them.
    pub uvs: Option<Vec<Vec2>>,
}

impl Object {
    /// `mesh` in `material`, where it is (identity transform), with the default sample count.
    pub fn new(mesh: Mesh, material: Material) -> Object {
        Object { mesh, material, transform: Mat4::IDENTITY, samples: None, texture: None, uvs: None }
    }

    /// The mesh in world coordinates: positions by the transform, normals by its inverse
    /// transpose, and the winding reversed by a mirroring transform so it stays counter-clockwise
    /// seen from outside.
    pub fn world_mesh(&self) -> Cow<'_, Mesh> {
        transformed(&self.mesh, self.transform)
    }
}

/// `mesh` by `transform`: positions by it, normals by its inverse transpose, and the winding
/// reversed by a mirroring transform so it stays counter-clockwise seen from outside.
fn transformed(mesh: &Mesh, transform: Mat4) -> Cow<'_, Mesh> {
    if transform == Mat4::IDENTITY {
        return Cow::Borrowed(mesh);
    }
    let mut mesh = mesh.clone();
    let normal_matrix = Mat3::from_mat4(transform).inverse().transpose();
    for p in &mut mesh.positions {
        *p = transform.transform_point3(*p);
    }
    for n in &mut mesh.normals {
        *n = (normal_matrix * *n).normalize_or_zero();
    }
    if Mat3::from_mat4(transform).determinant() < 0.0 {
        mesh.flip_winding();
    }
    Cow::Owned(mesh)
}

/// How an opaque surface reflects: Lambertian, with this reflectance (each channel in [0, 1]).
#[derive(Clone, Debug, PartialEq)]
pub enum Reflectance {
    Constant(Vec3),
    /// pbrt-v4's 2D checkerboard over the mesh's uv: `tex1` where ⌊u·uscale⌋ + ⌊v·vscale⌋ is
    /// even, `tex2` where odd.
    Checkerboard {
        uscale: f32,
        vscale: f32,
        tex1: Vec3,
        tex2: Vec3,
    },
    /// An image over the mesh's uv (pbrt-v4's `imagemap`: v runs up the image), repeated,
    /// filtered linearly.
    Image(Texture),
}

impl Reflectance {
    /// The value at `uv`, as the GPU reads it (shaders/include/surface_texture.glsl): a
    /// checkerboard by the parity of ⌊u·uscale⌋ + ⌊v·vscale⌋, an image with v running up it,
    /// repeated, filtered linearly between texel centres.
    pub fn at(&self, uv: Vec2) -> Vec3 {
        match self {
            Reflectance::Constant(c) => *c,
            Reflectance::Checkerboard { uscale, vscale, tex1, tex2 } => {
                let parity = (uv.x * uscale).floor() as i64 + (uv.y * vscale).floor() as i64;
                if parity.rem_euclid(2) == 0 {
                    *tex1
                } else {
                    *tex2
                }
            }
            Reflectance::Image(t) => {
                let (w, h) = (t.width as i64, t.height as i64);
                let x = uv.x * w as f32 - 0.5;
                let y = (1.0 - uv.y) * h as f32 - 0.5;
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let texel = |i: i64, j: i64| {
                    let p = t.texels[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
                    Vec3::new(p[0], p[1], p[2])
                };
                let (i, j) = (x0 as i64, y0 as i64);
                let top = texel(i, j).lerp(texel(i + 1, j), fx);
                let bottom = texel(i, j + 1).lerp(texel(i + 1, j + 1), fx);
                top.lerp(bottom, fy)
            }
        }
    }

    /// The mean over the surface's uv square: a checkerboard's two values equally, an image's
    /// texels (summed in f64).
    pub fn mean(&self) -> Vec3 {
        match self {
            Reflectance::Constant(c) => *c,
            Reflectance::Checkerboard { tex1, tex2, .. } => (*tex1 + *tex2) * 0.5,
            Reflectance::Image(t) => Vec3::from(t.mean().map(|c| c as f32)),
        }
    }
}

/// `material` for an object coloured by `texture`: its mean free path, g and η, with the
/// texture's mean reflectance as its albedo (the texture then weighs it per point); how a preset
/// (`--material`, the viewer's material) is applied to a textured object, whatever its file.
pub fn textured_material(material: &Material, texture: &Reflectance) -> Result<Material> {
    let mean = texture.mean();
    material.with_reflectance([mean.x as f64, mean.y as f64, mean.z as f64])
}

/// An image of linear reflectances, rows from the top.
#[derive(Clone, Debug)]
pub struct Texture {
    /// Where it came from, for messages.
    pub name: String,
    pub width: u32,
    pub height: u32,
    /// Linear RGB and 1, `width × height`.
    pub texels: std::sync::Arc<Vec<[f32; 4]>>,
}

impl PartialEq for Texture {
    fn eq(&self, other: &Texture) -> bool {
        (self.width, self.height) == (other.width, other.height)
            && (std::sync::Arc::ptr_eq(&self.texels, &other.texels) || self.texels == other.texels)
    }
}

/// The largest texture side accepted (the device's image limit is checked when it is made).
pub const MAX_TEXTURE_SIDE: u32 = 16384;
/// The most texels a texture may have: 2^24 (4096², 256 MiB as RGBA32F on the host and the GPU),
/// so that memory stays bounded whatever a file's header claims.
pub const MAX_TEXTURE_TEXELS: u64 = 1 << 24;

impl Texture {
    /// Reads a PNG (sRGB-encoded, decoded to linear) or an EXR (linear) file; `shown` names it in
    /// messages. The size is read from the header before the image is decoded.
    pub fn load(path: &std::path::Path, shown: &str) -> Result<Texture> {
        let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
        let meta = std::fs::metadata(path).map_err(|e| bad_input!("{shown}: {e}"))?;
        if !meta.is_file() {
            return Err(bad_input!("{shown}: not a regular file"));
        }
        let open = || {
            let reader = image::ImageReader::open(path).map_err(|e| bad_input!("{shown}: {e}"))?;
            reader.with_guessed_format().map_err(|e| bad_input!("{shown}: {e}"))
        };
        Texture::decode(open, ext == "exr", shown)
    }

    /// An image file's bytes (PNG or JPEG, sRGB-encoded, decoded to linear; EXR when `linear`),
    /// the format guessed from its first bytes; checked as [`Texture::load`] checks a file.
    pub fn from_bytes(bytes: &[u8], linear: bool, shown: &str) -> Result<Texture> {
        let open = || {
            image::ImageReader::new(std::io::Cursor::new(bytes))
                .with_guessed_format()
                .map_err(|e| bad_input!("{shown}: {e}"))
        };
        Texture::decode(open, linear, shown)
    }

    /// The one decoder: the size from the header checked against [`MAX_TEXTURE_SIDE`] and
    /// [`MAX_TEXTURE_TEXELS`] before decoding (`open` gives a fresh reader for each step), then
    /// linear RGB, every texel within [0, 1].
    fn decode<R: std::io::BufRead + std::io::Seek>(
        open: impl Fn() -> Result<image::ImageReader<R>>,
        linear: bool,
        shown: &str,
    ) -> Result<Texture> {
        let (width, height) = open()?.into_dimensions().map_err(|e| bad_input!("{shown}: not an image: {e}"))?;
        let texels = width as u64 * height as u64;
        if width == 0
            || height == 0
            || width > MAX_TEXTURE_SIDE
            || height > MAX_TEXTURE_SIDE
            || texels > MAX_TEXTURE_TEXELS
        {
            return Err(bad_input!(
                "{shown}: {width}x{height}: a texture's sides must be between 1 and {MAX_TEXTURE_SIDE}, and it may have at most {MAX_TEXTURE_TEXELS} texels"
            ));
        }
        let img = open()?.decode().map_err(|e| bad_input!("{shown}: not an image: {e}"))?.into_rgba32f();
        let decode = |c: f32| {
            if linear {
                c
            } else if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let texels: Vec<[f32; 4]> = img.pixels().map(|p| [decode(p[0]), decode(p[1]), decode(p[2]), 1.0]).collect();
        if let Some(t) = texels.iter().find(|t| !t[..3].iter().all(|c| c.is_finite() && (0.0..=1.0).contains(c))) {
            return Err(bad_input!("{shown}: reflectance {:?}: every texel must be finite and within [0, 1]", &t[..3]));
        }
        Ok(Texture { name: shown.to_string(), width, height, texels: std::sync::Arc::new(texels) })
    }

    /// The mean texel per channel (linear reflectance), summed in f64.
    pub fn mean(&self) -> [f64; 3] {
        let mut sum = [0.0f64; 3];
        for t in self.texels.iter() {
            for (s, &c) in sum.iter_mut().zip(&t[..3]) {
                *s += c as f64;
            }
        }
        sum.map(|s| s / self.texels.len().max(1) as f64)
    }
}

/// An opaque object: it reflects light (Lambertian) and casts shadows on every object; light
/// does not scatter into it.
#[derive(Clone, Debug, PartialEq)]
pub struct Opaque {
    pub mesh: Mesh,
    /// One per vertex of `mesh`, when it has them (a checkerboard needs them).
    pub uvs: Option<Vec<Vec2>>,
    pub transform: Mat4,
    pub reflectance: Reflectance,
}

impl Opaque {
    pub fn new(mesh: Mesh, reflectance: Reflectance) -> Opaque {
        Opaque { mesh, uvs: None, transform: Mat4::IDENTITY, reflectance }
    }

    pub fn world_mesh(&self) -> Cow<'_, Mesh> {
        transformed(&self.mesh, self.transform)
    }

    fn validate(&self) -> Result<()> {
        if !self.transform.is_finite() || Mat3::from_mat4(self.transform).determinant() == 0.0 {
            return Err(bad_input!("an opaque object's transform is not finite or not invertible"));
        }
        self.world_mesh().validate()?;
        check_reflectance(&self.reflectance, self.uvs.as_deref(), self.mesh.positions.len())
    }
}

/// A reflectance within [0, 1] per channel, with the uv per vertex a checkerboard or an image needs.
fn check_reflectance(reflectance: &Reflectance, uvs: Option<&[Vec2]>, vertex_count: usize) -> Result<()> {
    let in_range = |c: Vec3| c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0;
    let ok = match reflectance {
        Reflectance::Constant(c) => in_range(*c),
        Reflectance::Checkerboard { uscale, vscale, tex1, tex2 } => {
            if uvs.is_none() {
                return Err(bad_input!("a checkerboard reflectance needs the mesh's uv coordinates"));
            }
            uscale.is_finite() && vscale.is_finite() && in_range(*tex1) && in_range(*tex2)
        }
        Reflectance::Image(t) => {
            if uvs.is_none() {
                return Err(bad_input!("{}: an image reflectance needs the mesh's uv coordinates", t.name));
            }
            t.texels.len() == (t.width * t.height) as usize
        }
    };
    if !ok {
        return Err(bad_input!("reflectance {reflectance:?}: each channel must be within [0, 1] (and scales finite)"));
    }
    if let Some(uvs) = uvs {
        if uvs.len() != vertex_count || uvs.iter().any(|uv| !uv.is_finite()) {
            return Err(bad_input!("{} uv coordinates for {vertex_count} vertices, or not finite", uvs.len()));
        }
    }
    Ok(())
}

/// Everything drawn, in one scale.
#[derive(Clone, Debug, PartialEq)]
pub struct World {
    /// The translucent objects (none in a world of opaque objects only).
    pub objects: Vec<Object>,
    /// Opaque objects: they reflect the lights and cast shadows.
    pub opaque: Vec<Opaque>,
    /// Millimetres per world unit (materials are given per mm).
    pub mm_per_unit: f32,
}

impl World {
    /// A world of one object.
    pub fn single(mesh: Mesh, material: Material, mm_per_unit: f32) -> World {
        World { objects: vec![Object::new(mesh, material)], opaque: Vec::new(), mm_per_unit }
    }

    /// Every check of the world, with the flag each comes from named: the scale, each mesh (and
    /// its size in millimetres), each material, and the coefficients the GPU can hold in f32.
    pub fn validate(&self) -> Result<()> {
        if self.objects.is_empty() && self.opaque.is_empty() {
            return Err(bad_input!("the world has no object, translucent or opaque"));
        }
        for o in &self.opaque {
            o.validate()?;
        }
        for object in &self.objects {
            if !object.transform.is_finite() || Mat3::from_mat4(object.transform).determinant() == 0.0 {
                return Err(bad_input!("an object's transform is not finite or not invertible"));
            }
            check_geometry(&object.world_mesh(), self.mm_per_unit)?;
            check_material(&object.material)?;
            if let Some(texture) = &object.texture {
                check_reflectance(texture, object.uvs.as_deref(), object.mesh.positions.len())?;
            }
        }
        Ok(())
    }

    /// The box around every object, in world coordinates.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let opaque = self.opaque.iter().map(|o| o.world_mesh().bounds());
        self.objects
            .iter()
            .map(|o| o.world_mesh().bounds())
            .chain(opaque)
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), (a, b)| (lo.min(a), hi.max(b)))
    }
}

/// A mesh at a scale: the scale itself, the mesh's own checks and its size in millimetres.
pub fn check_geometry(mesh: &Mesh, mm_per_unit: f32) -> Result<()> {
    if !(mm_per_unit.is_finite() && mm_per_unit > 0.0) {
        return Err(bad_input!("--scale {mm_per_unit}: must be a positive number of millimetres per unit"));
    }
    let (_, radius) = crate::scene::bounding_sphere(&mesh.positions);
    let size_mm = 2.0 * radius as f64 * mm_per_unit as f64;
    if !(SIZE_MM_LIMITS.0..=SIZE_MM_LIMITS.1).contains(&size_mm) {
        return Err(bad_input!(
            "--scale {mm_per_unit}: the mesh would be {size_mm:.3e} mm across; it must be within [{:e}, {:e}] mm",
            SIZE_MM_LIMITS.0,
            SIZE_MM_LIMITS.1
        ));
    }
    mesh.validate()
}

/// A material's own checks, and the coefficients the GPU can hold in f32 (see `bssrdf --gpu`).
pub fn check_material(m: &Material) -> Result<()> {
    m.validate()?;
    let max = crate::bssrdf_csv::GPU_MAX_SIGMA_T;
    if let Some(ch) = (0..3).find(|&c| m.sigma_a[c] + m.sigma_s[c] > max) {
        return Err(bad_input!(
            "--sigma-a/--sigma-s: σa + σs = {:e} /mm in channel {ch} is above {max:e}, beyond what rendering in f32 can hold",
            m.sigma_a[ch] + m.sigma_s[ch],
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mirroring_transform_keeps_the_mesh_outward() {
        let mut object = Object::new(Mesh::sphere(1.0, 8), Material::find("marble").unwrap());
        object.transform = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)) * Mat4::from_translation(Vec3::X * 3.0);
        let mesh = object.world_mesh();
        assert!(mesh.signed_volume() > 0.0, "outward winding after a mirror");
        assert!(mesh.normal_agreement() > 0.0, "normals agree with the winding");
        assert!((mesh.bounds().0.x + 4.0).abs() < 1e-5, "moved, then mirrored: {:?}", mesh.bounds());
    }

    #[test]
    fn the_scale_and_the_coefficients_are_checked() {
        let mut world = World::single(Mesh::sphere(1.0, 8), Material::find("marble").unwrap(), 10.0);
        world.validate().unwrap();
        world.mm_per_unit = 1e12;
        assert!(world.validate().unwrap_err().to_string().contains("--scale"));
        world.mm_per_unit = 10.0;
        world.objects[0].material.sigma_s = [1e7; 3];
        assert!(world.validate().unwrap_err().to_string().contains("f32"));
    }
}
