//! `translucent compare A.exr B.exr`: how far image A (a render) is from image B (the reference,
//! e.g. a path tracer's), per colour channel, over the pixels both cover: the ratio of the means,
//! the relative RMSE, the largest error, FLIP on the tone-mapped pair, and an error image.
//!
//! Definitions (c a channel, P the compared pixels, mean over P):
//! - ratio = mean(A_c) / mean(B_c);
//! - relative RMSE = sqrt(Σ (A_c − B_c)² / Σ B_c²) (as `output::relative_rmse`, per channel);
//! - largest error = max |A_c − B_c|, also given as a fraction of mean(B_c), with its pixel;
//! - FLIP (Andersson et al. 2020, NVIDIA's code through nv-flip): both images through the same
//!   exposure (B's automatic one unless given) and the renderer's filmic curve to sRGB, LDR-FLIP at
//!   67 pixels per degree, mean over P;
//! - error image: per pixel max_c |A_c − B_c| / mean(B_c), magma colours from 0 to the scale
//!   (drawn under the image), pixels outside P dark grey.
//!
//! P: the pixels fully covered in both (alpha ≥ 0.999: a render's alpha is its coverage, and a path
//! tracer's box-filtered edge pixels mix the object with the background), or those of `--mask`.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::Result;
use crate::output::{Exposure, HdrImage};
use crate::{bad_input, runtime};

/// A pixel counts as covered from this alpha on.
pub const FULL_COVERAGE: f32 = 0.999;

/// What `compare` was asked for besides the two images.
#[derive(Clone, Debug, Default)]
pub struct CompareOptions {
    /// A mask image (PNG or EXR, same size): pixels whose mean of R, G, B is at least 0.5 are compared.
    pub mask: Option<PathBuf>,
    /// Exposure in stops for the FLIP tone mapping of both images (default: B's automatic exposure).
    pub exposure: Option<f32>,
    /// The error image's full scale, as a fraction of B's mean (default: B's 99th percentile, rounded up).
    pub error_scale: Option<f64>,
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct ChannelStats {
    pub mean_a: f64,
    pub mean_b: f64,
    /// mean A / mean B; `None` where B's mean is 0.
    pub ratio: Option<f64>,
    /// sqrt(Σ(A − B)² / Σ B²); `None` where B is 0 over every compared pixel.
    pub relative_rmse: Option<f64>,
    /// max |A − B| over the compared pixels.
    pub max_error: f64,
    /// max |A − B| / mean B; `None` where B's mean is 0.
    pub max_error_relative: Option<f64>,
    /// The pixel (x, y) of the largest error.
    pub max_error_at: [u32; 2],
}

#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Comparison {
    pub a: String,
    pub b: String,
    pub width: u32,
    pub height: u32,
    /// How many pixels were compared, and how they were chosen ("covered in both" or the mask's file).
    pub pixels: usize,
    pub selection: String,
    /// R, G, B.
    pub channels: [ChannelStats; 3],
    /// The mean of FLIP over the compared pixels (0: identical, 1: as different as it gets).
    pub flip_mean: f64,
    /// The exposure both were tone-mapped with for FLIP, in stops.
    pub flip_exposure_stops: f64,
    /// The error image's full scale (fraction of B's mean).
    pub error_scale: f64,
}

/// Reads a linear EXR. Anything else — a missing file, another format, a non-finite pixel — is bad
/// input naming the file.
pub fn read_exr(path: &Path) -> Result<HdrImage> {
    let bytes = std::fs::read(path).map_err(|e| bad_input!("{}: cannot be read: {e}", path.display()))?;
    if !bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return Err(bad_input!("{}: not an OpenEXR image", path.display()));
    }
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::OpenExr)
        .map_err(|e| bad_input!("{}: not a readable OpenEXR image: {e}", path.display()))?;
    let rgba = img.to_rgba32f();
    let (width, height) = rgba.dimensions();
    let pixels: Vec<[f32; 4]> = rgba.pixels().map(|p| p.0).collect();
    let (bad, first) = crate::output::non_finite_pixels(&HdrImage { width, height, pixels: pixels.clone() });
    if bad > 0 {
        let (x, y) = first.unwrap_or_default();
        return Err(bad_input!("{}: {bad} pixel(s) are NaN or infinite, the first at ({x}, {y})", path.display()));
    }
    Ok(HdrImage { width, height, pixels })
}

/// The pixels the mask file selects (mean of R, G, B ≥ 0.5), checked against the images' size.
fn read_mask(path: &Path, width: u32, height: u32) -> Result<Vec<bool>> {
    let img =
        image::open(path).map_err(|e| bad_input!("--mask {}: cannot be read as an image: {e}", path.display()))?;
    let rgba = img.to_rgba32f();
    if rgba.dimensions() != (width, height) {
        return Err(bad_input!(
            "--mask {}: is {}x{}, the images are {width}x{height}",
            path.display(),
            rgba.width(),
            rgba.height()
        ));
    }
    Ok(rgba.pixels().map(|p| (p[0] + p[1] + p[2]) / 3.0 >= 0.5).collect())
}

/// Compares A against the reference B. The error image, when asked for, is returned with the result.
pub fn compare(a_path: &Path, b_path: &Path, options: &CompareOptions) -> Result<(Comparison, image::RgbImage)> {
    let a = read_exr(a_path)?;
    let b = read_exr(b_path)?;
    if (a.width, a.height) != (b.width, b.height) {
        return Err(bad_input!(
            "{}: is {}x{}, but {} is {}x{}: the sizes must be the same",
            b_path.display(),
            b.width,
            b.height,
            a_path.display(),
            a.width,
            a.height
        ));
    }
    let (selected, selection) = match &options.mask {
        Some(m) => (read_mask(m, a.width, a.height)?, format!("mask {}", m.display())),
        None => (
            a.pixels.iter().zip(&b.pixels).map(|(p, q)| p[3] >= FULL_COVERAGE && q[3] >= FULL_COVERAGE).collect(),
            "covered in both".to_string(),
        ),
    };
    let pixels = selected.iter().filter(|&&s| s).count();
    if pixels == 0 {
        return Err(bad_input!(
            "{} and {}: no pixel to compare ({})",
            a_path.display(),
            b_path.display(),
            if options.mask.is_some() { "the mask selects none" } else { "none is fully covered in both" }
        ));
    }
    if let Some(s) = options.error_scale {
        if !(s.is_finite() && s > 0.0) {
            return Err(bad_input!("--error-scale {s}: must be a positive number"));
        }
    }
    let channels = std::array::from_fn(|c| channel_stats(&a, &b, &selected, c));
    let (flip_mean, flip_exposure_stops) = flip(&a, &b, &selected, options.exposure)?;
    let (error_image, error_scale) = error_image(&a, &b, &selected, &channels, options.error_scale)?;
    Ok((
        Comparison {
            a: a_path.display().to_string(),
            b: b_path.display().to_string(),
            width: a.width,
            height: a.height,
            pixels,
            selection,
            channels,
            flip_mean,
            flip_exposure_stops,
            error_scale,
        },
        error_image,
    ))
}

fn channel_stats(a: &HdrImage, b: &HdrImage, selected: &[bool], c: usize) -> ChannelStats {
    let (mut sa, mut sb, mut d2, mut b2, mut n) = (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0usize);
    let (mut max_error, mut at) = (-1.0f64, [0u32; 2]);
    for (i, ((p, q), _)) in a.pixels.iter().zip(&b.pixels).zip(selected).enumerate().filter(|(_, (_, &s))| s) {
        let (x, y) = (p[c] as f64, q[c] as f64);
        sa += x;
        sb += y;
        d2 += (x - y).powi(2);
        b2 += y * y;
        n += 1;
        if (x - y).abs() > max_error {
            max_error = (x - y).abs();
            at = [i as u32 % a.width, i as u32 / a.width];
        }
    }
    let (mean_a, mean_b) = (sa / n as f64, sb / n as f64);
    let finite = |v: f64| Some(v).filter(|v| v.is_finite());
    ChannelStats {
        mean_a,
        mean_b,
        ratio: finite(mean_a / mean_b),
        relative_rmse: finite((d2 / b2).sqrt()),
        max_error,
        max_error_relative: finite(max_error / mean_b),
        max_error_at: at,
    }
}

/// Mean FLIP over the selected pixels, and the exposure (stops) both were tone-mapped with.
fn flip(a: &HdrImage, b: &HdrImage, selected: &[bool], exposure: Option<f32>) -> Result<(f64, f64)> {
    let scale = crate::output::exposure_scale(b, exposure.map(Exposure::Stops).unwrap_or(Exposure::Auto));
    let stops = scale.log2();
    if !stops.is_finite() {
        return Err(bad_input!("--exposure: {stops} stops is not a usable exposure"));
    }
    let ldr = |img: &HdrImage| {
        // Coverage is not part of the picture FLIP sees: alpha 1 everywhere.
        let opaque = HdrImage {
            width: img.width,
            height: img.height,
            pixels: img.pixels.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect(),
        };
        let rgba = crate::output::tonemap(&opaque, Exposure::Stops(stops));
        let rgb: Vec<u8> = rgba.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect();
        nv_flip::FlipImageRgb8::with_data(img.width, img.height, &rgb)
    };
    let map = nv_flip::flip(ldr(b), ldr(a), nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec();
    if map.len() != selected.len() {
        return Err(runtime!("FLIP returned {} values for {} pixels", map.len(), selected.len()));
    }
    let (sum, n) = map
        .iter()
        .zip(selected)
        .filter(|(_, &s)| s)
        .fold((0.0f64, 0usize), |(sum, n), (v, _)| (sum + *v as f64, n + 1));
    Ok((sum / n as f64, stops as f64))
}

/// 1, 2 or 5 × 10^k, the smallest at or above `v`.
fn nice_ceiling(v: f64) -> f64 {
    let v = v.max(1e-6);
    let decade = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * decade).find(|s| *s >= v * (1.0 - 1e-12)).unwrap_or(10.0 * decade)
}

/// The false-colour error image (max over channels of |A − B| / mean B, magma from 0 to the scale)
/// with its colour bar and scale drawn under it, and the scale used.
fn error_image(
    a: &HdrImage,
    b: &HdrImage,
    selected: &[bool],
    channels: &[ChannelStats; 3],
    scale: Option<f64>,
) -> Result<(image::RgbImage, f64)> {
    let relative: Vec<Option<f64>> = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .zip(selected)
        .map(|((p, q), &s)| {
            s.then(|| {
                (0..3)
                    .filter(|&c| channels[c].mean_b > 0.0)
                    .map(|c| (p[c] as f64 - q[c] as f64).abs() / channels[c].mean_b)
                    .fold(0.0, f64::max)
            })
        })
        .collect();
    let scale = scale.unwrap_or_else(|| {
        let mut v: Vec<f64> = relative.iter().flatten().copied().collect();
        v.sort_by(|x, y| x.total_cmp(y));
        nice_ceiling(v[((v.len() - 1) as f64 * 0.99) as usize])
    });
    let lut = nv_flip::magma_lut().to_vec();
    let colour = |t: f64| {
        let i = ((t / scale).clamp(0.0, 1.0) * 255.0).round() as usize;
        [lut[3 * i], lut[3 * i + 1], lut[3 * i + 2]]
    };
    const BAR: u32 = 44;
    let width = a.width.max(220);
    let height = a.height + BAR;
    let mut buf = vec![0u8; (width * height * 3) as usize];
    {
        use plotters::prelude::*;
        crate::plot::register_font()?;
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        let fail = |e: String| runtime!("the error image could not be drawn: {e}");
        root.fill(&RGBColor(24, 24, 24)).map_err(|e| fail(e.to_string()))?;
        for (i, r) in relative.iter().enumerate() {
            let (x, y) = ((i as u32 % a.width) as i32, (i as u32 / a.width) as i32);
            let c = match r {
                Some(t) => colour(*t),
                None => [48, 48, 48],
            };
            root.draw_pixel((x, y), &RGBColor(c[0], c[1], c[2])).map_err(|e| fail(e.to_string()))?;
        }
        let (x0, x1, y0) = (10i32, width as i32 - 10, a.height as i32 + 6);
        for x in x0..x1 {
            let c = colour(scale * (x - x0) as f64 / (x1 - 1 - x0) as f64);
            root.draw(&Rectangle::new([(x, y0), (x + 1, y0 + 12)], RGBColor(c[0], c[1], c[2]).filled()))
                .map_err(|e| fail(e.to_string()))?;
        }
        let style = TextStyle::from(("sans-serif", 13).into_font()).color(&WHITE);
        root.draw_text("0", &style, (x0, y0 + 15)).map_err(|e| fail(e.to_string()))?;
        let label = format!("{} × mean B", trim_number(scale));
        let w = root.estimate_text_size(&label, &style).map(|s| s.0 as i32).unwrap_or(60);
        root.draw_text(&label, &style, (x1 - w, y0 + 15)).map_err(|e| fail(e.to_string()))?;
        root.draw_text("|A−B|", &style, ((x0 + x1) / 2 - 18, y0 + 15)).map_err(|e| fail(e.to_string()))?;
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    let img = image::RgbImage::from_raw(width, height, buf).ok_or_else(|| runtime!("error image buffer size"))?;
    Ok((img, scale))
}

fn trim_number(v: f64) -> String {
    let s = format!("{v:.6}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The comparison as the text `compare` prints.
pub fn report(c: &Comparison) -> String {
    let opt = |v: Option<f64>, f: &dyn Fn(f64) -> String| v.map(f).unwrap_or_else(|| "–".to_string());
    let mut s = format!(
        "A: {}\nB: {} (reference)\n{} of {}x{} pixels compared ({})\n\n| channel | mean A | mean B | A / B | relative RMSE | largest abs(A − B) | / mean B | at |\n|---|---:|---:|---:|---:|---:|---:|---|\n",
        c.a, c.b, c.pixels, c.width, c.height, c.selection
    );
    for (name, ch) in ["R", "G", "B"].iter().zip(&c.channels) {
        s += &format!(
            "| {name} | {:.6e} | {:.6e} | {} | {} | {:.4e} | {} | ({}, {}) |\n",
            ch.mean_a,
            ch.mean_b,
            opt(ch.ratio, &|v| format!("{v:.4}")),
            opt(ch.relative_rmse, &|v| format!("{:.3}%", 100.0 * v)),
            ch.max_error,
            opt(ch.max_error_relative, &|v| format!("{v:.3}")),
            ch.max_error_at[0],
            ch.max_error_at[1]
        );
    }
    s += &format!(
        "\nFLIP (both tone-mapped at {:+.2} stops): mean {:.4} over the compared pixels\n",
        c.flip_exposure_stops, c.flip_mean
    );
    s
}

/// Writes the error image (PNG), checking the path first.
pub fn write_error_image(path: &Path, img: &image::RgbImage) -> Result<()> {
    crate::output::write_file(path, &crate::output::encode(img.clone(), image::ImageFormat::Png)?)
}
