//! Checks of a rendered image that a mean or an RMSE does not see: negative light, and isolated
//! dots (speckles) that an estimator with the right mean can still leave. Used by the tests
//! (tests/image_quality.rs, tests/convergence.rs).

use crate::output::{luminance, HdrImage};

/// What [`inspect`] found in an image's covered pixels (alpha ≥ 0.999).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quality {
    /// Covered pixels.
    pub covered: usize,
    /// Covered pixels with a channel below zero, the lowest such channel, and the first (x, y).
    pub negative: usize,
    pub lowest: f32,
    pub first_negative: Option<(u32, u32)>,
    /// Covered pixels whose whole 3×3 neighbourhood is covered and whose luminance is below half
    /// (dark) or above twice (bright) the median of those nine luminances.
    pub dark_dots: usize,
    pub bright_dots: usize,
}

impl Quality {
    /// Isolated dots of either kind.
    pub fn dots(&self) -> usize {
        self.dark_dots + self.bright_dots
    }
}

fn covered(p: [f32; 4]) -> bool {
    p[3] >= 0.999
}

/// Negative pixels and isolated dots of `img` (see [`Quality`]). The dots' test is the one a
/// reader's eye makes at 100%: a pixel that stands out of its 3×3 neighbourhood by more than a
/// factor of two. Edge pixels of the object (a neighbour uncovered) are left out: a silhouette
/// pixel is rightly unlike the background beside it.
pub fn inspect(img: &HdrImage) -> Quality {
    let (w, h) = (img.width as usize, img.height as usize);
    let at = |x: usize, y: usize| img.pixels[y * w + x];
    let mut q = Quality { lowest: 0.0, ..Quality::default() };
    for y in 0..h {
        for x in 0..w {
            let p = at(x, y);
            if !covered(p) {
                continue;
            }
            q.covered += 1;
            let low = p[0].min(p[1]).min(p[2]);
            if low < 0.0 {
                q.negative += 1;
                q.lowest = q.lowest.min(low);
                q.first_negative = q.first_negative.or(Some((x as u32, y as u32)));
            }
            if x == 0 || y == 0 || x + 1 == w || y + 1 == h {
                continue;
            }
            let mut around = [0.0f32; 9];
            let mut all_covered = true;
            for (k, slot) in around.iter_mut().enumerate() {
                let n = at(x + k % 3 - 1, y + k / 3 - 1);
                all_covered &= covered(n);
                *slot = luminance(n);
            }
            if !all_covered {
                continue;
            }
            around.sort_by(f32::total_cmp);
            let (median, l) = (around[4], luminance(p));
            if l < 0.5 * median {
                q.dark_dots += 1;
            } else if l > 2.0 * median && median > 0.0 {
                q.bright_dots += 1;
            }
        }
    }
    q
}

/// The `fraction` quantile (0.999 for the 99.9th percentile) of the per-pixel error
/// max over channels |a − b| / (mean of b's covered luminance), over the pixels both cover; 0
/// when none is. The tail of the errors, where an RMSE averages a few bad pixels away.
pub fn error_quantile(a: &HdrImage, b: &HdrImage, fraction: f64) -> f64 {
    let both: Vec<usize> = (0..b.pixels.len()).filter(|&i| covered(a.pixels[i]) && covered(b.pixels[i])).collect();
    if both.is_empty() {
        return 0.0;
    }
    let mean = both.iter().map(|&i| luminance(b.pixels[i]) as f64).sum::<f64>() / both.len() as f64;
    let mut errors: Vec<f64> = both
        .iter()
        .map(|&i| (0..3).map(|c| (a.pixels[i][c] as f64 - b.pixels[i][c] as f64).abs()).fold(0.0, f64::max) / mean)
        .collect();
    errors.sort_by(f64::total_cmp);
    let k = ((errors.len() as f64 * fraction).ceil() as usize).clamp(1, errors.len()) - 1;
    errors[k]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat(w: u32, h: u32, v: f32) -> HdrImage {
        HdrImage { width: w, height: h, pixels: vec![[v, v, v, 1.0]; (w * h) as usize] }
    }

    #[test]
    fn a_flat_image_is_clean() {
        let q = inspect(&flat(8, 8, 0.3));
        assert_eq!((q.covered, q.negative, q.dots()), (64, 0, 0));
    }

    #[test]
    fn finds_negative_pixels_and_dots() {
        let mut img = flat(8, 8, 1.0);
        img.pixels[3 * 8 + 3] = [-0.2, 0.1, 0.1, 1.0];
        img.pixels[5 * 8 + 5] = [3.0, 3.0, 3.0, 1.0];
        let q = inspect(&img);
        assert_eq!((q.negative, q.lowest, q.first_negative), (1, -0.2, Some((3, 3))));
        assert_eq!((q.dark_dots, q.bright_dots), (1, 1));
    }

    #[test]
    fn edge_pixels_of_the_object_are_not_dots() {
        let mut img = flat(8, 8, 1.0);
        img.pixels[3 * 8 + 4] = [0.0, 0.0, 0.0, 0.0]; // background beside (3, 3)
        img.pixels[3 * 8 + 3] = [0.1, 0.1, 0.1, 1.0];
        assert_eq!(inspect(&img).dots(), 0);
    }

    #[test]
    fn the_error_tail_sees_two_bad_pixels_in_a_thousand() {
        let b = flat(10, 100, 1.0);
        let mut a = b.clone();
        a.pixels[17] = [1.5, 1.0, 1.0, 1.0];
        a.pixels[400] = [1.0, 0.5, 1.0, 1.0];
        assert_eq!(error_quantile(&a, &b, 0.999), 0.5);
        assert_eq!(error_quantile(&a, &b, 0.99), 0.0);
    }
}
