//! The Jensen–Buhler hierarchy, rebuilt on the GPU every frame: sample points over the mesh,
//! their irradiance (shadow maps + Fresnel), Morton sort, and a tree whose nodes summarise them.
//!
//! Why a Karras binary radix tree and not an octree: it is built from the sorted keys alone with
//! one thread per node and no atomics (octree builds need per-level passes and compaction), every
//! node has exactly two children (no empty nodes to skip), and each node's points are one
//! contiguous range of the sorted array. Leaves are single points; the shading pass can stop
//! descending at small ranges and loop over the points directly.

use glam::{DVec3, Vec3};

use crate::error::Result;
use crate::gpu::{NodeFlux, PointFlux, PointLight, SurfacePoint, TreeNode, LEAF_BIT, RADIX_TILE as TILE};
use crate::materials::Material;
use crate::mesh::Mesh;
use crate::passes::sampling::prefix_bytes;
use crate::passes::sort::SortBuffers;
use crate::passes::tree::TreeBuffers;
use crate::physics::Diffusion;
use crate::scene::Light;
use crate::shadows::Shadows;
use crate::vk::{self, Buffer, BufferUsageFlags, Context, MemoryLocation};
use crate::{bad_input, runtime};

impl TreeNode {
    /// The bounding box (min, max) from its half floats.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let h = |bits: u32| half_to_f32(bits as u16);
        let b = self.box_half;
        (
            Vec3::new(h(b[0] & 0xffff), h(b[0] >> 16), h(b[1] & 0xffff)),
            Vec3::new(h(b[1] >> 16), h(b[2] & 0xffff), h(b[2] >> 16)),
        )
    }
    pub fn normal(&self) -> Vec3 {
        decode_oct(self.normal_oct)
    }
    pub fn light_dir(&self) -> Vec3 {
        if self.light_oct == 0 {
            Vec3::ZERO
        } else {
            decode_oct(self.light_oct)
        }
    }
}

/// IEEE half to f32.
pub fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = ((h >> 10) & 0x1f) as i32;
    let mantissa = (h & 0x3ff) as f32;
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 => f32::INFINITY,
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

/// Octahedral decoding of 2×16-bit snorm (as GLSL's unpackSnorm2x16).
pub fn decode_oct(e: u32) -> Vec3 {
    let s = |v: u16| (v as i16 as f32 / 32767.0).clamp(-1.0, 1.0);
    let (x, y) = (s(e as u16), s((e >> 16) as u16));
    let mut n = Vec3::new(x, y, 1.0 - x.abs() - y.abs());
    if n.z < 0.0 {
        let (ox, oy) = (n.x, n.y);
        n.x = (1.0 - oy.abs()) * if ox >= 0.0 { 1.0 } else { -1.0 };
        n.y = (1.0 - ox.abs()) * if oy >= 0.0 { 1.0 } else { -1.0 };
    }
    n.normalize()
}

/// Bytes on the GPU per sample point: the point twice (unsorted, sorted), two keys, two values,
/// a point parent and about one node (with its parent and arrival counter), the merged light
/// record twice (unsorted, sorted) and about one node's; and, for brute force only, per light
/// the point's own record twice.
const BYTES_PER_POINT: u64 = 64 * 2
    + 8 * 2
    + 4 * 2
    + 4
    + 64
    + 4
    + 4
    + 4
    + 2 * POINT_FLUX_BYTES
    + std::mem::size_of::<NodeFlux>() as u64
    + 2 * POINT_SPREAD_BYTES;
const POINT_SPREAD_BYTES: u64 = 32;
const BYTES_PER_POINT_AND_LIGHT: u64 = 16 * 2;
const POINT_FLUX_BYTES: u64 = std::mem::size_of::<PointFlux>() as u64;

/// The largest sample count the device can hold with `per_light_count` lights that keep their
/// own records (brute force; 0 else): each buffer within `maxStorageBufferRange`.
pub fn max_points(ctx: &Context, per_light_count: u32) -> u32 {
    // Storage buffers, and the shade pass's texel views of them (16-byte texels).
    let range = (ctx.limits().max_storage_buffer_range as u64).min(ctx.limits().max_texel_buffer_elements as u64 * 16);
    // The largest per-point buffers are the points, nodes and node records (64 bytes per
    // element) and, for brute force, the per-light records (16 bytes per light); the radix
    // count table is about 4 bytes per key. The walk's stack entries hold a point or node index
    // in 24 bits (shaders/shade.frag).
    let per_light = range / (16 * per_light_count.max(1) as u64);
    (range / 64).min(per_light).min(1 << 24) as u32
}

/// Checks a requested sample count against the device, for `per_light_count` lights with their
/// own records (brute force; 0 else).
pub fn check_point_count(ctx: &Context, n: u32, per_light_count: u32) -> Result<()> {
    let max = max_points(ctx, per_light_count);
    if n < 2 {
        return Err(bad_input!("--samples {n}: at least 2 sample points are needed"));
    }
    if n > max {
        let records = if per_light_count > 0 {
            format!(", brute force with {per_light_count} light(s): 16 per point and light")
        } else {
            String::new()
        };
        return Err(bad_input!(
            "--samples {n}: more than this device can hold ({max}: {} MiB per storage buffer, 64 bytes per point and node{records})",
            ctx.limits().max_storage_buffer_range >> 20
        ));
    }
    Ok(())
}

/// Memory the hierarchy uses on the GPU for `n` points, with `per_light_count` lights keeping
/// their own records (brute force; 0 else), in bytes.
pub fn bytes_used(n: u32, per_light_count: u32) -> u64 {
    n as u64 * (BYTES_PER_POINT + per_light_count as u64 * BYTES_PER_POINT_AND_LIGHT)
}

/// The hierarchy's buffers and images, and their sizes; the passes that fill them every frame are
/// the renderer's (`HierarchyPasses` in src/frame.rs, which lists them in order).
pub struct Hierarchy {
    pub(crate) prefix: Buffer,
    pub(crate) points: Buffer,
    keys: [Buffer; 2],
    values: [Buffer; 2],
    counts: Buffer,
    pub sorted_points: Buffer,
    pub nodes: Buffer,
    /// Each light's own record of each point, [point · per_light_count + light], unsorted then
    /// sorted: for brute force only (a single element else).
    pub(crate) point_lights: Buffer,
    pub sorted_point_lights: Buffer,
    /// Every light's merged record of each point, unsorted then sorted.
    pub(crate) point_flux: Buffer,
    pub sorted_point_flux: Buffer,
    /// Every light's merged record of each node.
    pub node_flux: Buffer,
    /// How the lights' directions spread at each point (PointSpread), unsorted then sorted.
    pub(crate) point_spread: Buffer,
    pub sorted_point_spread: Buffer,
    pub node_parent: Buffer,
    pub point_parent: Buffer,
    pub arrivals: Buffer,
    /// The lights and the shadow maps fitted to this object (the irradiance pass reads them).
    pub shadows: Shadows,
    pub point_count: u32,
    /// Lights the shadow maps were made for (at creation; later light sets must match).
    pub light_count: u32,
    /// Lights with their own records (brute force): `light_count`, or 0.
    pub per_light_count: u32,
    pub(crate) triangle_count: u32,
    pub(crate) index_count: u32,
    bounds: (Vec3, Vec3),
    pub seed: u32,
}

pub struct HierarchyOptions {
    pub point_count: u32,
    pub shadow_resolution: u32,
    pub eta: f32,
    /// Keep each light's own record of each point too, for brute force's exact sum.
    pub per_light_records: bool,
}

impl Hierarchy {
    pub fn new(ctx: &Context, mesh: &Mesh, lights: &[Light], options: &HierarchyOptions) -> Result<Hierarchy> {
        let n = options.point_count;
        if lights.is_empty() {
            return Err(bad_input!("--light: at least one light is needed"));
        }
        let light_count = lights.len() as u32;
        let per_light_count = if options.per_light_records { light_count } else { 0 };
        check_point_count(ctx, n, per_light_count)?;
        let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC | BufferUsageFlags::TRANSFER_DST;
        let storage = |name: &str, bytes: u64| Buffer::new(ctx, name, bytes, usage, MemoryLocation::GpuOnly);
        // What the shade pass reads is also read as texels (see shaders/include/points.glsl).
        let texels = |name: &str, bytes: u64| {
            Buffer::new(ctx, name, bytes, usage | BufferUsageFlags::UNIFORM_TEXEL_BUFFER, MemoryLocation::GpuOnly)
        };
        let n64 = n as u64;
        let tiles = n.div_ceil(TILE) as u64;
        let res = options.shadow_resolution;
        let (lo, hi) = mesh.bounds();
        let pad = (hi - lo).max_element() * 1e-3;
        let mut h = Hierarchy {
            prefix: storage("triangle area prefix sum", prefix_bytes(mesh.triangle_count() as u32))?,
            points: storage("points", n64 * 64)?,
            keys: [storage("morton keys A", n64 * 8)?, storage("morton keys B", n64 * 8)?],
            values: [storage("sort order A", n64 * 4)?, storage("sort order B", n64 * 4)?],
            counts: storage("radix counts", tiles * 256 * 4)?,
            sorted_points: texels("sorted points", n64 * 64)?,
            nodes: texels("tree nodes", (n64 - 1) * 64)?,
            point_lights: storage("point light records", (n64 * per_light_count as u64).max(1) * 16)?,
            sorted_point_lights: texels("sorted point light records", (n64 * per_light_count as u64).max(1) * 16)?,
            point_flux: storage("point flux records", n64 * POINT_FLUX_BYTES)?,
            sorted_point_flux: texels("sorted point flux records", n64 * POINT_FLUX_BYTES)?,
            node_flux: texels("node flux records", (n64 - 1) * std::mem::size_of::<NodeFlux>() as u64)?,
            point_spread: storage("point spread records", n64 * POINT_SPREAD_BYTES)?,
            sorted_point_spread: texels("sorted point spread records", n64 * POINT_SPREAD_BYTES)?,
            node_parent: storage("node parents", (n64 - 1) * 4)?,
            point_parent: storage("point parents", n64 * 4)?,
            arrivals: storage("node arrival counters", (n64 - 1) * 4)?,
            shadows: Shadows::new(ctx, lights, res, options.eta)?,
            point_count: n,
            light_count,
            per_light_count,
            triangle_count: mesh.triangle_count() as u32,
            index_count: mesh.indices.len() as u32,
            bounds: (lo - Vec3::splat(pad), hi + Vec3::splat(pad)),
            seed: 0x9e37_79b9,
        };
        h.set_lights(mesh, lights)?;
        Ok(h)
    }

    /// Writes the lights and their shadow matrices (call when lights change, e.g. every frame).
    /// The number of shadow-map layers each light needs must stay what it was at creation.
    pub fn set_lights(&mut self, mesh: &Mesh, lights: &[Light]) -> Result<()> {
        if lights.len() != self.light_count as usize {
            return Err(runtime!("{} lights given, the hierarchy was made for {}", lights.len(), self.light_count));
        }
        for light in lights {
            if let Some(position) = light.position() {
                if mesh.contains_point(position) {
                    let kind = if matches!(light, Light::Spot { .. }) { "spot" } else { "point" };
                    return Err(bad_input!("{kind} light at {position} is inside the mesh: it would light nothing"));
                }
            }
        }
        let (centre, radius) = crate::scene::bounding_sphere(&mesh.positions);
        self.shadows.set_lights(centre, radius, lights)
    }

    /// The box of the world's other objects (`None`: this one is alone), whose shadows the maps
    /// must see; takes effect with the next `set_lights`.
    pub fn set_casters(&mut self, casters: Option<(Vec3, Vec3)>) {
        self.shadows.set_casters(casters);
    }

    pub fn casters(&self) -> Option<(Vec3, Vec3)> {
        self.shadows.casters()
    }

    /// What the Morton and radix sort stages read and write.
    pub(crate) fn sort_buffers(&self) -> SortBuffers<'_> {
        SortBuffers {
            points: &self.points,
            keys: [&self.keys[0], &self.keys[1]],
            values: [&self.values[0], &self.values[1]],
            counts: &self.counts,
            sorted_points: &self.sorted_points,
            point_lights: &self.point_lights,
            sorted_point_lights: &self.sorted_point_lights,
            per_light_count: self.per_light_count,
            point_flux: &self.point_flux,
            sorted_point_flux: &self.sorted_point_flux,
            point_spread: &self.point_spread,
            sorted_point_spread: &self.sorted_point_spread,
        }
    }

    /// What the tree build and summary stages read and write.
    pub(crate) fn tree_buffers(&self) -> TreeBuffers<'_> {
        TreeBuffers {
            keys: &self.keys[0],
            sorted_points: &self.sorted_points,
            nodes: &self.nodes,
            node_parent: &self.node_parent,
            point_parent: &self.point_parent,
            arrivals: &self.arrivals,
            sorted_point_flux: &self.sorted_point_flux,
            node_flux: &self.node_flux,
        }
    }

    /// Unsorted points, sorted keys, sort order, sorted points and nodes, for tests and tools.
    pub fn download(&self, ctx: &Context) -> Result<Snapshot> {
        let n = self.point_count as usize;
        Ok(Snapshot {
            points: vk::download_buffer(ctx, &self.points, n)?,
            keys: vk::download_buffer(ctx, &self.keys[0], n)?,
            order: vk::download_buffer(ctx, &self.values[0], n)?,
            sorted_points: vk::download_buffer(ctx, &self.sorted_points, n)?,
            nodes: vk::download_buffer(ctx, &self.nodes, n - 1)?,
            sorted_point_lights: vk::download_buffer(
                ctx,
                &self.sorted_point_lights,
                n * self.per_light_count as usize,
            )?,
            sorted_point_flux: vk::download_buffer(ctx, &self.sorted_point_flux, n)?,
            node_flux: vk::download_buffer(ctx, &self.node_flux, n - 1)?,
        })
    }

    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.bounds
    }

    pub fn eta(&self) -> f32 {
        self.shadows.eta()
    }

    /// The relative index of refraction used for the light entering the surface (a material
    /// change); written into the light set at once.
    pub fn set_eta(&mut self, eta: f32) -> Result<()> {
        self.shadows.set_eta(eta)
    }

    /// Follows a mesh that changed (deformed, or the next of a sequence): its triangle count,
    /// its bounds (the Morton codes' box) and the lights' shadow matrices. The point count stays.
    pub fn set_mesh(&mut self, ctx: &Context, mesh: &Mesh, lights: &[Light]) -> Result<()> {
        let triangles = mesh.triangle_count() as u32;
        if triangles != self.triangle_count {
            // The same size as `new` makes (it once allocated a quarter of it: frames after a
            // change of topology sampled garbage).
            self.prefix = Buffer::new(
                ctx,
                "triangle area prefix sum",
                prefix_bytes(triangles),
                BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC | BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )?;
            self.triangle_count = triangles;
        }
        self.index_count = mesh.indices.len() as u32;
        let (lo, hi) = mesh.bounds();
        let pad = (hi - lo).max_element() * 1e-3;
        self.bounds = (lo - Vec3::splat(pad), hi + Vec3::splat(pad));
        self.set_lights(mesh, lights)
    }
}

pub struct Snapshot {
    pub points: Vec<SurfacePoint>,
    pub keys: Vec<[u32; 2]>,
    pub order: Vec<u32>,
    pub sorted_points: Vec<SurfacePoint>,
    pub nodes: Vec<TreeNode>,
    /// [point · per_light_count + light], sorted order (brute force only; empty else).
    pub sorted_point_lights: Vec<PointLight>,
    /// Sorted order.
    pub sorted_point_flux: Vec<PointFlux>,
    pub node_flux: Vec<NodeFlux>,
}

/// A node built on the CPU in f64, for checking the GPU's.
#[derive(Clone, Debug)]
pub struct ReferenceNode {
    pub left: u32,
    pub right: u32,
    pub first_point: u32,
    pub point_count: u32,
    pub power: DVec3,
    pub area: f64,
    /// Area-weighted mean position.
    pub center: DVec3,
    pub normal: DVec3,
    /// |Σ child normal × weight| / Σ weight (power's luminance where lit, else area, as the
    /// normal): near 0 where the normals cancel (the direction is noise).
    pub normal_coherence: f64,
    pub light_dir: DVec3,
    pub light_coherence: f64,
    pub lo: DVec3,
    pub hi: DVec3,
}

/// The same Karras tree built serially from the sorted keys, with f64 summaries.
pub fn reference_tree(keys: &[[u32; 2]], points: &[SurfacePoint]) -> Vec<ReferenceNode> {
    let n = keys.len() as i64;
    let key = |i: i64| ((keys[i as usize][1] as u64) << 32) | keys[i as usize][0] as u64;
    let delta = |i: i64, j: i64| -> i64 {
        if j < 0 || j >= n {
            return -1;
        }
        let (a, b) = (key(i), key(j));
        if a == b {
            64 + ((i as u32) ^ (j as u32)).leading_zeros() as i64
        } else {
            (a ^ b).leading_zeros() as i64
        }
    };
    let mut nodes: Vec<ReferenceNode> = (0..n - 1)
        .map(|i| {
            let d = if delta(i, i + 1) - delta(i, i - 1) >= 0 { 1 } else { -1 };
            let delta_min = delta(i, i - d);
            let mut l_max = 2;
            while delta(i, i + l_max * d) > delta_min {
                l_max *= 2;
            }
            let mut l = 0;
            let mut t = l_max / 2;
            while t >= 1 {
                if delta(i, i + (l + t) * d) > delta_min {
                    l += t;
                }
                t /= 2;
            }
            let j = i + l * d;
            let delta_node = delta(i, j);
            let mut s = 0;
            let mut t = (l + 1) / 2;
            loop {
                if delta(i, i + (s + t) * d) > delta_node {
                    s += t;
                }
                if t == 1 {
                    break;
                }
                t = (t + 1) / 2;
            }
            let split = i + s * d + d.min(0);
            let (first, last) = (i.min(j), i.max(j));
            let left = if first == split { split as u32 | LEAF_BIT } else { split as u32 };
            let right = if last == split + 1 { (split + 1) as u32 | LEAF_BIT } else { (split + 1) as u32 };
            ReferenceNode {
                left,
                right,
                first_point: first as u32,
                point_count: (last - first + 1) as u32,
                power: DVec3::ZERO,
                area: 0.0,
                center: DVec3::ZERO,
                normal: DVec3::ZERO,
                normal_coherence: 0.0,
                light_dir: DVec3::ZERO,
                light_coherence: 0.0,
                lo: DVec3::ZERO,
                hi: DVec3::ZERO,
            }
        })
        .collect();
    // Summaries, children first: a node's children have larger depth; recurse from the root.
    fn summarise(
        k: u32,
        nodes: &mut Vec<ReferenceNode>,
        points: &[SurfacePoint],
    ) -> (DVec3, f64, DVec3, DVec3, DVec3, DVec3, DVec3) {
        if k & LEAF_BIT != 0 {
            let p = &points[(k & !LEAF_BIT) as usize];
            let pos = p.position.as_dvec3();
            return (
                (p.irradiance * p.area).as_dvec3(),
                p.area as f64,
                pos,
                p.normal.as_dvec3(),
                p.light_dir.as_dvec3(),
                pos,
                pos,
            );
        }
        let (l, r) = (nodes[k as usize].left, nodes[k as usize].right);
        let a = summarise(l, nodes, points);
        let b = summarise(r, nodes, points);
        let lum = |c: DVec3| c.dot(DVec3::new(0.2126, 0.7152, 0.0722));
        let (wa, wb) = (lum(a.0), lum(b.0));
        let centre = (a.2 * a.1 + b.2 * b.1) / (a.1 + b.1);
        // Power-weighted where lit, as tree_aggregate.comp: a lit node's normal is its sources'.
        let (na, nb) = if wa + wb > 0.0 { (wa, wb) } else { (a.1, b.1) };
        let normal = (a.3 * na + b.3 * nb).normalize_or(DVec3::Z);
        let light = (a.4 * wa + b.4 * wb).normalize_or_zero();
        let node = &mut nodes[k as usize];
        node.normal_coherence = (a.3 * na + b.3 * nb).length() / (na + nb);
        node.light_coherence = if wa + wb > 0.0 { (a.4 * wa + b.4 * wb).length() / (wa + wb) } else { 0.0 };
        node.power = a.0 + b.0;
        node.area = a.1 + b.1;
        node.center = centre;
        node.normal = normal;
        node.light_dir = light;
        node.lo = a.5.min(b.5);
        node.hi = a.6.max(b.6);
        (node.power, node.area, centre, normal, light, node.lo, node.hi)
    }
    if n >= 2 {
        summarise(0, &mut nodes, points);
    }
    nodes
}

/// The default points' spacing over the material's shortest length scale (choose_point_count).
pub const SPACING_PER_SHORTEST_LENGTH: f32 = 0.25;

/// Sample count from the material: spacing of a quarter of its shortest length scale (the smaller
/// of the mean free path 1/σ't and the diffusion length 1/σtr), within [4096, budget]. Returns the
/// count and the spacing it gives. The mean free path matters for the directional dipole, whose
/// near-field peak is about that wide: points farther apart than it show as speckle. A quarter,
/// not a half (4× the points), is what brings every model's default image within 1% of converged
/// brute force on a Skin1 sphere (`tests/convergence.rs`); the shade pass's cost stays flat, as
/// the near field's reach shrinks with the spacing and the tree's cut grows like log N.
pub fn choose_point_count(surface_area: f32, shortest_length: f32, budget: u32) -> (u32, f32) {
    let spacing = SPACING_PER_SHORTEST_LENGTH * shortest_length;
    let wanted = (surface_area / (spacing * spacing)).ceil();
    let n = if wanted.is_finite() { (wanted as u64).clamp(4096, budget as u64) as u32 } else { budget };
    (n, (surface_area / n as f32).sqrt())
}

/// Sample count from the material's shortest length scale (mean free path 1/σ't or diffusion
/// length 1/σtr) and the mesh's area (in mm), within the device's budget for `per_light_count`
/// lights with their own records (brute force; 0 else) shared by `objects` objects; prints the choice and warns when points are farther apart than
/// that length.
pub fn default_point_count(
    ctx: &Context,
    mesh: &Mesh,
    mm_per_unit: f32,
    material: &Material,
    per_light_count: u32,
    objects: u32,
) -> u32 {
    let mm = mm_per_unit;
    let area_mm2 = mesh.surface_area() * mm * mm;
    let shortest = (0..3)
        .map(|ch| material.channel(ch).constants(Diffusion::Classical))
        .filter(|c| c.transports && c.sigma_tr > 0.0)
        .map(|c| (1.0 / c.sigma_tr).min(1.0 / c.sigma_t_reduced))
        .fold(f64::INFINITY, f64::min) as f32;
    let budget = (max_points(ctx, per_light_count).min(1 << 18) / objects.max(1)).max(4096);
    let (n, spacing) = choose_point_count(area_mm2, shortest, budget);
    crate::note!(
        "samples: {n} points, {spacing:.3} mm apart on {area_mm2:.0} mm² (shortest of mean free path and diffusion length: {shortest:.3} mm)"
    );
    if spacing > shortest {
        crate::note!("warning: points are spaced wider than the mean free path or diffusion length; raise --samples for accuracy");
    }
    n
}
