//! Joins PNG frames into one animated PNG (for the README's animations):
//! `cargo run --release --example apng -- OUT.png DELAY_MS FRAME.png…`

use std::io::BufWriter;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, delay, frames @ ..] = args.as_slice() else {
        eprintln!("usage: apng OUT.png DELAY_MS FRAME.png…");
        std::process::exit(2);
    };
    let delay: u16 = delay.parse().expect("DELAY_MS: a whole number of milliseconds");
    let images: Vec<image::RgbaImage> =
        frames.iter().map(|f| image::open(f).unwrap_or_else(|e| panic!("{f}: {e}")).into_rgba8()).collect();
    let (w, h) = images.first().expect("at least one frame").dimensions();
    let file = std::fs::File::create(out).unwrap_or_else(|e| panic!("{out}: {e}"));
    let mut encoder = png::Encoder::new(BufWriter::new(file), w, h);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_animated(images.len() as u32, 0).unwrap();
    encoder.set_frame_delay(delay, 1000).unwrap();
    let mut writer = encoder.write_header().unwrap();
    for (f, image) in frames.iter().zip(&images) {
        assert_eq!(image.dimensions(), (w, h), "{f}: every frame must be {w}x{h}");
        writer.write_image_data(image.as_raw()).unwrap();
    }
    writer.finish().unwrap();
    eprintln!("wrote {out} ({} frames, {w}x{h}, {delay} ms each)", images.len());
}
