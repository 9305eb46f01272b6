//! The half-space's exact transport, tabulated by Monte Carlo (`--model mc`): multiple scattering
//! (two or more scatterings) as a separable BSSRDF S = Ft(θi) f(θt) · Sp(r) · h(θt, θo) Ft(θo)
//! whose parts are measured, per channel, by the analogue Monte Carlo of
//! [`super::halfspace::trace_half_space`] (which reproduces Mitsuba 3's path-traced thick slabs
//! within 0.5%, tests/halfspace.rs) instead of derived from diffusion, and single scattering
//! computed by the shade pass along the refracted view ray through the object itself (Jensen et
//! al. 2001 §3, the light's path inside from its shadow map's depth):
//!
//! - Sp(r): the radial exitance profile M(r) of a beam at normal incidence (orders ≥ 2), per unit
//!   power entering, as pbrt's separable BSSRDF spreads it: Sd = M / ∫Ft cos θ dω
//!   (src/physics/beam_diffusion.rs's notes);
//! - f(θt): how much more (or less) of the light entering along the refracted direction θt
//!   leaves than at normal incidence, P(θt)/P(0): grazing light enters shallower and more of it
//!   returns, which a radial profile alone cannot know (the directional dipole's motivation);
//! - h(θt, θo): the exit's radiance against the renderer's Ft(θo)-weighted Lambertian lobe, per
//!   angle of incidence (single scattering leaves more obliquely, and, lit and seen at grazing
//!   angles, brighter: Lommel–Seeliger's limb brightening). The shade pass reads it at the
//!   pixel's own incidence (the sources near a pixel, which carry the single scattering, are lit
//!   as it is).
//!
//! Like pbrt-v4's `TabulatedBSSRDF` it is a table of the semi-infinite medium (Christensen and
//! Burley 2015 fit such Monte Carlo profiles; here they are used as measured); it is exact on a
//! flat, thick medium lit at any angle (in total and exit distribution) and at normal incidence
//! (in profile). Its multiple scattering knows no curvature, and thickness only where the shade
//! pass reads a pair of points across the object as a local slab ([`super::slab_profile`]); its
//! single scattering sees both.
//!
//! Scattering is isotropic with the reduced coefficients (the similarity relation), as in the
//! half-space yardstick. Lengths are in mm; the Monte Carlo works in mean free paths 1/σ't.

use super::{fresnel, halfspace, Medium};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Log-spaced radial bins (in mean free paths) between [`RHO_MIN`] and [`RHO_MAX`], after bin 0,
/// the disc ρ < RHO_MIN.
pub const RADIAL_BINS: usize = 112;
pub const RHO_MIN: f64 = 1e-3;
pub const RHO_MAX: f64 = 1e4;
/// Nodes of f(θt), equally spaced in cos θt from the critical cosine (grazing entry) to 1.
pub const INCIDENCE_NODES: usize = 8;
/// Bins of h(θo), equal in cos²θo outside (equal projected solid angle).
pub const EXIT_BINS: usize = 10;

/// Escaping photons wanted at normal incidence (profile, exit distribution, P(0)) and at each
/// other incidence node: the noise of P is then about 1/√ of it (0.2%, 0.6%), of an exit bin
/// √10 times that. Photons go in batches until they are reached or the photon cap is (a dark
/// channel: ketchup's blue leaves 0.15%), whichever is first.
pub const ESCAPES_NORMAL: u64 = 200_000;
pub const ESCAPES_OBLIQUE: u64 = 40_000;
pub const MAX_PHOTONS_NORMAL: u64 = 20_000_000;
pub const MAX_PHOTONS_OBLIQUE: u64 = 2_500_000;
/// Scatterings after which a run stops taking batches, at normal incidence and at each other node:
/// what bounds the time where α' → 1 (at α' = 1 a photon's walk home has no finite mean; Marble's
/// α' = 0.999 takes about 5e7 and 1e7).
pub const MAX_SCATTERINGS_NORMAL: u64 = 60_000_000;
pub const MAX_SCATTERINGS_OBLIQUE: u64 = 15_000_000;
const BATCH: u64 = 5_000;
/// A photon's scatterings before it counts as absorbed: at α' = 0.999 its weight there is e^{−100};
/// at α' = 1 about 0.2% of the photons walk longer (the escape fraction that much low).
const MAX_COLLISIONS: u32 = 100_000;

/// Batches of [`halfspace::trace_half_space`] (seeds `seed`, `seed + 1`, …) until `escapes`
/// photons left, or `max_photons` were traced, or `max_scatterings` scatterings. Returns the
/// photons traced.
fn trace_until(
    albedo: f64,
    eta: f64,
    start: glam::DVec3,
    (escapes, max_photons, max_scatterings): (u64, u64, u64),
    seed: u64,
    mut on_escape: impl FnMut(&halfspace::Escape),
) -> u64 {
    let (mut traced, mut escaped, mut scatterings) = (0u64, 0u64, 0u64);
    while escaped < escapes && traced < max_photons && scatterings < max_scatterings {
        let seed = (seed.wrapping_add(traced / BATCH), MAX_COLLISIONS);
        scatterings += halfspace::trace_half_space(albedo, eta, start, BATCH, seed, |e| {
            escaped += 1;
            on_escape(e)
        });
        traced += BATCH;
    }
    traced
}

/// One channel's measured transport.
#[derive(Clone, Debug, PartialEq)]
pub struct McProfile {
    /// σ't (1/mm): the Monte Carlo's unit of length.
    pub sigma_t_reduced: f64,
    pub albedo_reduced: f64,
    pub eta: f64,
    /// ∫Ft cos θ dω over the outer hemisphere (Sd = M / this).
    pub exit_norm: f64,
    /// The fraction of the power entering at normal incidence that leaves after two or more
    /// scatterings (the table's part; single scattering is the shade pass's): ∫M dA.
    pub escape: f64,
    /// The fraction that leaves after exactly one (what the shade pass's single scattering
    /// computes on the flat half-space).
    pub single_escape: f64,
    /// Exitance M per unit power entering, per mean free path², in each radial bin (bin 0 the disc).
    pub density: Vec<f64>,
    /// cos θt of incidence node 0 ([`critical_cos_t`]).
    pub cos_t_min: f64,
    /// f at the incidence nodes (the last is normal incidence, 1).
    pub incidence: [f64; INCIDENCE_NODES],
    /// h per incidence node and exit bin: the radiance leaving per unit exitance, over the
    /// renderer's lobe Ft(θo)/∫Ft cos θ dω (so that it integrates to 1 against that lobe).
    pub exit: [[f64; EXIT_BINS]; INCIDENCE_NODES],
    /// Where light enters obliquely, what leaves (two or more scatterings) leans ahead along the
    /// refracted beam's tangential direction: at distance ρ and azimuth φ from that direction
    /// the exitance is M(ρ)·f(θt)·(1 + b(ρ) sin θt cos φ), the first harmonic of the azimuthal
    /// dependence measured at each oblique node (b = 2⟨cos φ⟩/sin θt, least squares over the
    /// nodes: it is nearly proportional to sin θt), per radial bin of [`AZIMUTH_BINS`]. Linear
    /// in the lights (the shade pass takes sin θt cos φ from the mean refracted direction's part
    /// along the surface), nothing on a flat surface lit evenly (cos φ averages out), but on a
    /// sphere lit from the front every source's light leans away from the pixel at the pole and
    /// toward the rim (physics::curvature_profile).
    pub azimuth: Vec<f64>,
    /// The second and third harmonics [b₂, b₃] of the same azimuthal dependence, per radial bin
    /// of [`AZIMUTH_BINS`]: the exitance is M(ρ)·f(θt)·(1 + b sin θt cos φ + b₂ sin²θt cos 2φ +
    /// b₃ sin³θt cos 3φ), b_n = 2⟨cos nφ⟩/sinⁿθt by least squares over the oblique nodes (each
    /// nearly proportional to sinⁿθt). Light entering obliquely is peaked ahead of its beam and
    /// flat behind it, which a cosine is not: with the first harmonic alone a flat half-space's
    /// light at 0.6–3.1 mm from a Skin1 beam entering at cos θi 0.2 and 0.5 was 0.81–0.97 of the
    /// walk's ahead, 1.09–1.30 to the sides and 0.68–0.90 behind, with all three within 2–7% of
    /// each other in red and green, 5–17% in blue (tests/curvature_profile.rs,
    /// `an_oblique_beam_s_light_follows_the_walk_around_it`). Sums of harmonics of the mean
    /// refracted direction, so not linear in the lights as b is: lights from different sides of a
    /// source shorten that direction and the higher harmonics fade before the first.
    pub harmonics: Vec<[f64; 2]>,
    /// How the radial profile itself changes with the angle of incidence, per radial bin of
    /// [`AZIMUTH_BINS`]: the azimuthal mean of the exitance is M(ρ)·f(θt)·(1 + a(ρ) sin²θt), a by
    /// least squares over the oblique nodes (their azimuthal mean against the normal beam's times
    /// f). An oblique beam's light spreads further than the normal beam's: without it the flat
    /// half-space's light 1.25–3.1 mm from a Skin1 beam entering at cos θi 0.2 was 0.95 / 0.93 /
    /// 0.87 of the walk's (R / G / B), all around the beam (`tests/curvature_profile.rs`,
    /// `an_oblique_beam_s_light_follows_the_walk_around_it`). It multiplies the harmonics (they
    /// were measured against each node's own mean).
    pub radial: Vec<f64>,
    /// Which way the light leaves (the exit's tilt), per radial bin of [`AZIMUTH_BINS`]: at
    /// distance ρ from where light entered, the radiance leaving toward ωo (outside, its part
    /// along the surface ωt, |ωt| = sin θo) is the azimuth-free one times
    /// 1 + c(ρ) ωt·â + g(ρ) ωt·m, â the way along the surface away from the entry, m the
    /// refracted beam's part along the surface (|m| = sin θt). Fitted by least squares over the
    /// exits of two or more scatterings of every incidence node, [c, g] per bin. Light leaves
    /// leaning away from where it entered (c 0.3-0.9: more so near the entry), and near an oblique
    /// entry back toward the light (g < 0 within a mean free path). Nothing on a flat surface lit
    /// evenly (â averages out, and g cancels c's share along the lean b); on a front-lit ball the
    /// rim's light comes from the brighter pole and leaves leaning away from the eye, on a
    /// back-lit one toward it (tests/exit_tilt.rs).
    pub exit_tilt: Vec<[f64; 2]>,
}

impl super::table_cache::Flat for McProfile {
    fn to_flat(&self) -> Vec<f64> {
        let mut v = vec![
            self.sigma_t_reduced,
            self.albedo_reduced,
            self.eta,
            self.exit_norm,
            self.escape,
            self.single_escape,
            self.cos_t_min,
        ];
        v.extend(self.incidence);
        v.extend(self.exit.iter().flatten());
        super::table_cache::push_vec(&mut v, self.density.iter().copied());
        super::table_cache::push_vec(&mut v, self.azimuth.iter().copied());
        super::table_cache::push_vec(&mut v, self.exit_tilt.concat().into_iter());
        super::table_cache::push_vec(&mut v, self.harmonics.concat().into_iter());
        super::table_cache::push_vec(&mut v, self.radial.iter().copied());
        v
    }
    fn from_flat(values: &[f64]) -> Option<McProfile> {
        let mut t = super::table_cache::Take(values);
        let [sigma_t_reduced, albedo_reduced, eta, exit_norm, escape, single_escape, cos_t_min] = t.array::<7>()?;
        let incidence = t.array::<INCIDENCE_NODES>()?;
        let mut exit = [[0.0; EXIT_BINS]; INCIDENCE_NODES];
        for row in &mut exit {
            *row = t.array::<EXIT_BINS>()?;
        }
        let (density, azimuth, tilt, harmonics, radial) = (t.vec()?, t.vec()?, t.vec()?, t.vec()?, t.vec()?);
        t.end()?;
        if tilt.len() % 2 != 0 || harmonics.len() % 2 != 0 {
            return None;
        }
        let exit_tilt = tilt.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
        let harmonics = harmonics.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
        Some(McProfile {
            sigma_t_reduced,
            albedo_reduced,
            eta,
            exit_norm,
            escape,
            single_escape,
            density,
            cos_t_min,
            incidence,
            exit,
            azimuth,
            harmonics,
            radial,
            exit_tilt,
        })
    }
}

/// The edges of radial bin `k` in mean free paths.
fn bin_edges(k: usize) -> (f64, f64) {
    let q = (RHO_MAX / RHO_MIN).powf(1.0 / RADIAL_BINS as f64);
    match k {
        0 => (0.0, RHO_MIN),
        _ => (RHO_MIN * q.powi(k as i32 - 1), RHO_MIN * q.powi(k as i32)),
    }
}

/// The radial bin of ρ (mean free paths), or None beyond [`RHO_MAX`].
fn bin_of(rho: f64) -> Option<usize> {
    if rho < RHO_MIN {
        return Some(0);
    }
    let k = 1 + ((rho / RHO_MIN).ln() / (RHO_MAX / RHO_MIN).ln() * RADIAL_BINS as f64) as usize;
    (k <= RADIAL_BINS).then_some(k)
}

/// Radial bins of the azimuthal harmonic: AZIMUTH_PER_OCTAVE an octave of ρ from AZIMUTH_MIN
/// mean free paths (bin 0 the disc below it).
pub const AZIMUTH_BINS: usize = 60;
const AZIMUTH_MIN: f64 = 0.01;
const AZIMUTH_PER_OCTAVE: f64 = 4.0;
/// Photons of the oblique nodes a bin's harmonic needs before it stands alone; fewer, and it is
/// pooled with its neighbours (the far bins, where few photons go).
const AZIMUTH_MIN_COUNT: u64 = 4000;

fn azimuth_bin_of(rho: f64) -> Option<usize> {
    if rho < AZIMUTH_MIN {
        return Some(0);
    }
    let b = 1 + ((rho / AZIMUTH_MIN).log2() * AZIMUTH_PER_OCTAVE) as usize;
    (b < AZIMUTH_BINS).then_some(b)
}

/// The centre of azimuth bin `b` in mean free paths (bin 0: half its edge).
pub fn azimuth_bin_centre(b: usize) -> f64 {
    if b == 0 {
        return 0.5 * AZIMUTH_MIN;
    }
    AZIMUTH_MIN * 2f64.powf((b as f64 - 0.5) / AZIMUTH_PER_OCTAVE)
}

/// Per oblique node and azimuth bin: Σ cos φ, Σ cos 2φ, Σ cos 3φ over the exits of two or more
/// scatterings, and their count.
type HarmonicSums = [([f64; 3], u64); AZIMUTH_BINS];

/// Harmonic `order` (1–3) per radial bin from the oblique nodes' sums:
/// b_n = Σ_k 2Σcos nφ_k s_k^n / Σ_k n_k s_k^2n (s_k = sin θt of node k), each bin pooled with
/// its neighbours until AZIMUTH_MIN_COUNT photons count.
fn azimuth_harmonic(
    harmonic: &[HarmonicSums; INCIDENCE_NODES],
    sin_t: impl Fn(usize) -> f64,
    order: usize,
) -> Vec<f64> {
    let sums: Vec<(f64, f64, u64)> = (0..AZIMUTH_BINS)
        .map(|b| {
            (0..INCIDENCE_NODES).fold((0.0, 0.0, 0), |(num, den, n), k| {
                let (cos_n, count) = harmonic[k][b];
                let c = cos_n[order - 1];
                let s = sin_t(k).powi(order as i32);
                (num + 2.0 * c * s, den + count as f64 * s * s, n + count)
            })
        })
        .collect();
    // A harmonic of a non-negative function: |b_n| sin^n θt ≤ 2.
    pooled_least_squares(&sums, (-2.0, 2.0))
}

/// Per azimuth bin, Σnum / Σden of `sums` (num, den, photons) pooled with the bin's neighbours
/// until AZIMUTH_MIN_COUNT photons count (the far bins, where few photons go), clamped to
/// `range`; 0 where nothing counted.
fn pooled_least_squares(sums: &[(f64, f64, u64)], (lo, hi): (f64, f64)) -> Vec<f64> {
    (0..sums.len())
        .map(|b| {
            let (mut num, mut den, mut n) = sums[b];
            let mut w = 1;
            while n < AZIMUTH_MIN_COUNT && w < sums.len() {
                for j in [b.wrapping_sub(w), b + w] {
                    if let Some(&(a, d, c)) = sums.get(j) {
                        (num, den, n) = (num + a, den + d, n + c);
                    }
                }
                w += 1;
            }
            if den > 0.0 {
                (num / den).clamp(lo, hi)
            } else {
                0.0
            }
        })
        .collect()
}

/// [`McProfile::radial`] per azimuth bin: a = Σ_k n_k y_k s_k² / Σ_k n_k s_k⁴ over the oblique
/// nodes k (y_k their exits per photon in the bin over the normal beam's times f_k, less 1; n_k
/// their count; s_k = sin θt), each bin pooled with its neighbours until AZIMUTH_MIN_COUNT
/// photons count, as the harmonics are.
fn radial_change(
    runs: &[(u64, [u64; EXIT_BINS]); INCIDENCE_NODES],
    harmonic: &[HarmonicSums; INCIDENCE_NODES],
    normal_counts: &[u64; AZIMUTH_BINS],
    incidence: &[f64; INCIDENCE_NODES],
    sin_t: impl Fn(usize) -> f64,
) -> Vec<f64> {
    let normal_traced = runs[INCIDENCE_NODES - 1].0 as f64;
    let sums: Vec<(f64, f64, u64)> = (0..AZIMUTH_BINS)
        .map(|b| {
            if normal_counts[b] == 0 {
                return (0.0, 0.0, 0);
            }
            let normal = normal_counts[b] as f64 / normal_traced;
            (0..INCIDENCE_NODES - 1).fold((0.0, 0.0, 0), |(num, den, n), k| {
                let count = harmonic[k][b].1;
                if count == 0 || runs[k].0 == 0 || incidence[k] <= 0.0 {
                    return (num, den, n);
                }
                let y = count as f64 / runs[k].0 as f64 / (normal * incidence[k]) - 1.0;
                let s2 = sin_t(k).powi(2);
                (num + count as f64 * y * s2, den + count as f64 * s2 * s2, n + count)
            })
        })
        .collect();
    // The mean stays non-negative: 1 + a sin²θt ≥ 0.
    pooled_least_squares(&sums, (-1.0, 4.0))
}

/// Per azimuth bin, the exit tilt's least-squares sums over escapes: Σ|ωt|², Σ|ωt|² â·m,
/// Σ|ωt|² |m|², Σ 2ωt·â, Σ 2ωt·m, and the count.
type TiltSums = [[f64; 6]; AZIMUTH_BINS];

/// Adds one escape at (x, y) leaving along `along` (outside) from an entry of tangential part
/// `m` to `sums`.
fn add_tilt(sums: &mut TiltSums, (x, y): (f64, f64), along: [f64; 2], m: f64) {
    let rho = (x * x + y * y).sqrt();
    let Some(b) = azimuth_bin_of(rho) else { return };
    if rho <= 0.0 {
        return;
    }
    let (ax, ay) = (x / rho, y / rho);
    let s = along[0] * along[0] + along[1] * along[1];
    let t = &mut sums[b];
    t[0] += s;
    t[1] += s * ax * m;
    t[2] += s * m * m;
    t[3] += 2.0 * (along[0] * ax + along[1] * ay);
    t[4] += 2.0 * along[0] * m;
    t[5] += 1.0;
}

/// [c, g] per bin from the nodes' pooled sums (each bin with its neighbours until
/// AZIMUTH_MIN_COUNT escapes count); g = 0 where no oblique light reached the bin.
fn exit_tilt(nodes: &[TiltSums]) -> Vec<[f64; 2]> {
    let pooled: Vec<[f64; 6]> = (0..AZIMUTH_BINS)
        .map(|b| {
            let mut t = [0.0; 6];
            for n in nodes {
                (0..6).for_each(|i| t[i] += n[b][i]);
            }
            t
        })
        .collect();
    (0..AZIMUTH_BINS)
        .map(|b| {
            let mut t = pooled[b];
            let mut w = 1;
            while t[5] < AZIMUTH_MIN_COUNT as f64 && w < AZIMUTH_BINS {
                for j in [b.wrapping_sub(w), b + w] {
                    if let Some(p) = pooled.get(j) {
                        (0..6).for_each(|i| t[i] += p[i]);
                    }
                }
                w += 1;
            }
            let [a, ab, bb, y1, y2, _] = t;
            let det = a * bb - ab * ab;
            let (c, g) = if det > 1e-9 * a * bb && det > 0.0 {
                ((y1 * bb - y2 * ab) / det, (a * y2 - ab * y1) / det)
            } else if a > 0.0 {
                (y1 / a, 0.0)
            } else {
                (0.0, 0.0)
            };
            // As the lean b: held within ±2 (a bin of few, noisy escapes).
            [c.clamp(-2.0, 2.0), g.clamp(-2.0, 2.0)]
        })
        .collect()
}

/// cos θt of incidence node `k`.
pub fn incidence_node(cos_t_min: f64, k: usize) -> f64 {
    cos_t_min + (1.0 - cos_t_min) * k as f64 / (INCIDENCE_NODES - 1) as f64
}

/// The refracted cosine of grazing entry, √(1 − 1/η²) for η > 1, and at least 0.05 (where η ≤ 1
/// refraction reaches the horizon; a photon starting along it never enters; below 0.05 the factor
/// is held).
pub fn critical_cos_t(eta: f64) -> f64 {
    (1.0 - 1.0 / (eta * eta)).max(0.0).sqrt().max(0.05)
}

impl McProfile {
    /// Measures one channel (deterministic: fixed seeds). Cached: a medium measured once is not
    /// measured again in this process (the viewer switching models, several objects of one material).
    /// Two threads asking for one medium at once (the curvature table reads this profile) measure
    /// it once: the second waits for the first.
    pub fn of(m: &Medium) -> Arc<McProfile> {
        type Cell = Arc<OnceLock<Arc<McProfile>>>;
        static CACHE: OnceLock<Mutex<HashMap<[u64; 4], Cell>>> = OnceLock::new();
        let key = [m.sigma_a, m.sigma_s, m.g, m.eta].map(f64::to_bits);
        let cache = CACHE.get_or_init(Default::default);
        let cell = cache.lock().unwrap_or_else(|e| e.into_inner()).entry(key).or_default().clone();
        cell.get_or_init(|| Arc::new(super::table_cache::cached("half-space", &key, || McProfile::measure(m)))).clone()
    }

    /// Measures the three channels of a material, in parallel.
    pub fn of_channels(media: &[Medium; 3]) -> [Arc<McProfile>; 3] {
        std::thread::scope(|s| {
            let handles = media.each_ref().map(|m| s.spawn(move || McProfile::of(m)));
            handles.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
        })
    }

    fn measure(m: &Medium) -> McProfile {
        let sigma_s_reduced = m.sigma_s * (1.0 - m.g);
        let sigma_t_reduced = m.sigma_a + sigma_s_reduced;
        let albedo = if sigma_t_reduced > 0.0 { sigma_s_reduced / sigma_t_reduced } else { 0.0 };
        let eta = m.eta;
        let cos_t_min = critical_cos_t(eta);
        let exit_bin = |e: &halfspace::Escape| ((e.mu_o2 * EXIT_BINS as f64) as usize).min(EXIT_BINS - 1);
        // Per incidence node: photons traced, escapes per exit bin, per azimuth bin Σ cos φ and
        // the count of the exits of two or more scatterings; the last node (normal incidence)
        // also gives the radial profile and the single scattering. Each node walks on its own
        // thread, seeded by its index: the same bits on any machine.
        let node = |k: usize| {
            let (mut exit_counts, mut cos_phi): ([u64; EXIT_BINS], HarmonicSums) =
                ([0; EXIT_BINS], [([0.0; 3], 0); AZIMUTH_BINS]);
            let (mut density, mut single) = (vec![0.0; RADIAL_BINS + 1], 0u64);
            let mut tilt: TiltSums = [[0.0; 6]; AZIMUTH_BINS];
            // The normal beam's exits of two or more scatterings per azimuth bin (the oblique
            // nodes count theirs in cos_phi).
            let mut normal_counts = [0u64; AZIMUTH_BINS];
            let cos_t = incidence_node(cos_t_min, k);
            let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
            let start = glam::DVec3::new(sin_t, 0.0, -cos_t);
            let seed = 0x5eed_0000_0000 + ((k as u64) << 32);
            let traced = if k == INCIDENCE_NODES - 1 {
                trace_until(
                    albedo,
                    eta,
                    start,
                    (ESCAPES_NORMAL, MAX_PHOTONS_NORMAL, MAX_SCATTERINGS_NORMAL),
                    seed,
                    |e| {
                        if e.scatterings == 1 {
                            single += 1;
                            return;
                        }
                        let rho = (e.x * e.x + e.y * e.y).sqrt();
                        if let Some(k) = bin_of(rho) {
                            density[k] += 1.0;
                        }
                        if let Some(b) = azimuth_bin_of(rho) {
                            normal_counts[b] += 1;
                        }
                        exit_counts[exit_bin(e)] += 1;
                        add_tilt(&mut tilt, (e.x, e.y), e.along, 0.0);
                    },
                )
            } else {
                trace_until(
                    albedo,
                    eta,
                    start,
                    (ESCAPES_OBLIQUE, MAX_PHOTONS_OBLIQUE, MAX_SCATTERINGS_OBLIQUE),
                    seed,
                    |e| {
                        if e.scatterings >= 2 {
                            exit_counts[exit_bin(e)] += 1;
                            let rho = (e.x * e.x + e.y * e.y).sqrt();
                            if let Some(b) = azimuth_bin_of(rho) {
                                // cos nφ by Chebyshev's T_n of cos φ.
                                let c = e.x / rho;
                                let sums = &mut cos_phi[b].0;
                                sums[0] += c;
                                sums[1] += 2.0 * c * c - 1.0;
                                sums[2] += (4.0 * c * c - 3.0) * c;
                                cos_phi[b].1 += 1;
                            }
                            add_tilt(&mut tilt, (e.x, e.y), e.along, sin_t);
                        }
                    },
                )
            };
            ((traced, exit_counts), cos_phi, density, single, tilt, normal_counts)
        };
        let node = &node;
        let nodes: Vec<_> = std::thread::scope(|s| {
            let handles: Vec<_> = (0..INCIDENCE_NODES).map(|k| s.spawn(move || node(k))).collect();
            handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
        });
        let runs: [(u64, [u64; EXIT_BINS]); INCIDENCE_NODES] = std::array::from_fn(|k| nodes[k].0);
        let harmonic: [HarmonicSums; INCIDENCE_NODES] = std::array::from_fn(|k| nodes[k].1);
        let tilts: Vec<TiltSums> = nodes.iter().map(|n| n.4).collect();
        let (_, _, mut density, single, _, normal_counts) = nodes[INCIDENCE_NODES - 1].clone();
        let escape_of = |(traced, counts): &(u64, [u64; EXIT_BINS])| counts.iter().sum::<u64>() as f64 / *traced as f64;
        let (normal_traced, _) = runs[INCIDENCE_NODES - 1];
        for (k, d) in density.iter_mut().enumerate() {
            let (lo, hi) = bin_edges(k);
            *d /= normal_traced as f64 * PI * (hi * hi - lo * lo);
        }
        let escape = escape_of(&runs[INCIDENCE_NODES - 1]);
        let single_escape = single as f64 / normal_traced as f64;
        let incidence = std::array::from_fn(|k| if escape > 0.0 { escape_of(&runs[k]) / escape } else { 1.0 });
        let exit_norm = super::beam_diffusion::exit_normalisation(eta);
        // h per bin: the measured radiance per unit exitance over the renderer's Ft(θo)/exit_norm,
        // Ft averaged over the bin (midpoints in cos²θo).
        let ft_of_bin = |b: usize| {
            let sub = 32;
            (0..sub)
                .map(|j| {
                    fresnel::transmittance(eta, ((b as f64 + (j as f64 + 0.5) / sub as f64) / EXIT_BINS as f64).sqrt())
                })
                .sum::<f64>()
                / sub as f64
        };
        let exit = std::array::from_fn(|k| {
            let (traced, counts) = &runs[k];
            let p = escape_of(&runs[k]);
            std::array::from_fn(|b| {
                // Bin b's projected solid angle is π/EXIT_BINS.
                let radiance = counts[b] as f64 / *traced as f64 / (PI / EXIT_BINS as f64);
                let ft = ft_of_bin(b);
                if p > 0.0 && ft > 0.0 && counts[b] > 0 {
                    radiance / (p * ft / exit_norm)
                } else {
                    1.0
                }
            })
        });
        let sin_t = |k: usize| (1.0 - incidence_node(cos_t_min, k).powi(2)).max(0.0).sqrt();
        let azimuth = azimuth_harmonic(&harmonic, sin_t, 1);
        let (second, third) = (azimuth_harmonic(&harmonic, sin_t, 2), azimuth_harmonic(&harmonic, sin_t, 3));
        let radial = radial_change(&runs, &harmonic, &normal_counts, &incidence, sin_t);
        let mut profile = McProfile {
            azimuth,
            harmonics: second.into_iter().zip(third).map(|(a, b)| [a, b]).collect(),
            radial,
            exit_tilt: exit_tilt(&tilts),
            sigma_t_reduced,
            albedo_reduced: albedo,
            eta,
            exit_norm,
            escape,
            single_escape,
            density,
            cos_t_min,
            incidence,
            exit,
        };
        // Log-log interpolation between the bins' centres bends below the profile's convex
        // stretches (0.5% of the plane integral on Skin1's green): scaled so that the
        // interpolated profile keeps the measured escape fraction.
        if profile.transports() && escape > 0.0 {
            let mfp = 1.0 / sigma_t_reduced;
            let interpolated =
                halfspace::plane_integral(|x| profile.exitance(x.length()), 1e-6 * mfp, RHO_MAX * mfp, 1);
            if interpolated > 0.0 {
                profile.density.iter_mut().for_each(|d| *d *= escape / interpolated);
            }
        }
        profile
    }

    /// Whether the channel carries light (σ's > 0).
    pub fn transports(&self) -> bool {
        self.albedo_reduced > 0.0 && self.sigma_t_reduced > 0.0
    }

    /// Exitance M(r) per unit power entering (1/mm²), r in mm: log-log between the bins' centres
    /// (linear where a bin is empty), the disc's mean held below the first centre, 0 past the last.
    pub fn exitance(&self, r: f64) -> f64 {
        if !self.transports() {
            return 0.0;
        }
        let rho = r * self.sigma_t_reduced;
        let centre = |k: usize| {
            let (lo, hi) = bin_edges(k);
            if k == 0 {
                0.5 * hi
            } else {
                (lo * hi).sqrt()
            }
        };
        let per_mfp2 = if rho <= centre(0) {
            self.density[0]
        } else if rho >= centre(RADIAL_BINS) {
            0.0
        } else {
            let k = match bin_of(rho) {
                Some(k) if rho >= centre(k) => k,
                Some(k) => k - 1,
                None => RADIAL_BINS - 1,
            };
            let (c0, c1) = (centre(k), centre(k + 1));
            let (d0, d1) = (self.density[k], self.density[k + 1]);
            let t = (rho / c0).ln() / (c1 / c0).ln();
            if d0 > 0.0 && d1 > 0.0 {
                (d0.ln() + t * (d1 / d0).ln()).exp()
            } else {
                d0 + t * (d1 - d0)
            }
        };
        per_mfp2 * self.sigma_t_reduced * self.sigma_t_reduced
    }

    /// Sd(r) = M(r) / ∫Ft cos θ dω (1/mm²).
    pub fn sd(&self, r: f64) -> f64 {
        self.exitance(r) / self.exit_norm
    }

    /// Where distance `r` (mm) falls among the azimuth bins: the two bins to mix and the weight
    /// of the second, linear in log ρ between bin centres, held beyond the outer ones (the
    /// first bin below AZIMUTH_MIN, the second up to its centre).
    fn azimuth_bins_at(&self, r: f64) -> (usize, usize, f64) {
        let rho = r * self.sigma_t_reduced;
        if rho <= azimuth_bin_centre(1) {
            let held = if rho < AZIMUTH_MIN { 0 } else { 1 };
            return (held, held, 0.0);
        }
        let x = (rho / AZIMUTH_MIN).log2() * AZIMUTH_PER_OCTAVE + 0.5;
        let i = (x.floor() as usize).min(AZIMUTH_BINS - 2);
        (i, i + 1, (x - i as f64).clamp(0.0, 1.0))
    }

    /// The azimuthal harmonic b at distance `r` (mm), read as `azimuth_bins_at` says.
    pub fn azimuth_factor(&self, r: f64) -> f64 {
        let (i, j, f) = self.azimuth_bins_at(r);
        self.azimuth[i] + (self.azimuth[j] - self.azimuth[i]) * f
    }

    /// The higher azimuthal harmonics [b₂, b₃] at distance `r` (mm), read as
    /// [`McProfile::azimuth_factor`] (0 for a profile without them).
    pub fn higher_harmonics(&self, r: f64) -> [f64; 2] {
        self.pair_at(&self.harmonics, r)
    }

    /// A per-bin pair of `table` at distance `r` (mm), read as `azimuth_bins_at` says (0 for a
    /// profile without the table).
    fn pair_at(&self, table: &[[f64; 2]], r: f64) -> [f64; 2] {
        if table.len() < AZIMUTH_BINS {
            return [0.0; 2];
        }
        let (i, j, f) = self.azimuth_bins_at(r);
        let (a, b) = (table[i], table[j]);
        [a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f]
    }

    /// The radial profile's change with incidence a at distance `r` (mm) ([`McProfile::radial`]),
    /// read as [`McProfile::azimuth_factor`] (0 for a profile without it).
    pub fn radial_at(&self, r: f64) -> f64 {
        if self.radial.len() < AZIMUTH_BINS {
            return 0.0;
        }
        let (i, j, f) = self.azimuth_bins_at(r);
        self.radial[i] + (self.radial[j] - self.radial[i]) * f
    }

    /// The factor (1 + a s²)(1 + b x + b₂ (2x² − s²) + b₃ (4x³ − 3xs²)) ≥ 0 at distance `r` (mm),
    /// x = m·d̂ = sin θt cos φ and s² = |m|² = sin²θt (m the refracted light's part along the
    /// surface, d̂ the way to the exit along it): the radial change and the three harmonics
    /// written in m, as the shade pass (`mc_sd`) writes them.
    pub fn lean(&self, r: f64, x: f64, s2: f64) -> f64 {
        let [b2, b3] = self.higher_harmonics(r);
        let around = 1.0 + self.azimuth_factor(r) * x + b2 * (2.0 * x * x - s2) + b3 * (4.0 * x * x - 3.0 * s2) * x;
        ((1.0 + self.radial_at(r) * s2) * around).max(0.0)
    }

    /// The exit's tilt [c, g] at distance `r` (mm), read as [`McProfile::azimuth_factor`]
    /// (0 for a profile without it).
    pub fn exit_tilt_at(&self, r: f64) -> [f64; 2] {
        self.pair_at(&self.exit_tilt, r)
    }

    /// f at refracted cosine `cos_t`, linear between nodes.
    pub fn incidence_factor(&self, cos_t: f64) -> f64 {
        let x = ((cos_t - self.cos_t_min) / (1.0 - self.cos_t_min)).clamp(0.0, 1.0) * (INCIDENCE_NODES - 1) as f64;
        let i = (x.floor() as usize).min(INCIDENCE_NODES - 2);
        let (a, b) = (self.incidence[i], self.incidence[i + 1]);
        a + (b - a) * (x - i as f64)
    }

    /// h at refracted incidence cosine `cos_t` and exit cosine `cos_o` (outside): linear
    /// between incidence nodes and, in cos²θo, between exit bins' centres (held beyond the outer ones).
    pub fn exit_factor(&self, cos_t: f64, cos_o: f64) -> f64 {
        let x = ((cos_t - self.cos_t_min) / (1.0 - self.cos_t_min)).clamp(0.0, 1.0) * (INCIDENCE_NODES - 1) as f64;
        let i = (x.floor() as usize).min(INCIDENCE_NODES - 2);
        let y = (cos_o * cos_o * EXIT_BINS as f64 - 0.5).clamp(0.0, (EXIT_BINS - 1) as f64);
        let j = (y.floor() as usize).min(EXIT_BINS - 2);
        let at = |k: usize| {
            let (a, b) = (self.exit[k][j], self.exit[k][j + 1]);
            a + (b - a) * (y - j as f64)
        };
        at(i) + (at(i + 1) - at(i)) * (x - i as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bins tile the radii without gaps, and the profile integrates back to the escape
    /// fraction.
    #[test]
    fn bins_tile_and_profile_integrates_to_escape() {
        for k in 1..=RADIAL_BINS {
            assert!((bin_edges(k).0 - bin_edges(k - 1).1).abs() < 1e-12 * bin_edges(k).0);
            let mid = (bin_edges(k).0 * bin_edges(k).1).sqrt();
            assert_eq!(bin_of(mid), Some(k));
        }
        let p = McProfile::of(&Medium { sigma_a: 0.17, sigma_s: 0.88, g: 0.0, eta: 1.3 });
        let binned: f64 = (0..=RADIAL_BINS)
            .map(|k| {
                let (lo, hi) = bin_edges(k);
                p.density[k] * PI * (hi * hi - lo * lo)
            })
            .sum();
        // The bins hold every escape but those beyond RHO_MAX; the interpolant is scaled to the
        // escape fraction by less than 1%.
        assert!((binned / p.escape - 1.0).abs() < 1e-2, "{binned} vs {}", p.escape);
        let interpolated = halfspace::plane_integral(|x| p.exitance(x.length()), 1e-7, 200.0, 1);
        assert!((interpolated / p.escape - 1.0).abs() < 1e-4, "{interpolated} vs {}", p.escape);
        assert_eq!(p.incidence[INCIDENCE_NODES - 1], 1.0);
        assert!((p.incidence_factor(1.0) - 1.0).abs() < 1e-12);
    }
}
