//! Light that leaves the object and enters it again (`--model mc`, closed meshes): an ear lit
//! through glows onto the other ear, a paw onto the chest above it. The path tracer's light is
//! 8–14% such on the bunnies (README, "Against a path tracer"); a BSSRDF joins only an entry to
//! an exit. After the tree's summaries, on a coarse set of patches (runs of the Morton-sorted
//! points, [`PATCHES`] of them):
//!
//! 1. `reentry/exitance.comp`: each patch's exitance M, the sources' sum as the shade pass makes
//!    it (sources.glsl), times ∫ Ft cos dω, single scattering's escape included;
//! 2. `reentry/gather.comp`: the irradiance each patch receives from the patches facing it
//!    through the air (the inside grid's chord test), radiance M/π, through Ft;
//! 3. `reentry/spread.comp`: each sorted point adds its patch's (and its neighbours') to its
//!    irradiance and merged light record;
//!
//! then the tree's summaries are made again. One bounce: light that re-enters and leaves again
//! to re-enter a second time is not drawn (a few % of a few %). Reads: the object's parameters,
//! tree nodes, sorted points and their records, the Sd table (profile, inside grid). Writes:
//! the patches' exitance and received light, the sorted points' irradiance and merged records.

use crate::error::Result;
use crate::gpu::ReentryConstants;
use crate::passes::Sources;
use crate::physics::Model;
use crate::vk::{self, Bind, Buffer, BufferUsageFlags, Context, MemoryLocation, Pipeline, Recorder};

/// Patches the points are cut into: 1024 over the default bunny's 960 mm² are 0.97 mm across,
/// the light they exchange is spread by the BSSRDF over its diffusion length after.
pub const PATCHES: u32 = 1024;

/// The exitance's own part reaches this many point spacings (the sources within are weighed
/// down, the patch's own irradiance times the profile's integral stands in).
pub const REACH_SPACINGS: f32 = 3.0;

/// The exitance walk's cut: the frame's default ε (`frame_desc::DEFAULT_EPSILON`), fixed
/// whatever `--epsilon` says, since a patch's exitance is spread over the patch and then by the
/// BSSRDF.
pub const EXITANCE_EPSILON: f32 = 0.2;

/// One object's patches: their exitance (vec4 each) and what they receive (two vec4 each).
pub struct ReentryBuffers {
    exitance: Buffer,
    received: Buffer,
}

impl ReentryBuffers {
    pub fn new(ctx: &Context) -> Result<ReentryBuffers> {
        let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC;
        let buffer = |name: &str, bytes: u64| Buffer::new(ctx, name, bytes, usage, MemoryLocation::GpuOnly);
        Ok(ReentryBuffers {
            exitance: buffer("patch exitance", PATCHES as u64 * 16)?,
            received: buffer("patch re-entry", PATCHES as u64 * 32)?,
        })
    }
}

/// One object's patches as the last frame left them (tests, tools).
#[derive(Clone, Debug)]
pub struct Patches {
    pub constants: ReentryConstants,
    /// The sorted point each patch is read at.
    pub points: Vec<u32>,
    /// Its exitance M (rgb, W/m²).
    pub exitance: Vec<[f32; 4]>,
    /// The light it received through the air, in through the boundary (rgb), and the
    /// luminance-weighted sum of the directions toward its sources (xyz).
    pub received: Vec<[[f32; 4]; 2]>,
}

impl ReentryBuffers {
    /// What the last frame drew with `constants`.
    pub fn download(&self, ctx: &Context, constants: ReentryConstants) -> Result<Patches> {
        let n = constants.patch_count.min(PATCHES) as usize;
        Ok(Patches {
            constants,
            points: (0..n as u32).map(|k| patch_point(&constants, k)).collect(),
            exitance: vk::download_buffer(ctx, &self.exitance, n)?,
            received: vk::download_buffer(ctx, &self.received, n)?,
        })
    }
}

/// The sorted point patch `k` is read at: its run's middle (reentry.glsl `patch_point`).
pub fn patch_point(c: &ReentryConstants, k: u32) -> u32 {
    k * c.stride + c.stride / 2
}

/// What one object's re-entry reads and writes: its sources (whose sorted points and their
/// merged records the last stage adds to) and its patches.
pub struct ReentryInputs<'a> {
    pub sources: Sources<'a>,
    pub buffers: &'a ReentryBuffers,
}

pub struct ReentryPass {
    exitance: Pipeline,
    gather: Pipeline,
    spread: Pipeline,
}

impl ReentryPass {
    pub fn new(ctx: &Context) -> Result<ReentryPass> {
        Ok(ReentryPass {
            // The Monte Carlo table's sources (the only model with an inside grid).
            exitance: Pipeline::compute_specialized(ctx, "reentry/exitance.comp", &[Model::Mc.gpu_code(), 0])?,
            gather: Pipeline::compute(ctx, "reentry/gather.comp")?,
            spread: Pipeline::compute(ctx, "reentry/spread.comp")?,
        })
    }

    /// The three stages for one object of `point_count` points (at least two).
    pub fn record(&self, rec: &mut Recorder, inputs: &ReentryInputs, constants: &ReentryConstants) -> Result<()> {
        let b = inputs.buffers;
        let push = bytemuck::bytes_of(constants);
        let patches = constants.patch_count;
        let [params, nodes, points, node_flux, point_flux, point_spread, sd_table] = inputs.sources.binds();
        rec.scope("re-entry exitance", |rec| {
            let binds =
                [params, nodes, points, node_flux, point_flux, point_spread, sd_table, Bind::Write(&b.exitance)];
            rec.dispatch(&self.exitance, &binds, push, [patches.div_ceil(8), 1, 1])
        })?;
        let sources = &inputs.sources;
        rec.scope("re-entry gather", |rec| {
            rec.dispatch(
                &self.gather,
                &[
                    Bind::Texels(sources.points),
                    Bind::Read(&b.exitance),
                    Bind::Texels(sources.sd_table),
                    Bind::Write(&b.received),
                ],
                push,
                [patches.div_ceil(64), 1, 1],
            )
        })?;
        rec.scope("re-entry spread", |rec| {
            rec.dispatch(
                &self.spread,
                &[
                    Bind::Write(sources.points),
                    Bind::Write(sources.point_flux),
                    Bind::Read(&b.received),
                    Bind::Texels(sources.sd_table),
                ],
                push,
                [constants.point_count.div_ceil(64), 1, 1],
            )
        })
    }
}

/// What the re-entry needs of an object's material: the flat profile's near integral and reach
/// ([`near_integral`]), ∫ Ft cos dω and η.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReentryProfile {
    pub near: [f32; 4],
    pub exit_integral: f32,
    pub eta: f32,
}

/// The constants for `point_count` points of `total_area` (scene units²) of a material's
/// `profile`.
pub fn constants(point_count: u32, total_area: f32, profile: &ReentryProfile) -> ReentryConstants {
    let patch_count = PATCHES.min(point_count);
    let stride = point_count / patch_count.max(1);
    let patch_area = total_area * stride as f32 / point_count.max(1) as f32;
    ReentryConstants {
        patch_count,
        stride,
        point_count,
        epsilon: EXITANCE_EPSILON,
        near: profile.near,
        exit_integral: profile.exit_integral,
        patch_area,
        eta: profile.eta,
        patch_spacing: patch_area.sqrt(),
    }
}

/// The surface's area (scene units²) from its points' spacing √(area / points).
pub fn total_area(point_spacing: f32, point_count: u32) -> f32 {
    point_spacing * point_spacing * point_count as f32
}

/// Per channel ∫₀^R (1 − w(r)) Sd(r) 2πr dr, w the smoothstep from R/2 to R (as exitance.comp
/// weighs the sources), for the flat profiles `sd` (1/mm², r in mm); R in w.
pub fn near_integral(sd: impl Fn(usize, f64) -> f64, reach_mm: f64) -> [f32; 4] {
    const STEPS: usize = 4096;
    let dr = reach_mm / STEPS as f64;
    let mut sums = [0.0f64; 3];
    for i in 0..STEPS {
        let r = (i as f64 + 0.5) * dr;
        let t = ((r - 0.5 * reach_mm) / (0.5 * reach_mm)).clamp(0.0, 1.0);
        let w = t * t * (3.0 - 2.0 * t);
        for (c, sum) in sums.iter_mut().enumerate() {
            *sum += (1.0 - w) * sd(c, r) * 2.0 * std::f64::consts::PI * r * dr;
        }
    }
    [sums[0] as f32, sums[1] as f32, sums[2] as f32, reach_mm as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The near integral of a constant profile is the inner disk's area plus the ring's part
    /// weighed by 1 − w (a finer sum of it here).
    #[test]
    fn the_near_integral_of_a_flat_profile_is_the_weighed_disk() {
        let r = 2.0;
        let got = near_integral(|_, _| 1.0, r);
        // Inner disk (w = 0): π (R/2)²; the ring: 2π ∫_{R/2}^{R} (1 − w) r dr, by a fine sum.
        let n = 1_000_000;
        let mut ring = 0.0;
        for i in 0..n {
            let x = 0.5 + (i as f64 + 0.5) / n as f64 * 0.5;
            let t = (x - 0.5) / 0.5;
            ring += (1.0 - t * t * (3.0 - 2.0 * t)) * x * (0.5 / n as f64);
        }
        let expected = std::f64::consts::PI * 0.25 * r * r + 2.0 * std::f64::consts::PI * ring * r * r;
        for value in &got[..3] {
            assert!((*value as f64 / expected - 1.0).abs() < 1e-5, "{value} vs {expected}");
        }
        assert_eq!(got[3], 2.0);
    }
}
