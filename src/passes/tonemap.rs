//! Tone mapping on the GPU, the twin of `output::tonemap`: HDR colour to 8-bit sRGB with alpha =
//! coverage, auto exposure from a luminance histogram without reading anything back.
//! Reads: the HDR colour image (storage, rgba32f). Writes: the histogram and the packed RGBA8 buffer.

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::output::{self, Exposure, HIST_BINS, HIST_BINS_PER_STOP, HIST_LOG2_MIN};
use crate::runtime;
use crate::vk::{self, Bind, Buffer, BufferUsageFlags, Context, Format, Image, Pipeline, Recorder};

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
const GROUP: u32 = 16;

/// Bytes of the histogram buffer. Usage: STORAGE_BUFFER | TRANSFER_DST (it is cleared with a fill).
pub fn histogram_bytes() -> u64 {
    HISTOGRAM_HEADER_BYTES + 4 * HIST_BINS as u64
}

/// Bytes of the output buffer: one u32 per pixel. Usage: STORAGE_BUFFER.
pub fn ldr_bytes(width: u32, height: u32) -> u64 {
    4 * width as u64 * height as u64
}

pub struct TonemapPass {
    pipeline: Pipeline,
    tables: Buffer,
}

impl TonemapPass {
    pub fn new(ctx: &Context) -> Result<TonemapPass> {
        let pipeline = Pipeline::compute(ctx, "tonemap.comp")?;
        let tables =
            vk::upload_buffer(ctx, "tonemap tables", &[HistogramTables::new()], BufferUsageFlags::STORAGE_BUFFER)?;
        Ok(TonemapPass { pipeline, tables })
    }

    /// Tone-maps all of `hdr` (R32G32B32A32_SFLOAT with STORAGE usage) into `ldr`, rows top to
    /// bottom. With `Exposure::Auto` the histogram is rebuilt and its header gets the scale used.
    pub fn record(
        &self,
        rec: &mut Recorder,
        hdr: &Image,
        histogram: &Buffer,
        ldr: &Buffer,
        exposure: Exposure,
    ) -> Result<()> {
        let (width, height) = (hdr.extent.width, hdr.extent.height);
        if hdr.format != Format::R32G32B32A32_SFLOAT {
            return Err(runtime!("tonemap: {} is {:?}, not R32G32B32A32_SFLOAT", hdr.name, hdr.format));
        }
        if histogram.size < histogram_bytes() || ldr.size < ldr_bytes(width, height) {
            return Err(runtime!(
                "tonemap: buffers {} ({} bytes) and {} ({} bytes) are smaller than {} and {}",
                histogram.name,
                histogram.size,
                ldr.name,
                ldr.size,
                histogram_bytes(),
                ldr_bytes(width, height)
            ));
        }
        let mut constants = TonemapConstants { stage: 0, width, height, fixed_exposure: 0, fixed_scale: 1.0 };
        let groups = [width.div_ceil(GROUP), height.div_ceil(GROUP), 1];
        match exposure {
            Exposure::Stops(s) => {
                constants.fixed_exposure = 1;
                constants.fixed_scale = 2f32.powf(s); // as output::exposure_scale
            }
            Exposure::Auto => {
                rec.fill_buffer(histogram, 0)?;
                for (stage, groups) in [(0, groups), (1, [1, 1, 1])] {
                    constants.stage = stage;
                    rec.dispatch(
                        &self.pipeline,
                        &[
                            Bind::StorageImageRead(hdr),
                            Bind::Read(&self.tables),
                            Bind::Write(histogram),
                            // The shader declares it writable (stage 2 writes it).
                            Bind::Write(ldr),
                        ],
                        bytemuck::bytes_of(&constants),
                        groups,
                    )?;
                }
            }
        }
        constants.stage = 2;
        rec.dispatch(
            &self.pipeline,
            // The histogram is declared writable (stages 0 and 1 write it).
            &[Bind::StorageImageRead(hdr), Bind::Read(&self.tables), Bind::Write(histogram), Bind::Write(ldr)],
            bytemuck::bytes_of(&constants),
            groups,
        )
    }
}
