//! A Mitsuba 3 scene (XML, meshes as binary PLY) of a camera, lights and objects, in millimetres.
//!
//! Everything here takes plain values — a camera, lights, objects each with its mesh, its surface
//! and its millimetres per unit — so that any scene description can be exported through it.
//!
//! What is written, and why:
//! - A translucent object is a shape with a smooth `dielectric` boundary (int_ior = η, ext_ior = 1)
//!   around a `homogeneous` medium: `sigma_t` = σa + σs per mm (Mitsuba wants RGB values in [0, 1],
//!   so it is written normalised, with its largest channel as `scale`), `albedo` = σs / σt, and an
//!   `hg` phase function with g (`isotropic` for g = 0). Mitsuba's `hg` has one g for all channels:
//!   a material whose g differs between channels is written with the similarity-reduced σ's =
//!   σs(1 − g) and g = 0 — what both diffusion models see — and a warning says so.
//! - An opaque object is `diffuse` with its reflectance.
//! - A directional light (irradiance E at normal incidence) becomes a far disk of angular radius δ
//!   emitting radiance E / (π sin²δ), which gives irradiance E at normal incidence: a delta
//!   `directional` emitter behind a smooth dielectric renders exactly black in Mitsuba's
//!   unidirectional integrators (no path from inside the medium can connect to it). δ = 5° by
//!   default. The disk lies beyond the camera's far clip, so the camera never sees it directly
//!   (translucent does not draw lights either).
//! - A point light of intensity I (per scene unit², E = I / d²; I × (mm per unit)² in mm) becomes
//!   a small sphere of radius ρ emitting radiance I / (πρ²): a sphere's intensity toward every
//!   direction is L πρ², and the irradiance it gives at distance d > ρ is I / d² exactly. A delta
//!   `point` emitter behind a smooth dielectric renders black as a directional one does (an
//!   export of the default bunny under a point light: its path-traced mean was exactly 0). ρ is
//!   D sin δ (D the light's distance from the objects' centre: the sphere is seen from there as
//!   the directional disks are), at most half its distance from the objects' bounding sphere.
//! - A spot light becomes Mitsuba's delta `spot` (no area emitter has its cone), which lights only
//!   opaque objects: a warning says so when there is a translucent one.
//! - The camera is a `perspective` sensor with the vertical field of view (`fov_axis` y, aspect
//!   width / height as the renderer's projection), a box reconstruction filter (a pixel is the mean
//!   over its area) and an RGBA film: alpha is coverage, as in translucent's EXR output.
//! - The integrator is `volpathmis` (spectral MIS: far less noisy than `volpath` when σt differs
//!   between channels) with unbounded depth (`max_depth` −1) and no Russian roulette (`rr_depth`
//!   [`NO_ROULETTE`]): with Mitsuba 3.9's roulette a thick slab of Marble (albedo 0.998–0.999 behind
//!   η = 1.3 or 1.5) rendered 9–10% darker than without it, which matches the half-space Monte Carlo
//!   and diffusion theory; Skin1 (0.68–0.96) was within the noise either way.
//! - `$spp`, `$seed`, `$max_depth`, `$rr_depth` and `$transmittance` are scene parameters:
//!   rendering with `transmittance` = 0 (the boundary's `specular_transmittance`) gives the
//!   boundary's reflection alone, and the full render minus that is the light that went through the
//!   medium — the subsurface term, what `render --no-specular` draws.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

use crate::error::Result;
use crate::mesh::Mesh;
use crate::{bad_input, runtime};

/// A pinhole camera in millimetres; `fov_y_deg` is the vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    pub fov_y_deg: f64,
}

/// Lights in millimetres: directions toward the light; irradiance in the renderer's units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Irradiance E per channel on a surface facing the light.
    Directional { toward: DVec3, irradiance: [f64; 3] },
    /// Radiant intensity per channel such that E = intensity / d², d in mm.
    Point { position: DVec3, intensity: [f64; 3] },
    /// A point light into a cone of half-angle `cone_deg` about `axis` (unit, from the light),
    /// falling off over its outer `delta_deg` (pbrt-v4's `spot`, see [`crate::scene::Light::Spot`]).
    Spot { position: DVec3, axis: DVec3, intensity: [f64; 3], cone_deg: f64, delta_deg: f64 },
}

/// A homogeneous medium, coefficients per mm.
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    pub sigma_a: [f64; 3],
    pub sigma_s: [f64; 3],
    pub g: [f64; 3],
    pub eta: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Surface {
    /// A smooth dielectric boundary of the medium's η around the medium.
    Translucent(Medium),
    /// The same around a `heterogeneous` medium: σt the medium's (similarity-reduced, g = 0),
    /// the single-scattering albedo per voxel of `albedo` (a textured material, [`albedo_grid`]).
    TexturedTranslucent { medium: Medium, albedo: AlbedoGrid },
    /// An opaque Lambertian surface.
    Diffuse { reflectance: [f64; 3] },
}

/// One object: its mesh in its own units, how many mm a unit is, and its surface.
#[derive(Clone, Debug)]
pub struct Object<'a> {
    pub name: String,
    pub mesh: &'a Mesh,
    pub mm_per_unit: f64,
    pub surface: Surface,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    pub width: u32,
    pub height: u32,
    /// Default samples per pixel (`$spp`).
    pub spp: u32,
    /// Angular radius of the disks that stand in for directional lights, degrees.
    pub light_radius_deg: f64,
    /// Default `$max_depth` (−1: unbounded).
    pub max_depth: i32,
    /// Default `$rr_depth` (`None`: [`NO_ROULETTE`]).
    pub rr_depth: Option<u32>,
}

impl Default for Options {
    fn default() -> Self {
        Options { width: 512, height: 512, spp: 256, light_radius_deg: 5.0, max_depth: -1, rr_depth: None }
    }
}

/// A single-scattering albedo per voxel over a box in mm (x fastest, then y, then z), written as
/// Mitsuba's `gridvolume` (.vol) for a textured material's medium (and, one voxel, its σt).
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoGrid {
    pub lo: DVec3,
    pub hi: DVec3,
    pub resolution: [u32; 3],
    pub albedo: Vec<[f32; 3]>,
}

/// The most voxels × triangles [`albedo_grid`] searches (its nearest-point search is exhaustive).
pub const ALBEDO_GRID_WORK: u64 = 4_000_000_000;

/// A textured translucent object's medium as a volume: each voxel of a grid over the mesh's box
/// (at most `max_side` voxels along its longest side, fewer where the mesh has many triangles)
/// takes the texture's reflectance at its nearest surface point's uv, inverted to the reduced
/// albedo α' with the material's mean free path (as the renderer's weight does: the classical
/// dipole's Rd), written similarity-reduced (g = 0, so σt = σ't is the same everywhere and only
/// the albedo varies). The texture lives on the surface; the volume extends it inward from the
/// nearest surface point, the one choice that is the same texture seen from outside.
pub fn albedo_grid(
    mesh: &Mesh,
    uvs: &[glam::Vec2],
    texture: &crate::world::Reflectance,
    medium: &Medium,
    mm_per_unit: f64,
    max_side: u32,
) -> Result<AlbedoGrid> {
    let triangles = mesh.indices.len() as u64 / 3;
    if uvs.len() != mesh.positions.len() || triangles == 0 {
        return Err(bad_input!("export: a textured object needs one uv per vertex and a triangle"));
    }
    let (lo, hi) = mesh.bounds();
    let (lo, hi) = (lo.as_dvec3(), hi.as_dvec3());
    let extent = (hi - lo).max(DVec3::splat(1e-9 * (hi - lo).max_element().max(1e-30)));
    let mut side = max_side.max(1);
    let res_of = |side: u32| extent.to_array().map(|e| ((e / extent.max_element() * side as f64).ceil() as u32).max(1));
    while side > 8 && res_of(side).iter().map(|&r| r as u64).product::<u64>() * triangles > ALBEDO_GRID_WORK {
        side = side * 3 / 4;
    }
    let resolution = res_of(side);
    if resolution.iter().map(|&r| r as u64).product::<u64>() * triangles > ALBEDO_GRID_WORK {
        return Err(bad_input!(
            "export: {triangles} triangles are too many to write the object's texture as a volume (a grid of at least 8 voxels a side)"
        ));
    }
    // α'(ρ) per channel by the classical dipole's Rd, on a table of α' (Rd rises monotonically).
    let inverse = [0, 1, 2].map(|c| {
        let m = crate::physics::Medium {
            sigma_a: medium.sigma_a[c],
            sigma_s: medium.sigma_s[c],
            g: medium.g[c],
            eta: medium.eta,
        };
        let a = m.constants(crate::physics::Diffusion::Classical).a_dipole;
        (0..=4096)
            .map(|k| (crate::physics::dipole::total_rd(k as f64 / 4096.0, a), k as f64 / 4096.0))
            .collect::<Vec<_>>()
    });
    let alpha_of = |c: usize, rho: f64| -> f64 {
        let t = &inverse[c];
        let k = t.partition_point(|&(rd, _)| rd < rho);
        match k {
            0 => 0.0,
            k if k >= t.len() => 1.0,
            k => {
                let ((r0, a0), (r1, a1)) = (t[k - 1], t[k]);
                a0 + (a1 - a0) * (rho - r0) / (r1 - r0).max(f64::MIN_POSITIVE)
            }
        }
    };
    let [nx, ny, nz] = resolution;
    let mut albedo = Vec::with_capacity((nx * ny * nz) as usize);
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let p = lo
                    + extent * DVec3::new(x as f64 + 0.5, y as f64 + 0.5, z as f64 + 0.5)
                        / DVec3::new(nx as f64, ny as f64, nz as f64);
                let uv = nearest_uv(mesh, uvs, p);
                let rho = texture.at(uv);
                albedo.push([0, 1, 2].map(|c| alpha_of(c, rho[c] as f64) as f32));
            }
        }
    }
    let mm = mm_per_unit;
    Ok(AlbedoGrid { lo: lo * mm, hi: (lo + extent) * mm, resolution, albedo })
}

/// The uv at the point of `mesh` nearest to `p` (every triangle tried).
fn nearest_uv(mesh: &Mesh, uvs: &[glam::Vec2], p: DVec3) -> glam::Vec2 {
    let mut best = (f64::MAX, glam::Vec2::ZERO);
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3());
        let (u, v, w) = closest_on_triangle(p, a, b, c);
        let q = a * u + b * v + c * w;
        let d = (q - p).length_squared();
        if d < best.0 {
            let uv = uvs[t[0] as usize] * u as f32 + uvs[t[1] as usize] * v as f32 + uvs[t[2] as usize] * w as f32;
            best = (d, uv);
        }
    }
    best.1
}

/// The barycentrics of the point of triangle abc nearest to p (Ericson, Real-Time Collision
/// Detection, 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (f64, f64, f64) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (1.0, 0.0, 0.0);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (0.0, 1.0, 0.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (1.0 - v, v, 0.0);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (0.0, 0.0, 1.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (1.0 - w, 0.0, w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (0.0, 1.0 - w, w);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    if !(v.is_finite() && w.is_finite()) {
        return (1.0, 0.0, 0.0); // a degenerate triangle: its first corner
    }
    (1.0 - v - w, v, w)
}

/// Mitsuba's `.vol` grid (format version 3, float32, `channels` per voxel, the box in mm).
fn write_vol(path: &Path, grid: &AlbedoGrid) -> Result<()> {
    let mut bytes = Vec::with_capacity(48 + grid.albedo.len() * 12);
    bytes.extend_from_slice(b"VOL\x03");
    bytes.extend_from_slice(&1i32.to_le_bytes());
    for r in grid.resolution {
        bytes.extend_from_slice(&(r as i32).to_le_bytes());
    }
    bytes.extend_from_slice(&3i32.to_le_bytes());
    for v in [grid.lo.x, grid.lo.y, grid.lo.z, grid.hi.x, grid.hi.y, grid.hi.z] {
        bytes.extend_from_slice(&(v as f32).to_le_bytes());
    }
    for a in &grid.albedo {
        for c in a {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    crate::output::write_file(path, &bytes)
}

/// What Mitsuba's `homogeneous` medium is given: σt normalised to [0, 1] with its largest channel
/// as the scale, the albedo, and one HG g (`None`: isotropic).
#[derive(Clone, Debug, PartialEq)]
pub struct Homogeneous {
    pub sigma_t: [f64; 3],
    pub scale: f64,
    pub albedo: [f64; 3],
    pub g: Option<f64>,
    /// Set when g differed between channels and the reduced σ's with g = 0 was written instead.
    pub warning: Option<String>,
}

/// The medium as Mitsuba takes it.
pub fn homogeneous(m: &Medium) -> Homogeneous {
    let same_g = m.g.iter().all(|&g| g == m.g[0]);
    let (sigma_s, g, warning) = if same_g {
        (m.sigma_s, m.g[0], None)
    } else {
        (
            std::array::from_fn(|c| m.sigma_s[c] * (1.0 - m.g[c])),
            0.0,
            Some(format!(
                "g = {:?} differs between channels and Mitsuba's hg has one g: the medium is written with σ's = σs(1 − g) = {:?} /mm and g = 0 (what both diffusion models see)",
                m.g,
                std::array::from_fn::<f64, 3, _>(|c| m.sigma_s[c] * (1.0 - m.g[c]))
            )),
        )
    };
    let sigma_t: [f64; 3] = std::array::from_fn(|c| m.sigma_a[c] + sigma_s[c]);
    let scale = sigma_t.iter().copied().fold(0.0, f64::max);
    Homogeneous {
        sigma_t: sigma_t.map(|v| if scale > 0.0 { v / scale } else { 0.0 }),
        scale,
        albedo: std::array::from_fn(|c| if sigma_t[c] > 0.0 { sigma_s[c] / sigma_t[c] } else { 0.0 }),
        g: (g != 0.0).then_some(g),
        warning,
    }
}

/// An `rr_depth` no path reaches: no Russian roulette. Measured on a thick slab of Marble's
/// coefficients behind η = 1.3 (`volpathmis`, `llvm_ad_rgb`, the object's mean): roulette from
/// depth 59 (where 0.999^n falls below Mitsuba's 0.95 cap) gave 0.261 / 0.252 / 0.244, none 0.286
/// / 0.277 / 0.265 (noise 0.3 / 3.3 / 5.6%), which the half-space Monte Carlo (`--model mc`)
/// matches within 0.5%. Paths then end only by leaving the medium: slower where the albedo is
/// near 1 (that slab: 25× the time).
pub const NO_ROULETTE: u32 = 1 << 30;

/// The radius (mm) of the sphere that stands in for a point light at `position` (mm): seen from
/// the objects' bounding sphere's centre at angular radius `radius_deg`, and at most half the
/// light's distance from that sphere (a thousandth of its radius when the light is inside it).
fn point_light_sphere(position: DVec3, (centre, radius): (DVec3, f64), radius_deg: f64) -> f64 {
    let d = position.distance(centre);
    let seen = d * radius_deg.to_radians().sin();
    if d > radius { seen.min(0.5 * (d - radius)) } else { seen.min(1e-3 * radius) }.max(1e-9 * radius)
}

/// The radiance of a disk of angular radius `radius_deg` that gives irradiance `e` at normal
/// incidence: E = π L sin²δ.
pub fn disk_radiance(e: f64, radius_deg: f64) -> f64 {
    e / (std::f64::consts::PI * radius_deg.to_radians().sin().powi(2))
}

/// Numbers as Mitsuba reads them: shortest round trip, exponent where long.
fn num(v: f64) -> String {
    format!("{v:?}")
}

fn triple(v: [f64; 3]) -> String {
    format!("{}, {}, {}", num(v[0]), num(v[1]), num(v[2]))
}

fn dv(v: DVec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// An up vector for `lookat` along `dir`: the world axis least aligned with it.
fn any_up(dir: DVec3) -> DVec3 {
    let a = dir.abs();
    if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    }
}

/// The files written.
#[derive(Clone, Debug, Default)]
pub struct Written {
    pub scene: PathBuf,
    pub meshes: Vec<PathBuf>,
    pub warnings: Vec<String>,
}

/// Writes `scene.xml` and one PLY per object (in mm) into `dir`, which must exist; an
/// environment becomes Mitsuba's `constant` emitter, or an `envmap` of `environment.exr` (a
/// latitude-longitude map in Mitsuba's convention, resampled from ours with its scale applied).
pub fn write_scene(
    dir: &Path,
    camera: &Camera,
    (lights, environment): (&[Light], Option<&crate::environment::Environment>),
    objects: &[Object],
    options: &Options,
) -> Result<Written> {
    if objects.is_empty() {
        return Err(bad_input!("export: nothing to export (no objects)"));
    }
    if !(options.light_radius_deg > 0.0 && options.light_radius_deg < 90.0) {
        return Err(bad_input!("--light-radius {}: must be within (0, 90) degrees", options.light_radius_deg));
    }
    let mut written = Written::default();
    // The objects' bounds in mm: where the disks and the clip planes go.
    let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
    for o in objects {
        for p in &o.mesh.positions {
            let p = p.as_dvec3() * o.mm_per_unit;
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-30);
    let distance = (camera.eye - centre).length();
    let far_clip = 2.0 * (distance + radius);
    let near_clip = ((distance - 1.5 * radius) * 0.5).max(far_clip * 1e-6);
    let disk_distance = 1000.0 * (distance + radius);

    let rr_depth = options.rr_depth.unwrap_or(NO_ROULETTE);
    let mut x = String::new();
    let w = &mut x;
    let _ = writeln!(w, "<?xml version=\"1.0\" encoding=\"utf-8\"?>");
    let _ = writeln!(
        w,
        "<!-- Written by translucent {} (export mitsuba). Lengths in mm. Directional lights are far disks of angular radius {}° (a delta light behind a smooth dielectric is black in unidirectional integrators). Render with transmittance=0 for the boundary's reflection alone; the full render minus it is the subsurface term. -->",
        env!("CARGO_PKG_VERSION"),
        num(options.light_radius_deg)
    );
    let _ = writeln!(w, "<scene version=\"3.0.0\">");
    for (name, value) in [
        ("spp", options.spp.to_string()),
        ("seed", "0".to_string()),
        ("max_depth", options.max_depth.to_string()),
        ("rr_depth", rr_depth.to_string()),
        ("transmittance", "1".to_string()),
    ] {
        let _ = writeln!(w, "    <default name=\"{name}\" value=\"{value}\"/>");
    }
    let _ = writeln!(w, "    <integrator type=\"volpathmis\">");
    let _ = writeln!(w, "        <integer name=\"max_depth\" value=\"$max_depth\"/>");
    let _ = writeln!(w, "        <integer name=\"rr_depth\" value=\"$rr_depth\"/>");
    let _ = writeln!(w, "    </integrator>");
    let _ = writeln!(w, "    <sensor type=\"perspective\">");
    let _ = writeln!(w, "        <string name=\"fov_axis\" value=\"y\"/>");
    let _ = writeln!(w, "        <float name=\"fov\" value=\"{}\"/>", num(camera.fov_y_deg));
    let _ = writeln!(w, "        <float name=\"near_clip\" value=\"{}\"/>", num(near_clip));
    let _ = writeln!(w, "        <float name=\"far_clip\" value=\"{}\"/>", num(far_clip));
    let _ = writeln!(w, "        <transform name=\"to_world\">");
    let _ = writeln!(
        w,
        "            <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/>",
        triple(dv(camera.eye)),
        triple(dv(camera.target)),
        triple(dv(camera.up))
    );
    let _ = writeln!(w, "        </transform>");
    let _ = writeln!(w, "        <sampler type=\"independent\">");
    let _ = writeln!(w, "            <integer name=\"sample_count\" value=\"$spp\"/>");
    let _ = writeln!(w, "            <integer name=\"seed\" value=\"$seed\"/>");
    let _ = writeln!(w, "        </sampler>");
    let _ = writeln!(w, "        <film type=\"hdrfilm\">");
    let _ = writeln!(w, "            <integer name=\"width\" value=\"{}\"/>", options.width);
    let _ = writeln!(w, "            <integer name=\"height\" value=\"{}\"/>", options.height);
    let _ = writeln!(w, "            <string name=\"pixel_format\" value=\"rgba\"/>");
    let _ = writeln!(w, "            <rfilter type=\"box\"/>");
    let _ = writeln!(w, "        </film>");
    let _ = writeln!(w, "    </sensor>");

    for (i, o) in objects.iter().enumerate() {
        let ply = format!("object{i}.ply");
        let path = dir.join(&ply);
        write_ply(&path, o.mesh, o.mm_per_unit)?;
        written.meshes.push(path);
        let _ = writeln!(w, "    <!-- {} -->", xml_comment(&o.name));
        // A translucent object's medium, and its albedo grid when it is textured.
        let translucent = match &o.surface {
            Surface::Translucent(m) => Ok((m, None)),
            Surface::TexturedTranslucent { medium, albedo } => Ok((medium, Some(albedo))),
            Surface::Diffuse { reflectance } => Err(reflectance),
        };
        match translucent {
            Ok((m, grid)) => {
                let mut h = homogeneous(m);
                if let Some(warning) = &h.warning {
                    written.warnings.push(format!("{}: {warning}", o.name));
                }
                if let Some(grid) = grid {
                    // Similarity-reduced, so that σt is the same in every voxel.
                    let reduced: [f64; 3] = std::array::from_fn(|c| m.sigma_a[c] + m.sigma_s[c] * (1.0 - m.g[c]));
                    let scale = reduced.iter().cloned().fold(0.0, f64::max).max(f64::MIN_POSITIVE);
                    (h.sigma_t, h.scale, h.g) = (reduced.map(|v| v / scale), scale, None);
                    // σt as a grid of one voxel over the same box: Mitsuba 3.9's heterogeneous
                    // medium takes its extent from σt's volume, and a constant one has none (the
                    // medium rendered black).
                    let sigma_t =
                        AlbedoGrid { resolution: [1, 1, 1], albedo: vec![h.sigma_t.map(|v| v as f32)], ..grid.clone() };
                    let _ = writeln!(w, "    <medium type=\"heterogeneous\" id=\"medium{i}\">");
                    let _ = writeln!(w, "        <float name=\"scale\" value=\"{}\"/>", num(h.scale));
                    for (name, volume) in [("sigma_t", &sigma_t), ("albedo", grid)] {
                        let vol = format!("object{i}-{name}.vol");
                        write_vol(&dir.join(&vol), volume)?;
                        written.meshes.push(dir.join(&vol));
                        let _ = writeln!(w, "        <volume name=\"{name}\" type=\"gridvolume\">");
                        let _ = writeln!(w, "            <string name=\"filename\" value=\"{vol}\"/>");
                        let _ = writeln!(w, "            <transform name=\"to_world\">");
                        let _ = writeln!(w, "                <scale value=\"{}\"/>", triple(dv(grid.hi - grid.lo)));
                        let _ = writeln!(w, "                <translate value=\"{}\"/>", triple(dv(grid.lo)));
                        let _ = writeln!(w, "            </transform>");
                        let _ = writeln!(w, "        </volume>");
                    }
                } else {
                    let _ = writeln!(w, "    <medium type=\"homogeneous\" id=\"medium{i}\">");
                    let _ = writeln!(w, "        <rgb name=\"sigma_t\" value=\"{}\"/>", triple(h.sigma_t));
                    let _ = writeln!(w, "        <float name=\"scale\" value=\"{}\"/>", num(h.scale));
                    let _ = writeln!(w, "        <rgb name=\"albedo\" value=\"{}\"/>", triple(h.albedo));
                }
                match h.g {
                    Some(g) => {
                        let _ =
                            writeln!(w, "        <phase type=\"hg\"><float name=\"g\" value=\"{}\"/></phase>", num(g));
                    }
                    None => {
                        let _ = writeln!(w, "        <phase type=\"isotropic\"/>");
                    }
                }
                let _ = writeln!(w, "    </medium>");
                let _ = writeln!(w, "    <bsdf type=\"dielectric\" id=\"bsdf{i}\">");
                let _ = writeln!(w, "        <float name=\"int_ior\" value=\"{}\"/>", num(m.eta));
                let _ = writeln!(w, "        <float name=\"ext_ior\" value=\"1.0\"/>");
                let _ = writeln!(w, "        <float name=\"specular_transmittance\" value=\"$transmittance\"/>");
                let _ = writeln!(w, "    </bsdf>");
                let _ = writeln!(w, "    <shape type=\"ply\" id=\"object{i}\">");
                let _ = writeln!(w, "        <string name=\"filename\" value=\"{ply}\"/>");
                let _ = writeln!(w, "        <ref id=\"bsdf{i}\"/>");
                let _ = writeln!(w, "        <ref name=\"interior\" id=\"medium{i}\"/>");
                let _ = writeln!(w, "    </shape>");
            }
            Err(reflectance) => {
                let _ = writeln!(w, "    <shape type=\"ply\" id=\"object{i}\">");
                let _ = writeln!(w, "        <string name=\"filename\" value=\"{ply}\"/>");
                let _ = writeln!(
                    w,
                    "        <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"{}\"/></bsdf>",
                    triple(*reflectance)
                );
                let _ = writeln!(w, "    </shape>");
            }
        }
    }

    for (i, light) in lights.iter().enumerate() {
        match *light {
            Light::Directional { toward, irradiance } => {
                let toward = toward.normalize();
                let origin = centre + toward * disk_distance;
                let disk_radius = disk_distance * options.light_radius_deg.to_radians().tan();
                let radiance = irradiance.map(|e| disk_radiance(e, options.light_radius_deg));
                let _ = writeln!(
                    w,
                    "    <!-- light {i}: directional, irradiance {} at normal incidence: a disk of angular radius {}° at {} mm -->",
                    triple(irradiance),
                    num(options.light_radius_deg),
                    num(disk_distance)
                );
                let _ = writeln!(w, "    <shape type=\"disk\" id=\"light{i}\">");
                let _ = writeln!(w, "        <transform name=\"to_world\">");
                let _ = writeln!(w, "            <scale value=\"{}\"/>", num(disk_radius));
                let _ = writeln!(
                    w,
                    "            <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/>",
                    triple(dv(origin)),
                    triple(dv(centre)),
                    triple(dv(any_up(toward)))
                );
                let _ = writeln!(w, "        </transform>");
                let _ = writeln!(
                    w,
                    "        <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                    triple(radiance)
                );
                let _ = writeln!(w, "    </shape>");
            }
            Light::Point { position, intensity } => {
                let sphere = point_light_sphere(position, (centre, radius), options.light_radius_deg);
                if position.distance(centre) <= radius {
                    written.warnings.push(format!(
                        "light {i}: point: it lies within the objects' bounds; its sphere (radius {} mm) may meet them",
                        num(sphere)
                    ));
                }
                let radiance = intensity.map(|v| v / (std::f64::consts::PI * sphere * sphere));
                let _ = writeln!(
                    w,
                    "    <!-- light {i}: point, intensity {}: a sphere of radius {} mm emitting I/(pi r^2) -->",
                    triple(intensity),
                    num(sphere)
                );
                let _ = writeln!(w, "    <shape type=\"sphere\" id=\"light{i}\">");
                let _ = writeln!(
                    w,
                    "        <point name=\"center\" x=\"{}\" y=\"{}\" z=\"{}\"/>",
                    num(position.x),
                    num(position.y),
                    num(position.z)
                );
                let _ = writeln!(w, "        <float name=\"radius\" value=\"{}\"/>", num(sphere));
                let _ = writeln!(
                    w,
                    "        <emitter type=\"area\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                    triple(radiance)
                );
                let _ = writeln!(w, "    </shape>");
            }
            Light::Spot { position, axis, intensity, cone_deg, delta_deg } => {
                // Mitsuba 3's `spot` (src/emitters/spot.cpp) ramps linearly in the angle from
                // beam_width out to cutoff_angle; pbrt-v4's and translucent's is a smoothstep in
                // cos θ over the same rim: equal inside the beam and beyond the cone, not between.
                let _ = writeln!(
                    w,
                    "    <!-- light {i}: spot, cone {}°, falloff over its outer {}° (Mitsuba's ramp is linear in the angle there, translucent's a smoothstep in cos θ) -->",
                    num(cone_deg),
                    num(delta_deg)
                );
                let _ = writeln!(w, "    <emitter type=\"spot\" id=\"light{i}\">");
                let _ = writeln!(w, "        <transform name=\"to_world\">");
                let _ = writeln!(
                    w,
                    "            <lookat origin=\"{}\" target=\"{}\" up=\"{}\"/>",
                    triple(dv(position)),
                    triple(dv(position + axis)),
                    triple(dv(any_up(axis)))
                );
                let _ = writeln!(w, "        </transform>");
                let _ = writeln!(w, "        <rgb name=\"intensity\" value=\"{}\"/>", triple(intensity));
                let _ = writeln!(w, "        <float name=\"cutoff_angle\" value=\"{}\"/>", num(cone_deg));
                let _ = writeln!(w, "        <float name=\"beam_width\" value=\"{}\"/>", num(cone_deg - delta_deg));
                let _ = writeln!(w, "    </emitter>");
                if objects.iter().any(|o| !matches!(o.surface, Surface::Diffuse { .. })) {
                    written.warnings.push(format!(
                        "light {i}: spot: Mitsuba's delta `spot` behind a smooth dielectric lights no translucent object (no path from inside the medium can connect to it): only opaque objects see it; compare translucent ones under point or directional lights"
                    ));
                }
                if delta_deg > 0.0 {
                    written.warnings.push(format!(
                        "light {i}: spot: Mitsuba's falloff over the outer {}° of its {}° cone is linear in the angle, translucent's (pbrt-v4's) a smoothstep in cos θ: the images differ on that rim",
                        num(delta_deg),
                        num(cone_deg)
                    ));
                }
            }
        }
    }
    if let Some(env) = environment {
        use crate::environment::{uv_to_direction, Layout, Radiance};
        match &env.radiance {
            Radiance::Constant(l) => {
                let _ = writeln!(w, "    <!-- the environment: constant radiance -->");
                let _ = writeln!(
                    w,
                    "    <emitter type=\"constant\"><rgb name=\"radiance\" value=\"{}\"/></emitter>",
                    triple((*l * env.scale).as_dvec3().to_array())
                );
            }
            Radiance::Image { height, .. } => {
                // Mitsuba reads latitude-longitude maps only: resampled at each of its texels'
                // centres (the nearest texel of ours, as render reads it), the scale applied.
                let h = *height;
                let img = image::Rgb32FImage::from_fn(2 * h, h, |x, y| {
                    let d = uv_to_direction(
                        Layout::LatLong,
                        (x as f64 + 0.5) / (2 * h) as f64,
                        (y as f64 + 0.5) / h as f64,
                    );
                    image::Rgb(env.radiance_toward(d.as_vec3()).to_array())
                });
                let path = dir.join("environment.exr");
                image::DynamicImage::ImageRgb32F(img).save(&path).map_err(|e| runtime!("{}: {e}", path.display()))?;
                let _ =
                    writeln!(w, "    <!-- the environment: {}, resampled to {}x{h} -->", xml_comment(&env.name), 2 * h);
                let _ = writeln!(
                    w,
                    "    <emitter type=\"envmap\"><string name=\"filename\" value=\"environment.exr\"/></emitter>"
                );
            }
        }
    }
    let _ = writeln!(w, "</scene>");
    if x.contains("NaN") || x.contains("inf") {
        return Err(runtime!("export: a non-finite number would be written to the scene"));
    }
    let scene = dir.join("scene.xml");
    crate::output::write_file(&scene, x.as_bytes())?;
    written.scene = scene;
    Ok(written)
}

fn xml_comment(s: &str) -> String {
    s.replace("--", "- -")
}

/// A binary little-endian PLY of the mesh scaled to mm: float x y z nx ny nz, int triangles.
pub fn write_ply(path: &Path, mesh: &Mesh, mm_per_unit: f64) -> Result<()> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian 1.0\ncomment translucent export mitsuba: millimetres\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.indices.len() / 3
    )
    .into_bytes();
    for (i, p) in mesh.positions.iter().enumerate() {
        let q = (p.as_dvec3() * mm_per_unit).as_vec3();
        let n = mesh.normals.get(i).copied().unwrap_or(Vec3::Y);
        for v in [q.x, q.y, q.z, n.x, n.y, n.z] {
            if !v.is_finite() {
                return Err(runtime!("{}: vertex {i} is not finite in mm", path.display()));
            }
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    for t in mesh.indices.chunks_exact(3) {
        bytes.push(3);
        for &i in t {
            bytes.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    crate::output::write_file(path, &bytes)
}

/// Reads back a PLY as [`write_ply`] writes it: positions, normals, triangle indices (for tests
/// and checks of exported scenes).
pub fn read_ply(path: &Path) -> Result<Mesh> {
    let bytes = std::fs::read(path).map_err(|e| bad_input!("{}: cannot be read: {e}", path.display()))?;
    let end = b"end_header\n";
    let header_len = bytes
        .windows(end.len())
        .position(|w| w == end)
        .ok_or_else(|| bad_input!("{}: no PLY header", path.display()))?
        + end.len();
    let header =
        std::str::from_utf8(&bytes[..header_len]).map_err(|_| bad_input!("{}: header is not text", path.display()))?;
    if !header.contains("format binary_little_endian 1.0") {
        return Err(bad_input!("{}: not a binary little-endian PLY", path.display()));
    }
    let count = |element: &str| -> Result<usize> {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {element} ")))
            .and_then(|n| n.trim().parse().ok())
            .ok_or_else(|| bad_input!("{}: no element {element}", path.display()))
    };
    let (nv, nf) = (count("vertex")?, count("face")?);
    let body = &bytes[header_len..];
    if body.len() != nv * 24 + nf * 13 {
        return Err(bad_input!(
            "{}: {} bytes of data for {nv} vertices and {nf} triangles",
            path.display(),
            body.len()
        ));
    }
    let f = |o: usize| f32::from_le_bytes([body[o], body[o + 1], body[o + 2], body[o + 3]]);
    let mut mesh = Mesh { positions: Vec::with_capacity(nv), normals: Vec::with_capacity(nv), indices: Vec::new() };
    for v in 0..nv {
        let o = v * 24;
        mesh.positions.push(Vec3::new(f(o), f(o + 4), f(o + 8)));
        mesh.normals.push(Vec3::new(f(o + 12), f(o + 16), f(o + 20)));
    }
    for t in 0..nf {
        let o = nv * 24 + t * 13;
        if body[o] != 3 {
            return Err(bad_input!("{}: face {t} is not a triangle", path.display()));
        }
        for k in 0..3 {
            let p = o + 1 + 4 * k;
            mesh.indices.push(i32::from_le_bytes([body[p], body[p + 1], body[p + 2], body[p + 3]]) as u32);
        }
    }
    Ok(mesh)
}
