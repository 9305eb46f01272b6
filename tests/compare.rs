//! `translucent compare`: on EXR pairs whose answers are known by construction (no GPU needed).

mod common;

use std::path::{Path, PathBuf};

use common::{output_dir, translucent};
use translucent::compare::{compare, read_exr, CompareOptions};
use translucent::output::{write_image, Exposure, HdrImage};

const W: u32 = 48;
const H: u32 = 32;

fn path(name: &str) -> PathBuf {
    output_dir().join(format!("compare-{name}"))
}

/// A reference image: a smooth gradient, covered (alpha 1) inside a disk of radius 12 about
/// (24, 16), alpha 0 (and radiance 0) outside.
fn reference() -> HdrImage {
    let pixels = (0..W * H)
        .map(|i| {
            let (x, y) = ((i % W) as f32, (i / W) as f32);
            if (x - 24.0).powi(2) + (y - 16.0).powi(2) <= 144.0 {
                [0.1 + 0.01 * x, 0.2 + 0.005 * y, 0.05 + 0.001 * (x + y), 1.0]
            } else {
                [0.0, 0.0, 0.0, 0.0]
            }
        })
        .collect();
    HdrImage { width: W, height: H, pixels }
}

fn write(name: &str, img: &HdrImage) -> PathBuf {
    let p = path(name);
    write_image(&p, img, Exposure::Auto).expect("write EXR");
    p
}

fn scaled(img: &HdrImage, k: [f32; 3]) -> HdrImage {
    let pixels = img.pixels.iter().map(|p| [p[0] * k[0], p[1] * k[1], p[2] * k[2], p[3]]).collect();
    HdrImage { pixels, ..img.clone() }
}

fn covered(img: &HdrImage) -> usize {
    img.pixels.iter().filter(|p| p[3] > 0.0).count()
}

#[test]
fn exr_round_trip_keeps_values_and_coverage() {
    let b = reference();
    let p = write("round-trip.exr", &b);
    let back = read_exr(&p).expect("read");
    assert_eq!((back.width, back.height), (W, H));
    assert_eq!(back.pixels, b.pixels);
}

#[test]
fn identical_images_compare_as_identical() {
    let b = write("same-b.exr", &reference());
    let (c, _) = compare(&b, &b, &CompareOptions::default()).expect("compare");
    assert_eq!(c.pixels, covered(&reference()));
    for ch in &c.channels {
        assert_eq!(ch.ratio, Some(1.0));
        assert_eq!(ch.relative_rmse, Some(0.0));
        assert_eq!(ch.max_error, 0.0);
    }
    assert_eq!(c.flip_mean, 0.0);
}

#[test]
fn per_channel_scale_gives_known_ratio_rmse_and_largest_error() {
    let b_img = reference();
    let k = [2.0f32, 1.0, 0.5];
    let a = write("scaled-a.exr", &scaled(&b_img, k));
    let b = write("scaled-b.exr", &b_img);
    let (c, _) = compare(&a, &b, &CompareOptions::default()).expect("compare");
    for (ch, s) in c.channels.iter().zip(k) {
        let s = s as f64;
        // A = s·B: the ratio of means is s, the relative RMSE |s − 1|, and the largest error
        // |s − 1|·max B, at the pixel where B is largest.
        assert!((ch.ratio.unwrap() - s).abs() < 1e-6, "ratio {:?} vs {s}", ch.ratio);
        assert!((ch.relative_rmse.unwrap() - (s - 1.0).abs()).abs() < 1e-6);
        let c_idx = c.channels.iter().position(|x| std::ptr::eq(x, ch)).unwrap();
        let max_b = b_img.pixels.iter().filter(|p| p[3] > 0.0).map(|p| p[c_idx] as f64).fold(0.0, f64::max);
        assert!((ch.max_error - (s - 1.0).abs() * max_b).abs() < 1e-6 * max_b, "{} vs {}", ch.max_error, max_b);
        assert!((ch.max_error_relative.unwrap() - ch.max_error / ch.mean_b).abs() < 1e-12);
    }
    // Red grows with x: its largest error is on the disk's right edge (x = 36, y = 16).
    assert_eq!(c.channels[0].max_error_at, [36, 16]);
    assert!(c.flip_mean > 0.0);
}

#[test]
fn only_pixels_fully_covered_in_both_are_compared() {
    let b_img = reference();
    // A covers the left half only, and a partly covered pixel in B (alpha 0.5) is left out too.
    let mut a_img = scaled(&b_img, [3.0; 3]);
    for (i, p) in a_img.pixels.iter_mut().enumerate() {
        if i as u32 % W >= 24 {
            *p = [100.0, 100.0, 100.0, 0.0];
        }
    }
    let mut b_edge = b_img.clone();
    b_edge.pixels[(16 * W + 13) as usize][3] = 0.5;
    let a = write("half-a.exr", &a_img);
    let b = write("half-b.exr", &b_edge);
    let (c, _) = compare(&a, &b, &CompareOptions::default()).expect("compare");
    let expected = (0..W * H).filter(|&i| i % W < 24 && b_edge.pixels[i as usize][3] >= 0.999).count();
    assert_eq!(c.pixels, expected);
    for ch in &c.channels {
        assert!((ch.ratio.unwrap() - 3.0).abs() < 1e-6);
    }
}

#[test]
fn a_mask_selects_the_pixels() {
    let b_img = reference();
    // A is B doubled in the top half, B elsewhere; a mask of the bottom half sees no difference.
    let mut a_img = b_img.clone();
    for (i, p) in a_img.pixels.iter_mut().enumerate() {
        if (i as u32) / W < H / 2 {
            for v in p.iter_mut().take(3) {
                *v *= 2.0;
            }
        }
    }
    let mask =
        image::RgbImage::from_fn(W, H, |_, y| if y >= H / 2 { image::Rgb([255; 3]) } else { image::Rgb([0; 3]) });
    let mask_path = path("mask.png");
    mask.save(&mask_path).unwrap();
    let a = write("mask-a.exr", &a_img);
    let b = write("mask-b.exr", &b_img);
    let (c, _) =
        compare(&a, &b, &CompareOptions { mask: Some(mask_path.clone()), ..Default::default() }).expect("compare");
    assert_eq!(c.pixels, (W * H / 2) as usize);
    assert!(c.selection.contains("mask"));
    for ch in &c.channels {
        assert_eq!(ch.ratio, Some(1.0));
        assert_eq!(ch.max_error, 0.0);
    }
    // A mask of the wrong size is bad input naming it.
    image::RgbImage::new(W + 1, H).save(path("mask-small.png")).unwrap();
    let out = translucent(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--mask",
        path("mask-small.png").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("mask-small.png"));
}

#[test]
fn json_output_has_the_numbers_and_the_error_image_its_scale() {
    let b_img = reference();
    let a = write("json-a.exr", &scaled(&b_img, [1.5, 1.0, 1.0]));
    let b = write("json-b.exr", &b_img);
    let err = path("json-error.png");
    let out = translucent(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--json",
        "--error-image",
        err.to_str().unwrap(),
        "--error-scale",
        "0.5",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(v["pixels"].as_u64().unwrap() as usize, covered(&b_img));
    assert!((v["channels"][0]["ratio"].as_f64().unwrap() - 1.5).abs() < 1e-6);
    assert_eq!(v["channels"][1]["ratio"].as_f64().unwrap(), 1.0);
    assert_eq!(v["error_scale"].as_f64().unwrap(), 0.5);
    assert!(v["flip_mean"].as_f64().unwrap() > 0.0);
    // The error image: the picture with a colour bar under it; uncovered pixels dark grey, a
    // pixel without error the bottom of the colour map, the bar's right end its top.
    let img = image::open(&err).expect("error image").to_rgb8();
    assert_eq!(img.dimensions(), (W.max(220), H + 44));
    assert_eq!(img.get_pixel(0, 0).0, [48, 48, 48]);
    let lut = nv_flip_lut();
    let bottom = [lut[0], lut[1], lut[2]];
    let top = [lut[765], lut[766], lut[767]];
    assert_ne!(img.get_pixel(24, 16).0, bottom, "red differs by half of itself: not zero error");
    assert_eq!(img.get_pixel(10, H + 10).0, bottom);
    assert_eq!(img.get_pixel(W.max(220) - 11, H + 10).0, top);
}

/// The magma colour map the error image uses (nv-flip's), as 256 RGB triples.
fn nv_flip_lut() -> Vec<u8> {
    nv_flip::magma_lut().to_vec()
}

fn expect_bad_input(args: &[&str], names: &Path) {
    let out = translucent(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.starts_with("error:"), "{stderr}");
    assert!(stderr.contains(names.file_name().unwrap().to_str().unwrap()), "{stderr} should name {}", names.display());
}

#[test]
fn bad_input_exits_2_naming_the_file() {
    let b = write("bad-b.exr", &reference());
    // Sizes differ.
    let small = write("bad-small.exr", &HdrImage { width: 4, height: 4, pixels: vec![[1.0, 1.0, 1.0, 1.0]; 16] });
    expect_bad_input(&["compare", small.to_str().unwrap(), b.to_str().unwrap()], &b);
    // A NaN pixel (written through the image crate directly: write_image refuses NaN).
    let mut raw: Vec<f32> = reference().pixels.iter().flatten().copied().collect();
    raw[4 * 100] = f32::NAN;
    let nan = path("bad-nan.exr");
    image::Rgba32FImage::from_raw(W, H, raw).unwrap().save(&nan).unwrap();
    expect_bad_input(&["compare", nan.to_str().unwrap(), b.to_str().unwrap()], &nan);
    // Not an EXR: a PNG, and text.
    let png = path("bad-png.exr");
    image::RgbImage::new(W, H).save_with_format(&png, image::ImageFormat::Png).unwrap();
    expect_bad_input(&["compare", b.to_str().unwrap(), png.to_str().unwrap()], &png);
    let text = path("bad-text.exr");
    std::fs::write(&text, "not an image\n").unwrap();
    expect_bad_input(&["compare", text.to_str().unwrap(), b.to_str().unwrap()], &text);
    // Missing.
    let missing = path("bad-missing.exr");
    expect_bad_input(&["compare", b.to_str().unwrap(), missing.to_str().unwrap()], &missing);
    // Nothing covered in both.
    let empty = write("bad-empty.exr", &HdrImage { width: W, height: H, pixels: vec![[0.0; 4]; (W * H) as usize] });
    let out = translucent(&["compare", empty.to_str().unwrap(), b.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no pixel to compare"));
    // An error image that cannot be written is refused before the work.
    let out =
        translucent(&["compare", b.to_str().unwrap(), b.to_str().unwrap(), "--error-image", "/nonexistent/e.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--error-image"));
}

#[test]
fn a_reference_black_in_a_channel_gives_no_ratio_not_nan() {
    let b_img = scaled(&reference(), [1.0, 1.0, 0.0]);
    let a = write("black-a.exr", &reference());
    let b = write("black-b.exr", &b_img);
    let out = translucent(&["compare", a.to_str().unwrap(), b.to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert!(v["channels"][2]["ratio"].is_null());
    assert!(v["channels"][2]["relative_rmse"].is_null());
}
