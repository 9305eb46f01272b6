//! GPU tone mapping (shaders/tonemap.comp) against the CPU definition in `output`, under validation.

mod common;

use common::{assert_clean, validated_context};
use translucent::output::{self, Exposure, HdrImage};
use translucent::passes::tonemap::{self, TonemapPass};
use translucent::vk::{Buffer, BufferUsageFlags, Context, Extent2D, Format, Image, ImageUsageFlags, MemoryLocation};

/// 97×61 (not a multiple of the 16×16 work group): values from 1e-6 to 1e4 per channel, zeros,
/// a NaN, infinities, negatives, partial coverage and alpha-0 background.
fn test_image() -> HdrImage {
    let (width, height) = (97u32, 61u32);
    let mut state = 12345u32;
    let mut next = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    let mut pixels = Vec::new();
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let mut p = [0.0f32; 4];
            for c in p.iter_mut().take(3) {
                *c = 10f32.powf(-6.0 + 10.0 * next());
            }
            p[3] = if (x + 2 * y) % 7 == 0 {
                0.0
            } else if i % 11 == 0 {
                0.37
            } else {
                1.0
            };
            if i % 13 == 0 {
                p = [0.0, 0.0, 0.0, 1.0];
            }
            pixels.push(p);
        }
    }
    let at = |x: u32, y: u32| (y * width + x) as usize;
    pixels[at(5, 5)][0] = f32::NAN;
    pixels[at(10, 3)][1] = f32::INFINITY;
    pixels[at(11, 3)] = [f32::INFINITY; 4];
    pixels[at(12, 3)][2] = -3.0;
    pixels[at(13, 3)][3] = f32::NAN;
    pixels[at(96, 60)] = [1e4, 1e4, 1e4, 1.0];
    // Below and above the histogram's range: they count, in the end bins.
    for x in 20..30 {
        pixels[at(x, 7)] = [1e-20, 1e-25, 1e-30, 1.0];
        pixels[at(x, 8)] = [1e30, 0.0, 1e30, 1.0];
    }
    HdrImage { width, height, pixels }
}

struct Gpu {
    pass: TonemapPass,
    hdr: Image,
    histogram: Buffer,
    ldr: Buffer,
}

impl Gpu {
    fn new(ctx: &Context, width: u32, height: u32) -> Gpu {
        let hdr = Image::new_2d(
            ctx,
            "test hdr",
            Format::R32G32B32A32_SFLOAT,
            Extent2D { width, height },
            1,
            ImageUsageFlags::STORAGE | ImageUsageFlags::TRANSFER_DST,
        )
        .unwrap();
        let histogram = Buffer::new(
            ctx,
            "histogram",
            tonemap::histogram_bytes(),
            BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )
        .unwrap();
        let ldr = Buffer::new(
            ctx,
            "ldr",
            tonemap::ldr_bytes(width, height),
            BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )
        .unwrap();
        Gpu { pass: TonemapPass::new(ctx).unwrap(), hdr, histogram, ldr }
    }

    /// Uploads `img`, tone-maps it and returns (the histogram header's scale, the image).
    fn run(&self, ctx: &Context, img: &HdrImage, exposure: Exposure) -> (f32, image::RgbaImage) {
        let mut staging = Buffer::new(
            ctx,
            "hdr upload",
            img.pixels.len() as u64 * 16,
            BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )
        .unwrap();
        staging.write(0, &img.pixels).unwrap();
        ctx.submit(None, |rec| {
            rec.copy_buffer_to_image(&staging, &self.hdr)?;
            self.pass.record(rec, &self.hdr, &self.histogram, &self.ldr, exposure)?;
            rec.host_read(&self.histogram)?;
            rec.host_read(&self.ldr)
        })
        .unwrap();
        let scale = self.histogram.read::<f32>(1).unwrap()[0];
        let packed = self.ldr.read::<u32>(img.pixels.len()).unwrap();
        (scale, output::rgba8_from_packed(img.width, img.height, &packed).unwrap())
    }
}

/// The largest per-channel difference (alpha included); panics naming the first pixel off by more
/// than one.
fn worst_difference(gpu: &image::RgbaImage, cpu: &image::RgbaImage, img: &HdrImage) -> u8 {
    let mut worst = 0;
    for (i, (g, c)) in gpu.pixels().zip(cpu.pixels()).enumerate() {
        for ch in 0..4 {
            let d = g[ch].abs_diff(c[ch]);
            assert!(d <= 1, "pixel {i} channel {ch}: GPU {:?} CPU {:?} from {:?}", g.0, c.0, img.pixels[i]);
            worst = worst.max(d);
        }
    }
    worst
}

#[test]
fn gpu_tonemap_matches_cpu() {
    let (ctx, counts) = validated_context();
    let img = test_image();
    let gpu = Gpu::new(&ctx, img.width, img.height);

    let (scale, auto) = gpu.run(&ctx, &img, Exposure::Auto);
    let cpu_scale = output::auto_exposure_scale(&img);
    assert_eq!(scale.to_bits(), cpu_scale.to_bits(), "GPU scale {scale} vs CPU {cpu_scale}");
    let header_words = (translucent::gpu::HISTOGRAM_HEADER_BYTES / 4) as usize;
    let words = gpu.histogram.read::<u32>(header_words + output::HIST_BINS).unwrap();
    let (counted, bins) = (words[1], &words[header_words..]);
    let cpu_bins = output::luminance_histogram(&img);
    assert_eq!(bins, cpu_bins, "GPU histogram differs from the CPU one");
    assert_eq!(counted, cpu_bins.iter().sum::<u32>());
    assert!(bins[0] >= 10 && bins[output::HIST_BINS - 1] >= 10, "the end bins are exercised");
    let worst_auto = worst_difference(&auto, &output::tonemap(&img, Exposure::Auto), &img);
    // Something must be mid-grey, or the comparison would only see saturated pixels.
    let mid = auto.pixels().filter(|p| (40..216).contains(&p[1])).count();
    assert!(mid > 100, "only {mid} mid-tone pixels");

    let fixed = Exposure::Stops(1.5);
    let (_, stops) = gpu.run(&ctx, &img, fixed);
    let worst_fixed = worst_difference(&stops, &output::tonemap(&img, fixed), &img);
    println!(
        "auto scale {scale:e} from {counted} pixels; worst channel difference: auto {worst_auto}, stops {worst_fixed}"
    );
    drop(gpu);
    drop(ctx);
    assert_clean(&counts);
}

#[test]
fn all_background_gets_scale_one() {
    let (ctx, counts) = validated_context();
    let img = HdrImage { width: 20, height: 17, pixels: vec![[5.0, 0.5, 1e-3, 0.0]; 20 * 17] };
    let gpu = Gpu::new(&ctx, img.width, img.height);
    let (scale, out) = gpu.run(&ctx, &img, Exposure::Auto);
    assert_eq!(scale, 1.0);
    assert_eq!(output::auto_exposure_scale(&img), 1.0);
    worst_difference(&out, &output::tonemap(&img, Exposure::Auto), &img);
    assert!(out.pixels().all(|p| p[3] == 0 && p[0] > p[1] && p[1] > p[2]), "{:?}", out.get_pixel(0, 0));
    drop(gpu);
    drop(ctx);
    assert_clean(&counts);
}
