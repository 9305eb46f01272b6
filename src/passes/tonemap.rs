//! Tone mapping on the GPU, the twin of `output::tonemap`: HDR colour to 8-bit sRGB with alpha =
//! coverage, auto exposure from a luminance histogram without reading anything back.
//! Reads: the HDR colour image (storage, rgba32f). Writes: the histogram and the packed RGBA8 buffer.

use crate::error::Result;
use crate::gpu::{HistogramTables, TonemapConstants, HISTOGRAM_HEADER_BYTES};
use crate::output::{Exposure, HIST_BINS};
use crate::runtime;
use crate::vk::{self, Bind, Buffer, BufferUsageFlags, Context, Format, Image, Pipeline, Recorder};

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
            vk::upload_buffer(ctx, "tonemap tables", &[HistogramTables::new()], BufferUsageFlags::UNIFORM_BUFFER)?;
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
                            Bind::Uniform(&self.tables),
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
            &[Bind::StorageImageRead(hdr), Bind::Uniform(&self.tables), Bind::Write(histogram), Bind::Write(ldr)],
            bytemuck::bytes_of(&constants),
            groups,
        )
    }
}
