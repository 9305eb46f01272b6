//! What a curved surface does to the Monte Carlo table's multiple scattering (`--model mc`): per
//! channel, the ratio C(r; κ) of the exit profile of a sphere of curvature κ = 1/R (κ < 0: the
//! medium outside a spherical cavity, a concave surface) to the half-space's, at the same chord
//! r = |xo − xi| from where a pencil beam entered at normal incidence, two or more scatterings,
//! measured by [`super::sphere::trace_sphere`] against [`super::halfspace::trace_half_space`].
//!
//! Why: every profile here is the flat half-space's, but a sphere's walls keep inside the light
//! that a half-space lets go deep, and it comes out nearer: the 10 mm spheres of Skin1, Marble and
//! Potato were 7–13% too dark against the path tracer (README) while thick slabs were exact. The
//! shade pass reads the half-space's Sp(r) at the chord, so the ratio is taken at the chord too;
//! a sphere's area within chord c of a point is πc² (4πR² sin²(s/2R)), the disc's, so the ratio of
//! photon counts per chord ring is the ratio of exitances per unit area.
//!
//! Each photon walks the sphere and the half-space from the same seed (the same draws until the
//! two boundaries part), so the ratio's noise cancels where curvature changes little. Nodes:
//! κ_k = 2^(k + FIRST_CURVATURE_LOG2) / L, k = 0 … CURVATURE_NODES − 1 (1/16 … 8 of κL: radii 16 L
//! down to L/8), each sign, L the longest diffusion length 1/σtr of the material's channels (the
//! Sd table's reach); entries equally spaced in u = r/(r + L). The shade pass (bssrdf.glsl
//! `curvature_ratio`) reads it at the pixel's mean curvature (the mesh's, smoothed over L:
//! `mesh::smoothed_mean_curvature`), linear in κ from the flat row (1) to node 0 and linear in
//! log κ between nodes, held beyond the last. A chord longer than a sphere's diameter 2R does not
//! exist on it: there the ratio fades to 1 by 4R (the surface is no sphere there; the half-space
//! is the safe guess). Where the sphere and half-space counted fewer than MIN_COUNT photons an
//! entry holds the last entry that did.

use super::{halfspace, sphere, Medium};
use glam::DVec3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Nodes per sign of curvature, an octave apart.
pub const CURVATURE_NODES: usize = 8;
/// κ_0·L = 2^FIRST_CURVATURE_LOG2.
pub const FIRST_CURVATURE_LOG2: i32 = -4;
/// Radial entries per node, at the centres of u = r/(r + L) ∈ [i, i + 1)/ENTRIES.
pub const ENTRIES: usize = 48;
/// Multiply scattered escapes wanted of the half-space walk per channel (its photon count is then
/// each sphere's), and the caps on photons and on the scatterings a walk may take in all (what
/// bounds a medium that absorbs almost nothing).
const ESCAPES: u64 = 60_000;
const MAX_PHOTONS: u64 = 2_000_000;
const MAX_SCATTERINGS: u64 = 30_000_000;
const MAX_COLLISIONS: u32 = 20_000;
/// Photons an entry needs in both walks to be measured rather than held.
const MIN_COUNT: u64 = 100;

/// Curvature of node `k` in units of 1/L.
pub fn node_curvature(k: usize) -> f64 {
    2f64.powi(k as i32 + FIRST_CURVATURE_LOG2)
}

/// The centre of entry `i` in u.
pub fn entry_centre(i: usize) -> f64 {
    (i as f64 + 0.5) / ENTRIES as f64
}

/// One channel's ratios.
#[derive(Clone, Debug, PartialEq)]
pub struct CurvatureChannel {
    /// L, mm.
    pub unit_mm: f64,
    /// Per node (convex, then concave), per entry.
    pub convex: Vec<[f64; ENTRIES]>,
    pub concave: Vec<[f64; ENTRIES]>,
}

/// The flat rows: a channel that carries nothing, or a material that does not.
fn flat(unit_mm: f64) -> CurvatureChannel {
    CurvatureChannel {
        unit_mm,
        convex: vec![[1.0; ENTRIES]; CURVATURE_NODES],
        concave: vec![[1.0; ENTRIES]; CURVATURE_NODES],
    }
}

/// The longest diffusion length 1/σtr of the channels that carry light (mm), σtr = √(3σaσ't) of
/// the reduced coefficients; 0 where none does.
pub fn unit_of(media: &[Medium; 3]) -> f64 {
    media
        .iter()
        .map(|m| {
            let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
            let sigma_tr = (3.0 * m.sigma_a * sigma_t).sqrt();
            if m.sigma_s > 0.0 && sigma_tr > 0.0 {
                1.0 / sigma_tr
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max)
}

/// The three channels of a material, measured in parallel; cached per material in the process.
pub fn of_channels(media: &[Medium; 3]) -> [Arc<CurvatureChannel>; 3] {
    let unit_mm = unit_of(media);
    std::thread::scope(|s| {
        let handles = media.each_ref().map(|m| s.spawn(move || of(m, unit_mm)));
        handles.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
    })
}

fn of(m: &Medium, unit_mm: f64) -> Arc<CurvatureChannel> {
    static CACHE: OnceLock<Mutex<HashMap<[u64; 5], Arc<CurvatureChannel>>>> = OnceLock::new();
    let key = [m.sigma_a, m.sigma_s, m.g, m.eta, unit_mm].map(f64::to_bits);
    let cache = CACHE.get_or_init(Default::default);
    if let Some(c) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return c.clone();
    }
    let c = Arc::new(measure(m, unit_mm));
    cache.lock().unwrap_or_else(|e| e.into_inner()).insert(key, c.clone());
    c
}

/// The entry of chord `r_mm`, or None past the last.
fn entry_of(r_mm: f64, unit_mm: f64) -> Option<usize> {
    let i = (r_mm / (r_mm + unit_mm) * ENTRIES as f64) as usize;
    (i < ENTRIES).then_some(i)
}

/// Counts of multiply scattered photons per entry from photons seeded each on its own (so that
/// two walks of one seed share their draws) by `trace` (one photon, its seed; returns its
/// scatterings): `photons` of them, or (None) until ESCAPES counted or a cap is reached. Returns
/// the counts and the photons traced.
fn counts(
    sigma_t: f64,
    unit_mm: f64,
    photons: Option<u64>,
    trace: impl Fn(u64, &mut dyn FnMut(DVec3, u32)) -> u64,
) -> ([u64; ENTRIES], u64) {
    let mut counts = [0u64; ENTRIES];
    let (mut scatterings, mut escaped, mut traced) = (0u64, 0u64, 0u64);
    loop {
        let done = match photons {
            Some(n) => traced >= n,
            None => escaped >= ESCAPES || traced >= MAX_PHOTONS || scatterings >= MAX_SCATTERINGS,
        };
        if done {
            return (counts, traced);
        }
        let seed = 0xc0a7_0000_0000_0000 ^ traced.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        scatterings += trace(seed, &mut |exit: DVec3, n: u32| {
            if n >= 2 {
                escaped += 1;
                if let Some(i) = entry_of(exit.length() / sigma_t, unit_mm) {
                    counts[i] += 1;
                }
            }
        });
        traced += 1;
    }
}

fn measure(m: &Medium, unit_mm: f64) -> CurvatureChannel {
    let sigma_s = m.sigma_s * (1.0 - m.g);
    let sigma_t = m.sigma_a + sigma_s;
    if !(unit_mm > 0.0) || !(sigma_s > 0.0) || !(sigma_t > 0.0) {
        return flat(unit_mm);
    }
    let albedo = sigma_s / sigma_t;
    let start = halfspace::entry_direction(m.eta, 1.0);
    let (flat_counts, photons) = counts(sigma_t, unit_mm, None, |seed, tally| {
        halfspace::trace_half_space(albedo, m.eta, start, 1, (seed, MAX_COLLISIONS), |e| {
            tally(DVec3::new(e.x, e.y, 0.0), e.scatterings)
        })
    });
    // Signed radius in this channel's mean free paths.
    let row = |radius: f64| -> [f64; ENTRIES] {
        let (curved, _) = counts(sigma_t, unit_mm, Some(photons), |seed, tally| {
            sphere::trace_sphere(albedo, m.eta, radius, start, 1, (seed, MAX_COLLISIONS), |e| {
                tally(e.position, e.scatterings)
            })
        });
        ratios(&curved, &flat_counts, radius / sigma_t, unit_mm)
    };
    let radius_of = |k: usize| unit_mm / node_curvature(k) * sigma_t;
    CurvatureChannel {
        unit_mm,
        convex: (0..CURVATURE_NODES).map(|k| row(radius_of(k))).collect(),
        concave: (0..CURVATURE_NODES).map(|k| row(-radius_of(k))).collect(),
    }
}

/// The ratio per entry of `curved` (a sphere of signed radius `radius_mm`) to `flat` counts, held
/// where either counted under MIN_COUNT (the first measured one before it, the last after), faded
/// to 1 past a ball's diameter.
fn ratios(curved: &[u64; ENTRIES], flat: &[u64; ENTRIES], radius_mm: f64, unit_mm: f64) -> [f64; ENTRIES] {
    // Over three entries (weights 1 2 1) where the neighbours counted too: the walks' noise.
    let sum3 = |c: &[u64; ENTRIES], i: usize| {
        let at = |j: usize| c[j] as f64;
        match i {
            0 => 3.0 * at(0) + at(1),
            _ if i == ENTRIES - 1 => at(i - 1) + 3.0 * at(i),
            _ => at(i - 1) + 2.0 * at(i) + at(i + 1),
        }
    };
    let measured: Vec<Option<f64>> = (0..ENTRIES)
        .map(|i| (curved[i] >= MIN_COUNT && flat[i] >= MIN_COUNT).then(|| sum3(curved, i) / sum3(flat, i)))
        .collect();
    let first = measured.iter().flatten().next().copied().unwrap_or(1.0);
    let mut held = first;
    let mut out = [1.0; ENTRIES];
    for i in 0..ENTRIES {
        if let Some(v) = measured[i] {
            held = v;
        }
        let u = entry_centre(i);
        let r = unit_mm * u / (1.0 - u);
        // Past 2R a ball has no such chord: back to the half-space by 4R.
        let fade = if radius_mm > 0.0 { ((r - 2.0 * radius_mm) / (2.0 * radius_mm)).clamp(0.0, 1.0) } else { 0.0 };
        out[i] = held + (1.0 - held) * fade;
    }
    out
}

impl CurvatureChannel {
    /// The ratio at chord `r_mm` and curvature `kappa` (1/mm), as the shade pass reads it
    /// (bssrdf.glsl's `curvature_ratio`).
    pub fn ratio(&self, r_mm: f64, kappa: f64) -> f64 {
        if !(self.unit_mm > 0.0) {
            return 1.0;
        }
        let (rows, a_row, b_row, f) = self.rows_at(kappa);
        let x = (r_mm / (r_mm + self.unit_mm) * ENTRIES as f64 - 0.5).clamp(0.0, (ENTRIES - 1) as f64);
        let i = (x.floor() as usize).min(ENTRIES - 2);
        let at = |row: Option<usize>| match row {
            None => 1.0,
            Some(k) => {
                let (a, b) = (rows[k][i], rows[k][i + 1]);
                a + (b - a) * (x - i as f64)
            }
        };
        at(a_row) + (at(b_row) - at(a_row)) * f
    }

    /// The two rows of curvature `kappa` (None: the flat one) and the weight of the second.
    fn rows_at(&self, kappa: f64) -> (&[[f64; ENTRIES]], Option<usize>, Option<usize>, f64) {
        let rows = if kappa < 0.0 { &self.concave } else { &self.convex };
        let x = kappa.abs() * self.unit_mm;
        let first = node_curvature(0);
        if x < first {
            return (rows, None, Some(0), x / first);
        }
        let k = (x.log2() - FIRST_CURVATURE_LOG2 as f64).min((CURVATURE_NODES - 1) as f64);
        let i = (k.floor() as usize).min(CURVATURE_NODES - 2);
        (rows, Some(i), Some(i + 1), k - i as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Skin1's red: a timing and a sanity check (more light returns on a ball, less in a cavity).
    #[test]
    fn a_ball_returns_more_and_a_cavity_less() {
        let m = Medium { sigma_a: 0.032, sigma_s: 0.74, g: 0.0, eta: 1.3 };
        let t = std::time::Instant::now();
        let unit = unit_of(&[m, m, m]);
        let c = measure(&m, unit);
        eprintln!("measured in {:?}, L = {unit} mm", t.elapsed());
        for k in 0..CURVATURE_NODES {
            eprintln!(
                "convex {k}: {:?}",
                &c.convex[k].iter().step_by(4).map(|v| (v * 100.0).round() / 100.0).collect::<Vec<_>>()
            );
            eprintln!(
                "concave {k}: {:?}",
                &c.concave[k].iter().step_by(4).map(|v| (v * 100.0).round() / 100.0).collect::<Vec<_>>()
            );
        }
        assert!(c.ratio(unit, 1.0 / unit) > 1.05);
        assert!(c.ratio(unit, -1.0 / unit) < 0.98);
    }
}
#[cfg(test)]
mod probe {
    use super::*;

    /// m·d̂: the refracted direction's part along the surface `m` at xi (on a sphere about the
    /// origin) against the direction to xo along it.
    fn harmonic(xi: DVec3, xo: DVec3, m: DVec3) -> f64 {
        let n = xi.normalize();
        let d = xo - xi;
        let t = d - d.dot(n) * n;
        if t.length() > 0.0 {
            m.dot(t.normalize())
        } else {
            0.0
        }
    }
    /// A front-lit sphere by the walk (directional light along −z onto a sphere of radius R mm):
    /// the exitance of orders ≥ 2 within 10° of the pole, against the renderer's superposition of
    /// normal-incidence profiles, flat (Sp) and curved (Sp·C).
    #[test]
    fn probe_front_lit() {
        use std::f64::consts::PI;
        let mat = crate::materials::Material::find(&std::env::var("PROBE_MATERIAL").unwrap_or("skin1".into())).unwrap();
        let media = [0, 1, 2].map(|c| mat.channel(c));
        let curv = of_channels(&media);
        let r_mm = 5.0;
        for c in 0..3 {
            let m = media[c];
            let sigma_t = m.sigma_a + m.sigma_s;
            let albedo = m.sigma_s / sigma_t;
            let radius = r_mm * sigma_t;
            let centre = DVec3::new(0.0, 0.0, -radius);
            let cap = 10f64.to_radians();
            let photons = 400_000u64;
            let mut count = 0u64;
            let mut by_theta = [0u64; 9];
            let mut rng = halfspace::SplitMix(12345 + c as u64);
            for i in 0..photons {
                let (rho, phi) = (radius * rng.next().sqrt(), 2.0 * PI * rng.next());
                let (x, y) = (rho * phi.cos(), rho * phi.sin());
                let z = -radius + (radius * radius - rho * rho).max(0.0).sqrt();
                let p = DVec3::new(x, y, z);
                let n = (p - centre) / radius;
                let cos_i = n.z.clamp(0.0, 1.0);
                if rng.next() < crate::physics::fresnel::reflectance(m.eta, cos_i) {
                    continue;
                }
                let d = DVec3::new(0.0, 0.0, -1.0);
                let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
                let t = ((d + cos_i * n) / m.eta - cos_t * n).normalize();
                sphere::trace_from(
                    (albedo, m.eta, radius),
                    p,
                    t,
                    (0x1234_5678 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15), 100_000),
                    |e| {
                        if e.scatterings >= 2 && e.geodesic / radius < cap {
                            count += 1;
                            by_theta[((cos_i.acos() / (PI / 18.0)) as usize).min(8)] += 1;
                        }
                    },
                );
            }
            let cap_area_mm2 = 2.0 * PI * r_mm * r_mm * (1.0 - cap.cos());
            let truth = count as f64 * (PI * r_mm * r_mm / photons as f64) / cap_area_mm2;
            // The renderer: Σ over entry points E cosθ Ft f(θt) Sp(chord) [C(chord)], exit at the pole.
            let profile = crate::physics::mc_profile::McProfile::of(&m);
            let (mut flat, mut curved) = (0.0, 0.0);
            let (mut flat_by, mut curved_by) = ([0.0f64; 9], [0.0f64; 9]);
            let steps = 2000;
            for k in 0..steps {
                let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let cos_i = theta.cos();
                let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
                let chord = 2.0 * r_mm * (theta / 2.0).sin();
                let weight = cos_i
                    * crate::physics::fresnel::transmittance(m.eta, cos_i)
                    * profile.incidence_factor(cos_t)
                    * 2.0
                    * PI
                    * r_mm
                    * r_mm
                    * theta.sin()
                    * (PI / 2.0 / steps as f64);
                flat += weight * profile.exitance(chord);
                curved += weight * profile.exitance(chord) * curv[c].ratio(chord, 1.0 / r_mm);
                let b = ((theta / (PI / 18.0)) as usize).min(8);
                flat_by[b] += weight * profile.exitance(chord);
                curved_by[b] += weight * profile.exitance(chord) * curv[c].ratio(chord, 1.0 / r_mm);
            }
            let unit = PI * r_mm * r_mm / photons as f64 / cap_area_mm2;
            for b in 0..9 {
                eprintln!(
                    "  θ {:2}-{:2}°: walk {:.5} flat {:.5} curved {:.5}",
                    b * 10,
                    b * 10 + 10,
                    by_theta[b] as f64 * unit,
                    flat_by[b],
                    curved_by[b]
                );
            }
            // The sphere's own pencil at normal incidence, tallied by chord in fine bins, superposed.
            let bins = 200;
            let top = 2.0 * r_mm;
            let mut pencil = vec![0u64; bins];
            let start = halfspace::entry_direction(m.eta, 1.0);
            let n_pencil = 400_000u64;
            for i in 0..n_pencil {
                sphere::trace_from(
                    (albedo, m.eta, radius),
                    DVec3::ZERO,
                    start,
                    (0x77 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15), 100_000),
                    |e| {
                        if e.scatterings >= 2 {
                            let b = ((e.position.length() / sigma_t / top * bins as f64) as usize).min(bins - 1);
                            pencil[b] += 1;
                        }
                    },
                );
            }
            let mut half = vec![0u64; bins];
            for i in 0..n_pencil {
                halfspace::trace_half_space(
                    albedo,
                    m.eta,
                    start,
                    1,
                    (0x77 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15), 100_000),
                    |e| {
                        if e.scatterings >= 2 {
                            let r = (e.x * e.x + e.y * e.y).sqrt() / sigma_t;
                            if r < top {
                                half[((r / top * bins as f64) as usize).min(bins - 1)] += 1;
                            }
                        }
                    },
                );
            }
            let half_at = |chord: f64| {
                let b = ((chord / top * bins as f64) as usize).min(bins - 1);
                let (a0, a1) = (b as f64 * top / bins as f64, (b + 1) as f64 * top / bins as f64);
                half[b] as f64 / n_pencil as f64 / (PI * (a1 * a1 - a0 * a0))
            };
            let mut superposed_half = 0.0;
            for k in 0..steps {
                let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let cos_i = theta.cos();
                let chord = 2.0 * r_mm * (theta / 2.0).sin();
                let weight = cos_i
                    * crate::physics::fresnel::transmittance(m.eta, cos_i)
                    * 2.0
                    * PI
                    * r_mm
                    * r_mm
                    * theta.sin()
                    * (PI / 2.0 / steps as f64);
                superposed_half += weight * half_at(chord);
            }
            eprintln!("  superposed half-space pencils {superposed_half:.5} ({:.3})", superposed_half / truth);
            let pencil_at = |chord: f64| {
                let b = ((chord / top * bins as f64) as usize).min(bins - 1);
                let (a0, a1) = (b as f64 * top / bins as f64, (b + 1) as f64 * top / bins as f64);
                pencil[b] as f64 / n_pencil as f64 / (PI * (a1 * a1 - a0 * a0))
            };
            let mut superposed = 0.0;
            for k in 0..steps {
                let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let cos_i = theta.cos();
                let chord = 2.0 * r_mm * (theta / 2.0).sin();
                let weight = cos_i
                    * crate::physics::fresnel::transmittance(m.eta, cos_i)
                    * 2.0
                    * PI
                    * r_mm
                    * r_mm
                    * theta.sin()
                    * (PI / 2.0 / steps as f64);
                superposed += weight * pencil_at(chord);
            }
            for deg in [0.0f64, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
                let ci = deg.to_radians().cos();
                let ct = (1.0 - (1.0 - ci * ci) / (m.eta * m.eta)).max(0.0).sqrt();
                eprint!(" f({deg})={:.3}", profile.incidence_factor(ct));
            }
            eprintln!();
            // The oblique pencil's shift: mean exit x (mm) of orders ≥ 2 in the half-space, per incidence.
            let shift_nodes: Vec<(f64, f64)> = (0..=9)
                .map(|k| {
                    let deg = k as f64 * 9.5;
                    let ci = deg.to_radians().cos();
                    let st = halfspace::entry_direction(m.eta, ci);
                    let (mut sx, mut n) = (0.0, 0u64);
                    halfspace::trace_half_space(albedo, m.eta, st, 200_000, (99 + k as u64, 100_000), |e| {
                        if e.scatterings >= 2 {
                            sx += e.x;
                            n += 1;
                        }
                    });
                    (deg.to_radians(), sx / n.max(1) as f64 / sigma_t)
                })
                .collect();
            eprintln!(
                "  shifts (deg, mm, mm/sinθt): {:?}",
                shift_nodes
                    .iter()
                    .map(|&(t, d)| {
                        let st = t.sin() / m.eta;
                        format!("{:.0}:{:.3}:{:.3}", t.to_degrees(), d, d / st.max(1e-9))
                    })
                    .collect::<Vec<_>>()
            );
            let shift_at = |theta: f64| {
                let x = theta / 9.5f64.to_radians();
                let i = (x.floor() as usize).min(8);
                let f = x - i as f64;
                shift_nodes[i].1 * (1.0 - f) + shift_nodes[i + 1].1 * f
            };
            let (mut shifted_sphere, mut shifted_flat) = (0.0, 0.0);
            for k in 0..steps {
                let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let cos_i = theta.cos();
                let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
                let moved = theta + shift_at(theta) / r_mm;
                let chord = 2.0 * r_mm * (moved / 2.0).sin();
                let weight = cos_i
                    * crate::physics::fresnel::transmittance(m.eta, cos_i)
                    * profile.incidence_factor(cos_t)
                    * 2.0
                    * PI
                    * r_mm
                    * r_mm
                    * theta.sin()
                    * (PI / 2.0 / steps as f64);
                shifted_sphere += weight * pencil_at(chord);
                shifted_flat += weight * profile.exitance(chord);
            }
            // The model as the shade pass has it: xi moved by δ·sinθt along its tangent away from
            // the pole, Sp at that distance times C at the chord.
            let mut model = 0.0;
            for k in 0..steps {
                let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let cos_i = theta.cos();
                let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
                let sin_t = (1.0 - cos_t * cos_t).sqrt();
                let xi = DVec3::new(theta.sin(), 0.0, theta.cos()) * r_mm;
                let xo = DVec3::new(0.0, 0.0, r_mm);
                let lean = harmonic(xi, xo, DVec3::new(theta.cos(), 0.0, -theta.sin()) * sin_t);
                let weight = cos_i
                    * crate::physics::fresnel::transmittance(m.eta, cos_i)
                    * profile.incidence_factor(cos_t)
                    * 2.0
                    * PI
                    * r_mm
                    * r_mm
                    * theta.sin()
                    * (PI / 2.0 / steps as f64);
                let r = (xo - xi).length();
                model += weight
                    * profile.exitance(r)
                    * (1.0 + profile.azimuth_factor(r) * lean).max(0.0)
                    * curv[c].ratio(r, 1.0 / r_mm);
            }
            eprintln!("  model (azimuthal harmonic, table C): {:.3}", model / truth);
            eprintln!("  shifted: sphere pencils {:.3}, flat {:.3}", shifted_sphere / truth, shifted_flat / truth);
            eprintln!("  superposed sphere pencils {superposed:.5} ({:.3})", superposed / truth);
            eprintln!(
                "channel {c}: walk {truth:.5} ({count} photons), flat {flat:.5} ({:.3}), curved {curved:.5} ({:.3})",
                flat / truth,
                curved / truth
            );
        }
    }

    /// Pencil at the pole, incidence 0/15/30/60° tilted toward +x: sphere (R = 5 mm) over half-space
    /// counts per chord bin (mm), exits with x < 0 (behind the tilt) and x > 0.
    /// The front-lit sphere's exitance in caps at angle α from the pole: walk against the model.
    #[test]
    fn probe_rim() {
        use std::f64::consts::PI;
        let mat = crate::materials::Material::find(&std::env::var("PROBE_MATERIAL").unwrap_or("skin1".into())).unwrap();
        let media = [0, 1, 2].map(|c| mat.channel(c));
        let curv = of_channels(&media);
        let r_mm = 5.0;
        let alphas = [0.0f64, 30.0, 50.0, 65.0, 80.0];
        let cap = 8f64.to_radians();
        for c in 0..3 {
            let m = media[c];
            let sigma_t = m.sigma_a + m.sigma_s;
            let albedo = m.sigma_s / sigma_t;
            let radius = r_mm * sigma_t;
            let centre = DVec3::new(0.0, 0.0, -radius);
            let photons = 1_000_000u64;
            let mut counts = [0u64; 5];
            let mut toward = [0u64; 5];
            let cone = 12f64.to_radians();
            let mut rng = halfspace::SplitMix(777 + c as u64);
            let caps: Vec<DVec3> =
                alphas.iter().map(|a| DVec3::new(a.to_radians().sin(), 0.0, a.to_radians().cos())).collect();
            for i in 0..photons {
                let (rho, phi) = (radius * rng.next().sqrt(), 2.0 * PI * rng.next());
                let p = DVec3::new(
                    rho * phi.cos(),
                    rho * phi.sin(),
                    -radius + (radius * radius - rho * rho).max(0.0).sqrt(),
                );
                let n = (p - centre) / radius;
                let cos_i = n.z.clamp(0.0, 1.0);
                if rng.next() < crate::physics::fresnel::reflectance(m.eta, cos_i) {
                    continue;
                }
                let d = DVec3::new(0.0, 0.0, -1.0);
                let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
                let t = ((d + cos_i * n) / m.eta - cos_t * n).normalize();
                sphere::trace_from(
                    (albedo, m.eta, radius),
                    p,
                    t,
                    (0x4321 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15), 100_000),
                    |e| {
                        if e.scatterings >= 2 {
                            let q = ((e.position - centre) / radius).normalize();
                            for (k, cp) in caps.iter().enumerate() {
                                if q.dot(*cp) > cap.cos() {
                                    counts[k] += 1;
                                    if e.direction.z > cone.cos() {
                                        toward[k] += 1;
                                    }
                                }
                            }
                        }
                    },
                );
            }
            let cap_area = 2.0 * PI * r_mm * r_mm * (1.0 - cap.cos());
            let profile = crate::physics::mc_profile::McProfile::of(&m);
            let mut line = String::new();
            for (k, a) in alphas.iter().enumerate() {
                let truth = counts[k] as f64 * (PI * r_mm * r_mm / photons as f64) / cap_area;
                let xo = DVec3::new(a.to_radians().sin(), 0.0, a.to_radians().cos()) * r_mm;
                let (nt, np) = (400, 200);
                let (mut model, mut flat) = (0.0, 0.0);
                for it in 0..nt {
                    let theta = (it as f64 + 0.5) / nt as f64 * PI / 2.0;
                    let cos_i = theta.cos();
                    let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
                    let sin_t = (1.0 - cos_t * cos_t).sqrt();
                    let w = cos_i
                        * crate::physics::fresnel::transmittance(m.eta, cos_i)
                        * profile.incidence_factor(cos_t)
                        * r_mm
                        * r_mm
                        * theta.sin()
                        * (PI / 2.0 / nt as f64)
                        * (2.0 * PI / np as f64);
                    for ip in 0..np {
                        let phi = (ip as f64 + 0.5) / np as f64 * 2.0 * PI;
                        let xi = DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()) * r_mm;
                        let e_theta = DVec3::new(theta.cos() * phi.cos(), theta.cos() * phi.sin(), -theta.sin());
                        let lean = harmonic(xi, xo, e_theta * sin_t);
                        let r = (xo - xi).length();
                        model += w
                            * profile.exitance(r)
                            * (1.0 + profile.azimuth_factor(r) * lean).max(0.0)
                            * curv[c].ratio(r, 1.0 / r_mm);
                        flat += w * profile.exitance((xo - xi).length());
                    }
                }
                // Radiance toward +z (the camera along the light): the walk's, and the model's
                // exitance times the half-space's exit distribution at the pixel's own incidence.
                let cos_o = a.to_radians().cos();
                let cos_t_own = (1.0 - (1.0 - cos_o * cos_o) / (m.eta * m.eta)).max(0.0).sqrt();
                let lobe = crate::physics::fresnel::transmittance(m.eta, cos_o) * profile.exit_factor(cos_t_own, cos_o)
                    / profile.exit_norm;
                let radiance =
                    toward[k] as f64 * (PI * r_mm * r_mm / photons as f64) / (cap_area * PI * cone.sin().powi(2));
                line += &format!(
                    " α {a}: model {:.3} flat {:.3} radiance {:.3} ({} ph)",
                    model / truth,
                    flat / truth,
                    model * lobe / radiance,
                    toward[k]
                );
            }
            eprintln!("channel {c}:{line}");
        }
    }

    #[test]
    fn probe_oblique() {
        let mat = crate::materials::Material::find("skin1").unwrap();
        let m = mat.channel(0);
        let sigma_t = m.sigma_a + m.sigma_s;
        let albedo = m.sigma_s / sigma_t;
        let radius = 5.0 * sigma_t;
        let edges = [0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0];
        for deg in [0.0f64, 45.0, 75.0, 89.0] {
            let start = halfspace::entry_direction(m.eta, deg.to_radians().cos());
            let mut tallies = [[[0u64; 8]; 2]; 2]; // [sphere?][x<0?][bin]
            for photon in 0..200_000u64 {
                let seed = 0xabc ^ photon.wrapping_mul(0x9E37_79B9_7F4A_7C15);
                let mut add = |which: usize, p: DVec3, n: u32| {
                    if n < 2 {
                        return;
                    }
                    let r = p.length() / sigma_t;
                    if let Some(b) = (0..8).find(|&b| r >= edges[b] && r < edges[b + 1]) {
                        tallies[which][(p.x < 0.0) as usize][b] += 1;
                    }
                };
                halfspace::trace_half_space(albedo, m.eta, start, 1, (seed, 100_000), |e| {
                    add(0, DVec3::new(e.x, e.y, 0.0), e.scatterings)
                });
                sphere::trace_sphere(albedo, m.eta, radius, start, 1, (seed, 100_000), |e| {
                    add(1, e.position, e.scatterings)
                });
            }
            let ratio = |side: usize| {
                (0..8)
                    .map(|b| format!("{:.2}", tallies[1][side][b] as f64 / tallies[0][side][b].max(1) as f64))
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            let flat = |side: usize| (0..8).map(|b| format!("{}", tallies[0][side][b])).collect::<Vec<_>>().join(" ");
            let all = (0..8)
                .map(|b| {
                    format!(
                        "{:.2}",
                        (tallies[1][0][b] + tallies[1][1][b]) as f64
                            / (tallies[0][0][b] + tallies[0][1][b]).max(1) as f64
                    )
                })
                .collect::<Vec<_>>()
                .join(" ");
            eprintln!(
                "{deg}°: all {all} | behind (x<0) {} | ahead {} | flat counts behind {}",
                ratio(1),
                ratio(0),
                flat(1)
            );
        }
    }

    #[test]
    fn probe_skin1() {
        let mat = crate::materials::Material::find("skin1").unwrap();
        let media = [0, 1, 2].map(|c| mat.channel(c));
        let ch = of_channels(&media);
        eprintln!("blue convex 3: {:?}", ch[2].convex[3]);
        let m = media[2];
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let start = halfspace::entry_direction(m.eta, 1.0);
        let (f, _) = counts(sigma_t, ch[2].unit_mm, None, |seed, tally| {
            halfspace::trace_half_space(m.sigma_s / sigma_t, m.eta, start, 1, (seed, MAX_COLLISIONS), |e| {
                tally(DVec3::new(e.x, e.y, 0.0), e.scatterings)
            })
        });
        eprintln!("blue flat counts {:?} {m:?}", f);
        for (c, chan) in ch.iter().enumerate() {
            for kappa in [0.2, -0.2] {
                let v: Vec<String> = [0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0]
                    .iter()
                    .map(|&r| format!("{r}:{:.2}", chan.ratio(r, kappa)))
                    .collect();
                eprintln!("ch {c} κ {kappa}: {}", v.join(" "));
            }
        }
    }
}
