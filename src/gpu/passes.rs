//! The other passes' push constants and blocks: bssrdf_eval.comp, tonemap.comp, the hierarchy's
//! compute shaders (sampling, Morton codes, radix sort) and the debug views.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

use crate::output::{self, HIST_BINS, HIST_BINS_PER_STOP, HIST_LOG2_MIN};

use super::GpuChannel;

/// Mirrors `BssrdfQuery` in shaders/bssrdf_eval.comp (std430: 64 + 6 × 16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct BssrdfQueryGpu {
    pub channel: GpuChannel,
    pub xi: Vec4,
    pub ni: Vec4,
    pub wi: Vec4,
    pub xo: Vec4,
    pub no: Vec4,
    /// x: the row's Sd table among the dispatch's (photon beam diffusion); the rest unused.
    pub table: [u32; 4],
}

/// Mirrors the push constants of shaders/bssrdf_eval.comp.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct EvalConstants {
    pub count: u32,
    pub model: u32,
}

/// Mirrors `HistogramTables` in shaders/tonemap.comp: the histogram definition of `output`, so the
/// shader has no constants of its own.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct HistogramTables {
    pub thresholds: [f32; HIST_BINS_PER_STOP],
    pub inv_centres: [f32; HIST_BINS_PER_STOP],
    pub log2_min: i32,
    pub bin_count: u32,
}

impl HistogramTables {
    pub fn new() -> HistogramTables {
        HistogramTables {
            thresholds: output::stop_thresholds(),
            inv_centres: output::bin_inverse_centres(),
            log2_min: HIST_LOG2_MIN,
            bin_count: HIST_BINS as u32,
        }
    }
}

impl Default for HistogramTables {
    fn default() -> Self {
        Self::new()
    }
}

/// Mirrors `TonemapConstants` in shaders/tonemap.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TonemapConstants {
    pub stage: u32,
    pub width: u32,
    pub height: u32,
    pub fixed_exposure: u32,
    pub fixed_scale: f32,
}

/// The histogram buffer starts with this header: the exposure scale (f32) at byte 0, the number of
/// pixels counted (u32) at byte 4; the bins (u32) follow.
pub const HISTOGRAM_HEADER_BYTES: u64 = 16;

/// Mirrors the push constants of shaders/hierarchy/sample_points.comp.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct SampleConstants {
    pub point_count: u32,
    pub triangle_count: u32,
    pub seed: u32,
    /// The object's texture (its scatter weight), as [`SurfaceConstants`](crate::gpu::SurfaceConstants) gives it.
    pub texture_kind: u32,
    pub tex1: Vec4,
    pub tex2: Vec4,
}

/// Mirrors the push constants of shaders/hierarchy/morton.comp.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct MortonConstants {
    pub bounds_min: Vec4,
    pub bounds_extent: Vec4,
    pub point_count: u32,
    pub pad: [u32; 3],
}

/// Mirrors the push constants of the radix sort's shaders (shaders/hierarchy/radix_*.comp).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct RadixConstants {
    pub count: u32,
    pub tile_count: u32,
    pub shift: u32,
}

/// Mirrors the push constants of the debug views (shaders/debug/).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct DebugConstants {
    pub view_projection: Mat4,
    /// rgb: colour scale; w: point size in pixels.
    pub color_scale: Vec4,
}

/// Push constants of shaders/far_field.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FarFieldConstants {
    /// 8x8 tiles across and down.
    pub tiles: [u32; 2],
    /// The object whose pixels and tree the far field is of.
    pub object: u32,
    pub pad: u32,
    /// The camera's position (xyz; w unused): the exit's tilt toward it.
    pub eye: [f32; 4],
}

/// Push constants of shaders/tile_cut.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TileCutConstants {
    /// Tiles across and down.
    pub tiles: [u32; 2],
    /// Image width and height.
    pub pixels: [u32; 2],
    /// Entries the list buffer holds.
    pub capacity: u32,
    /// The object whose pixels (G-buffer position w = object + 1) and tree the lists are of.
    pub object: u32,
    /// Pixels per side of a tile.
    pub list_tile: u32,
    /// The frame's model (`Model::gpu_code`): whether the normal enters Sd (the far field's test).
    pub model: u32,
}

/// Push constants of the re-entry's three stages (shaders/include/reentry.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct ReentryConstants {
    pub patch_count: u32,
    /// Sorted points per patch (the last patch takes the rest too).
    pub stride: u32,
    pub point_count: u32,
    /// The exitance walk's cut: a node is whole when area < epsilon · distance².
    pub epsilon: f32,
    /// Per channel ∫ (1 − w) Sd 2πr dr over the flat profile (xyz), and the reach (w, mm).
    pub near: [f32; 4],
    /// ∫ Ft(θo) cos θo dω: exitance per unit of Sd · power.
    pub exit_integral: f32,
    /// A patch's area (scene units²) and its square root.
    pub patch_area: f32,
    pub eta: f32,
    pub patch_spacing: f32,
}
