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
//! `curvature_ratio`) reads it per source at the pair's own curvature along the way between them
//! ([`pair_curvature`]; the exit's distribution and the light across at the pixel's mean
//! curvature, the mesh's smoothed over L: `mesh::smoothed_mean_curvature`), linear in κ from the
//! flat row (1) to node 0 and linear in log κ between nodes, held beyond the last, each node read
//! at the same chord relative to its own radius (r·κ/κ_k: the same place on its ball; the shade
//! pass's rows are laid out in r·κ). A chord longer than a sphere's diameter 2R does not
//! exist on it, but a row is read there all the same: a pixel's ball between two nodes is larger
//! than the smaller node's, and its long chords read that row. So the row holds its antipode's
//! ratio out to 4R (the next node's diameter) and only then fades to 1, by 8R (the surface is no
//! sphere there; the half-space is the safe guess). Fading from 2R, as it once did, took half
//! of the light a 10 mm Skin1 ball sends to its far side (the exact walk, tests/curvature_profile.rs:
//! 0.84-0.88 of it in red past 145°, 0.94-0.96 now). Where the half-space walk counted fewer
//! than MIN_COUNT photons (beyond about 2 L), the ball's count is read against the escapes the
//! Monte Carlo table's profile predicts (the profile the shade pass multiplies the ratio by); where
//! the ball's walk counted too few, an entry holds the last entry that did. Photons split as they
//! go far from the entry (up to 64 copies of less weight each, [`halfspace::Split`]), so that the
//! far chords are measured rather than held: a ball's ratio rises toward its antipode, and held
//! it read low there (green 0.85-0.99 of a 10 mm Skin1 ball's exact walk past 1.1R, 0.93-1.04
//! split).
//!
//! The rows are measured for beams at three angles of incidence (INCIDENCE_SIN2: cos θi 1, 0.6,
//! 0.2), each ball against the half-space lit by the same beam (the profile the shade pass
//! draws for it: M(r) f(θt) (1 + a(r) sin²θt)), and read per pair at its light's sin²θi. An
//! oblique beam enters shallower and nearer the surface that bends away from it, so less of its
//! light reaches a ball's far side: Skin1's red row at R = L/2 (node 4) holds 5.0 at its
//! antipode for a normal beam, 3.0 at cos θi 0.2. Read with the normal beam's rows alone, a 10 mm
//! Skin1 ball lit from the front was 1.13-1.38 of its exact walk in red past 135° from the light.
//! The exit's rows below are kept per angle of incidence too, and read per pixel at the mean
//! sin²θi of the light it gathers (weighted by what each source sends): read at a normal beam's,
//! a front-lit 10 mm Skin1 ball's rim was 0.93 of the walk's radiance toward the eye in red and
//! a back-lit one's centre 1.48 (tests/exit_tilt.rs), now 0.955 and 1.12.
//!
//! The same walks give the exit's direction: a ball lets less light out at grazing angles and
//! more near its normal than the half-space (looking back inside at a grazing exit, a chord of
//! the ball ends where the half-space's ray would go on into lit depth). Per node, the ratio of
//! the two normalised distributions over the Monte Carlo table's exit bins (cos²θo outside), of
//! the photons leaving within a chord R√2 (the hemisphere around the entry: what a pixel of a
//! lit ball gathers), multiplies the table's exit factor h: it keeps the exitance, and is 1 on a
//! flat surface. Skin1's red at R = 5 mm (3.9 mean free paths): 0.95 in the most grazing bin, 1.04
//! in the most normal.

use super::{
    halfspace,
    mc_profile::{McProfile, EXIT_BINS},
    sphere, Medium,
};
use glam::DVec3;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Nodes per sign of curvature, an octave apart.
pub const CURVATURE_NODES: usize = 8;
/// The angles of incidence whose beams the ratio rows are measured with, as sin²θi outside
/// (cos θi 1, 0.6, 0.2): a ball's light from an oblique beam reaches its far side less, against
/// the half-space's oblique beam, than a normal beam's does (the 10 mm Skin1 ball's red past 95°
/// from the light was 1.04-1.38 of its exact walk read with the normal beam's rows alone,
/// 0.99-1.005 to 145° with these; tests/curvature_profile.rs `the_front_lit_sphere_ring_by_ring`).
/// Linear in sin²θi between them, held past the last (what the shade pass has per pair is
/// η²|m|², m the refracted direction's part along the surface).
pub const INCIDENCE_SIN2: [f64; 3] = [0.0, 0.64, 0.96];
/// Rows per node and sign: one per angle of incidence.
pub const INCIDENCES: usize = INCIDENCE_SIN2.len();
/// κ_0·L = 2^FIRST_CURVATURE_LOG2.
pub const FIRST_CURVATURE_LOG2: i32 = -4;
/// Radial entries per node, at the centres of u = r/(r + L) ∈ [i, i + 1)/ENTRIES (96: at 48 the
/// entries near a ball's antipode, where its ratio rises steepest, were 0.2R wide and read 7%
/// low in red, 18% in green, of the 10 mm Skin1 ball's walk).
pub const ENTRIES: usize = 96;
/// Multiply scattered escapes wanted of the half-space walk per channel (its photon count is then
/// each sphere's), and the caps on photons and on the scatterings a walk may take in all (what
/// bounds a medium that absorbs almost nothing).
const ESCAPES: u64 = 60_000;
const MAX_PHOTONS: u64 = 2_000_000;
const MAX_SCATTERINGS: u64 = 30_000_000;
const MAX_COLLISIONS: u32 = 20_000;
/// Photons an entry needs in both walks to be measured rather than held.
const MIN_COUNT: u64 = 100;
/// Photons the ball's walk needs in an entry read against the Monte Carlo table's profile (past
/// the half-space walk's reach): the ball's count is then all of the noise, 10% over three entries.
const MIN_COUNT_TAIL: u64 = 25;
/// Photons per entry that splitting aims at where the analogue walk counted fewer, and the most
/// halvings a photon takes (2^6 copies). Measured on the default Skin1 bunny's multiple
/// scattering: 150 and 300 give the same image (1.086 0.971 0.932 of the path tracer's; 1.089
/// 0.962 0.920 unsplit, 1.088 0.973 0.935 with ten times the photons); the table's walks take
/// 1.4x their unsplit time at 150, 2.3x at 300, 5x at 1000.
const SPLIT_TARGET: u64 = 150;
const SPLIT_LEVELS: u32 = 6;

/// Curvature of node `k` in units of 1/L.
pub fn node_curvature(k: usize) -> f64 {
    2f64.powi(k as i32 + FIRST_CURVATURE_LOG2)
}

/// The last node's curvature (1/mm) for L = `unit_mm`: past it a row is read as at it.
pub fn last_curvature(unit_mm: f64) -> f64 {
    node_curvature(CURVATURE_NODES - 1) / unit_mm
}

/// The two nodes of curvature κL = `kappa_l` (None: the flat surface) and the weight of the
/// second: linear in κ from flat to node 0, in log κ between nodes, held past the last; NaN
/// reads as flat. The shade pass's `curvature_rows` and the GPU table's mirror read the same.
pub fn nodes_at(kappa_l: f64) -> (Option<usize>, usize, f64) {
    let x = kappa_l.abs();
    let first = node_curvature(0);
    if x.is_nan() || x < first {
        return (None, 0, if x.is_nan() { 0.0 } else { x / first });
    }
    let k = (x.log2() - FIRST_CURVATURE_LOG2 as f64).min((CURVATURE_NODES - 1) as f64);
    let i = (k.floor() as usize).min(CURVATURE_NODES - 2);
    (Some(i), i + 1, k - i as f64)
}

/// The curvature of the surface between a source (position, normal `ni`) and an exit (normal
/// `no`) along the way from one to the other, `d` the exit's position less the source's:
/// κ = (no − ni)·d/|d|² (1/length of d; `None` where d = 0). The shade pass reads each pair's
/// ratio at it (sources.glsl `pair_curvature`, which this mirrors). On a sphere of radius R it is
/// exactly 1/R for every pair (no − ni = d/R), between points of one plane 0, in a spherical
/// cavity −1/R; on a cylinder c²/(R(c² + a²)) for a chord c around it and a along its axis (the
/// normal curvature cos²ψ/R of the chord's direction, Euler's). Light between two points bends
/// with the surface along their way: a cylinder's exits around its bend are the ball's of its
/// radius at the same chord and along its axis the half-space's (`cargo run --release --example
/// cylinder_walk`), so a pair is read as on the ball of its own curvature, not the pixel's mean.
pub fn pair_curvature(d: DVec3, ni: DVec3, no: DVec3) -> Option<f64> {
    let r2 = d.length_squared();
    (r2 > 0.0).then(|| (no - ni).dot(d) / r2)
}

/// The row of incidence below sin²θi = `sin2_i` and the weight of the next (NaN: normal incidence).
pub fn incidence_rows(sin2_i: f64) -> (usize, f64) {
    if sin2_i.is_nan() {
        return (0, 0.0);
    }
    let j = INCIDENCE_SIN2[1..INCIDENCES - 1].iter().take_while(|&&s| sin2_i >= s).count();
    let (a, b) = (INCIDENCE_SIN2[j], INCIDENCE_SIN2[j + 1]);
    (j, ((sin2_i - a) / (b - a)).clamp(0.0, 1.0))
}

/// The cosine of incidence (outside) of row `j`.
pub fn incidence_cos(j: usize) -> f64 {
    (1.0 - INCIDENCE_SIN2[j]).sqrt()
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
    /// Per angle of incidence (INCIDENCE_SIN2), per node (convex, then concave), per entry.
    pub convex: [Vec<[f64; ENTRIES]>; INCIDENCES],
    pub concave: [Vec<[f64; ENTRIES]>; INCIDENCES],
    /// Per node, per exit bin (the Monte Carlo table's, in cos²θo): the exit distribution's ratio
    /// of the light that leaves within a chord R√2 of where it entered.
    /// Per angle of incidence as the ratios.
    pub convex_exit: [Vec<[f64; EXIT_BINS]>; INCIDENCES],
    pub concave_exit: [Vec<[f64; EXIT_BINS]>; INCIDENCES],
    /// The same of the light that leaves farther (a ball's far hemisphere): nearer the normal.
    pub convex_exit_far: [Vec<[f64; EXIT_BINS]>; INCIDENCES],
    pub concave_exit_far: [Vec<[f64; EXIT_BINS]>; INCIDENCES],
}

impl super::table_cache::Flat for CurvatureChannel {
    fn to_flat(&self) -> Vec<f64> {
        let mut v = vec![self.unit_mm];
        for rows in self.convex.iter().chain(&self.concave) {
            super::table_cache::push_vec(&mut v, rows.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        }
        for rows in
            [&self.convex_exit, &self.concave_exit, &self.convex_exit_far, &self.concave_exit_far].into_iter().flatten()
        {
            super::table_cache::push_vec(&mut v, rows.iter().flatten().copied().collect::<Vec<_>>().into_iter());
        }
        v
    }
    fn from_flat(values: &[f64]) -> Option<CurvatureChannel> {
        let mut t = super::table_cache::Take(values);
        let unit_mm = t.scalar()?;
        fn rows<const N: usize>(flat: Vec<f64>) -> Option<Vec<[f64; N]>> {
            (flat.len() == N * CURVATURE_NODES)
                .then(|| flat.chunks_exact(N).filter_map(|c| c.try_into().ok()).collect())
        }
        fn incidences<const N: usize>(t: &mut super::table_cache::Take) -> Option<[Vec<[f64; N]>; INCIDENCES]> {
            let rows: Vec<_> = (0..INCIDENCES).map(|_| rows::<N>(t.vec()?)).collect::<Option<_>>()?;
            rows.try_into().ok()
        }
        let (convex, concave) = (incidences::<ENTRIES>(&mut t)?, incidences::<ENTRIES>(&mut t)?);
        let (convex_exit, concave_exit) = (incidences::<EXIT_BINS>(&mut t)?, incidences::<EXIT_BINS>(&mut t)?);
        let (convex_exit_far, concave_exit_far) = (incidences::<EXIT_BINS>(&mut t)?, incidences::<EXIT_BINS>(&mut t)?);
        t.end()?;
        Some(CurvatureChannel {
            unit_mm,
            convex,
            concave,
            convex_exit,
            concave_exit,
            convex_exit_far,
            concave_exit_far,
        })
    }
}

/// The flat rows: a channel that carries nothing, or a material that does not.
fn flat(unit_mm: f64) -> CurvatureChannel {
    CurvatureChannel {
        unit_mm,
        convex: std::array::from_fn(|_| vec![[1.0; ENTRIES]; CURVATURE_NODES]),
        concave: std::array::from_fn(|_| vec![[1.0; ENTRIES]; CURVATURE_NODES]),
        convex_exit: std::array::from_fn(|_| vec![[1.0; EXIT_BINS]; CURVATURE_NODES]),
        concave_exit: std::array::from_fn(|_| vec![[1.0; EXIT_BINS]; CURVATURE_NODES]),
        convex_exit_far: std::array::from_fn(|_| vec![[1.0; EXIT_BINS]; CURVATURE_NODES]),
        concave_exit_far: std::array::from_fn(|_| vec![[1.0; EXIT_BINS]; CURVATURE_NODES]),
    }
}

/// Escapes of two or more scatterings per entry (chord) and exit bin: their weight (photons
/// entering count 1, their copies less once they split), and how many of the photons entering
/// left there (a photon's copies count once: they share its walk up to where they split, so
/// this, not the escapes, is what a count's noise is judged by; without splitting the same).
#[derive(Clone)]
struct Counts {
    weight: [[f64; EXIT_BINS]; ENTRIES],
    photons: [[u64; EXIT_BINS]; ENTRIES],
}

/// The same per entry: the weight over the exit bins, and the photons that left there.
struct Totals {
    weight: [f64; ENTRIES],
    photons: [u64; ENTRIES],
}

/// The exit bin of cos²θo outside, as the Monte Carlo table's.
fn exit_bin(mu_o2: f64) -> usize {
    ((mu_o2 * EXIT_BINS as f64) as usize).min(EXIT_BINS - 1)
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
    let c = Arc::new(super::table_cache::cached("curvature", &key, || measure(m, unit_mm)));
    cache.lock().unwrap_or_else(|e| e.into_inner()).insert(key, c.clone());
    c
}

/// The entry of chord `r_mm`, or None past the last.
fn entry_of(r_mm: f64, unit_mm: f64) -> Option<usize> {
    let i = (r_mm / (r_mm + unit_mm) * ENTRIES as f64) as usize;
    (i < ENTRIES).then_some(i)
}

/// Counts of multiply scattered photons per entry and exit bin from photons seeded each on its
/// own (so that two walks of one seed share their draws) by `trace` (one photon, its seed; tells
/// its exit point, cos²θo, scatterings and weight; returns its scatterings): `photons` of them,
/// or (None) until ESCAPES counted or a cap is reached. Returns the counts, the photons traced
/// and their scatterings.
fn counts(
    sigma_t: f64,
    unit_mm: f64,
    photons: Option<u64>,
    trace: impl Fn(u64, &mut dyn FnMut(DVec3, f64, u32, f64)) -> u64,
) -> (Counts, u64, u64) {
    let mut counts = Counts { weight: [[0.0; EXIT_BINS]; ENTRIES], photons: [[0; EXIT_BINS]; ENTRIES] };
    let (mut scatterings, mut escaped, mut traced) = (0u64, 0u64, 0u64);
    let mut reached = Vec::new(); // the cells this photon's copies left by
    loop {
        let done = match photons {
            Some(n) => traced >= n,
            None => escaped >= ESCAPES || traced >= MAX_PHOTONS || scatterings >= MAX_SCATTERINGS,
        };
        if done {
            return (counts, traced, scatterings);
        }
        let seed = 0xc0a7_0000_0000_0000 ^ traced.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        scatterings += trace(seed, &mut |exit: DVec3, mu_o2: f64, n: u32, weight: f64| {
            if n >= 2 {
                escaped += 1;
                if let Some(i) = entry_of(exit.length() / sigma_t, unit_mm) {
                    counts.weight[i][exit_bin(mu_o2)] += weight;
                    reached.push((i, exit_bin(mu_o2)));
                }
            }
        });
        reached.sort_unstable();
        reached.dedup();
        for (i, b) in reached.drain(..) {
            counts.photons[i][b] += 1;
        }
        traced += 1;
    }
}

fn measure(m: &Medium, unit_mm: f64) -> CurvatureChannel {
    let sigma_s = m.sigma_s * (1.0 - m.g);
    let sigma_t = m.sigma_a + sigma_s;
    // Also NaN: a comparison with it is false.
    let positive = |x: f64| x > 0.0;
    if !positive(unit_mm) || !positive(sigma_s) || !positive(sigma_t) {
        return flat(unit_mm);
    }
    let albedo = sigma_s / sigma_t;
    let flat_walk = |cos_i: f64, photons: Option<u64>, split: Option<&halfspace::Split>| {
        let start = halfspace::entry_direction(m.eta, cos_i);
        counts(sigma_t, unit_mm, photons, |seed, tally| {
            let seeds = (seed, MAX_COLLISIONS);
            halfspace::trace_slab_split(albedo, m.eta, f64::INFINITY, start, 1, seeds, split, |e| {
                tally(DVec3::new(e.x, e.y, 0.0), e.mu_o2, e.scatterings, e.weight)
            })
        })
    };
    // The analogue walk at normal incidence sets how many photons each walk takes and where they
    // split: the far chords, where it counted a handful, get SPLIT_TARGET (to SPLIT_LEVELS
    // halvings). Then the half-space and each ball walk those photons, split alike, at each
    // angle of incidence. Without splitting the far chords, too few to measure, held a nearer
    // entry's ratio where a ball's keeps rising toward its antipode: a 10 mm Skin1 ball's far
    // rings in green were 0.85-0.99 of its exact walk.
    let (analogue, photons, analogue_scatterings) = flat_walk(1.0, None, None);
    let levels = split_levels(&totals(&analogue).photons);
    let level = |distance: f64| entry_of(distance / sigma_t, unit_mm).map_or(SPLIT_LEVELS, |i| levels[i]);
    // Each walk's copies may take half the analogue walk's scatterings (Skin1's take less).
    let split = || halfspace::Split { level: &level, allowance: analogue_scatterings.div_ceil(2).into() };
    let (flat_walk, split) = (&flat_walk, &split);
    let flat_counts: Vec<Counts> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..INCIDENCES)
            .map(|j| s.spawn(move || flat_walk(incidence_cos(j), Some(photons), Some(&split())).0))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
    });
    let flat_counts = &flat_counts;
    // The half-space's escapes per entry that the Monte Carlo table's profile gives for as many
    // photons at each angle of incidence: where the paired walk counts too few (far from the
    // entry) the ball is read against the profile the shade pass multiplies the ratio by, so that
    // their product is the ball's. Taken once the first row has walked: the profile is measured
    // meanwhile on another thread (gpu_world), and McProfile::of waits for it rather than measure
    // it again.
    let expected: [OnceLock<[f64; ENTRIES]>; INCIDENCES] = Default::default();
    let expected = &expected;
    // Row of incidence `j`, signed radius in this channel's mean free paths: the node's ratios
    // per entry and (at normal incidence) per exit bin.
    let row = |j: usize, radius: f64| -> ([f64; ENTRIES], ([f64; EXIT_BINS], [f64; EXIT_BINS])) {
        let split = split();
        let start = halfspace::entry_direction(m.eta, incidence_cos(j));
        let (curved, _, _) = counts(sigma_t, unit_mm, Some(photons), |seed, tally| {
            sphere::trace_sphere_split(albedo, m.eta, radius, start, 1, (seed, MAX_COLLISIONS), Some(&split), |e| {
                tally(e.position, e.mu_o2, e.scatterings, e.weight)
            })
        });
        let radius_mm = radius / sigma_t;
        let sin2_i = INCIDENCE_SIN2[j];
        let expected = expected[j]
            .get_or_init(|| expected_counts_within(&McProfile::of(m), photons, unit_mm, f64::INFINITY, sin2_i, m.eta));
        // The share of each entry's chords that a ball has (none past its diameter 2R).
        let within = if radius_mm > 0.0 {
            let within = expected_counts_within(&McProfile::of(m), photons, unit_mm, 2.0 * radius_mm, sin2_i, m.eta);
            std::array::from_fn(|i| if expected[i] > 0.0 { within[i] / expected[i] } else { 1.0 })
        } else {
            [1.0; ENTRIES]
        };
        let flat_counts = &flat_counts[j];
        let exits = (
            exit_ratios(&curved, flat_counts, radius_mm, unit_mm, false),
            exit_ratios(&curved, flat_counts, radius_mm, unit_mm, true),
        );
        (ratios(&totals(&curved), &totals(flat_counts), expected, &within, radius_mm, unit_mm), exits)
    };
    let radius_of = |k: usize| unit_mm / node_curvature(k) * sigma_t;
    // Each row walks on its own thread: the rows are independent and seeded alike whichever
    // thread walks them, so the table is the same bits on any machine, in a sixteenth of the time
    // where there are the cores (20 s to 2-3 s of a `--model mc` start).
    let (row, radius_of) = (&row, &radius_of);
    let per_incidence = 2 * CURVATURE_NODES;
    let rows: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..INCIDENCES * per_incidence)
            .map(|i| {
                let (j, i) = (i / per_incidence, i % per_incidence);
                let signed = if i < CURVATURE_NODES { 1.0 } else { -1.0 };
                s.spawn(move || row(j, signed * radius_of(i % CURVATURE_NODES)))
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
    });
    let side = |j: usize, concave: bool| {
        let first = j * per_incidence + if concave { CURVATURE_NODES } else { 0 };
        &rows[first..first + CURVATURE_NODES]
    };
    let ratios_of = |concave: bool| std::array::from_fn(|j| side(j, concave).iter().map(|r| r.0).collect());
    let exits_of = |concave: bool, far: bool| {
        std::array::from_fn(|j| side(j, concave).iter().map(|r| if far { r.1 .1 } else { r.1 .0 }).collect())
    };
    CurvatureChannel {
        unit_mm,
        convex: ratios_of(false),
        concave: ratios_of(true),
        convex_exit: exits_of(false, false),
        concave_exit: exits_of(true, false),
        convex_exit_far: exits_of(false, true),
        concave_exit_far: exits_of(true, true),
    }
}

/// The multiply scattered escapes per entry of `photons` entering a half-space by the Monte
/// Carlo table's profile: photons · ∫ M(r) 2πr dr over the entry's chords (midpoints in u,
/// 64 per entry; the last entry to u = 1 − 1/(64·ENTRIES)).
#[cfg(test)]
fn expected_counts(profile: &McProfile, photons: u64, unit_mm: f64) -> [f64; ENTRIES] {
    expected_counts_within(profile, photons, unit_mm, f64::INFINITY, 0.0, 1.0)
}

/// The same of the chords shorter than `limit_mm` only, for a beam at sin²θi = `sin2_i` into a
/// medium of index `eta`: the profile the shade pass draws there, M(r) f(θt) (1 + a(r) sin²θt).
fn expected_counts_within(
    profile: &McProfile,
    photons: u64,
    unit_mm: f64,
    limit_mm: f64,
    sin2_i: f64,
    eta: f64,
) -> [f64; ENTRIES] {
    const STEPS: usize = 64;
    let sin2_t = sin2_i / (eta * eta);
    let incidence = if sin2_i > 0.0 { profile.incidence_factor((1.0 - sin2_t).max(0.0).sqrt()) } else { 1.0 };
    std::array::from_fn(|i| {
        (0..STEPS)
            .map(|j| {
                let u = (i as f64 + (j as f64 + 0.5) / STEPS as f64) / ENTRIES as f64;
                let r = unit_mm * u / (1.0 - u);
                let dr = unit_mm / ((1.0 - u) * (1.0 - u)) / (ENTRIES * STEPS) as f64;
                if r < limit_mm {
                    let radial = if sin2_i > 0.0 { (1.0 + profile.radial_at(r) * sin2_t).max(0.0) } else { 1.0 };
                    incidence * profile.exitance(r) * radial * 2.0 * std::f64::consts::PI * r * dr
                } else {
                    0.0
                }
            })
            .sum::<f64>()
            * photons as f64
    })
}

/// Escapes per entry, over the exit bins.
fn totals(c: &Counts) -> Totals {
    Totals { weight: c.weight.map(|bins| bins.iter().sum()), photons: c.photons.map(|bins| bins.iter().sum()) }
}

/// Halvings a photon takes by the time it reaches each entry's chords: enough that the analogue
/// walk's `photons` there (at least one) would reach SPLIT_TARGET, never fewer than a nearer
/// entry's, at most SPLIT_LEVELS.
fn split_levels(photons: &[u64; ENTRIES]) -> [u32; ENTRIES] {
    let mut level = 0;
    std::array::from_fn(|i| {
        let wanted = (SPLIT_TARGET as f64 / photons[i].max(1) as f64).log2().ceil();
        level = level.max(wanted.clamp(0.0, SPLIT_LEVELS as f64) as u32);
        level
    })
}

/// The ratio per exit bin of the curved surface's exit distribution to the flat one's, each
/// normalised over the bins, of the escapes within a chord |R|√2 (at least the first entry; `far`:
/// the curved surface's escapes beyond it, against the same flat ones): over three bins (weights
/// 1 2 1, the ends 3 1) for the walks' noise; 1 where either counted under MIN_COUNT in all, or
/// in the bin. Light that crossed a ball leaves it nearer its normal (Skin1's red at R = 5 mm,
/// past 90° from the entry: 0.8 of the half-space's share in the most grazing bins, 1.2-1.5 in the
/// most normal; examples/cylinder_walk.rs `exits`).
fn exit_ratios(curved: &Counts, flat: &Counts, radius_mm: f64, unit_mm: f64, far: bool) -> [f64; EXIT_BINS] {
    let cut = entry_of(radius_mm.abs() * std::f64::consts::SQRT_2, unit_mm).unwrap_or(ENTRIES).max(1);
    // Per bin over the entries `range`: the weight, and the photons.
    let sum = |c: &Counts, range: std::ops::Range<usize>| -> ([f64; EXIT_BINS], [f64; EXIT_BINS]) {
        let over = |bins: &[[f64; EXIT_BINS]]| std::array::from_fn(|b| bins.iter().map(|bins| bins[b]).sum());
        let photons = c.photons[range.clone()].iter().map(|bins| bins.map(|n| n as f64)).collect::<Vec<_>>();
        (over(&c.weight[range]), over(&photons))
    };
    let (curved, flat) = (if far { sum(curved, cut..ENTRIES) } else { sum(curved, 0..cut) }, sum(flat, 0..cut));
    let smooth = |c: &[f64; EXIT_BINS], b: usize| match b {
        0 => 3.0 * c[0] + c[1],
        _ if b == EXIT_BINS - 1 => c[b - 1] + 3.0 * c[b],
        _ => c[b - 1] + 2.0 * c[b] + c[b + 1],
    };
    let few = |photons: &[f64; EXIT_BINS]| photons.iter().sum::<f64>() < (MIN_COUNT * EXIT_BINS as u64) as f64;
    if few(&curved.1) || few(&flat.1) {
        return [1.0; EXIT_BINS];
    }
    let (n_curved, n_flat) = (curved.0.iter().sum::<f64>(), flat.0.iter().sum::<f64>());
    std::array::from_fn(|b| {
        // A bin either walk hardly reaches (η < 1: no light leaves at some angles) stays 1.
        if smooth(&curved.1, b) < MIN_COUNT as f64 || smooth(&flat.1, b) < MIN_COUNT as f64 {
            return 1.0;
        }
        (smooth(&curved.0, b) / n_curved) / (smooth(&flat.0, b) / n_flat)
    })
}

/// The ratio per entry of `curved` (a sphere of signed radius `radius_mm`) to `flat` counts;
/// where the flat walk counted under MIN_COUNT, to the counts the Monte Carlo table's profile
/// `expected` (its walk has 3.3 times the escapes, and its product with this ratio is what the
/// shade pass draws); held where the curved walk counted under MIN_COUNT (the first measured
/// one before it, the last after), faded to 1 from twice a ball's diameter. `within`: the share
/// of each entry's flat escapes at chords the ball has (under 2R): the entry across a ball's
/// diameter counts the ball's escapes of its shorter chords only, and was read against all of the
/// half-space's (Skin1's red at R = 3.67 mm: 3.6-3.8 held from it where the ball's own walk
/// finds 4.4-5.3 toward its antipode). Held, as it once was
/// wherever the flat walk ran out, a 10 mm Skin1 ball's far side read the ratio of 7 mm chords
/// in green (1.9 L) and 4.3 mm in blue, where the walk's own kept growing.
fn ratios(
    curved: &Totals,
    flat: &Totals,
    expected: &[f64; ENTRIES],
    within: &[f64; ENTRIES],
    radius_mm: f64,
    unit_mm: f64,
) -> [f64; ENTRIES] {
    // Over three entries (weights 1 2 1) where the neighbours counted too: the walks' noise.
    let sum3 = |at: &dyn Fn(usize) -> f64, i: usize| match i {
        0 => 3.0 * at(0) + at(1),
        _ if i == ENTRIES - 1 => at(i - 1) + 3.0 * at(i),
        _ => at(i - 1) + 2.0 * at(i) + at(i + 1),
    };
    let (curved_at, flat_at) = (|j: usize| curved.weight[j], |j: usize| flat.weight[j] * within[j]);
    let expected_at = |j: usize| expected[j] * within[j];
    let (curved_n, flat_n) = (&curved.photons, &flat.photons);
    let measured: Vec<Option<f64>> = (0..ENTRIES)
        .map(|i| {
            if curved_n[i] < MIN_COUNT_TAIL {
                None
            } else if flat_n[i] >= MIN_COUNT && curved_n[i] >= MIN_COUNT {
                Some(sum3(&curved_at, i) / sum3(&flat_at, i))
            } else {
                let e = sum3(&expected_at, i);
                (e > 0.0 && curved_n[i] >= MIN_COUNT_TAIL).then(|| sum3(&curved_at, i) / e)
            }
        })
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
        // Past 2R a ball has no such chord, but a larger ball between this node and the next
        // reads this row there: its antipode's ratio out to 4R, then back to the half-space by 8R.
        let fade = if radius_mm > 0.0 { ((r - 4.0 * radius_mm) / (4.0 * radius_mm)).clamp(0.0, 1.0) } else { 0.0 };
        out[i] = held + (1.0 - held) * fade;
    }
    out
}

impl CurvatureChannel {
    /// The ratio at chord `r_mm` and curvature `kappa` (1/mm) for light that entered at
    /// sin²θi = `sin2_i` (outside), linear between the measured entries and between the rows of
    /// incidence ([`incidence_rows`]; the shade pass's table, gpu::sd_table::CurvatureRatios, is
    /// made from it).
    ///
    /// Between two nodes each is read at the same chord relative to its own radius, r·κ/κ_k (the
    /// same place on its ball: a 10 mm ball's antipode reads each node's antipode), not at the
    /// same chord: a ratio grows steeply toward its ball's antipode, and read at one chord the
    /// smaller node's antipode leaked into the larger ball's middle chords. Against a walk of the
    /// ball itself between nodes (Skin1, R = 5 mm, κL = 0.74): 2.13 against 2.09 at a 4.75 mm
    /// chord (2.27 read at one chord), 2.61 against 2.65 at 6.25 mm (3.08).
    pub fn ratio(&self, r_mm: f64, kappa: f64, sin2_i: f64) -> f64 {
        if self.unit_mm.is_nan() || self.unit_mm <= 0.0 {
            return 1.0;
        }
        let (a_row, b_row, f) = self.nodes_at(kappa);
        // r·|κ|: the chord in units of the ball's radius (NaN: flat); past the last node, whose
        // row is held, its own (a pair across a box's edge reads a curvature of no ball there,
        // and read at r·κ it took the smallest ball's antipode: 2-10 times the half-space).
        let relative = if kappa.is_nan() { 0.0 } else { r_mm * kappa.abs().min(last_curvature(self.unit_mm)) };
        let (j, g) = incidence_rows(sin2_i);
        let at = |row: Option<usize>| match row {
            None => 1.0,
            Some(k) => {
                let chord = relative * self.unit_mm / node_curvature(k);
                let (a, b) = (self.node_ratio(kappa < 0.0, j, k, chord), self.node_ratio(kappa < 0.0, j + 1, k, chord));
                a + (b - a) * g
            }
        };
        at(a_row) + (at(b_row) - at(a_row)) * f
    }

    /// Node `k`'s ratio (a cavity's where `concave`) for incidence row `j` at chord `r_mm`,
    /// linear between entries.
    pub fn node_ratio(&self, concave: bool, j: usize, k: usize, r_mm: f64) -> f64 {
        let rows = if concave { &self.concave[j] } else { &self.convex[j] };
        let x = (r_mm / (r_mm + self.unit_mm) * ENTRIES as f64 - 0.5).clamp(0.0, (ENTRIES - 1) as f64);
        if x.is_nan() {
            return 1.0;
        }
        let i = (x.floor() as usize).min(ENTRIES - 2);
        let (a, b) = (rows[k][i], rows[k][i + 1]);
        a + (b - a) * (x - i as f64)
    }

    /// The two nodes of curvature `kappa` (1/mm; see [`nodes_at`]).
    fn nodes_at(&self, kappa: f64) -> (Option<usize>, Option<usize>, f64) {
        let (lower, upper, f) = nodes_at(kappa * self.unit_mm);
        (lower, Some(upper), f)
    }

    /// The exit distribution's ratio at exit cosine `cos_o` (outside) and curvature `kappa`
    /// (1/mm): linear in cos²θo between the bins' centres (held beyond the outer ones, as the
    /// table's exit factor h), and between nodes as [`CurvatureChannel::ratio`].
    /// `far`: the share of the light that came from beyond a chord R√2, whose rows it weighs.
    /// `sin2_i`: the light's mean sin²θi where it entered (weighted by what each entry sends the
    /// pixel), linear between the rows of incidence as [`CurvatureChannel::ratio`].
    pub fn exit_ratio(&self, cos_o: f64, kappa: f64, far: f64, sin2_i: f64) -> f64 {
        if self.unit_mm.is_nan() || self.unit_mm <= 0.0 {
            return 1.0;
        }
        let (j, g) = incidence_rows(sin2_i);
        let at = |j: usize| {
            let (near_rows, far_rows) = if kappa < 0.0 {
                (&self.concave_exit[j], &self.concave_exit_far[j])
            } else {
                (&self.convex_exit[j], &self.convex_exit_far[j])
            };
            let (near, beyond) =
                (self.exit_ratio_of(near_rows, cos_o, kappa), self.exit_ratio_of(far_rows, cos_o, kappa));
            near + (beyond - near) * far
        };
        at(j) + (at(j + 1) - at(j)) * g
    }

    fn exit_ratio_of(&self, rows: &[[f64; EXIT_BINS]], cos_o: f64, kappa: f64) -> f64 {
        let (a_row, b_row, f) = self.nodes_at(kappa);
        let y = (cos_o * cos_o * EXIT_BINS as f64 - 0.5).clamp(0.0, (EXIT_BINS - 1) as f64);
        let j = (y.floor() as usize).min(EXIT_BINS - 2);
        let at = |row: Option<usize>| match row {
            None => 1.0,
            Some(k) => rows[k][j] + (rows[k][j + 1] - rows[k][j]) * (y - j as f64),
        };
        at(a_row) + (at(b_row) - at(a_row)) * f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Past the half-space walk's reach the ratio is the ball's count over the profile's
    /// prediction, not the last paired ratio held: Skin1's green ball of R = 7.3 mm read 3.24 from
    /// 8.5 mm on when held, where its count over the profile's goes on to 4.2 at 10.4 mm and 6.9
    /// at 13 mm.
    #[test]
    fn past_the_flat_walk_the_ball_is_read_against_the_profile() {
        let mut curved = [1000u64; ENTRIES];
        let mut flat = [1000u64; ENTRIES];
        let mut expected = [1000.0; ENTRIES];
        for i in 30..ENTRIES {
            flat[i] = 10; // too few to measure
            expected[i] = 100.0;
            curved[i] = if i < 40 { 400 } else { 10 }; // the ball's walk, too, runs out at 40
        }
        let unit = 1.0;
        let radius = 1e6; // no fade
        let totals = |n: [u64; ENTRIES]| Totals { weight: n.map(|n| n as f64), photons: n };
        let (curved, flat) = (totals(curved), totals(flat));
        let r = ratios(&curved, &flat, &expected, &[1.0; ENTRIES], radius, unit);
        assert!((r[20] - 1.0).abs() < 1e-12, "paired where both walks counted");
        assert!((r[35] - 4.0).abs() < 1e-12, "the ball over the profile: {}", r[35]);
        assert!((r[45] - r[39]).abs() < 1e-12, "held past the ball's reach");
        let held = ratios(&curved, &flat, &[0.0; ENTRIES], &[1.0; ENTRIES], radius, unit);
        assert!((held[35] - r[29]).abs() < 1e-12, "without a profile: held at the last paired entry");
    }

    /// The profile's prediction is the half-space walk's count where that counted enough (the
    /// same medium, the same normalisation: per photon entering): Skin1's green, every entry with
    /// 400 or more within 5σ of it and their sum within 2%.
    #[test]
    fn the_profile_predicts_the_half_space_walk() {
        let m = crate::materials::Material::find("skin1").expect("preset").channel(1);
        let unit = unit_of(&[m, m, m]);
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let albedo = m.sigma_s * (1.0 - m.g) / sigma_t;
        let start = halfspace::entry_direction(m.eta, 1.0);
        let (flat, photons, _) = counts(sigma_t, unit, None, |seed, tally| {
            halfspace::trace_half_space(albedo, m.eta, start, 1, (seed, MAX_COLLISIONS), |e| {
                tally(DVec3::new(e.x, e.y, 0.0), e.mu_o2, e.scatterings, e.weight)
            })
        });
        let (flat, expected) = (totals(&flat).photons, expected_counts(&McProfile::of(&m), photons, unit));
        let (mut sum_flat, mut sum_expected) = (0.0, 0.0);
        for i in 0..ENTRIES {
            if expected[i] >= 400.0 {
                let sigma = expected[i].sqrt();
                assert!(
                    (flat[i] as f64 - expected[i]).abs() < 5.0 * sigma,
                    "entry {i}: {} against {}",
                    flat[i],
                    expected[i]
                );
                sum_flat += flat[i] as f64;
                sum_expected += expected[i];
            }
        }
        assert!((sum_flat / sum_expected - 1.0).abs() < 0.02, "{sum_flat} against {sum_expected}");
    }

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
                &c.convex[0][k].iter().step_by(4).map(|v| (v * 100.0).round() / 100.0).collect::<Vec<_>>()
            );
            eprintln!(
                "concave {k}: {:?}",
                &c.concave[0][k].iter().step_by(4).map(|v| (v * 100.0).round() / 100.0).collect::<Vec<_>>()
            );
        }
        for k in 0..CURVATURE_NODES {
            eprintln!("convex exit {k}: {:?}", c.convex_exit[0][k].map(|v| (v * 1000.0).round() / 1000.0));
            eprintln!("concave exit {k}: {:?}", c.concave_exit[0][k].map(|v| (v * 1000.0).round() / 1000.0));
        }
        for k in 0..CURVATURE_NODES {
            eprintln!(
                "convex {k} at cos θi 0.2: {:?}",
                &c.convex[INCIDENCES - 1][k].iter().step_by(4).map(|v| (v * 100.0).round() / 100.0).collect::<Vec<_>>()
            );
        }
        for sin2_i in INCIDENCE_SIN2 {
            assert!(c.ratio(unit, 1.0 / unit, sin2_i) > 1.05);
            assert!(c.ratio(unit, -1.0 / unit, sin2_i) < 0.98);
        }
    }
}
