//! Interim image output (the full version lands from the mesh branch).
use std::path::Path;

use crate::error::Result;

pub struct HdrImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 4]>,
}

pub enum Exposure {
    Auto,
    Stops(f32),
}

pub fn write_image(path: &Path, img: &HdrImage, _exposure: Exposure) -> Result<()> {
    let mut out = image::RgbaImage::new(img.width, img.height);
    for (i, p) in out.pixels_mut().enumerate() {
        let c = img.pixels[i];
        let f = |v: f32| ((v / (1.0 + v)).powf(1.0 / 2.2) * 255.0) as u8;
        *p = image::Rgba([f(c[0]), f(c[1]), f(c[2]), (c[3] * 255.0) as u8]);
    }
    out.save(path).map_err(|e| crate::runtime!("{}: {e}", path.display()))
}
