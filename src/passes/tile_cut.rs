//! The tile-cut pass (shaders/tile_cut.comp): per screen tile of 4² or 8² pixels, the list of
//! tree nodes and points that are far and small enough for every pixel of the tile, so that the
//! shade pass's lanes for a tile evaluate the same sources in step. Reads: the object's and the frame's parameters,
//! tree nodes, sorted points, the G-buffer's positions and normals, the lights and their shadow
//! maps (whether any pixel of the tile is lit: only then does it need the near field). Writes:
//! tile headers, list entries, the allocation counter, and per 8x8 tile the header of its far
//! sources (passes/far_field.rs sums them).

use crate::error::Result;
use crate::gpu::TileCutConstants;
use crate::physics::Model;
use crate::vk::{Bind, Buffer, BufferUsageFlags, Context, Image, MemoryLocation, Pipeline, Recorder, Sampler};

pub use crate::gpu::{FAR_FIELD_SAMPLES, FAR_FIELD_TILE, LIST_TILE_SIZES, NEAR_FIELD_TILE, WALK_FROM_ROOT};
/// List entries allotted per tile before a frame has told how many it needs, at the default ε.
const INITIAL_ENTRIES_PER_TILE: u64 = 256;

/// List entries to allot per tile before a frame has told how many it needs: 256 at the default
/// ε = 0.2 (the default frames' lists fit), and √(0.2/ε) times that below it (a cut holds about
/// ∫ dA / (ε d²) nodes, up to 1/ε times more, but allotting that much over-allots: pbrt-v2's
/// scene needs about 400 per tile at ε = 0.05, where 1/ε allotted 1024), never more than the
/// tree's points and nodes (2N). A list
/// that does not fit makes the frame cut twice: pbrt-v2's scene (ε = 0.05, 3,100 points, about
/// 400 entries per 8x8 tile) spent 160 ms of its single frame's 1.5 s on the second cut.
pub fn initial_entries_per_tile(epsilon: f32, points: u32) -> u64 {
    let ratio = (crate::frame_desc::DEFAULT_EPSILON as f64 / epsilon as f64).max(1.0);
    let scaled = (INITIAL_ENTRIES_PER_TILE as f64 * ratio.sqrt()).min(1e9) as u64;
    scaled.min(2 * points as u64).max(4)
}

/// Pixels per side of an object's list tiles for a frame. A tile's list opens every node that
/// any of its pixels must open, so where a tile spans several point spacings on the object its
/// pixels evaluate many points that each alone would have taken as one node: there the small
/// tile (4) wins, the large one (8) elsewhere, as it walks the tree for 4x the pixels. Measured
/// frame times (llvmpipe, BENCHMARKS.md "A clean frame"): the default bunny at 256² 983 → 320 ms,
/// at 512² 853 → 610 ms (an 8x8 tile 3-4 spacings wide); pbrt-v2's sphere at 1024² 2077 →
/// 2653 ms (0.5 spacings), 512² 563 → 708 ms (1.05), 256² 375 → 219 ms (2.1). The small tile
/// needs the device's subgroups to fit in it: a warp over two tiles would run both lists.
/// `pixel_footprint`: a pixel's width at the object (scene units); `point_spacing` the same.
pub fn list_tile(pixel_footprint: f32, point_spacing: f32, subgroup_size: u32) -> u32 {
    let [small, large] = LIST_TILE_SIZES;
    let spans = large as f32 * pixel_footprint / point_spacing;
    if subgroup_size <= small * small && spans > 1.5 {
        small
    } else {
        large
    }
}

/// The lists of one frame size: a header per tile, the entries, and the allocation counter the
/// host reads to learn whether every list fitted.
pub struct TileLists {
    pub headers: Buffer,
    pub entries: Buffer,
    /// Per tile, where its far sources are in `entries` (tile_cut.comp's far_headers).
    pub far_headers: Buffer,
    /// Per 8x8 tile, the far-field pass's nine sums (vec4 each).
    pub far_field: Buffer,
    allocation: Buffer,
    /// Entries the buffer holds.
    pub capacity: u64,
    /// The most entries the lists may grow to (the device's limit unless set lower).
    limit: u64,
    /// Pixels per side of a tile this frame (`list_tile`), and the tiles across and down.
    pub list_tile: u32,
    pub tiles: [u32; 2],
    pixels: [u32; 2],
}

impl TileLists {
    /// Lists for a `width` x `height` image in tiles of `list_tile` pixels a side, holding
    /// `capacity` entries (by default 256 per tile; see `initial_entries_per_tile`), which may grow up to `limit` entries (by
    /// default the device's limit); headers for the smaller tiles, so that a later frame may use
    /// either size.
    pub fn new(
        ctx: &Context,
        (width, height): (u32, u32),
        list_tile: u32,
        capacity: Option<u64>,
        limit: Option<u64>,
    ) -> Result<TileLists> {
        let tiles_of = |size: u32| width.div_ceil(size) as u64 * height.div_ceil(size) as u64;
        let limit = limit.unwrap_or(u64::MAX).clamp(4, max_entries(ctx));
        let capacity = capacity.unwrap_or(tiles_of(list_tile) * INITIAL_ENTRIES_PER_TILE).clamp(4, limit);
        let tile_count = tiles_of(LIST_TILE_SIZES[0]);
        // TRANSFER_DST: frames without a cut clear the headers.
        let usage =
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::UNIFORM_TEXEL_BUFFER | BufferUsageFlags::TRANSFER_DST;
        let far_tiles = tiles_of(FAR_FIELD_TILE);
        Ok(TileLists {
            headers: Buffer::new(ctx, "tile list headers", tile_count * 16, usage, MemoryLocation::GpuOnly)?,
            far_headers: Buffer::new(ctx, "far-field headers", tile_count * 16, usage, MemoryLocation::GpuOnly)?,
            far_field: Buffer::new(
                ctx,
                "far-field sums",
                far_tiles * FAR_FIELD_SAMPLES as u64 * 16,
                usage,
                MemoryLocation::GpuOnly,
            )?,
            // Whole texels of 4 entries.
            entries: Buffer::new(
                ctx,
                "tile list entries",
                capacity.next_multiple_of(4) * 4,
                usage,
                MemoryLocation::GpuOnly,
            )?,
            allocation: Buffer::new(
                ctx,
                "tile list allocation",
                4,
                BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuToCpu,
            )?,
            capacity,
            limit,
            list_tile,
            tiles: [width.div_ceil(list_tile), height.div_ceil(list_tile)],
            pixels: [width, height],
        })
    }

    /// Tiles of `size` pixels a side (one of `LIST_TILE_SIZES`) from the next cut on.
    pub fn set_list_tile(&mut self, size: u32) {
        debug_assert!(LIST_TILE_SIZES.contains(&size));
        self.list_tile = size;
        self.tiles = [self.pixels[0].div_ceil(size), self.pixels[1].div_ceil(size)];
    }

    /// Entries the last cut asked for (all tiles, whether they fitted or not).
    pub fn entries_needed(&self) -> Result<u64> {
        Ok(self.allocation.read::<u32>(1)?[0] as u64)
    }

    /// `None` when every tile's list fitted, or the lists are as big as allowed (tiles whose
    /// list did not fit then walk from the root per pixel); else lists big enough for the last
    /// cut's needs (a quarter more, within the limit).
    pub fn grown(&self, ctx: &Context) -> Result<Option<TileLists>> {
        let needed = self.entries_needed()?;
        if needed <= self.capacity || self.capacity >= self.limit {
            return Ok(None);
        }
        let capacity = (needed + needed / 4).min(self.limit);
        let size = (self.pixels[0], self.pixels[1]);
        Ok(Some(TileLists::new(ctx, size, self.list_tile, Some(capacity), Some(self.limit))?))
    }
}

/// The most list entries: one storage buffer, and its texel view (4 entries per texel).
fn max_entries(ctx: &Context) -> u64 {
    let limits = ctx.limits();
    (limits.max_storage_buffer_range as u64 / 4).min(limits.max_texel_buffer_elements as u64 * 4)
}

pub struct TileCutPass {
    pipeline: Pipeline,
}

impl TileCutPass {
    pub fn new(ctx: &Context) -> Result<TileCutPass> {
        Ok(TileCutPass { pipeline: Pipeline::compute(ctx, "tile_cut.comp")? })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        (object_params, frame_params): (&Buffer, &Buffer),
        nodes: &Buffer,
        points: &Buffer,
        (position, normal): (&Image, &Image),
        (lights, shadow_map, shadow_sampler): (&Buffer, &Image, &Sampler),
        lists: &TileLists,
        (object, model): (u32, Model),
    ) -> Result<()> {
        rec.fill_buffer(&lists.allocation, 0)?;
        let constants = TileCutConstants {
            tiles: lists.tiles,
            pixels: lists.pixels,
            capacity: lists.capacity.min(u32::MAX as u64) as u32,
            object,
            list_tile: lists.list_tile,
            model: model.gpu_code(),
        };
        rec.dispatch(
            &self.pipeline,
            &[
                Bind::Uniform(object_params),
                Bind::Texels(nodes),
                Bind::Texels(points),
                Bind::StorageImageRead(position),
                Bind::Write(&lists.headers),
                Bind::Write(&lists.entries),
                Bind::Write(&lists.allocation),
                Bind::Uniform(frame_params),
                Bind::Read(lights),
                Bind::Sampled(shadow_map, shadow_sampler),
                Bind::StorageImageRead(normal),
                Bind::Write(&lists.far_headers),
            ],
            bytemuck::bytes_of(&constants),
            [lists.tiles[0].div_ceil(8), lists.tiles[1], 1],
        )?;
        rec.host_read(&lists.allocation)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 256 entries per tile at the default ε, twice that at ε / 4, never more than the points
    /// and nodes, never fewer than 256 at a coarser ε.
    #[test]
    fn initial_lists_grow_as_epsilon_shrinks_up_to_the_tree() {
        assert_eq!(initial_entries_per_tile(0.2, 100_000), 256);
        assert_eq!(initial_entries_per_tile(0.05, 100_000), 512);
        assert_eq!(initial_entries_per_tile(0.05, 200), 400);
        assert_eq!(initial_entries_per_tile(1.0, 100_000), 256);
        assert_eq!(initial_entries_per_tile(1e-20, 100_000), 200_000);
    }

    /// The small tile where the large one spans more than 1.5 spacings and a subgroup fits in 16
    /// pixels (llvmpipe's 8 lanes, not a 32-lane warp).
    #[test]
    fn list_tile_follows_the_footprint_and_the_subgroup() {
        assert_eq!(list_tile(0.1, 1.0, 8), 8, "0.8 spacings");
        assert_eq!(list_tile(0.2, 1.0, 8), 4, "1.6 spacings");
        assert_eq!(list_tile(0.2, 1.0, 16), 4);
        assert_eq!(list_tile(0.2, 1.0, 32), 8, "a warp spans 32 pixels");
        assert_eq!(list_tile(5.0, 1.0, 64), 8);
    }
}
