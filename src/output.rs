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

/// The scale that maps the 95th-percentile luminance of the covered pixels to 1.0 before the tone
/// curve (≈ 0.8 after it): highlights keep some room and a few hot pixels cannot darken the image.
/// An all-black image gets scale 1.
pub fn auto_exposure_scale(img: &HdrImage) -> f32 {
    let mut lum: Vec<f32> =
        img.pixels.iter().filter(|p| p[3] > 0.0).map(|&p| luminance(p)).filter(|l| l.is_finite() && *l > 0.0).collect();
    if lum.is_empty() {
        return 1.0;
    }
    let k = ((lum.len() - 1) as f32 * 0.95) as usize;
    let (_, p95, _) = lum.select_nth_unstable_by(k, f32::total_cmp);
    1.0 / *p95
}

/// ACES filmic curve, Narkowicz's 2015 fit: maps [0, ∞) to [0, 1), monotonic, f(0) = 0.
pub fn filmic(x: f32) -> f32 {
    let x = x.max(0.0);
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

/// Exposure → filmic curve → sRGB → 8 bits; alpha from coverage. NaN becomes black.
pub fn tonemap(img: &HdrImage, exposure: Exposure) -> image::RgbaImage {
    let scale = match exposure {
        Exposure::Auto => auto_exposure_scale(img),
        Exposure::Stops(s) => 2f32.powf(s),
    };
    let to8 = |v: f32| (srgb_encode(filmic(if v.is_nan() { 0.0 } else { v * scale })) * 255.0 + 0.5) as u8;
    let mut out = image::RgbaImage::new(img.width, img.height);
    for (dst, src) in out.pixels_mut().zip(&img.pixels) {
        let alpha = (src[3].clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        *dst = image::Rgba([to8(src[0]), to8(src[1]), to8(src[2]), alpha]);
    }
    out
}

/// Writes `.exr` (linear float RGBA, untouched) or `.png` (tone-mapped sRGB), by extension.
pub fn write_image(path: &Path, img: &HdrImage, exposure: Exposure) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    match ext.as_str() {
        "exr" => {
            let raw: Vec<f32> = img.pixels.iter().flatten().copied().collect();
            let buffer = image::Rgba32FImage::from_raw(img.width, img.height, raw).ok_or_else(|| {
                runtime!("{}: pixel count does not match {}x{}", path.display(), img.width, img.height)
            })?;
            buffer.save(path).map_err(|e| runtime!("cannot write {}: {e}", path.display()))
        }
        "png" => tonemap(img, exposure).save(path).map_err(|e| runtime!("cannot write {}: {e}", path.display())),
        _ => Err(bad_input!("{}: unknown image format; use .png or .exr", path.display())),
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
