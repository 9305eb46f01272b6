//! Images out of the renderer: linear radiance to EXR untouched, or through exposure and a filmic
//! tone curve to 8-bit sRGB PNG; and comparison of images for golden tests.

use std::path::Path;

use crate::error::Result;
use crate::{bad_input, runtime};

/// Linear RGBA radiance, rows top to bottom; alpha is coverage (1 where the mesh is).
#[derive(Clone, Debug)]
pub struct HdrImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// Chosen from the image: see [`auto_exposure_scale`].
    Auto,
    /// Multiply radiance by 2^stops.
    Stops(f32),
}

/// Rec. 709 luminance.
pub fn luminance(p: [f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

/// Auto-exposure histogram of log2 luminance: `HIST_BINS_PER_STOP` bins per stop from
/// 2^`HIST_LOG2_MIN` up (1/16 stop over [−40, +24) stops); the ends collect what lies outside.
/// shaders/tonemap.comp gets these through `HistogramTables` (passes/tonemap.rs), never its own copy.
pub const HIST_LOG2_MIN: i32 = -40;
pub const HIST_BINS_PER_STOP: usize = 16;
pub const HIST_BINS: usize = 1024;

/// Lower bin edges within one stop, 2^(j/16) rounded to f32. A luminance is binned by its exponent
/// bits and by comparing its mantissa with these, so CPU and GPU bin identically (a log2 in f32
/// differs in the last bit between libraries and would move pixels across bin edges).
pub fn stop_thresholds() -> [f32; HIST_BINS_PER_STOP] {
    std::array::from_fn(|j| (j as f64 / HIST_BINS_PER_STOP as f64).exp2() as f32)
}

/// 1 / (geometric centre) of each bin within one stop, 2^(−(j+½)/16) rounded to f32: the exposure
/// scale of a bin is this times an exact power of two, again identical on CPU and GPU.
pub fn bin_inverse_centres() -> [f32; HIST_BINS_PER_STOP] {
    std::array::from_fn(|j| (-(j as f64 + 0.5) / HIST_BINS_PER_STOP as f64).exp2() as f32)
}

/// The histogram bin of a covered pixel's luminance, or `None` when it does not count: not finite,
/// ≤ 0, or subnormal (a GPU may flush those to zero).
pub fn luminance_bin(l: f32, thresholds: &[f32; HIST_BINS_PER_STOP]) -> Option<usize> {
    let bits = l.to_bits();
    if !(0x0080_0000..0x7f80_0000).contains(&bits) {
        return None;
    }
    let stop = (bits >> 23) as i32 - 127 - HIST_LOG2_MIN;
    if stop < 0 {
        return Some(0);
    }
    let mantissa = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000); // in [1, 2)
    let within = thresholds[1..].iter().filter(|&&t| mantissa >= t).count();
    Some((stop as usize * HIST_BINS_PER_STOP + within).min(HIST_BINS - 1))
}

/// The exposure scale of bin `bin`: 1 / its geometric centre 2^(HIST_LOG2_MIN + (bin + ½)/16).
pub fn bin_exposure_scale(bin: usize, inverse_centres: &[f32; HIST_BINS_PER_STOP]) -> f32 {
    let stop = HIST_LOG2_MIN + (bin / HIST_BINS_PER_STOP) as i32;
    inverse_centres[bin % HIST_BINS_PER_STOP] * f32::from_bits(((127 - stop) as u32) << 23)
}

/// The auto-exposure histogram: how many covered pixels (alpha > 0) fall in each luminance bin.
pub fn luminance_histogram(img: &HdrImage) -> Vec<u32> {
    let thresholds = stop_thresholds();
    let mut bins = vec![0u32; HIST_BINS];
    for p in img.pixels.iter().filter(|p| p[3] > 0.0) {
        if let Some(b) = luminance_bin(luminance(*p), &thresholds) {
            bins[b] += 1;
        }
    }
    bins
}

/// The scale that maps the 95th-percentile luminance of the covered pixels (alpha > 0) to 1.0 before
/// the tone curve (≈ 0.8 after it): highlights keep some room and a few hot pixels cannot darken the
/// image. The percentile is the centre of the histogram bin holding rank ⌊(n−1)·0.95⌋ (0-based), the
/// same walk the GPU does. An image with nothing covered, or only black, gets scale 1.
pub fn auto_exposure_scale(img: &HdrImage) -> f32 {
    let bins = luminance_histogram(img);
    let count: u32 = bins.iter().sum();
    if count == 0 {
        return 1.0;
    }
    let rank = ((count - 1) as f32 * 0.95) as u32;
    let mut seen = 0;
    let bin = bins.iter().position(|&n| {
        seen += n;
        seen > rank
    });
    bin_exposure_scale(bin.unwrap_or(HIST_BINS - 1), &bin_inverse_centres())
}

/// filmic(x) is 1 from x ≈ 7.25 on; inputs are capped here so that +∞ and huge values stay white
/// instead of overflowing to ∞/∞ = NaN.
const FILMIC_INPUT_MAX: f32 = 64.0;

/// ACES filmic curve, Narkowicz's 2015 fit: maps [0, ∞] to [0, 1], monotonic, f(0) = 0, NaN → 0.
pub fn filmic(x: f32) -> f32 {
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, FILMIC_INPUT_MAX) };
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// The sRGB transfer function (IEC 61966-2-1) from linear [0, 1].
pub fn srgb_encode(linear: f32) -> f32 {
    let c = linear.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// The multiplier applied to radiance before the tone curve.
pub fn exposure_scale(img: &HdrImage, exposure: Exposure) -> f32 {
    match exposure {
        Exposure::Auto => auto_exposure_scale(img),
        Exposure::Stops(s) => 2f32.powf(s),
    }
}

/// Exposure → filmic curve → sRGB → 8 bits (+0.5 rounding); alpha from coverage. NaN becomes 0, +∞
/// white. shaders/tonemap.comp (stage 2) is the GPU twin.
pub fn tonemap(img: &HdrImage, exposure: Exposure) -> image::RgbaImage {
    let scale = exposure_scale(img, exposure);
    let to8 = |v: f32| (srgb_encode(filmic(if v.is_nan() { 0.0 } else { v * scale })) * 255.0 + 0.5) as u8;
    let mut out = image::RgbaImage::new(img.width, img.height);
    for (dst, src) in out.pixels_mut().zip(&img.pixels) {
        let alpha = (src[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        *dst = image::Rgba([to8(src[0]), to8(src[1]), to8(src[2]), alpha]);
    }
    out
}

/// The GPU tone-mapping output (one u32 per pixel, R in the low byte, rows top to bottom) as an
/// image.
pub fn rgba8_from_packed(width: u32, height: u32, packed: &[u32]) -> Result<image::RgbaImage> {
    let bytes: Vec<u8> = packed.iter().flat_map(|p| p.to_le_bytes()).collect();
    let n = packed.len();
    image::RgbaImage::from_raw(width, height, bytes)
        .ok_or_else(|| runtime!("{n} packed pixels do not make a {width}x{height} image"))
}

/// Writes `bytes` to `path` and makes sure they arrived: every write error is reported, including
/// the one a full disk gives only at `fsync` (delayed allocation), so a file that could not be
/// written never passes for success. On error the partial file is removed.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    use std::io::Write;
    let fail = |e: std::io::Error| runtime!("cannot write {}: {e}", path.display());
    let mut file = std::fs::File::create(path).map_err(fail)?;
    let result = file.write_all(bytes).and_then(|_| file.flush()).and_then(|_| {
        // Only regular files can be synced (a character device such as /dev/null cannot).
        if file.metadata()?.is_file() {
            file.sync_all()
        } else {
            Ok(())
        }
    });
    if let Err(e) = result {
        drop(file);
        if std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
            std::fs::remove_file(path).ok();
        }
        return Err(fail(e));
    }
    Ok(())
}

/// Encodes an image (PNG or EXR, by `format`) in memory; see [`write_file`] for writing it.
pub fn encode<I: Into<image::DynamicImage>>(img: I, format: image::ImageFormat) -> Result<Vec<u8>> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.into().write_to(&mut bytes, format).map_err(|e| runtime!("cannot encode the image: {e}"))?;
    Ok(bytes.into_inner())
}

/// Writes `.exr` (linear float RGBA, untouched) or `.png` (tone-mapped sRGB), by extension. An
/// image with a non-finite pixel is refused: no NaN or infinity reaches a file.
pub fn write_image(path: &Path, img: &HdrImage, exposure: Exposure) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    if !matches!(ext.as_str(), "exr" | "png") {
        return Err(bad_input!("{}: unknown image format; use .png or .exr", path.display()));
    }
    check_finite(img)?;
    match ext.as_str() {
        "exr" => {
            let raw: Vec<f32> = img.pixels.iter().flatten().copied().collect();
            let buffer = image::Rgba32FImage::from_raw(img.width, img.height, raw).ok_or_else(|| {
                runtime!("{}: pixel count does not match {}x{}", path.display(), img.width, img.height)
            })?;
            write_file(path, &encode(buffer, image::ImageFormat::OpenExr)?)
        }
        _ => write_file(path, &encode(tonemap(img, exposure), image::ImageFormat::Png)?),
    }
}

/// The number of pixels with a NaN or infinite channel, and the first one (x, y).
pub fn non_finite_pixels(img: &HdrImage) -> (usize, Option<(u32, u32)>) {
    let mut first = None;
    let mut count = 0;
    for (i, p) in img.pixels.iter().enumerate() {
        if !p.iter().all(|c| c.is_finite()) {
            count += 1;
            first = first.or(Some((i as u32 % img.width.max(1), i as u32 / img.width.max(1))));
        }
    }
    (count, first)
}

/// A run-time error when any pixel is not finite: a frame with NaN or infinite radiance is a
/// failure, never a picture.
pub fn check_finite(img: &HdrImage) -> Result<()> {
    match non_finite_pixels(img) {
        (0, _) => Ok(()),
        (n, first) => {
            let (x, y) = first.unwrap_or_default();
            Err(runtime!(
                "the frame has {n} pixel(s) with non-finite radiance (NaN or infinity; the first at x={x}, y={y}); \
                 no image is written (TRANSLUCENT_CHECK_PASSES=1 names the pass that produced it)"
            ))
        }
    }
}

/// How two 8-bit images differ, over RGB in [0, 255].
#[derive(Clone, Copy, Debug)]
pub struct ImageDiff {
    pub rmse: f64,
    pub max_abs: u8,
    /// Fraction of pixels where some channel differs by more than 8/255.
    pub differing_fraction: f64,
}

/// The relative RMSE of `a` against the reference `b`, sqrt(Σ(a − b)² / Σ b²), over the pixels `b`
/// covers (alpha > 0) and all three colour channels. NaN when `b` covers nothing or is black where
/// it does: there is nothing to be relative to.
pub fn relative_rmse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for (p, q) in a.iter().zip(b) {
        if q[3] > 0.0 {
            for c in 0..3 {
                num += (p[c] as f64 - q[c] as f64).powi(2);
                den += (q[c] as f64).powi(2);
            }
        }
    }
    (num / den).sqrt()
}

pub fn compare(actual: &image::RgbaImage, expected: &image::RgbaImage) -> Result<ImageDiff> {
    if actual.dimensions() != expected.dimensions() {
        return Err(runtime!("image sizes differ: {:?} vs {:?}", actual.dimensions(), expected.dimensions()));
    }
    let mut sum = 0.0f64;
    let mut max_abs = 0u8;
    let mut differing = 0usize;
    for (a, e) in actual.pixels().zip(expected.pixels()) {
        let mut worst = 0u8;
        for c in 0..3 {
            let d = a[c].abs_diff(e[c]);
            sum += (d as f64).powi(2);
            worst = worst.max(d);
        }
        max_abs = max_abs.max(worst);
        differing += (worst > 8) as usize;
    }
    let n = (actual.width() * actual.height()) as f64;
    Ok(ImageDiff { rmse: (sum / (3.0 * n)).sqrt(), max_abs, differing_fraction: differing as f64 / n })
}

/// |actual − expected| × 8 per channel, for looking at what changed.
pub fn difference_image(actual: &image::RgbaImage, expected: &image::RgbaImage) -> image::RgbaImage {
    let mut out = image::RgbaImage::new(actual.width(), actual.height());
    for ((d, a), e) in out.pixels_mut().zip(actual.pixels()).zip(expected.pixels()) {
        let f = |c: usize| a[c].abs_diff(e[c]).saturating_mul(8);
        *d = image::Rgba([f(0), f(1), f(2), 255]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn filmic_is_monotonic_from_zero() {
        assert_eq!(filmic(0.0), 0.0);
        let mut last = 0.0;
        for i in 1..1000 {
            let v = filmic(i as f32 * 0.05);
            assert!(v >= last && v <= 1.0);
            last = v;
        }
    }

    #[test]
    fn srgb_matches_the_standard() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.002) - 0.002 * 12.92).abs() < 1e-7);
        assert!((srgb_encode(0.5) - (1.055 * 0.5f32.powf(1.0 / 2.4) - 0.055)).abs() < 1e-6);
    }

    #[test]
    fn auto_exposure_survives_black_and_nan() {
        let black = HdrImage { width: 2, height: 1, pixels: vec![[0.0, 0.0, 0.0, 1.0]; 2] };
        assert_eq!(auto_exposure_scale(&black), 1.0);
        let nan = HdrImage { width: 2, height: 1, pixels: vec![[f32::NAN, 0.0, 0.0, 1.0], [1.0, 1.0, 1.0, 1.0]] };
        let png = tonemap(&nan, Exposure::Auto);
        assert_eq!(png.get_pixel(0, 0)[0], 0);
    }

    #[test]
    fn histogram_bins_follow_log2_luminance() {
        let t = stop_thresholds();
        assert_eq!(luminance_bin(1.0, &t), Some(640));
        assert_eq!(luminance_bin(2f32.powf(1.0 / 16.0) * 1.0001, &t), Some(641));
        assert_eq!(luminance_bin(0.999, &t), Some(639));
        assert_eq!(luminance_bin(1e-30, &t), Some(0));
        assert_eq!(luminance_bin(1e30, &t), Some(HIST_BINS - 1));
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e-40] {
            assert_eq!(luminance_bin(bad, &t), None);
        }
        // Agrees with log2 away from the edges, over 1e-11 … 1e7 (inside [2^-40, 2^24)).
        for i in 0..1800 {
            let l = 10f32.powf(-11.0 + i as f32 * 0.01);
            let exact = ((l as f64).log2() - HIST_LOG2_MIN as f64) * HIST_BINS_PER_STOP as f64;
            if (exact - exact.round()).abs() > 1e-3 {
                assert_eq!(luminance_bin(l, &t), Some(exact.floor() as usize), "{l}");
            }
        }
        let scale = bin_exposure_scale(640, &bin_inverse_centres());
        assert!((scale as f64 - (-1.0f64 / 32.0).exp2()).abs() < 1e-7);
    }

    #[test]
    fn auto_exposure_takes_the_95th_percentile_bin() {
        // 100 pixels at 1.0 and 5 far brighter: rank ⌊104·0.95⌋ = 98 is still at 1.0.
        let mut pixels = vec![[1.0, 1.0, 1.0, 1.0]; 100];
        pixels.extend([[1e3, 1e3, 1e3, 1.0]; 5]);
        pixels.push([1e6, 1e6, 1e6, 0.0]); // background does not count
        let img = HdrImage { width: 106, height: 1, pixels };
        let lum = luminance([1.0; 4]);
        let expected = bin_exposure_scale(luminance_bin(lum, &stop_thresholds()).unwrap(), &bin_inverse_centres());
        assert_eq!(auto_exposure_scale(&img), expected);
        assert!((expected * lum - 1.0).abs() < 0.025, "within half a bin (1/32 stop) of 1/L95");
    }

    #[test]
    fn infinity_is_white_and_packing_is_rgba() {
        let img = HdrImage { width: 1, height: 1, pixels: vec![[f32::INFINITY, f32::NEG_INFINITY, 1e30, 0.5]] };
        let png = tonemap(&img, Exposure::Stops(0.0));
        assert_eq!(png.get_pixel(0, 0).0, [255, 0, 255, 128]);
        let packed = rgba8_from_packed(1, 1, &[0x8040_2010]).unwrap();
        assert_eq!(packed.get_pixel(0, 0).0, [0x10, 0x20, 0x40, 0x80]);
        assert!(rgba8_from_packed(2, 1, &[0]).is_err());
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let dir = std::env::temp_dir().join(format!("translucent-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.exr");
        let img = HdrImage { width: 3, height: 2, pixels: (0..6).map(|i| [i as f32 * 1.5, 1e-3, 1e4, 1.0]).collect() };
        write_image(&path, &img, Exposure::Auto).unwrap();
        let back = image::open(&path).unwrap().into_rgba32f();
        let flat: Vec<f32> = img.pixels.iter().flatten().copied().collect();
        assert_eq!(back.into_raw(), flat);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn unknown_extension_is_bad_input() {
        let img = HdrImage { width: 1, height: 1, pixels: vec![[0.0; 4]] };
        let err = write_image(Path::new("x.bmp"), &img, Exposure::Auto).unwrap_err();
        assert_eq!(err.exit_code(), 2);
        assert!(err.to_string().contains("x.bmp"));
    }
}
