//! Environment light: radiance arriving from every direction, read from an image (latitude-
//! longitude 2:1, or pbrt-v4's square equal-area octahedral map) or constant, and sampled into K
//! directional lights whose directions are stratified by the map's energy. Each sample is then an
//! ordinary shadowed directional light, so the irradiance at every point integrates the map with
//! visibility and converges as K grows.
//!
//! Directions: world space, +y up. A latitude-longitude map follows Mitsuba 3's `envmap` (so that
//! `export mitsuba` can hand it the same file, src/emitters/envmap.cpp): u = atan2(x, −z)/2π
//! (mod 1) across, v = acos(y)/π down: the left edge looks along −z, a quarter across along +x. An equal-area octahedral map follows pbrt-v4's `EqualAreaSquareToSphere` (Clarberg 2008)
//! in the light's own frame, z up there; pbrt scenes give the frame with the light's transform.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DMat3, DVec3, Mat3, Vec3};

use crate::error::Result;
use crate::scene::Light;
use crate::{bad_input, world::MAX_TEXTURE_SIDE, world::MAX_TEXTURE_TEXELS};

/// How an image's texels map to directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// 2:1, Mitsuba's convention (see the module's notes).
    LatLong,
    /// Square, pbrt-v4's equal-area octahedral map.
    Octahedral,
}

/// Radiance per direction.
#[derive(Clone, Debug)]
pub enum Radiance {
    Constant(Vec3),
    Image { width: u32, height: u32, layout: Layout, texels: Arc<Vec<[f32; 3]>> },
}

impl PartialEq for Radiance {
    /// The same map: the same texels (the same shared copy compares at once).
    fn eq(&self, other: &Radiance) -> bool {
        match (self, other) {
            (Radiance::Constant(a), Radiance::Constant(b)) => a == b,
            (
                Radiance::Image { width, height, layout, texels },
                Radiance::Image { width: w2, height: h2, layout: l2, texels: t2 },
            ) => (width, height, layout) == (w2, h2, l2) && (Arc::ptr_eq(texels, t2) || texels == t2),
            _ => false,
        }
    }
}

/// The default number of directions an environment is sampled in (`--env-samples`).
pub const DEFAULT_SAMPLES: u32 = 64;

/// An environment light and its samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// Where it came from, for messages.
    pub name: String,
    pub radiance: Radiance,
    /// Multiplies the radiance.
    pub scale: f32,
    /// From the map's frame to the world (a rotation).
    pub to_world: Mat3,
    /// Directions sampled.
    pub samples: u32,
}

impl Environment {
    /// Reads an EXR or Radiance HDR (linear) or a PNG (sRGB, decoded to linear) map; `shown`
    /// names it in messages. 2:1 images are latitude-longitude, square ones equal-area
    /// octahedral; every texel must be finite and ≥ 0.
    pub fn load(path: &std::path::Path, shown: &str) -> Result<Radiance> {
        let meta = std::fs::metadata(path).map_err(|e| bad_input!("{shown}: {e}"))?;
        if !meta.is_file() {
            return Err(bad_input!("{shown}: not a regular file"));
        }
        let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
        let reader = image::ImageReader::open(path).map_err(|e| bad_input!("{shown}: {e}"))?;
        let reader = reader.with_guessed_format().map_err(|e| bad_input!("{shown}: {e}"))?;
        let (width, height) = reader.into_dimensions().map_err(|e| bad_input!("{shown}: not an image: {e}"))?;
        if width == 0
            || height == 0
            || width > MAX_TEXTURE_SIDE
            || height > MAX_TEXTURE_SIDE
            || width as u64 * height as u64 > MAX_TEXTURE_TEXELS
        {
            return Err(bad_input!(
                "{shown}: {width}x{height}: an environment map's sides must be between 1 and {MAX_TEXTURE_SIDE}, with at most {MAX_TEXTURE_TEXELS} texels"
            ));
        }
        let layout = if width == 2 * height {
            Layout::LatLong
        } else if width == height {
            Layout::Octahedral
        } else {
            return Err(bad_input!(
                "{shown}: {width}x{height}: an environment map is 2:1 (latitude-longitude) or square (equal-area octahedral)"
            ));
        };
        let img = image::open(path).map_err(|e| bad_input!("{shown}: not an image: {e}"))?.into_rgb32f();
        let srgb = ext == "png";
        let decode = |c: f32| {
            if !srgb {
                c
            } else if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        let texels: Vec<[f32; 3]> = img.pixels().map(|p| [decode(p[0]), decode(p[1]), decode(p[2])]).collect();
        if let Some((i, t)) = texels.iter().enumerate().find(|(_, t)| !t.iter().all(|c| c.is_finite() && *c >= 0.0)) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(bad_input!("{shown}: texel ({x}, {y}) is {t:?}: radiance must be finite and ≥ 0"));
        }
        Ok(Radiance::Image { width, height, layout, texels: Arc::new(texels) })
    }

    /// Checks the scale, the rotation, the sample count and that the map sends any light.
    pub fn validate(&self) -> Result<()> {
        if !(self.scale.is_finite() && self.scale >= 0.0) {
            return Err(bad_input!("--env-scale {}: must be finite and ≥ 0", self.scale));
        }
        // A rotation, or a mirrored one (a left-handed pbrt scene is mirrored into ours).
        if !self.to_world.is_finite() || (self.to_world.determinant().abs() - 1.0).abs() > 1e-3 {
            return Err(bad_input!("{}: the environment's frame must be a rotation", self.name));
        }
        if self.samples == 0 || self.samples > MAX_SAMPLES {
            return Err(bad_input!("--env-samples {}: must be between 1 and {MAX_SAMPLES}", self.samples));
        }
        if let Radiance::Constant(l) = self.radiance {
            if !(l.is_finite() && l.min_element() >= 0.0) {
                return Err(bad_input!("{}: radiance {l} must be finite and ≥ 0", self.name));
            }
        }
        Ok(())
    }

    /// Several environments as one (pbrt-v4 scenes may give several `infinite` lights, e.g. a map
    /// and a constant): constants add; otherwise the result is the largest map, in its own
    /// resolution, layout and frame, with every other environment's radiance (scaled, through its
    /// own frame) added per texel, sampled 4×4 within the texel so a finer map is averaged rather
    /// than point-sampled. Scales are folded into the texels (the sum's scale is 1).
    pub fn sum(parts: &[Environment]) -> Result<Environment> {
        let [first, rest @ ..] = parts else {
            return Err(crate::runtime!("Environment::sum: no environment"));
        };
        for p in parts {
            p.validate()?;
        }
        if rest.is_empty() {
            return Ok(first.clone());
        }
        let name = parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(" + ");
        let texels_of = |p: &Environment| match &p.radiance {
            Radiance::Image { width, height, .. } => *width as u64 * *height as u64,
            Radiance::Constant(_) => 0,
        };
        let (b, base) = parts.iter().enumerate().max_by_key(|(i, p)| (texels_of(p), std::cmp::Reverse(*i))).unwrap();
        let Radiance::Image { width, height, layout, texels } = &base.radiance else {
            let total: Vec3 = parts
                .iter()
                .map(|p| if let Radiance::Constant(l) = p.radiance { l * p.scale } else { Vec3::ZERO })
                .sum();
            return Ok(Environment {
                name,
                radiance: Radiance::Constant(total),
                scale: 1.0,
                to_world: Mat3::IDENTITY,
                samples: first.samples,
            });
        };
        let (w, h, layout) = (*width, *height, *layout);
        const SUB: u32 = 4;
        let mut sum: Vec<[f32; 3]> = Vec::with_capacity(texels.len());
        for y in 0..h {
            for x in 0..w {
                let mut l = Vec3::from(texels[(y * w + x) as usize]) * base.scale;
                let mut others = Vec3::ZERO;
                for p in parts.iter().enumerate().filter(|&(i, _)| i != b).map(|(_, p)| p) {
                    if let Radiance::Constant(c) = p.radiance {
                        others += c * p.scale;
                        continue;
                    }
                    let mut acc = Vec3::ZERO;
                    for sy in 0..SUB {
                        for sx in 0..SUB {
                            let u = (x as f64 + (sx as f64 + 0.5) / SUB as f64) / w as f64;
                            let v = (y as f64 + (sy as f64 + 0.5) / SUB as f64) / h as f64;
                            let world = base.to_world * uv_to_direction(layout, u, v).as_vec3();
                            acc += p.radiance_toward(world.normalize());
                        }
                    }
                    others += acc / (SUB * SUB) as f32;
                }
                l += others;
                sum.push(l.to_array());
            }
        }
        Ok(Environment {
            name,
            radiance: Radiance::Image { width: w, height: h, layout, texels: Arc::new(sum) },
            scale: 1.0,
            to_world: base.to_world,
            samples: first.samples,
        })
    }

    /// Radiance arriving from world direction `d` (unit), scaled: the texel it falls in.
    pub fn radiance_toward(&self, d: Vec3) -> Vec3 {
        let local = self.to_world.transpose() * d;
        match &self.radiance {
            Radiance::Constant(l) => *l * self.scale,
            Radiance::Image { width, height, layout, texels } => {
                let (u, v) = direction_to_uv(*layout, local.as_dvec3());
                let x = ((u * *width as f64) as u32).min(width - 1);
                let y = ((v * *height as f64) as u32).min(height - 1);
                Vec3::from(texels[(y * width + x) as usize]) * self.scale
            }
        }
    }

    /// The environment as directional lights: the map cut into `samples` regions of equal
    /// energy (luminance × solid angle), in the order of a Morton curve over the texels so that
    /// each region is compact on the sphere; each region is one light toward its energy-weighted
    /// mean direction, carrying the region's ∫ L dω (texels split between regions by the
    /// fraction of their energy in each) as its irradiance at normal incidence. The lights' sum
    /// is the whole map's; a map whose only bright texels have equal energy, K of them, gives
    /// exactly those K texels as lights. A constant map is cut from an equal-area octahedral grid
    /// of 64² texels. Regions within one texel (a bright sun) are one light. `Ok(vec![])` when
    /// the map is black.
    pub fn lights(&self) -> Result<Vec<Light>> {
        self.validate()?;
        const CONSTANT_GRID: u32 = 64;
        let (width, height, layout) = match &self.radiance {
            Radiance::Constant(_) => (CONSTANT_GRID, CONSTANT_GRID, Layout::Octahedral),
            Radiance::Image { width, height, layout, .. } => (*width, *height, *layout),
        };
        let texel = |i: usize| -> DVec3 {
            match &self.radiance {
                Radiance::Constant(l) => l.as_dvec3(),
                Radiance::Image { texels, .. } => Vec3::from(texels[i]).as_dvec3(),
            }
        };
        let luminance = |c: DVec3| c.dot(DVec3::new(0.2126, 0.7152, 0.0722));
        let n = width as usize * height as usize;
        let mut order: Vec<u32> = (0..n as u32).collect();
        order.sort_by_key(|&i| morton(i % width, i / width));
        // Energy per texel, in f64 (millions of texels).
        let energy: Vec<f64> = order
            .iter()
            .map(|&i| luminance(texel(i as usize)) * solid_angle(layout, width, height, i / width))
            .collect();
        let total: f64 = energy.iter().sum();
        if total.is_nan() || total <= 0.0 {
            return Ok(Vec::new());
        }
        let to_world: DMat3 = self.to_world.as_dmat3();
        let k = self.samples as usize;
        let mut lights: Vec<Light> = Vec::with_capacity(k);
        let (mut at, mut start) = (0usize, 0.0f64); // the texel and where its energy starts
        for j in 0..k {
            let (b0, b1) = (total * j as f64 / k as f64, total * (j + 1) as f64 / k as f64);
            let (mut direction, mut rgb) = (DVec3::ZERO, DVec3::ZERO);
            while at < n {
                let end = start + energy[at];
                let overlap = end.min(b1) - start.max(b0);
                if overlap > 0.0 {
                    let i = order[at];
                    let (x, y) = (i % width, i / width);
                    let d = uv_to_direction(layout, (x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64);
                    let fraction = overlap / energy[at];
                    direction += d * overlap;
                    rgb += texel(i as usize) * solid_angle(layout, width, height, y) * fraction;
                }
                if end > b1 || (at + 1 == n) {
                    break;
                }
                start = end;
                at += 1;
            }
            let toward = (to_world * direction).normalize_or_zero().as_vec3();
            let irradiance = (rgb * self.scale as f64).as_vec3();
            if toward == Vec3::ZERO {
                continue;
            }
            match lights.last_mut() {
                Some(Light::Directional { toward: t, irradiance: e }) if *t == toward => *e += irradiance,
                _ => lights.push(Light::Directional { toward, irradiance }),
            }
        }
        Ok(lights)
    }
}

/// Interleaves the bits of x and y (a Morton key).
fn morton(x: u32, y: u32) -> u64 {
    let spread = |v: u32| {
        let mut v = v as u64;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        v = (v | (v << 1)) & 0x5555_5555_5555_5555;
        v
    };
    spread(x) | (spread(y) << 1)
}

/// A synthetic sky with a sun, as a latitude-longitude map of 512×256 texels: blue toward the
/// zenith, bright at the horizon, a dim ground below it, and a sun 2.5° in radius at `elevation`
/// degrees above the horizon and `azimuth` degrees from −z toward +x (0: behind the object as
/// the default camera sees it). Its sun brings about twice the sky's irradiance.
pub fn sky(elevation: f32, azimuth: f32) -> Radiance {
    let (width, height) = (512u32, 256u32);
    let (e, a) = (elevation.to_radians() as f64, azimuth.to_radians() as f64);
    let sun = DVec3::new(e.cos() * a.sin(), e.sin(), -e.cos() * a.cos());
    let cos_sun = 2.5f64.to_radians().cos();
    let mut texels = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let d = uv_to_direction(Layout::LatLong, (x as f64 + 0.5) / width as f64, (y as f64 + 0.5) / height as f64);
            let l = if d.dot(sun) >= cos_sun {
                DVec3::new(500.0, 450.0, 380.0)
            } else if d.y >= 0.0 {
                let t = d.y.powf(0.5);
                DVec3::new(0.45, 0.45, 0.5) * (1.0 - t) + DVec3::new(0.1, 0.18, 0.4) * t
            } else {
                DVec3::new(0.06, 0.05, 0.04)
            };
            texels.push(l.as_vec3().to_array());
        }
    }
    Radiance::Image { width, height, layout: Layout::LatLong, texels: Arc::new(texels) }
}

/// The most directions an environment may be sampled in: each is a directional light with its
/// own shadow-map layer (the device's layer limit is checked with the frame).
pub const MAX_SAMPLES: u32 = 4096;

/// Solid angle of a texel in row `y`.
pub fn solid_angle(layout: Layout, width: u32, height: u32, y: u32) -> f64 {
    match layout {
        Layout::Octahedral => 4.0 * PI / (width as f64 * height as f64),
        Layout::LatLong => {
            let (t0, t1) = (PI * y as f64 / height as f64, PI * (y + 1) as f64 / height as f64);
            2.0 * PI / width as f64 * (t0.cos() - t1.cos())
        }
    }
}

/// The direction at (u, v) ∈ [0, 1]² of the map (v down the image).
pub fn uv_to_direction(layout: Layout, u: f64, v: f64) -> DVec3 {
    match layout {
        Layout::LatLong => {
            // Mitsuba 3 envmap: φ = 2πu measured from −z toward +x, θ = πv from +y.
            let (phi, theta) = (2.0 * PI * u, PI * v);
            DVec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
        }
        Layout::Octahedral => equal_area_square_to_sphere(u, v),
    }
}

/// The map coordinates (u, v) of a unit direction.
pub fn direction_to_uv(layout: Layout, d: DVec3) -> (f64, f64) {
    match layout {
        Layout::LatLong => {
            let u = d.x.atan2(-d.z) / (2.0 * PI);
            let v = d.y.clamp(-1.0, 1.0).acos() / PI;
            (u.rem_euclid(1.0), v)
        }
        Layout::Octahedral => equal_area_sphere_to_square(d),
    }
}

/// Clarberg's equal-area map of the square onto the sphere (pbrt-v4 `EqualAreaSquareToSphere`).
pub fn equal_area_square_to_sphere(px: f64, py: f64) -> DVec3 {
    let (u, v) = (2.0 * px - 1.0, 2.0 * py - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed_distance = 1.0 - (up + vp);
    let d = signed_distance.abs();
    let r = 1.0 - d;
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * PI / 4.0;
    let z = (1.0 - r * r).copysign(signed_distance);
    let cos_phi = phi.cos().copysign(u);
    let sin_phi = phi.sin().copysign(v);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    DVec3::new(cos_phi * s, sin_phi * s, z)
}

/// Its inverse (pbrt-v4 `EqualAreaSphereToSquare`, with atan in f64 where pbrt uses a polynomial).
pub fn equal_area_sphere_to_square(d: DVec3) -> (f64, f64) {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let a = x.max(y);
    let b = if a == 0.0 { 0.0 } else { x.min(y) / a };
    let mut phi = b.atan() * 2.0 / PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    u = u.copysign(d.x);
    v = v.copysign(d.y);
    (0.5 * (u + 1.0), 0.5 * (v + 1.0))
}

/// A rotation about the world's up axis (+y) by `deg` degrees (`--env-rotate`).
pub fn rotation_about_up(deg: f32) -> Mat3 {
    Mat3::from_rotation_y(deg.to_radians())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_invert_and_solid_angles_cover_the_sphere() {
        for layout in [Layout::LatLong, Layout::Octahedral] {
            for i in 0..40 {
                for j in 0..40 {
                    let (u, v) = ((i as f64 + 0.37) / 40.0, (j as f64 + 0.61) / 40.0);
                    let d = uv_to_direction(layout, u, v);
                    assert!((d.length() - 1.0).abs() < 1e-12, "{layout:?} {u} {v}");
                    let (u2, v2) = direction_to_uv(layout, d);
                    assert!((u - u2).abs() < 1e-9 && (v - v2).abs() < 1e-9, "{layout:?}: {u},{v} -> {u2},{v2}");
                }
            }
            let (w, h) = if layout == Layout::LatLong { (64, 32) } else { (32, 32) };
            let total: f64 = (0..h).map(|y| w as f64 * solid_angle(layout, w, h, y)).sum();
            assert!((total - 4.0 * PI).abs() < 1e-9, "{layout:?}: {total}");
        }
        // Mitsuba's latitude-longitude convention: the left edge looks along −z, a quarter
        // across along +x, half across along +z; +y at the top.
        assert!((uv_to_direction(Layout::LatLong, 0.0, 0.5) - DVec3::NEG_Z).length() < 1e-12);
        assert!((uv_to_direction(Layout::LatLong, 0.25, 0.5) - DVec3::X).length() < 1e-12);
        assert!((uv_to_direction(Layout::LatLong, 0.5, 0.5) - DVec3::Z).length() < 1e-12);
        assert!((uv_to_direction(Layout::LatLong, 0.3, 0.0) - DVec3::Y).length() < 1e-12);
    }

    /// A constant map's samples carry its whole irradiance: Σ E_k = π L · 4 (the sphere's
    /// ∫ L dω = 4π L, each sample's E at normal incidence being its share of it).
    #[test]
    fn samples_carry_the_whole_map() {
        for k in [1, 16, 64, 256] {
            let env = Environment {
                name: "test".into(),
                radiance: Radiance::Constant(Vec3::new(1.0, 0.5, 0.25)),
                scale: 2.0,
                to_world: Mat3::IDENTITY,
                samples: k,
            };
            let lights = env.lights().unwrap();
            assert_eq!(lights.len(), k as usize);
            let sum: Vec3 = lights
                .iter()
                .map(|l| if let Light::Directional { irradiance, .. } = l { *irradiance } else { Vec3::ZERO })
                .sum();
            let expected = Vec3::new(1.0, 0.5, 0.25) * 2.0 * 4.0 * std::f32::consts::PI;
            assert!((sum - expected).abs().max_element() < 1e-4 * expected.max_element(), "{k}: {sum} vs {expected}");
        }
    }
}
