//! The tile-cut pass (shaders/tile_cut.comp): per screen tile of `TILE_SIZE`² pixels, the list of
//! tree nodes and points that are far and small enough for every pixel of the tile, so that the
//! shade pass's lanes for a tile evaluate the same sources in step. Reads: the object's and the frame's parameters,
//! tree nodes, sorted points, the G-buffer's positions. Writes: tile headers, list entries, the
//! allocation counter.

use crate::error::Result;
use crate::gpu::TileCutConstants;
use crate::vk::{Bind, Buffer, BufferUsageFlags, Context, Image, MemoryLocation, Pipeline, Recorder};

pub use crate::gpu::{TILE_SIZE, WALK_FROM_ROOT};
/// List entries allotted per tile before a frame has told how many it needs.
const INITIAL_ENTRIES_PER_TILE: u64 = 256;

/// The lists of one frame size: a header per tile, the entries, and the allocation counter the
/// host reads to learn whether every list fitted.
pub struct TileLists {
    pub headers: Buffer,
    pub entries: Buffer,
    allocation: Buffer,
    /// Entries the buffer holds.
    pub capacity: u64,
    /// The most entries the lists may grow to (the device's limit unless set lower).
    limit: u64,
    pub tiles: [u32; 2],
    pixels: [u32; 2],
}

impl TileLists {
    /// Lists for a `width` x `height` image holding `capacity` entries (by default 256 per tile),
    /// which may grow up to `limit` entries (by default the device's limit).
    pub fn new(ctx: &Context, width: u32, height: u32, capacity: Option<u64>, limit: Option<u64>) -> Result<TileLists> {
        let tiles = [width.div_ceil(TILE_SIZE), height.div_ceil(TILE_SIZE)];
        let tile_count = tiles[0] as u64 * tiles[1] as u64;
        let limit = limit.unwrap_or(u64::MAX).clamp(4, max_entries(ctx));
        let capacity = capacity.unwrap_or(tile_count * INITIAL_ENTRIES_PER_TILE).clamp(4, limit);
        // TRANSFER_DST: frames without a cut clear the headers.
        let usage =
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::UNIFORM_TEXEL_BUFFER | BufferUsageFlags::TRANSFER_DST;
        Ok(TileLists {
            headers: Buffer::new(ctx, "tile list headers", tile_count * 16, usage, MemoryLocation::GpuOnly)?,
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
            tiles,
            pixels: [width, height],
        })
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
        Ok(Some(TileLists::new(ctx, self.pixels[0], self.pixels[1], Some(capacity), Some(self.limit))?))
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
        position: &Image,
        lists: &TileLists,
        object: u32,
    ) -> Result<()> {
        rec.fill_buffer(&lists.allocation, 0)?;
        let constants = TileCutConstants {
            tiles: lists.tiles,
            pixels: lists.pixels,
            capacity: lists.capacity.min(u32::MAX as u64) as u32,
            object,
            pad0: 0,
            pad1: 0,
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
            ],
            bytemuck::bytes_of(&constants),
            [lists.tiles[0].div_ceil(8), lists.tiles[1], 1],
        )?;
        rec.host_read(&lists.allocation)
    }
}
