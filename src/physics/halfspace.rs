//! The semi-infinite medium under a collimated beam, in f64, as a yardstick for the models:
//! the plane integral of a model's Sd, the exact radiative transfer answer by Monte Carlo
//! (isotropic scattering, a smooth Fresnel boundary, the σ' of the similarity relation), and
//! Chandrasekhar's H-function, whose closed form checks the Monte Carlo where η = 1.
//!
//! Units: the Monte Carlo works in mean free paths (1/σ't), so its answers depend only on the
//! reduced albedo α', η and the angle of incidence.

use super::{dipole, dirpole, fresnel, ChannelConstants};
use glam::DVec3;
use std::f64::consts::PI;

/// ∫ f(xo) dA over the plane z = 0 (xo = (ρ cos φ, ρ sin φ, 0)), ρ from `r_min` to `r_max`:
/// composite Simpson in ln ρ (the integrands span many decades) and the trapezoid rule in φ
/// (periodic, so spectrally accurate) with `angles` points.
pub fn plane_integral(f: impl Fn(DVec3) -> f64, r_min: f64, r_max: f64, angles: usize) -> f64 {
    let (a, b) = (r_min.ln(), r_max.ln());
    let n = 8_000;
    let h = (b - a) / n as f64;
    let ring = |u: f64| {
        let r = u.exp();
        let mut s = 0.0;
        for k in 0..angles {
            let phi = 2.0 * PI * k as f64 / angles as f64;
            s += f(DVec3::new(r * phi.cos(), r * phi.sin(), 0.0));
        }
        s * 2.0 * PI / angles as f64 * r * r
    };
    let mut sum = ring(a) + ring(b);
    for k in 1..n {
        sum += ring(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    sum * h / 3.0
}

/// ∫ Ft(η, ωo) cos θo dωo over the outer hemisphere, = π(1 − the boundary's diffuse reflectance
/// seen from outside): what a BSSRDF S = Ft Sd Ft returns per unit ∫Sd dA.
pub fn cosine_weighted_transmittance(eta: f64) -> f64 {
    // 2π ∫ Ft(μ) μ dμ = π ∫ Ft(√s) ds with s = μ², midpoint rule.
    let n = 100_000;
    (0..n).map(|k| fresnel::transmittance(eta, ((k as f64 + 0.5) / n as f64).sqrt())).sum::<f64>() * PI / n as f64
}

/// Cosine of the refracted ray to the normal for light at cos θi = `cos_i` entering index `eta`.
pub fn refracted_cos(eta: f64, cos_i: f64) -> f64 {
    (1.0 - (1.0 - cos_i * cos_i) / (eta * eta)).max(0.0).sqrt()
}

/// ∫Sd dA of the published directional dipole over the plane, light at cos θi = `cos_i`.
pub fn dirpole_plane(c: &ChannelConstants, cos_i: f64) -> f64 {
    if !c.transports {
        return 0.0;
    }
    let n = DVec3::Z;
    let wi = DVec3::new((1.0 - cos_i * cos_i).max(0.0).sqrt(), 0.0, cos_i);
    plane_integral(|xo| dirpole::sd(c, DVec3::ZERO, n, wi, xo, n), 1e-6 * c.d, 40.0 / c.sigma_tr, 48)
}

/// ∫M dA for a unit isotropic point source at depth z under the directional dipole's boundary
/// (its negative image 2A·de above the surface, exitance M = Cφφ + CE·E·n, φ = e^{−σtr d}/(4πDd)):
/// Cφ/(2Dσtr)(e^{−σtr z} − e^{−σtr(z+2zb)}) + (CE/2)(e^{−σtr z} + e^{−σtr(z+2zb)}), zb = A·de.
pub fn point_source_plane(c: &ChannelConstants, z: f64) -> f64 {
    let s = c.sigma_tr;
    let zb = c.a_dirpole * c.de;
    let (er, ev) = ((-s * z).exp(), (-s * (z + 2.0 * zb)).exp());
    c.c_phi / (2.0 * c.d * s) * (er - ev) + c.c_e / 2.0 * (er + ev)
}

/// The same for the ray source the directional dipole is derived from, integrated exactly
/// instead of expanded about the entry point: ∫σ's e^{−σ't t} ∫M(t μt) dA dt, where the
/// e^{−σtr z} factors average to σ't/(σ't + σtr μt) (μt the refracted ray's cosine).
pub fn ray_source_plane(c: &ChannelConstants, mu_t: f64) -> f64 {
    let s = c.sigma_tr;
    let zb = c.a_dirpole * c.de;
    let k = c.sigma_t_reduced / (c.sigma_t_reduced + s * mu_t);
    let ev = (-s * 2.0 * zb).exp();
    c.alpha_reduced * k * (c.c_phi / (2.0 * c.d * s) * (1.0 - ev) + c.c_e / 2.0 * (1.0 + ev))
}

/// Total diffuse reflectance a model renders on a flat half-space, per unit incident power at
/// cos θi = `cos_i`: Ft(θi) · ∫Sd dA · ∫Ft cos θo dωo (the quantity [`rte_reflectance`] measures).
pub fn model_total(plane_sd: f64, eta: f64, cos_i: f64) -> f64 {
    fresnel::transmittance(eta, cos_i) * plane_sd * cosine_weighted_transmittance(eta)
}

/// [`model_total`] of the classical dipole (Sd = Rd/π, one radial profile for every angle).
pub fn dipole_total(c: &ChannelConstants, cos_i: f64) -> f64 {
    if !c.transports {
        return 0.0;
    }
    model_total(dipole::total_rd(c.alpha_reduced, c.a_dipole) / PI, c.eta, cos_i)
}

/// [`model_total`] for an exitance M (per unit source power) rendered as Sd = N·M/π, the
/// directional dipole's normalisation N = 1/(4Cφ(1/η)).
pub fn exitance_total(c: &ChannelConstants, plane_m: f64, cos_i: f64) -> f64 {
    model_total(c.n_norm * plane_m / PI, c.eta, cos_i)
}

/// Chandrasekhar's H-function for isotropic scattering of single-scattering albedo `albedo`
/// (0 < albedo < 1) at `mu`, from 1/H(μ) = √(1−ϖ) + (ϖ/2)∫₀¹ μ'H(μ')/(μ+μ') dμ', iterated on
/// 96 Gauss–Legendre nodes (about 1/√(1−ϖ) iterations; at ϖ = 1 itself it stalls).
pub fn h_function(albedo: f64, mu: f64) -> f64 {
    let (nodes, weights) = gauss_legendre_unit(96);
    let root = (1.0 - albedo).max(0.0).sqrt();
    let mut h = vec![1.0; nodes.len()];
    let eval = |h: &[f64], m: f64| {
        let s: f64 = nodes.iter().zip(weights.iter()).zip(h).map(|((&x, &w), &hx)| w * x * hx / (m + x)).sum();
        1.0 / (root + 0.5 * albedo * s)
    };
    for _ in 0..200_000 {
        let next: Vec<f64> = nodes.iter().map(|&m| eval(&h, m)).collect();
        let change = next.iter().zip(&h).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        h = next;
        if change < 1e-14 {
            break;
        }
    }
    eval(&h, mu)
}

/// The exact plane albedo of an index-matched (η = 1) half-space with isotropic scattering
/// under a beam at cos θ = `mu0`: 1 − H(μ0)√(1 − ϖ) (Chandrasekhar, Radiative Transfer, §IV).
pub fn index_matched_plane_albedo(albedo: f64, mu0: f64) -> f64 {
    1.0 - h_function(albedo, mu0) * (1.0 - albedo).sqrt()
}

/// Nodes and weights of n-point Gauss–Legendre quadrature on [0, 1].
pub fn gauss_legendre_unit(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        // Newton on P_n from the Chebyshev guess.
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let dx = p1 / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        nodes.push(0.5 * (1.0 - x));
        weights.push(1.0 / ((1.0 - x * x) * dp * dp));
    }
    (nodes, weights)
}

/// What the Monte Carlo measured, per unit irradiance on the surface.
#[derive(Clone, Debug)]
pub struct RteTally {
    /// Diffuse reflectance: the power that leaves after at least one scattering, per unit
    /// incident power (the boundary's own reflection excluded).
    pub total: f64,
    /// Its standard error.
    pub total_error: f64,
    /// The part of `total` that left after exactly one scattering (single scattering), and its
    /// standard error.
    pub single: f64,
    pub single_error: f64,
    /// Outgoing radiance per unit irradiance in `RADIANCE_BINS` bins of equal projected solid
    /// angle, bin k covering cos²θo in [k, k+1)/RADIANCE_BINS.
    pub radiance: Vec<f64>,
}

/// Bins of [`RteTally::radiance`].
pub const RADIANCE_BINS: usize = 40;

impl RteTally {
    /// Radiance per unit irradiance leaving at cos θo = `mu` (the bins around μ², averaged
    /// over ±0.025 in μ²).
    pub fn radiance_at(&self, mu: f64) -> f64 {
        let x = mu * mu * RADIANCE_BINS as f64;
        let k = (x.round() as usize).clamp(1, RADIANCE_BINS - 1);
        0.5 * (self.radiance[k - 1] + self.radiance[k])
    }

    /// Radiance per unit irradiance averaged over the bins of cos θo from `mu_lo` to `mu_hi`
    /// (weighted by projected solid angle), with the bins' mean of `weight(μ)` over the same
    /// range: what a model's radiance ∝ weight(μ) is compared with.
    pub fn radiance_between(&self, mu_lo: f64, mu_hi: f64, weight: impl Fn(f64) -> f64) -> (f64, f64) {
        let n = RADIANCE_BINS as f64;
        let (a, b) = ((mu_lo * mu_lo * n).floor() as usize, ((mu_hi * mu_hi * n).ceil() as usize).min(RADIANCE_BINS));
        let bins = (b - a) as f64;
        let l = self.radiance[a..b].iter().sum::<f64>() / bins;
        let w = (a..b).map(|k| weight(((k as f64 + 0.5) / n).sqrt())).sum::<f64>() / bins;
        (l, w)
    }
}

/// SplitMix64: a small, fast, reproducible generator for the Monte Carlo (the half-space's, the
/// slab's and the sphere's walks).
pub(crate) struct SplitMix(pub(crate) u64);

impl SplitMix {
    /// The `i`-th stream split off this one at its present state (SplitMix64's finaliser of the
    /// state offset by i times another odd constant).
    pub(crate) fn child(&self, i: u64) -> SplitMix {
        let mut z = self.0 ^ i.wrapping_mul(0xD1B5_4A32_D192_ED03);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        SplitMix(z ^ (z >> 31))
    }

    /// Uniform in (0, 1).
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
}

/// Where a photon of [`trace_slab`] left the medium: its position on the boundary it crossed
/// relative to the entry point (mean free paths), cos²θo outside, how often it scattered, and
/// whether it left through the far face (transmitted) rather than the one it entered by.
#[derive(Clone, Copy, Debug)]
pub struct Escape {
    pub x: f64,
    pub y: f64,
    pub mu_o2: f64,
    /// The direction outside along the face (x, y): the inside one's, times η (Snell).
    pub along: [f64; 2],
    pub scatterings: u32,
    pub transmitted: bool,
    /// The photon's weight: 1, less after it split ([`Split`]).
    pub weight: f64,
}

/// Collisions after which a photon of [`rte_reflectance`] counts as absorbed: far past any path
/// that matters for α' < 1 (its weight α'^n), and an end for α' = 1, whose returns take
/// arbitrarily long.
pub const MAX_COLLISIONS: u32 = 1_000_000;

/// [`trace_slab`] of infinite thickness: the half-space z < 0.
pub fn trace_half_space(
    albedo: f64,
    eta: f64,
    start: DVec3,
    photons: u64,
    seeds: (u64, u32),
    on_escape: impl FnMut(&Escape),
) -> u64 {
    trace_slab(albedo, eta, f64::INFINITY, start, photons, seeds, on_escape)
}

/// The analogue Monte Carlo walk of a slab −`thickness` < z < 0 (mean free paths; infinite: the
/// half-space) of reduced albedo `albedo`, relative index `eta` on both faces, isotropic
/// scattering, smooth boundaries: `photons` photons start at the origin going `start` (downward),
/// fly exponential free paths, are absorbed with probability 1 − α' at each collision (and after
/// `max_collisions`), and at either face are Fresnel-reflected or escape (with refraction), which
/// `on_escape` is told. Returns the scatterings traced.
pub fn trace_slab(
    albedo: f64,
    eta: f64,
    thickness: f64,
    start: DVec3,
    photons: u64,
    seeds: (u64, u32),
    on_escape: impl FnMut(&Escape),
) -> u64 {
    trace_slab_split(albedo, eta, thickness, start, photons, seeds, None, on_escape)
}

/// [`trace_slab`] whose photons split as they go far from the entry (`split`; None: the
/// analogue walk, the same draws and escapes bit for bit).
#[allow(clippy::too_many_arguments)]
pub fn trace_slab_split(
    albedo: f64,
    eta: f64,
    thickness: f64,
    start: DVec3,
    photons: u64,
    (seed, max_collisions): (u64, u32),
    split: Option<&Split>,
    mut on_escape: impl FnMut(&Escape),
) -> u64 {
    let mut rng = SplitMix(seed);
    (0..photons)
        .map(|_| {
            slab_walk(
                &mut rng,
                (albedo, eta, thickness),
                Photon::entering(start),
                max_collisions,
                split,
                &mut on_escape,
            )
        })
        .sum()
}

/// One photon's walk in the slab from where `photon` is (and its copies', where it splits);
/// returns their scatterings.
fn slab_walk(
    rng: &mut SplitMix,
    (albedo, eta, thickness): (f64, f64, f64),
    mut photon: Photon,
    max_collisions: u32,
    split: Option<&Split>,
    on_escape: &mut dyn FnMut(&Escape),
) -> u64 {
    let mut collisions = 0u64;
    // A copy split off at a collision starts there, before its own absorption and scattering.
    let mut fly = !std::mem::take(&mut photon.colliding);
    loop {
        if std::mem::replace(&mut fly, true) {
            let s = -rng.next().ln();
            let (p, d) = (&mut photon.p, &mut photon.d);
            let z_next = p.z + s * d.z;
            if z_next >= 0.0 || z_next <= -thickness {
                // Reaches a face from inside: the cosine there is |d.z| > 0.
                let far = z_next < 0.0;
                let t = if far { (-thickness - p.z) / d.z } else { -p.z / d.z };
                p.x += t * d.x;
                p.y += t * d.y;
                let cos = d.z.abs();
                if rng.next() < fresnel::reflectance(1.0 / eta, cos) {
                    d.z = -d.z;
                    p.z = if far { -thickness } else { 0.0 };
                    continue;
                }
                let mu_o2 = 1.0 - eta * eta * (1.0 - cos * cos);
                on_escape(&Escape {
                    x: p.x,
                    y: p.y,
                    mu_o2: mu_o2.clamp(0.0, 1.0),
                    along: [eta * d.x, eta * d.y],
                    scatterings: photon.scatterings,
                    transmitted: far,
                    weight: photon.weight,
                });
                return collisions;
            }
            p.x += s * d.x;
            p.y += s * d.y;
            p.z = z_next;
            if let Some(split) = split {
                collisions += split.at(rng, &mut photon, &mut |rng, copy| {
                    slab_walk(rng, (albedo, eta, thickness), copy, max_collisions, Some(split), on_escape)
                });
            }
        }
        if !photon.collide(rng, albedo, max_collisions) {
            return collisions;
        }
        collisions += 1;
    }
}

/// A photon of the walks: where it is relative to the entry point (mean free paths), which way
/// it goes, how often it scattered, its splitting level and weight ([`Split`]), and whether it
/// is at a collision it has yet to take (a copy split off there).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Photon {
    pub(crate) p: DVec3,
    pub(crate) d: DVec3,
    pub(crate) scatterings: u32,
    pub(crate) level: u32,
    pub(crate) weight: f64,
    pub(crate) colliding: bool,
}

impl Photon {
    /// At the entry point, going `d` into the medium, unsplit.
    pub(crate) fn entering(d: DVec3) -> Photon {
        Photon { p: DVec3::ZERO, d, scatterings: 0, level: 0, weight: 1.0, colliding: false }
    }

    /// A collision: absorbed with probability 1 − `albedo` (and after `max_collisions`
    /// scatterings; false), else scattered isotropically (true).
    pub(crate) fn collide(&mut self, rng: &mut SplitMix, albedo: f64, max_collisions: u32) -> bool {
        if rng.next() >= albedo || self.scatterings >= max_collisions {
            return false;
        }
        self.scatterings += 1;
        let mu = 2.0 * rng.next() - 1.0;
        let phi = 2.0 * PI * rng.next();
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        self.d = DVec3::new(s * phi.cos(), s * phi.sin(), mu);
        true
    }
}

/// Splitting by distance from the entry, for tallies far from it (the curvature ratios' far
/// chords, where an analogue walk counts a handful of photons): `level(|p|)` (|p| the distance
/// from the entry point in mean free paths) is how many times a photon there should have halved;
/// one that reaches a level above its own becomes 2^(difference) photons of as much less weight
/// each, the copies walking on from there on draws of their own. Unbiased for any level (the
/// weights of the copies sum to the photon's); they are seeded from the walk's own state, so two
/// walks that coincide until then (a ball's and the half-space's, `curvature_profile`) split
/// alike and their noise still cancels. `allowance`: the scatterings the copies may take in all;
/// once spent, no photon splits (one that has split walks all its copies), which bounds the cost
/// where photons live long (Marble's albedo of 0.999: its first `--model mc` run took 4.3x as
/// long without it). Still unbiased: whether a photon splits depends on the photons before it.
pub struct Split<'a> {
    pub level: &'a (dyn Fn(f64) -> u32 + Sync),
    pub allowance: std::cell::Cell<u64>,
}

impl Split<'_> {
    /// Splits `photon` if its place calls for it, walking each new copy by `walk`; returns what
    /// those walks return (their scatterings).
    pub(crate) fn at(
        &self,
        rng: &SplitMix,
        photon: &mut Photon,
        walk: &mut dyn FnMut(&mut SplitMix, Photon) -> u64,
    ) -> u64 {
        let to = (self.level)(photon.p.length());
        if to <= photon.level || self.allowance.get() == 0 {
            return 0;
        }
        let copies = 1u64 << (to - photon.level).min(20);
        photon.level = to;
        photon.weight /= copies as f64;
        let taken: u64 = (1..copies).map(|i| walk(&mut rng.child(i), Photon { colliding: true, ..*photon })).sum();
        self.allowance.set(self.allowance.get().saturating_sub(taken));
        taken
    }
}

/// The refracted direction of light entering at cos θi = `cos_i` (z down into the medium is
/// negative), in the xz plane.
pub fn entry_direction(eta: f64, cos_i: f64) -> DVec3 {
    let sin_t = (1.0 - cos_i * cos_i).max(0.0).sqrt() / eta;
    DVec3::new(sin_t, 0.0, -(1.0 - sin_t * sin_t).sqrt())
}

/// The exact radiative transfer answer for a half-space of reduced albedo `albedo` and relative
/// index `eta` (isotropic scattering, smooth boundary) lit by a beam at cos θi = `cos_i`, by
/// analogue Monte Carlo with `photons` photons ([`trace_half_space`], entry through the boundary
/// with weight Ft(θi)).
pub fn rte_reflectance(albedo: f64, eta: f64, cos_i: f64, photons: u64, seed: u64) -> RteTally {
    let entry = fresnel::transmittance(eta, cos_i);
    let mut escaped = vec![0u64; RADIANCE_BINS];
    let mut count = 0u64;
    let mut once = 0u64;
    let _ = trace_half_space(albedo, eta, entry_direction(eta, cos_i), photons, (seed, MAX_COLLISIONS), |e| {
        let k = ((e.mu_o2 * RADIANCE_BINS as f64) as usize).min(RADIANCE_BINS - 1);
        escaped[k] += 1;
        count += 1;
        once += (e.scatterings == 1) as u64;
    });
    let n = photons as f64;
    let p = count as f64 / n;
    let p1 = once as f64 / n;
    RteTally {
        total: entry * p,
        total_error: entry * (p * (1.0 - p) / n).sqrt(),
        single: entry * p1,
        single_error: entry * (p1 * (1.0 - p1) / n).sqrt(),
        // Bin k's projected solid angle is π/RADIANCE_BINS.
        radiance: escaped.iter().map(|&c| entry * c as f64 / n / (PI / RADIANCE_BINS as f64)).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_exactly() {
        let (x, w) = gauss_legendre_unit(12);
        for p in 0..20 {
            let got: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(p)).sum();
            assert!((got - 1.0 / (p as f64 + 1.0)).abs() < 1e-14, "x^{p}: {got}");
        }
    }

    #[test]
    fn h_function_known_values() {
        // Towards conservative scattering H(1) rises to Chandrasekhar's 2.9078.
        let h1 = h_function(0.9999, 1.0);
        assert!(h1 > 2.85 && h1 < 2.9078, "{h1}");
        // The zeroth moment, exactly: ∫₀¹ H dμ = (2/ϖ)(1 − √(1−ϖ)).
        for albedo in [0.3, 0.5, 0.9, 0.99, 0.999] {
            let (x, w) = gauss_legendre_unit(64);
            let m0: f64 = x.iter().zip(&w).map(|(&x, &w)| w * h_function(albedo, x)).sum();
            let exact = 2.0 / albedo * (1.0 - (1.0 - albedo).sqrt());
            assert!((m0 - exact).abs() < 1e-6 * exact, "albedo {albedo}: {m0} vs {exact}");
        }
        // No scattering: H = 1.
        assert!((h_function(1e-9, 0.7) - 1.0).abs() < 1e-8);
    }

    /// The closed-form plane integral of a point source under the directional dipole's boundary
    /// against the numerical plane integral of its exitance.
    #[test]
    fn point_source_plane_matches_its_integrand() {
        let m = crate::physics::Medium { sigma_a: 0.17, sigma_s: 0.88, g: 0.0, eta: 1.3 };
        let c = m.constants(crate::physics::Diffusion::Classical);
        let s = c.sigma_tr;
        let zb = c.a_dirpole * c.de;
        for z in [0.1, 0.5, 2.0] {
            let exitance = |x: DVec3| {
                let rho2 = x.length_squared();
                let dr = (rho2 + z * z).sqrt();
                let dv = (rho2 + (z + 2.0 * zb).powi(2)).sqrt();
                let g = |d: f64| (-s * d).exp() / (4.0 * PI * c.d * d);
                let flux = |h: f64, d: f64| h * (1.0 + s * d) * (-s * d).exp() / (4.0 * PI * d * d * d);
                c.c_phi * (g(dr) - g(dv)) + c.c_e * (flux(z, dr) + flux(z + 2.0 * zb, dv))
            };
            let numeric = plane_integral(exitance, 1e-6, 60.0 / s, 4);
            let closed = point_source_plane(&c, z);
            assert!((numeric - closed).abs() < 1e-6 * closed, "z {z}: {numeric} vs {closed}");
        }
    }
}
