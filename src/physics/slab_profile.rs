//! Light across an object, tabulated by Monte Carlo (`--model mc`'s transmission): the radial
//! profile T(ρ; t) of the multiple scattering (two or more scatterings) that a flat slab of
//! thickness t lets out of its far face, at lateral distance ρ from where a beam entered the near
//! face at normal incidence, per unit power entering, measured per channel by the analogue
//! Monte Carlo of [`super::halfspace::trace_slab`] at thicknesses t_k = L · 2^(k/2 − 4), k = 0 …
//! [`THICKNESS_NODES`] − 1 (L/16 to 90 L), L the material's longest reduced mean free path (its
//! most translucent channel), with the exit distribution h_T of what it lets through.
//!
//! Why: the half-space's profile Sp(r) of [`super::mc_profile`] read at the distance through an
//! object is a different transport: in the half-space light that travels r has done so along
//! the surface, leaving through it all the way, and no far face reflects any back. Through
//! Skin1's 2 mm slab it made 0.92 / 0.41 / 0.19 (R G B) of the slab's transmitted multiple
//! scattering and Potato's red 1.86× it (tests/slab_profile.rs prints them).
//!
//! The shade pass (shaders/shade.frag `across`, bssrdf.glsl `slab_transmission`) reads a pair of
//! points whose normals face away from each other, the source behind the pixel's tangent plane,
//! as a local slab: thickness t = (xo − xi)·no, lateral distance ρ, in the blend
//! S = (1 − w) Sp(r) + w T(ρ; t), w = −ni·no (1 across a flat slab, 0 where the normals are
//! perpendicular, so nothing jumps), with the exit factor h_T read once per pixel at the
//! luminance-weighted mean thickness of its sources across, and the transmitted fraction's change
//! with the light's angle of incidence ([`SlabChannel::oblique_factor`]: light refracted
//! obliquely into Skin1's 2 mm slab, θt = 42°, lets through 1.10 / 1.03 / 0.92 (R G B) of what
//! enters at normal incidence: less of it crosses unscattered, and it scatters first nearer the
//! near face; read at normal incidence the back-lit 2 mm slab at 60° was 0.944 1.029 1.135 of
//! the path tracer). Between nodes the profile
//! is interpolated at the same u = ρ/(ρ + t + L) in units of (t + L)² (its width grows as t + L),
//! geometrically in value and linearly in t (a thick slab's transmission falls exponentially in
//! t); below node 0 it holds; over the last half octave it fades to 0 (there a slab lets through
//! less than 1e-3 of what enters wherever anything is absorbed). Where the object is not a slab
//! (a sphere, whose walls keep the light a slab would spread sideways) it is an approximation:
//! the README's table measures it.

use super::{halfspace, Medium};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// Thickness nodes t_k = L · 2^(k/2 + FIRST_NODE_LOG2), half an octave apart (an octave apart,
/// the interpolation between them lost up to 14% of Skin1's blue through 2 mm).
pub const THICKNESS_NODES: usize = 22;
pub const FIRST_NODE_LOG2: i32 = -4;
/// The nodes the lookup reads, a quarter octave apart (2 × THICKNESS_NODES − 1: the measured ones
/// and, between each two, their geometric interpolation), so that the shade pass interpolates
/// linearly, with no logarithm or exponential per pair but the thickness's log2.
pub const LOOKUP_NODES: usize = 2 * THICKNESS_NODES - 1;
/// Bins of the transmitted exit distribution h_T, equal in cos²θo outside (as
/// [`super::mc_profile::EXIT_BINS`]).
pub const EXIT_BINS: usize = super::mc_profile::EXIT_BINS;
/// Radial entries per node, equally spaced in u = ρ/(ρ + reach), reach = t_k + L: entry i holds
/// the bin u ∈ [i, i + 1)/ENTRIES at its centre.
pub const ENTRIES: usize = 64;

/// Rows of [`SlabChannel::oblique`]: row q at sin²θt = q / (OBLIQUE_ROWS − 1) of the largest a
/// refracted ray can have (1/η²), held at 0.9 (θt = 72°) where η is near or below 1: a beam
/// started along the face (θt = 90°) never leaves it, and the walk of η = 0.7 did not end.
pub const OBLIQUE_ROWS: usize = 6;
/// The largest sin²θt of the rows (bssrdf.glsl's `slab_oblique_factor` holds the same).
pub const OBLIQUE_LARGEST_SIN2: f64 = 0.9;

/// The oblique rows walk the normal beam's first batches: a share 1/OBLIQUE_SHARE of them, or as
/// many as let OBLIQUE_COUNT photons through at normal incidence.
const OBLIQUE_SHARE: usize = 4;
const OBLIQUE_COUNT: u64 = 2_500;
/// Transmitted photons wanted per node, and the caps on photons and scatterings (what bounds a
/// thick node of a medium that absorbs nothing).
const TRANSMITTED: u64 = 20_000;
const MAX_PHOTONS: u64 = 400_000;
const MAX_SCATTERINGS: u64 = 3_000_000;
/// A node past the peak of the transmission (at least a mean free path thick, and letting
/// through less than the most any thinner node did) that lets through less than this fraction
/// of what enters (after NEGLIGIBLE_AFTER photons) ends the measurement: it and every thicker
/// node hold 0 (thicker slabs let through less still; what they would add to a pixel is far
/// below the half-space's own noise). Before the peak it does not: light scattered twice or
/// more grows with the thickness there (a thin slab scatters little), and where the albedo is
/// low the first node is below this fraction and thicker ones are not: Ketchup's green and blue
/// had ended at the first node, no light across at all (its 2 mm slab lit from behind: green
/// 0.937 of the path tracer, all of it single scattering).
const NEGLIGIBLE: f64 = 1e-4;
/// Photons each node walks at least, for its lit face's light ([`SlabChannel::reflected`]), and
/// the half-space's walk it is measured against (capped in scatterings: a medium that absorbs
/// nothing returns nearly every photon after arbitrarily many). A ratio is taken over three
/// entries holding at least REFLECTED_LEAST of the half-space's photons (held outward beyond).
const REFLECTED_PHOTONS: u64 = 100_000;
const HALF_SPACE_PHOTONS: u64 = 200_000;
const HALF_SPACE_SCATTERINGS: u64 = 40_000_000;
const REFLECTED_LEAST: u64 = 400;
const NEGLIGIBLE_AFTER: u64 = 40_000;
const BATCH: u64 = 5_000;
const MAX_COLLISIONS: u32 = 100_000;

/// Thickness of node `k` in units of L.
pub fn node_thickness(k: usize) -> f64 {
    2f64.powf(k as f64 / 2.0 + FIRST_NODE_LOG2 as f64)
}

/// The centre of radial entry `i` in u.
pub fn entry_centre(i: usize) -> f64 {
    (i as f64 + 0.5) / ENTRIES as f64
}

/// The lookup coordinate of thickness t (units of L): j at lookup node j (t = 2^(j/4 − 4)).
pub fn lookup_coordinate(thickness: f64) -> f64 {
    4.0 * (thickness.log2() - FIRST_NODE_LOG2 as f64)
}

/// The node coordinate of thickness t (units of L): k at node k.
pub fn node_coordinate(thickness: f64) -> f64 {
    2.0 * (thickness.log2() - FIRST_NODE_LOG2 as f64)
}

/// Thickness t read between lookup nodes: its lookup coordinate x (≥ 0), the node j below it and
/// the weight a of j + 1, and reach = t + L (mm), the scale of both nodes' radial maps there.
struct LookupPlace {
    x: f64,
    j: usize,
    a: f64,
    reach: f64,
}

/// One channel's transmission profiles.
#[derive(Clone, Debug, PartialEq)]
pub struct SlabChannel {
    /// L (mm): the unit of the nodes' thicknesses.
    pub unit_mm: f64,
    /// Per node, the fraction of the power entering that leaves the far face after two or more
    /// scatterings.
    pub transmitted: [f64; THICKNESS_NODES],
    /// Per node, per entry: T as an Sd, the exitance per unit power entering over the lobe's
    /// ∫Ft cos θ dω (1/mm²).
    pub sd: Vec<[f64; ENTRIES]>,
    /// Per lookup node (thickness L · 2^(j/4 − 4)), per entry: T·reach_j² at the entries' centres,
    /// reach_j = t_j + L (what the shade pass reads, [`SlabChannel::sd`]).
    pub lookup: Vec<[f64; ENTRIES]>,
    /// Per node, per exit bin: h_T, the transmitted radiance per unit transmitted exitance over
    /// the lobe Ft(θo)/∫Ft cos θ dω (1 where the lobe is exact).
    pub exit: Vec<[f64; EXIT_BINS]>,
    /// Per node, per row of incidence ([`OBLIQUE_ROWS`]): the fraction let through (two or more
    /// scatterings) by a beam refracted in at that sin²θt, over the normal beam's (row 0: 1).
    pub oblique: Vec<[f64; OBLIQUE_ROWS]>,
    /// Per lookup node, per entry (the same u = ρ/(ρ + reach_j) as `lookup`): what the slab's lit
    /// face lets out again (two or more scatterings) over what the half-space's does at the same
    /// ρ, R_slab(ρ; t)/R_hs(ρ) (1 where the slab is too thick to matter). Light that would have
    /// come back from deep in a half-space leaves a thin slab through its far face instead.
    pub reflected: Vec<[f64; ENTRIES]>,
}

/// sin²θt of row q of [`SlabChannel::oblique`] for relative index `eta`.
pub fn oblique_row_sin2(q: usize, eta: f64) -> f64 {
    let largest = (1.0 / (eta * eta)).min(OBLIQUE_LARGEST_SIN2);
    largest * q as f64 / (OBLIQUE_ROWS - 1) as f64
}

impl super::table_cache::Flat for SlabChannel {
    fn to_flat(&self) -> Vec<f64> {
        let mut v = vec![self.unit_mm];
        v.extend(self.transmitted);
        super::table_cache::push_vec(&mut v, self.sd.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        super::table_cache::push_vec(&mut v, self.lookup.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        super::table_cache::push_vec(&mut v, self.exit.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        super::table_cache::push_vec(&mut v, self.oblique.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        super::table_cache::push_vec(&mut v, self.reflected.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        v
    }
    fn from_flat(values: &[f64]) -> Option<SlabChannel> {
        let mut t = super::table_cache::Take(values);
        let unit_mm = t.scalar()?;
        let transmitted = t.array::<THICKNESS_NODES>()?;
        let rows = |flat: Vec<f64>| -> Option<Vec<[f64; ENTRIES]>> {
            flat.len()
                .is_multiple_of(ENTRIES)
                .then(|| flat.chunks_exact(ENTRIES).filter_map(|c| c.try_into().ok()).collect())
        };
        let (sd, lookup) = (rows(t.vec()?)?, rows(t.vec()?)?);
        let exit_flat = t.vec()?;
        let oblique_flat = t.vec()?;
        let reflected = rows(t.vec()?)?;
        t.end()?;
        if reflected.len() != LOOKUP_NODES {
            return None;
        }
        if !exit_flat.len().is_multiple_of(EXIT_BINS) || oblique_flat.len() != THICKNESS_NODES * OBLIQUE_ROWS {
            return None;
        }
        let exit = exit_flat.chunks_exact(EXIT_BINS).filter_map(|c| c.try_into().ok()).collect();
        let oblique = oblique_flat.chunks_exact(OBLIQUE_ROWS).filter_map(|c| c.try_into().ok()).collect();
        Some(SlabChannel { unit_mm, transmitted, sd, lookup, exit, oblique, reflected })
    }
}

/// The reach of node `k`'s radial map (mm).
fn reach_mm(unit_mm: f64, k: usize) -> f64 {
    unit_mm * (node_thickness(k) + 1.0)
}

/// ρ (mm) at u of a map of `reach`.
fn rho_of(u: f64, reach: f64) -> f64 {
    if u >= 1.0 {
        f64::INFINITY
    } else {
        reach * u / (1.0 - u)
    }
}

impl SlabChannel {
    /// Measures one channel with unit `unit_mm` (deterministic: fixed seeds); cached.
    pub fn of(m: &Medium, unit_mm: f64) -> Arc<SlabChannel> {
        static CACHE: OnceLock<Mutex<HashMap<[u64; 5], Arc<SlabChannel>>>> = OnceLock::new();
        let key = [m.sigma_a, m.sigma_s, m.g, m.eta, unit_mm].map(f64::to_bits);
        let cache = CACHE.get_or_init(Default::default);
        if let Some(p) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
            return p.clone();
        }
        let p = Arc::new(super::table_cache::cached("slab", &key, || SlabChannel::measure(m, unit_mm)));
        cache.lock().unwrap_or_else(|e| e.into_inner()).insert(key, p.clone());
        p
    }

    fn measure(m: &Medium, unit_mm: f64) -> SlabChannel {
        let sigma_s_reduced = m.sigma_s * (1.0 - m.g);
        let sigma_t = m.sigma_a + sigma_s_reduced;
        let mut out = SlabChannel {
            unit_mm,
            transmitted: [0.0; THICKNESS_NODES],
            sd: vec![[0.0; ENTRIES]; THICKNESS_NODES],
            lookup: vec![[0.0; ENTRIES]; LOOKUP_NODES],
            exit: vec![[1.0; EXIT_BINS]; THICKNESS_NODES],
            oblique: vec![[1.0; OBLIQUE_ROWS]; THICKNESS_NODES],
            reflected: vec![[1.0; ENTRIES]; LOOKUP_NODES],
        };
        if !(sigma_s_reduced > 0.0 && sigma_t > 0.0 && unit_mm > 0.0 && unit_mm.is_finite()) {
            return out;
        }
        let albedo = sigma_s_reduced / sigma_t;
        let exit_norm = super::beam_diffusion::exit_normalisation(m.eta);
        let entry_start = glam::DVec3::new(0.0, 0.0, -1.0);
        let mut peak = 0.0f64; // the largest fraction let through so far
                               // The half-space's light out again, binned as each node's map bins it: what the nodes'
                               // lit faces are measured against.
        let mut half_space = vec![[0u64; ENTRIES]; THICKNESS_NODES];
        let mut half_space_traced = 0u64;
        let mut half_space_scatterings = 0u64;
        while half_space_traced < HALF_SPACE_PHOTONS && half_space_scatterings < HALF_SPACE_SCATTERINGS {
            let seed = (0x51ab_ffff_0000_0000 + half_space_traced / BATCH, MAX_COLLISIONS);
            half_space_scatterings += halfspace::trace_half_space(albedo, m.eta, entry_start, BATCH, seed, |e| {
                if e.scatterings < 2 {
                    return;
                }
                let rho = (e.x * e.x + e.y * e.y).sqrt() / sigma_t;
                for (k, counts) in half_space.iter_mut().enumerate() {
                    let u = rho / (rho + reach_mm(unit_mm, k));
                    counts[((u * ENTRIES as f64) as usize).min(ENTRIES - 1)] += 1;
                }
            });
            half_space_traced += BATCH;
        }
        let mut reflected_nodes = vec![[1.0f64; ENTRIES]; THICKNESS_NODES];
        for k in 0..THICKNESS_NODES {
            let thickness_mfp = node_thickness(k) * unit_mm * sigma_t;
            let reach = reach_mm(unit_mm, k);
            let mut counts = [0u64; ENTRIES];
            let mut exit_counts = [0u64; EXIT_BINS];
            let mut back = [0u64; ENTRIES]; // out again through the lit face
            let (mut traced, mut through, mut scatterings) = (0u64, 0u64, 0u64);
            // Photons let through after each batch (the oblique rows compare over the first ones).
            let mut through_after = Vec::new();
            let negligible = |through: u64, traced: u64| {
                traced >= NEGLIGIBLE_AFTER
                    && (through as f64) < NEGLIGIBLE * traced as f64
                    && thickness_mfp >= 1.0
                    && (through as f64) < peak * traced as f64
            };
            while (through < TRANSMITTED || traced < REFLECTED_PHOTONS)
                && traced < MAX_PHOTONS
                && scatterings < MAX_SCATTERINGS
                && !negligible(through, traced)
            {
                let seed = (0x51ab_0000_0000 + ((k as u64) << 32) + traced / BATCH, MAX_COLLISIONS);
                scatterings += halfspace::trace_slab(albedo, m.eta, thickness_mfp, entry_start, BATCH, seed, |e| {
                    if e.scatterings < 2 {
                        return;
                    }
                    let rho = (e.x * e.x + e.y * e.y).sqrt() / sigma_t;
                    let u = rho / (rho + reach);
                    if !e.transmitted {
                        back[((u * ENTRIES as f64) as usize).min(ENTRIES - 1)] += 1;
                        return;
                    }
                    through += 1;
                    counts[((u * ENTRIES as f64) as usize).min(ENTRIES - 1)] += 1;
                    exit_counts[((e.mu_o2 * EXIT_BINS as f64) as usize).min(EXIT_BINS - 1)] += 1;
                });
                traced += BATCH;
                through_after.push(through);
            }
            if negligible(through, traced) {
                break;
            }
            reflected_nodes[k] = reflected_ratio(&back, traced, &half_space[k], half_space_traced);
            let fraction = through as f64 / traced as f64;
            peak = peak.max(fraction);
            out.transmitted[k] = fraction;
            for (i, sd) in out.sd[k].iter_mut().enumerate() {
                let (r0, r1) =
                    (rho_of(i as f64 / ENTRIES as f64, reach), rho_of((i + 1) as f64 / ENTRIES as f64, reach));
                let area = PI * (r1 * r1 - r0 * r0);
                *sd = if area.is_finite() { counts[i] as f64 / traced as f64 / area / exit_norm } else { 0.0 };
            }
            for (b, h) in out.exit[k].iter_mut().enumerate() {
                // Bin b's projected solid angle is π/EXIT_BINS; Ft over it at its midpoint in cos²θo.
                let radiance = exit_counts[b] as f64 / traced as f64 / (PI / EXIT_BINS as f64);
                let ft = super::fresnel::transmittance(m.eta, ((b as f64 + 0.5) / EXIT_BINS as f64).sqrt());
                if exit_counts[b] > 0 && fraction > 0.0 && ft > 0.0 {
                    *h = radiance / (fraction * ft / exit_norm);
                }
            }
            // Linear interpolation between the bins' centres is not the bins' histogram: scaled
            // so that the interpolated profile keeps the measured fraction.
            let interpolated =
                halfspace::plane_integral(|x| out.node_sd(k, x.length()), 1e-9, 1e3 * reach, 1) * exit_norm;
            if interpolated > 0.0 && fraction > 0.0 {
                out.sd[k].iter_mut().for_each(|v| *v *= fraction / interpolated);
            }
            // The oblique rows: the first quarter of the same batches (seeds), entering at each
            // row's angle, against what the normal beam let through over them (the same random
            // numbers, so the ratio's noise is less than either fraction's; all the batches cost
            // Skin1's table 12.7 s instead of 2.1).
            // At least OBLIQUE_COUNT of the normal beam's photons through (all of them where
            // fewer went through), so that a row's noise stays near 2% where little crosses.
            let wanted = (through / OBLIQUE_SHARE as u64).max(through.min(OBLIQUE_COUNT));
            let batches = through_after.iter().position(|&n| n >= wanted).map_or(through_after.len(), |b| b + 1).max(1);
            let normal_through = through_after.get(batches - 1).copied().unwrap_or(0);
            for q in 1..OBLIQUE_ROWS {
                let sin2 = oblique_row_sin2(q, m.eta);
                let start = glam::DVec3::new(sin2.sqrt(), 0.0, -(1.0 - sin2).max(0.0).sqrt());
                let mut oblique_through = 0u64;
                for batch in 0..batches as u64 {
                    let seed = (0x51ab_0000_0000 + ((k as u64) << 32) + batch, MAX_COLLISIONS);
                    halfspace::trace_slab(albedo, m.eta, thickness_mfp, start, BATCH, seed, |e| {
                        if e.transmitted && e.scatterings >= 2 {
                            oblique_through += 1;
                        }
                    });
                }
                if normal_through > 0 {
                    out.oblique[k][q] = oblique_through as f64 / normal_through as f64;
                }
            }
        }
        out.lookup =
            (0..LOOKUP_NODES).map(|j| std::array::from_fn(|i| out.measured_scaled(j, entry_centre(i)))).collect();
        // Between measured nodes, linearly at the same u (a ratio, near 1 where it matters least).
        out.reflected = (0..LOOKUP_NODES)
            .map(|j| {
                let (k, odd) = (j / 2, j % 2 == 1);
                std::array::from_fn(|i| {
                    if odd {
                        0.5 * (reflected_nodes[k][i] + reflected_nodes[k + 1][i])
                    } else {
                        reflected_nodes[k][i]
                    }
                })
            })
            .collect();
        out
    }

    /// R_slab(ρ; t)/R_hs(ρ) on the lit face (the f64 mirror of bssrdf.glsl's
    /// `slab_reflected_ratio`): between lookup nodes linearly in log t at the same
    /// u = ρ/(ρ + reach), reach = t + L, and between the entries' centres (held below the first
    /// and past the last); 1 past the last node.
    pub fn reflected_ratio(&self, rho_mm: f64, thickness_mm: f64) -> f64 {
        let Some(place) = self.lookup_place(thickness_mm) else { return 1.0 };
        let u = rho_mm / (rho_mm + place.reach);
        let at = |j: usize| {
            let e = (u * ENTRIES as f64 - 0.5).clamp(0.0, (ENTRIES - 1) as f64);
            let i = (e.floor() as usize).min(ENTRIES - 2);
            self.reflected[j][i] + (self.reflected[j][i + 1] - self.reflected[j][i]) * (e - i as f64)
        };
        at(place.j) + (at(place.j + 1) - at(place.j)) * place.a
    }

    /// Where thickness t (mm) is read between lookup nodes (bssrdf.glsl's `slab_transmission` and
    /// `slab_reflected_rows` alike): None for no thickness or past the last node.
    fn lookup_place(&self, thickness_mm: f64) -> Option<LookupPlace> {
        if thickness_mm.is_nan() || thickness_mm <= 0.0 {
            return None;
        }
        let x = lookup_coordinate(thickness_mm / self.unit_mm);
        if x >= (LOOKUP_NODES - 1) as f64 {
            return None;
        }
        let x = x.max(0.0);
        let j = (x.floor() as usize).min(LOOKUP_NODES - 2);
        let reach = thickness_mm.max(self.unit_mm * node_thickness(0)) + self.unit_mm;
        Some(LookupPlace { x, j, a: x - j as f64, reach })
    }

    /// The measured nodes' T·reach² at lookup node `j` and u: node j/2 itself for even j; between
    /// two (odd j) at the same u, geometrically in value and linearly in t (a thick slab's
    /// transmission falls exponentially in t; an octave between measured nodes instead of half
    /// lost 14% of Skin1's blue through 2 mm).
    fn measured_scaled(&self, j: usize, u: f64) -> f64 {
        let k = j / 2;
        if j.is_multiple_of(2) {
            return self.node_scaled(k, u);
        }
        let a = (2f64.powf(0.25) - 1.0) / (2f64.sqrt() - 1.0);
        let (v0, v1) = (self.node_scaled(k, u), self.node_scaled(k + 1, u));
        if v0 > 0.0 && v1 > 0.0 {
            (v0.ln() + a * (v1 / v0).ln()).exp()
        } else {
            v0 + a * (v1 - v0)
        }
    }

    /// Lookup node `j`'s T·reach² at u: linear between the entries' centres, held below the first,
    /// falling linearly to 0 at u = 1 past the last (as [`SlabChannel::node_scaled`]).
    pub fn lookup_scaled(&self, j: usize, u: f64) -> f64 {
        between_entries(&self.lookup[j], u)
    }

    /// Node `k`'s T as an Sd times reach_k² (dimensionless) at u = ρ/(ρ + reach): linear between
    /// the entries' centres, held below the first, falling linearly to 0 at u = 1 past the last.
    pub fn node_scaled(&self, k: usize, u: f64) -> f64 {
        let reach = reach_mm(self.unit_mm, k);
        between_entries(&self.sd[k], u) * reach * reach
    }

    /// Node `k`'s T as an Sd at lateral distance ρ (mm).
    pub fn node_sd(&self, k: usize, rho_mm: f64) -> f64 {
        let reach = reach_mm(self.unit_mm, k);
        self.node_scaled(k, rho_mm / (rho_mm + reach)) / (reach * reach)
    }

    /// T(ρ; t) as an Sd (1/mm²), ρ and t in mm (the f64 mirror of bssrdf.glsl's
    /// `slab_transmission`): between lookup nodes, at the same u = ρ/(ρ + reach), reach = t + L, in
    /// units of reach² (a profile's width grows with t + L, so that is a change of scale between
    /// nodes, not a blur of two widths), linearly in log t; faded to 0 over the last half octave.
    pub fn sd(&self, rho_mm: f64, thickness_mm: f64) -> f64 {
        let Some(LookupPlace { x, j, a, reach }) = self.lookup_place(thickness_mm) else { return 0.0 };
        let last = (LOOKUP_NODES - 1) as f64;
        let u = rho_mm / (rho_mm + reach);
        let (v0, v1) = (self.lookup_scaled(j, u), self.lookup_scaled(j + 1, u));
        (v0 + (v1 - v0) * a) / (reach * reach) * (1.0 - smoothstep(last - 2.0, last, x))
    }

    /// The transmitted fraction's change with incidence at thickness t (mm) for light refracted in
    /// at sin²θt = `sin2_t` (the f64 mirror of bssrdf.glsl's `slab_oblique_factor`): linear in t
    /// between nodes and in sin²θt between rows (held past the last).
    pub fn oblique_factor(&self, thickness_mm: f64, sin2_t: f64, eta: f64) -> f64 {
        let x = node_coordinate((thickness_mm / self.unit_mm).max(node_thickness(0)))
            .clamp(0.0, (THICKNESS_NODES - 1) as f64);
        let k = (x.floor() as usize).min(THICKNESS_NODES - 2);
        let (t0, t1) = (node_thickness(k), node_thickness(k + 1));
        let a = ((thickness_mm / self.unit_mm - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let y = (sin2_t / oblique_row_sin2(1, eta)).clamp(0.0, (OBLIQUE_ROWS - 1) as f64);
        let q = (y.floor() as usize).min(OBLIQUE_ROWS - 2);
        let at = |k: usize| self.oblique[k][q] + (self.oblique[k][q + 1] - self.oblique[k][q]) * (y - q as f64);
        at(k) + (at(k + 1) - at(k)) * a
    }

    /// h_T at thickness t (mm) and exit cosine `cos_o` (outside): linear in t between nodes and,
    /// in cos²θo, between the bins' centres (held beyond the outer ones).
    pub fn exit_factor(&self, thickness_mm: f64, cos_o: f64) -> f64 {
        let x = node_coordinate((thickness_mm / self.unit_mm).max(node_thickness(0)))
            .clamp(0.0, (THICKNESS_NODES - 1) as f64);
        let k = (x.floor() as usize).min(THICKNESS_NODES - 2);
        let (t0, t1) = (node_thickness(k), node_thickness(k + 1));
        let a = ((thickness_mm / self.unit_mm - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let y = (cos_o * cos_o * EXIT_BINS as f64 - 0.5).clamp(0.0, (EXIT_BINS - 1) as f64);
        let j = (y.floor() as usize).min(EXIT_BINS - 2);
        let at = |k: usize| self.exit[k][j] + (self.exit[k][j + 1] - self.exit[k][j]) * (y - j as f64);
        at(k) + (at(k + 1) - at(k)) * a
    }
}

/// `entries` at u: linear between their centres, held below the first, falling linearly to 0 at
/// u = 1 past the last (bssrdf.glsl's `slab_lookup`).
fn between_entries(entries: &[f64; ENTRIES], u: f64) -> f64 {
    let x = u * ENTRIES as f64 - 0.5;
    if x <= 0.0 {
        return entries[0];
    }
    let i = x.floor() as usize;
    let f = x - i as f64;
    let a = entries[i.min(ENTRIES - 1)];
    let b = if i + 1 < ENTRIES { entries[i + 1] } else { 0.0 };
    a + (b - a) * f
}

/// Per entry, a slab node's light out of its lit face over the half-space's (`back` of `traced`
/// photons against `half_space` of `half_space_traced`, binned alike), each over three entries
/// (the noise of a bin's few photons far out): 1 where the half-space has too few to say.
fn reflected_ratio(
    back: &[u64; ENTRIES],
    traced: u64,
    half_space: &[u64; ENTRIES],
    half_space_traced: u64,
) -> [f64; ENTRIES] {
    let window = |c: &[u64; ENTRIES], i: usize| c[i.saturating_sub(1)..(i + 2).min(ENTRIES)].iter().sum::<u64>();
    // A slab whose lit face gives back all but 0.5% of the half-space's is one (its bins' ratios
    // would be noise about 1: the 20 mm textured slab's red moved +0.6%).
    let total = |c: &[u64; ENTRIES]| c.iter().sum::<u64>() as f64;
    if traced == 0 || total(back) / traced as f64 >= 0.995 * total(half_space) / half_space_traced as f64 {
        return [1.0; ENTRIES];
    }
    let mut held = 1.0;
    std::array::from_fn(|i| {
        let (b, h) = (window(back, i), window(half_space, i));
        if h >= REFLECTED_LEAST && traced > 0 {
            // At most 1: the far face only takes light away (where ρ ≪ t none reaches it; above
            // 1 is a bin's noise).
            held = ((b as f64 / traced as f64) / (h as f64 / half_space_traced as f64)).min(1.0);
        }
        held
    })
}

fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// L of a material: the longest reduced mean free path of its channels that carry light (mm); 1
/// where none does.
pub fn unit_mm(media: &[Medium; 3]) -> f64 {
    media
        .iter()
        .map(|m| (m.sigma_a + m.sigma_s * (1.0 - m.g), m.sigma_s * (1.0 - m.g)))
        .filter(|&(t, s)| s > 0.0 && t > 0.0)
        .map(|(t, _)| 1.0 / t)
        .fold(None, |a: Option<f64>, b| Some(a.map_or(b, |a| a.max(b))))
        .unwrap_or(1.0)
}

/// The three channels of a material, measured in parallel with one L.
pub fn of_channels(media: &[Medium; 3]) -> [Arc<SlabChannel>; 3] {
    let unit = unit_mm(media);
    std::thread::scope(|s| {
        let handles = media.each_ref().map(|m| s.spawn(move || SlabChannel::of(m, unit)));
        handles.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    })
}
