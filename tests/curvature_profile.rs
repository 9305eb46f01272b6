//! The Monte Carlo table's curved-surface terms (issue "Curved objects against the path
//! tracer"), checked without a GPU against the exact walk of `physics::sphere`:
//! - the curvature ratios C(r; κ) of `physics::curvature_profile` (a ball returns more, a cavity
//!   less, the flat limit 1) and the shade pass's table of them;
//! - the oblique entry's azimuthal harmonic of `physics::mc_profile` (1 + b(r) sin θt cos φ);
//! - a 10 mm Skin1 sphere lit from the front, by the walk, against the renderer's sum over the
//!   lit hemisphere (normal-incidence profile, incidence factor f(θt), harmonic, ratio): the
//!   flat half-space's sum is 0.86–0.90 of it at the pole (the README's deficit), the curved
//!   model within 6%;
//! - each pair's curvature along its way (`pair_curvature`), at which the shade pass reads the
//!   ratio: exact on spheres, cavities, planes and cylinders.

mod common;

use common::front_lit_walk;
use glam::DVec3;
use std::f64::consts::PI;
use translucent::gpu::sd_table::{self, CurvatureRatios};
use translucent::materials::Material;
use translucent::physics::curvature_profile::{self, node_curvature, CURVATURE_NODES};
use translucent::physics::mc_profile::McProfile;
use translucent::physics::{fresnel, halfspace, sphere, Medium};

fn skin1() -> [Medium; 3] {
    let m = Material::find("skin1").expect("preset");
    [0, 1, 2].map(|c| m.channel(c))
}

/// κ = (no − ni)·d/|d|², against the closed forms: 1/R for any two points of a sphere, −1/R of a
/// cavity, 0 on a plane (normals equal), c²/(R(c² + a²)) on a cylinder (chord c around, a along
/// the axis: around 1/R, along 0).
#[test]
fn the_pair_curvature_is_the_surface_s_along_the_way() {
    let mut seed = 0x5eed_u64;
    let mut next = move || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let on_sphere = |next: &mut dyn FnMut() -> f64| {
        let (z, phi) = (2.0 * next() - 1.0, 2.0 * PI * next());
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    let centre = DVec3::new(0.3, -2.0, 5.0);
    for _ in 0..1000 {
        let r = 0.1 + 20.0 * next();
        let (ni, no) = (on_sphere(&mut next), on_sphere(&mut next));
        let d = (centre + r * no) - (centre + r * ni);
        let k = curvature_profile::pair_curvature(d, ni, no).expect("distinct points");
        assert!((k * r - 1.0).abs() < 1e-9, "ball: {k} against {}", 1.0 / r);
        // The medium outside the ball: the outward normals point at the centre.
        let k = curvature_profile::pair_curvature(d, -ni, -no).expect("distinct points");
        assert!((k * r + 1.0).abs() < 1e-9, "cavity: {k} against {}", -1.0 / r);
        // Any two points of one plane.
        let n = on_sphere(&mut next);
        let along = d - d.dot(n) * n;
        assert!(curvature_profile::pair_curvature(along, n, n).expect("distinct").abs() < 1e-12);
        // A cylinder of radius r about y: angles φ1, φ2 around it, heights y1, y2.
        let (p1, p2) = (2.0 * PI * next(), 2.0 * PI * next());
        let (y1, y2) = (10.0 * next(), 10.0 * next());
        let (n1, n2) = (DVec3::new(p1.sin(), 0.0, p1.cos()), DVec3::new(p2.sin(), 0.0, p2.cos()));
        let d = (r * n2 + y2 * DVec3::Y) - (r * n1 + y1 * DVec3::Y);
        let c2 = (r * (n2 - n1)).length_squared();
        let expected = c2 / (r * (c2 + (y2 - y1).powi(2)));
        let k = curvature_profile::pair_curvature(d, n1, n2).expect("distinct points");
        assert!((k - expected).abs() < 1e-9 * (1.0 + expected.abs()), "cylinder: {k} against {expected}");
    }
    assert_eq!(curvature_profile::pair_curvature(DVec3::ZERO, DVec3::Z, DVec3::Z), None);
}

#[test]
fn a_ball_returns_more_a_cavity_less_and_flat_is_one() {
    let media = skin1();
    let channels = curvature_profile::of_channels(&media);
    let unit = curvature_profile::unit_of(&media);
    for (c, ch) in channels.iter().enumerate() {
        // At κ = 0 exactly the half-space.
        for r in [0.1, 1.0, 5.0] {
            for sin2_i in curvature_profile::INCIDENCE_SIN2 {
                assert_eq!(ch.ratio(r * unit, 0.0, sin2_i), 1.0);
            }
        }
        // R = L: a chord of one diffusion length of the red returns more on the ball, less in
        // the cavity, in every channel (README: Skin1's green 1.67 at s = ℓ on R = 2ℓ).
        let (ball, cavity) = (ch.ratio(0.5 * unit, 1.0 / unit, 0.0), ch.ratio(0.5 * unit, -1.0 / unit, 0.0));
        println!("channel {c}: C(L/2; ±1/L) = {ball:.3} / {cavity:.3}");
        assert!(ball > 1.1, "channel {c}: ball {ball}");
        assert!(cavity < 0.95, "channel {c}: cavity {cavity}");
        // The exit's direction: on a flat surface the half-space's; on a ball of radius L less
        // light leaves at grazing angles and more near the normal (the walk's escapes within a
        // chord R√2, normalised), in the red and green, which diffuse furthest (the blue's R is
        // 5.5 of its mean free paths: nearly flat to it).
        for cos_o in [0.1, 0.5, 1.0] {
            assert_eq!(ch.exit_ratio(cos_o, 0.0, 0.0, 0.5), 1.0);
            assert_eq!(ch.exit_ratio(cos_o, 0.0, 1.0, 0.5), 1.0);
        }
        let (grazing, normal) = (ch.exit_ratio(0.2, 1.0 / unit, 0.0, 0.0), ch.exit_ratio(1.0, 1.0 / unit, 0.0, 0.0));
        println!("channel {c}: exit ratio at κL = 1, cos θo 0.2 / 1: {grazing:.3} / {normal:.3}");
        if c < 2 {
            assert!(grazing < 1.0 && normal > 1.0 && normal - grazing > 0.05, "channel {c}: {grazing} / {normal}");
        }
        // The light from the far side of the ball leaves still nearer the normal.
        let (far_grazing, far_normal) =
            (ch.exit_ratio(0.2, 1.0 / unit, 1.0, 0.0), ch.exit_ratio(1.0, 1.0 / unit, 1.0, 0.0));
        println!("channel {c}: the far light's at κL = 1, cos θo 0.2 / 1: {far_grazing:.3} / {far_normal:.3}");
        if c < 2 {
            assert!(far_grazing < grazing && far_normal > normal, "channel {c}: {far_grazing} / {far_normal}");
        }
        // The smallest curvature changes little near the entry.
        let slight = ch.ratio(0.25 * unit, node_curvature(0) / unit, 0.0);
        assert!((slight - 1.0).abs() < 0.1, "channel {c}: κL = 1/16 gives {slight}");
        // Monotone in κ at r = L/2 over the convex nodes whose diameter exceeds it (more
        // curvature, more light kept; past 4R the ratio fades back to 1: no such chord on a ball).
        let mut last = 1.0;
        for k in (0..CURVATURE_NODES).filter(|&k| node_curvature(k) <= 2.0) {
            let v = ch.ratio(0.5 * unit, node_curvature(k) / unit, 0.0);
            assert!(v > last - 0.03, "channel {c}: node {k} {v} after {last}");
            last = v;
        }
    }
}

/// The shade pass's table (nearest of 1024 entries, one fetch interpolating in κ) against the
/// ratios it is made from: within 1% (measured 0.58%; 512 entries gave 1.2% once the rows' tails
/// were read against the profile, at a cavity's steep blue row, κL = −1.2 and r = L).
#[test]
fn the_gpu_table_reads_the_ratios() {
    let media = skin1();
    let channels = curvature_profile::of_channels(&media);
    let table = CurvatureRatios::monte_carlo(&channels, &McProfile::of_channels(&media));
    let unit = table.unit_mm as f64;
    let mut worst = 0.0f64;
    for kappa_l in [0.03, 0.2, 0.73, 1.5, 3.0, -0.3, -1.2] {
        for r_l in [0.05, 0.2, 0.5, 1.0, 2.0] {
            for sin2_i in [0.0, 0.3, 0.64, 0.8, 0.96, 1.0] {
                let (r, kappa) = (r_l * unit, kappa_l / unit);
                let gpu = table.lookup(r, kappa, [sin2_i; 3]);
                for c in 0..3 {
                    let exact = channels[c].ratio(r, kappa, sin2_i);
                    let d = (gpu[c] / exact - 1.0).abs();
                    if d > 0.01 {
                        println!(
                            "κL {kappa_l} r/L {r_l} sin²θi {sin2_i} channel {c}: table {:.4} ratio {exact:.4}",
                            gpu[c]
                        );
                    }
                    worst = worst.max(d);
                }
            }
        }
    }
    println!("worst relative difference {worst:.4}");
    assert!(worst < 0.01, "{worst}");
    assert_eq!(CurvatureRatios::none().lookup(1.0, 0.5, [0.5; 3]), [1.0; 3]);
    // The exit distribution's rows: f16, the same interpolation in κ and cos²θo.
    let mut worst_exit = 0.0f64;
    for kappa_l in [0.03, 0.2, 0.73, 1.5, 3.0, -0.3, -1.2] {
        for cos_o in [0.0, 0.1, 0.35, 0.7, 0.9, 1.0] {
            for far in [0.0, 0.3, 1.0] {
                for sin2_i in [0.0, 0.5, 0.8, 1.0] {
                    let gpu = table.lookup_exit(cos_o, kappa_l / unit, far, sin2_i);
                    for c in 0..3 {
                        let exact = channels[c].exit_ratio(cos_o, kappa_l / unit, far, sin2_i);
                        worst_exit = worst_exit.max((gpu[c] / exact - 1.0).abs());
                    }
                }
            }
        }
    }
    println!("exit rows: worst relative difference {worst_exit:.5}");
    assert!(worst_exit < 2e-3, "{worst_exit}");
    assert_eq!(CurvatureRatios::none().lookup_exit(0.3, 0.5, 0.5, 0.5), [1.0; 3]);
}

#[test]
fn the_azimuthal_harmonic_packs_and_leans_ahead() {
    for b in [[0.0, 0.5, -0.25], [1.0, -1.0, 0.001], [0.3, 1.999, -1.999]] {
        let back = sd_table::unpack_azimuth(sd_table::pack_azimuth(b));
        for c in 0..3 {
            assert!((back[c] - b[c]).abs() <= 0.5 / 255.5 + 1e-12, "{b:?} -> {back:?}");
        }
    }
    // Light entering obliquely leaves ahead of its entry (b > 0) within a few mean free paths.
    for m in skin1() {
        let p = McProfile::of(&m);
        let mfp = 1.0 / p.sigma_t_reduced;
        for r in [0.5 * mfp, mfp, 2.0 * mfp] {
            let b = p.azimuth_factor(r);
            println!("b({:.2} mfp) = {b:.3}", r / mfp);
            assert!(b > 0.05 && b <= 2.0, "b({r:.2} mm) = {b}");
        }
    }
}

/// Escapes of two or more scatterings per chord ring (`rings` over the diameter) of `photons`
/// entering a ball of radius `r_mm` at its pole by a beam at cos θi = `cos_i`, seeded from `seed`.
fn chord_rings(m: &Medium, r_mm: f64, cos_i: f64, seed: u64, rings: usize, photons: u64) -> Vec<u64> {
    let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
    let (albedo, radius) = (m.sigma_s * (1.0 - m.g) / sigma_t, r_mm * sigma_t);
    let mut counts = vec![0u64; rings];
    let start = halfspace::entry_direction(m.eta, cos_i);
    for p in 0..photons {
        sphere::trace_sphere(
            albedo,
            m.eta,
            radius,
            start,
            1,
            (seed ^ p.wrapping_mul(0x9E37_79B9_7F4A_7C15), 100_000),
            |e| {
                let k = (e.position.length() / (2.0 * radius) * rings as f64) as usize;
                if e.scatterings >= 2 && k < rings {
                    counts[k] += 1;
                }
            },
        );
    }
    counts
}

/// ∫ `exitance(r)` 2πr dr over chord ring `k` of `rings` over a ball's diameter 2·`r_mm`
/// (midpoints, 200 steps): what [`chord_rings`] counts, per photon.
fn ring_integral(k: usize, rings: usize, r_mm: f64, exitance: impl Fn(f64) -> f64) -> f64 {
    let (c0, c1) = (k as f64 / rings as f64 * 2.0 * r_mm, (k + 1) as f64 / rings as f64 * 2.0 * r_mm);
    let steps = 200;
    (0..steps)
        .map(|j| {
            let r = c0 + (j as f64 + 0.5) / steps as f64 * (c1 - c0);
            exitance(r) * 2.0 * PI * r * (c1 - c0) / steps as f64
        })
        .sum()
}

/// A ball between two curvature nodes (Skin1, R = 5 mm: κL = 0.74, between nodes 0.5 and 1),
/// walked itself: its multiply scattered exitance per chord ring (0.5 mm) against what the shade
/// pass draws, the Monte Carlo table's profile times the ratio read between the nodes. Each node
/// is read at the same chord relative to its own radius (`CurvatureChannel::ratio`); read at the
/// same chord, as before, the smaller node's steep rise toward its antipode leaked into the middle
/// chords and the larger node's middle into the antipode: red 1.04-1.17 of the walk at 2-6.5 mm,
/// 0.66-0.88 in the last 2 mm. Measured now (the walk's noise 0.7-1.4% in red, 1-6% in green):
/// red and green 0.97-1.03 out to 1.1R; beyond, red 0.98-1.08 and green 0.94-1.05. Before the
/// table's photons split as they go far (`halfspace::Split`), the far chords counted 100-300
/// photons per entry or too few to measure, held a nearer entry's ratio where the ball's keeps
/// rising, and green was 0.85-1.00 beyond 1.1R (with a walk of 2M photons, 0.89-0.99 unsplit,
/// 0.93-1.04 split): the bound there, 10%, is one the unsplit table fails. (Blue, not held to
/// it: its far rings, where the walk counts a handful, 0.60-0.86 unsplit and 0.65-0.97 split.)
#[test]
fn between_nodes_the_ratio_reads_each_ball_at_the_same_place() {
    let media = skin1();
    let ratios = curvature_profile::of_channels(&media);
    let r_mm = 5.0;
    for c in 0..2 {
        let m = media[c];
        let (rings, photons) = (20usize, 400_000u64);
        let counts = chord_rings(&m, r_mm, 1.0, 0x77, rings, photons);
        let profile = McProfile::of(&m);
        let mut line = format!("channel {c}, table / walk per ring:");
        let mut measured = Vec::new();
        for (k, &count) in counts.iter().enumerate() {
            let drawn = ring_integral(k, rings, r_mm, |r| profile.exitance(r) * ratios[c].ratio(r, 1.0 / r_mm, 0.0));
            let ratio = drawn / (count as f64 / photons as f64);
            line += &format!(" {ratio:.3}");
            if count >= 400 {
                let bound = if k < 11 { 0.05 } else { 0.10 };
                measured.push((k, ratio, bound));
            }
        }
        println!("{line}");
        for (k, ratio, bound) in measured {
            assert!((ratio - 1.0).abs() < bound, "channel {c}, ring {k}: {ratio:.3} of the ball's walk");
        }
    }
}

/// The same ball lit by an oblique beam (cos θi 0.4: sin²θi 0.84, between the rows of 0.64 and
/// 0.96), walked itself, against what the shade pass draws for it: the table's profile, its
/// incidence factor f(θt) and radial change 1 + a(r) sin²θt, times the ratio read at the
/// beam's sin²θi. An oblique beam enters shallow and its light reaches the ball's far side less
/// than a normal beam's: read with the normal beam's rows (as before the rows of incidence) the
/// far rings were too bright. Measured (red / green, 2026-12-07): with the rows of incidence
/// 0.95-1.03 out to 1.1R (rings 1-10) and 0.97-1.08 / 0.91-1.06 beyond; with the normal beam's
/// rows 1.10-1.57 / 1.08-2.01 beyond 1.3R (held to be over 1.15: the test tells them apart).
#[test]
fn an_oblique_beam_on_a_ball_reads_the_rows_of_its_incidence() {
    let media = skin1();
    let ratios = curvature_profile::of_channels(&media);
    let (r_mm, cos_i) = (5.0, 0.4);
    let sin2_i = 1.0 - cos_i * cos_i;
    for c in 0..2 {
        let m = media[c];
        let (rings, photons) = (20usize, 400_000u64);
        let counts = chord_rings(&m, r_mm, cos_i, 0x0b11, rings, photons);
        let profile = McProfile::of(&m);
        let sin2_t = sin2_i / (m.eta * m.eta);
        let incidence = profile.incidence_factor((1.0 - sin2_t).sqrt());
        let drawn = |k: usize, sin2: f64| -> f64 {
            ring_integral(k, rings, r_mm, |r| {
                incidence
                    * profile.exitance(r)
                    * (1.0 + profile.radial_at(r) * sin2_t).max(0.0)
                    * ratios[c].ratio(r, 1.0 / r_mm, sin2)
            })
        };
        let (mut line, mut normal_line) = (format!("channel {c}, table / walk per ring:"), String::new());
        let (mut normal_worst, mut measured) = (0.0f64, Vec::new());
        for (k, &count) in counts.iter().enumerate() {
            let walk = count as f64 / photons as f64;
            let (ratio, normal) = (drawn(k, sin2_i) / walk, drawn(k, 0.0) / walk);
            line += &format!(" {ratio:.3}");
            normal_line += &format!(" {normal:.3}");
            if count >= 400 {
                // Ring 0 (chords under 0.5 mm) is the half-space's oblique profile near its entry
                // (1.06 in red with either rows: the ball is flat there).
                let bound = match k {
                    0 => 0.08,
                    _ if k < 11 => 0.05,
                    _ => 0.10,
                };
                measured.push((k, ratio, bound));
                normal_worst = normal_worst.max(normal);
            }
        }
        println!("{line}\nchannel {c}, with the normal beam's rows:{normal_line}");
        for (k, ratio, bound) in measured {
            assert!((ratio - 1.0).abs() < bound, "channel {c}, ring {k}: {ratio:.3} of the ball's walk");
        }
        assert!(normal_worst > 1.15, "channel {c}: the normal beam's rows reach only {normal_worst:.3}");
    }
}

/// A 10 mm Skin1 sphere under light along −z, by the walk: the exitance of two or more
/// scatterings within 10° of the pole, against the renderer's sum over the lit hemisphere.
/// Measured: 0.979 / 0.975 / 0.998 (R / G / B; the walk's noise 1.3-3%), the flat half-space
/// 0.86 / 0.87 / 0.92. With the lean's first harmonic alone it was 0.936 / 0.94 / 1.01: every
/// source's light reaches the pole from behind its beam, where that harmonic left 0.68–0.90 of
/// the walk's (`an_oblique_beam_s_light_follows_the_walk_around_it`); the second and third
/// harmonics give it back. (Red was 0.95 before when the ratio was read between nodes at one
/// chord, which overstated the middle chords by 4-17%:
/// `between_nodes_the_ratio_reads_each_ball_at_the_same_place`.) Within 4%.
#[test]
fn the_front_lit_sphere_at_its_pole_matches_the_walk() {
    let media = skin1();
    let curvature = curvature_profile::of_channels(&media);
    let r_mm = 5.0;
    let cap = 10f64.to_radians();
    let cap_area = 2.0 * PI * r_mm * r_mm * (1.0 - cap.cos());
    for c in 0..3 {
        let m = media[c];
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let radius = r_mm * sigma_t;
        let (mut squares, mut weighted) = (0.0f64, 0.0f64);
        let photons = front_lit_walk(&m, r_mm, (600, 1000), false, |w, e| {
            if e.scatterings >= 2 && e.geodesic / radius < cap {
                squares += w * w;
                weighted += w;
            }
        });
        let truth = weighted * (PI * r_mm * r_mm / photons as f64) / cap_area;
        let noise = squares.sqrt() / weighted;
        // The renderer at the pole: Σ over the lit hemisphere of E cos θ Ft f(θt) Sp(r)
        // (1 + b(r) sin θt cos φ) C(r; 1/R); cos φ = −1 (every source leans away from the pole).
        let profile = McProfile::of(&m);
        let (mut flat, mut curved) = (0.0, 0.0);
        let steps = 4000;
        for k in 0..steps {
            let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
            let cos_i = theta.cos();
            let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
            let sin_t = (1.0 - cos_t * cos_t).sqrt();
            let chord = 2.0 * r_mm * (theta / 2.0).sin();
            let weight = cos_i
                * fresnel::transmittance(m.eta, cos_i)
                * profile.incidence_factor(cos_t)
                * 2.0
                * PI
                * r_mm
                * r_mm
                * theta.sin()
                * (PI / 2.0 / steps as f64);
            flat += weight * profile.exitance(chord);
            let lean = profile.lean(chord, -sin_t, sin_t * sin_t);
            curved +=
                weight * profile.exitance(chord) * lean * curvature[c].ratio(chord, 1.0 / r_mm, 1.0 - cos_i * cos_i);
        }
        println!(
            "channel {c}: walk {truth:.5} ± {:.1}%, flat half-space {:.3}, curved model {:.3}",
            100.0 * noise,
            flat / truth,
            curved / truth
        );
        assert!((curved / truth - 1.0).abs() < 0.04, "channel {c}: model {:.3} of the walk", curved / truth);
        if c < 2 {
            assert!(flat / truth < 0.93, "channel {c}: the flat half-space {:.3} of the walk", flat / truth);
        }
    }
}

/// Ten-degree rings of exit polar angle from the light's axis, the lit half (the first nine) and
/// the dark half: what a front-lit and a back-lit view of the sphere see.
const RINGS: usize = 18;

/// One channel of a front-lit sphere of radius `r_mm`, ring by ring: the walk's exitance of two or
/// more scatterings against a sum over the lit hemisphere's sources at the ring's middle of
/// E cos θi Ft(θi) dA · `term(cos θi, chord, cos φ)`, φ the angle along the source's surface
/// between its light's lean and the way to the exit (0 where either vanishes); `dark_side`: the
/// walk splits past the equator (`front_lit_walk`). Returns per ring (sum / walk, the walk's
/// relative noise √Σw²/Σw, its escapes taken as independent: a split photon's copies share
/// their way there, so the dark half's is a floor).
fn ring_sums(
    m: &Medium,
    r_mm: f64,
    steps: usize,
    dark_side: bool,
    term: impl Fn(f64, f64, f64) -> f64,
) -> Vec<(f64, f64)> {
    let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
    let radius = r_mm * sigma_t;
    let (mut weighted, mut squares) = ([0.0f64; RINGS], [0.0f64; RINGS]);
    let photons = front_lit_walk(m, r_mm, (400, 800), dark_side, |w, e| {
        let b = ((e.geodesic / radius) / PI * RINGS as f64) as usize;
        if e.scatterings >= 2 && b < RINGS {
            weighted[b] += w;
            squares[b] += w * w;
        }
    });
    (0..RINGS)
        .map(|b| {
            let (a0, a1) = (b as f64 / RINGS as f64 * PI, (b + 1) as f64 / RINGS as f64 * PI);
            let area = 2.0 * PI * r_mm * r_mm * (a0.cos() - a1.cos());
            let truth = weighted[b] * (PI * r_mm * r_mm / photons as f64) / area;
            let a = 0.5 * (a0 + a1);
            let xo = r_mm * DVec3::new(a.sin(), 0.0, a.cos());
            let mut model = 0.0;
            for k in 0..steps {
                let theta = (k as f64 + 0.5) / steps as f64 * PI / 2.0;
                let cos_i = theta.cos();
                let w = cos_i
                    * fresnel::transmittance(m.eta, cos_i)
                    * r_mm
                    * r_mm
                    * theta.sin()
                    * (PI / 2.0 / steps as f64)
                    * (2.0 * PI / steps as f64);
                for q in 0..steps {
                    let ph = (q as f64 + 0.5) / steps as f64 * 2.0 * PI;
                    let n = DVec3::new(theta.sin() * ph.cos(), theta.sin() * ph.sin(), theta.cos());
                    let d = xo - r_mm * n;
                    // The source's lean: its light's direction along the surface against the way
                    // to the exit (the merged records' m·d̂).
                    let (ahead, along) = (DVec3::new(0.0, 0.0, -1.0) + cos_i * n, d - d.dot(n) * n);
                    let cos_phi = if ahead.length() > 1e-9 && along.length() > 1e-9 {
                        ahead.normalize().dot(along.normalize())
                    } else {
                        0.0
                    };
                    model += w * term(cos_i, d.length(), cos_phi);
                }
            }
            (model / truth, if weighted[b] > 0.0 { squares[b].sqrt() / weighted[b] } else { 1.0 })
        })
        .collect()
}

/// [`ring_sums`] of the renderer's term (each source's half-space profile at the chord, its
/// incidence factor, its lean's harmonics, the ratio at the chord), multiplied by
/// `incidence(cos θi, chord)` (1: the renderer's) and with its lean replaced by the first
/// harmonic `harmonic(chord)` alone when given; `dark_side`: the walk splits past the equator.
fn rings(
    m: &Medium,
    ratios: &curvature_profile::CurvatureChannel,
    r_mm: f64,
    incidence: impl Fn(f64, f64) -> f64,
    harmonic: Option<&dyn Fn(f64) -> f64>,
    dark_side: bool,
) -> Vec<(f64, f64)> {
    let profile = McProfile::of(m);
    ring_sums(m, r_mm, 400, dark_side, |cos_i, chord, cos_phi| {
        let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        let lean = match harmonic {
            Some(h) => (1.0 + h(chord) * sin_t * cos_phi).max(0.0),
            None => profile.lean(chord, sin_t * cos_phi, sin_t * sin_t),
        };
        profile.incidence_factor(cos_t)
            * profile.exitance(chord)
            * lean
            * ratios.ratio(chord, 1.0 / r_mm, 1.0 - cos_i * cos_i)
            * incidence(cos_i, chord)
    })
}

/// A 10 mm Marble sphere lit from the front, ring by ring from the pole to the silhouette: the
/// model within 3% of the walk in every ring and channel of the lit half. Measured: 0.99–1.02
/// (noise 0.5–1.3%). The dark half, printed (this walk does not split: 5 s, not 60), is too
/// bright: 1.00–1.21 past 95° by the split walk (`the_front_lit_sphere_ring_by_ring`, noise
/// 1–5%). Skin1 and Potato, whose diffusion lengths are longer against the radius, are not
/// within 3%: see there.
#[test]
fn the_front_lit_marble_sphere_matches_the_walk_ring_by_ring() {
    let m3 = Material::find("marble").expect("preset");
    let media = [0, 1, 2].map(|c| m3.channel(c));
    let ratios = curvature_profile::of_channels(&media);
    for c in 0..3 {
        let r = rings(&media[c], &ratios[c], 5.0, |_, _| 1.0, None, false);
        println!("channel {c}: {:?}", r.iter().map(|(x, n)| format!("{x:.3} ±{:.1}%", 100.0 * n)).collect::<Vec<_>>());
        for (k, (ratio, _)) in r.iter().enumerate().take(RINGS / 2) {
            assert!((ratio - 1.0).abs() < 0.03, "channel {c}, ring {k}: model {ratio:.3} of the walk");
        }
    }
}

/// The same for any preset (`MATERIAL=potato`, default skin1) and radius (`RADIUS=3.67`, mm,
/// default 5), printed, with the corrections
/// that first-order reasoning suggests, each measured by the walks and tried in the sum. A
/// diagnostic (issue #30): `MATERIAL=skin1 cargo test --release --test curvature_profile --
/// --ignored --nocapture` (about 1 minute; Marble 3). The walk splits past the equator
/// (`front_lit_walk`), so the dark half is measured too (Skin1's blue at 125–145°: noise 7–9%,
/// 13–28% unsplit). Measured (R / G / B; walk noise 0.5–2.5% on the lit half, 1–5% on the dark
/// but Skin1's green and blue, 2–8% and 4–15%), 2026-12-07:
/// - the model: Skin1 0.96/0.95/1.02 at the pole, 1.04/1.03/1.03 at 65°; on the dark half red
///   1.04 at 95° rising to 1.13–1.38 past 135°, green 0.93–0.96 at 95–125° and 1.03–1.59 past,
///   blue 0.89 at 95° and 0.67–0.86 at 105–155°. Potato 0.97–1.05 on the lit half, 1.01–1.26
///   on the dark (blue 0.98–1.23); Marble 0.99–1.02 and 1.00–1.21. So every material is too
///   bright far from the light, and Skin1's blue too dark beside the terminator. (Earlier, on
///   the unsplit walk: Skin1 1.11/1.11/1.08 at 65° and 0.87/0.75/0.3–0.5 past 145° before the
///   rows held their antipode's ratio and read their tails against the profile, and before the
///   exit's tilt, the lean's harmonics and the split table.) With the radial change with
///   incidence (`McProfile::radial`, the same day) Skin1's blue at 85–125° went 0.92 0.89 0.86
///   0.74 0.67 → 0.97 0.98 0.94 0.80 0.73 and its green at 95–125° 0.93–0.96 → 0.98–1.01.
/// - the ball's escapes over the half-space's change with the angle of incidence by at most 6%
///   (Skin1 red 1.63 → 1.53 from normal to grazing): weighting each source by it lowers the lit
///   rings by at most 3.5% and the dark ones by as much;
/// - the ball's own lean (the harmonic b of an oblique beam, per chord) is the half-space's
///   within 5–10% out to 1.5R and falls to 0 at the antipode: with it the dark half gets darker;
/// - the ball's radial ratio measured per angle of incidence (cos θi 1, 0.6, 0.2) is lower at
///   long chords for oblique beams. Measured here first (Skin1 red 0.99–1.005 from 95° to 145°),
///   it is now the table's (`curvature_profile::INCIDENCE_SIN2`, read per pair at its light's
///   sin²θi). The model with it, against the split walk (2026-12-07): Skin1 red 0.96–1.02 on
///   the lit half, 0.98–1.01 from 95° to 145° and 1.06–1.13 past; green 1.00–1.02 on the lit
///   half but the pole's 0.955, 0.92–1.03 on the dark; blue 0.96–1.03 to 85° and 0.73–0.97
///   beside the terminator and past it (its noise 4–15%).
///
/// None of them is the whole cause: the pieces are exact for a normal beam, and what Skin1's blue
/// misses beside the terminator is how an oblique beam's light is placed around a ball.
#[test]
#[ignore]
fn the_front_lit_sphere_ring_by_ring() {
    let material = std::env::var("MATERIAL").unwrap_or_else(|_| "skin1".into());
    let m3 = Material::find(&material).expect("preset");
    let media = [0, 1, 2].map(|c| m3.channel(c));
    let ratios = curvature_profile::of_channels(&media);
    let r_mm: f64 = std::env::var("RADIUS").ok().and_then(|v| v.parse().ok()).unwrap_or(5.0);
    for c in 0..3 {
        let m = media[c];
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let (albedo, radius) = (m.sigma_s * (1.0 - m.g) / sigma_t, r_mm * sigma_t);
        let cos_nodes: [f64; 8] = [1.0, 0.85, 0.7, 0.55, 0.4, 0.25, 0.1, 0.0];
        let totals: Vec<f64> = cos_nodes
            .iter()
            .map(|&cos_i| {
                let start = halfspace::entry_direction(m.eta, cos_i.max(1e-3));
                let (mut ball, mut plane) = (0u64, 0u64);
                for p in 0..200_000u64 {
                    let seed = 0xc0a7 ^ p.wrapping_mul(0x9E37_79B9_7F4A_7C15);
                    sphere::trace_sphere(albedo, m.eta, radius, start, 1, (seed, 100_000), |e| {
                        ball += (e.scatterings >= 2) as u64
                    });
                    halfspace::trace_half_space(albedo, m.eta, start, 1, (seed, 100_000), |e| {
                        plane += (e.scatterings >= 2) as u64
                    });
                }
                ball as f64 / plane as f64
            })
            .collect();
        let incidence = |cos_i: f64| {
            let k = cos_nodes.iter().position(|&x| x <= cos_i).unwrap_or(cos_nodes.len() - 1).max(1);
            let w = (cos_nodes[k - 1] - cos_i) / (cos_nodes[k - 1] - cos_nodes[k]);
            ((1.0 - w) * totals[k - 1] + w * totals[k]) / totals[0]
        };
        println!("{material} channel {c}: ball / half-space escapes at cos θi {cos_nodes:?}: {totals:.3?}");
        let plain = rings(&m, &ratios[c], r_mm, |_, _| 1.0, None, true);
        let inclined = rings(&m, &ratios[c], r_mm, |x, _| incidence(x), None, true);
        // The ball's own harmonic of an oblique beam (cos θi = 0.5) per chord, over [0, 2R]: the
        // azimuth of the exit about the entry's normal, 2⟨cos φ⟩ / sin θt.
        let bins = 20usize;
        let start = halfspace::entry_direction(m.eta, 0.5);
        let (mut n_in, mut cos_sum) = (vec![0f64; bins], vec![0f64; bins]);
        for p in 0..400_000u64 {
            let seed = 0x1ea7 ^ p.wrapping_mul(0x9E37_79B9_7F4A_7C15);
            sphere::trace_sphere(albedo, m.eta, radius, start, 1, (seed, 100_000), |e| {
                let (chord, flat) = (e.position.length(), (e.position.x.powi(2) + e.position.y.powi(2)).sqrt());
                let k = ((chord / (2.0 * radius)) * bins as f64) as usize;
                if e.scatterings >= 2 && k < bins && flat > 0.0 {
                    n_in[k] += 1.0;
                    cos_sum[k] += e.position.x / flat;
                }
            });
        }
        let ball_b: Vec<f64> = (0..bins).map(|k| 2.0 * cos_sum[k] / n_in[k].max(1.0) / start.x).collect();
        let profile = McProfile::of(&m);
        println!(
            "{material} channel {c}: harmonic b by chord/2R (ball | half-space): {}",
            (0..bins)
                .map(|k| {
                    let r = (k as f64 + 0.5) / bins as f64 * 2.0 * r_mm;
                    format!("{:.2}|{:.2}", ball_b[k], profile.azimuth_factor(r))
                })
                .collect::<Vec<_>>()
                .join(" ")
        );
        let ball_harmonic = |r: f64| ball_b[((r / (2.0 * r_mm) * bins as f64) as usize).min(bins - 1)];
        let leaned = rings(&m, &ratios[c], r_mm, |_, _| 1.0, Some(&ball_harmonic), true);
        println!(
            "{material} channel {c}, with the ball's harmonic: {}",
            leaned
                .iter()
                .enumerate()
                .map(|(k, (x, _))| format!("{}°: {x:.3}", 5 + 10 * k))
                .collect::<Vec<_>>()
                .join(" ")
        );
        let mut line = format!("{material} channel {c}, model / walk (with the incidence weighting):");
        for k in 0..RINGS {
            line += &format!(" {}°: {:.3} ({:.3}) ±{:.1}%", 5 + 10 * k, plain[k].0, inclined[k].0, 100.0 * plain[k].1);
        }
        println!("{line}");
    }
}

/// Why the sum above is not the walk, settled by superposition (issue #30): a front-lit ball is
/// the sum of the oblique pencil beams that enter it, so the renderer's sum with each source's term
/// replaced by the ball's own exitance for a beam at its angle of incidence (walked at cos θi 1,
/// 0.8, 0.6, 0.4, 0.2, 0.05; per chord and azimuth from the beam's lean, 40 × 12 bins) must be
/// the walk: measured 0.99-1.02 on the lit half of a 10 mm Skin1 ball in red (0.95-0.99 on the
/// dark). Cut to its first azimuthal harmonic (what the model's lean 1 + b sin θt cos φ can
/// hold), the same table gives 0.96 at the pole, 1.04 at 65° and 0.90-0.92 on the dark half in
/// red, and in green 0.81 past 145° where the whole table gives 0.92-0.95 (the back-lit balls'
/// and the bunny's green deficit against the path tracer): the
/// ball's light around an oblique entry has a second harmonic (more both ahead and behind, less
/// to the sides) that a first harmonic cannot carry, which is most of the model's remaining error
/// on the lit half. `MATERIAL=skin1 cargo test --release --test curvature_profile --
/// --ignored --nocapture` (about 10 s a channel).
#[test]
#[ignore]
fn the_ball_s_own_oblique_beams_sum_to_the_walk() {
    let material = std::env::var("MATERIAL").unwrap_or_else(|_| "skin1".into());
    let m3 = Material::find(&material).expect("preset");
    let r_mm = 5.0;
    const AZIMUTHS: usize = 12;
    for c in 0..3 {
        let m = m3.channel(c);
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let (albedo, radius) = (m.sigma_s * (1.0 - m.g) / sigma_t, r_mm * sigma_t);
        let chords = 40usize;
        let cos_at = [1.0, 0.8, 0.6, 0.4, 0.2, 0.05];
        let photons = 300_000u64;
        // Exitance per mm² per unit power entering, per angle of incidence, chord and azimuth.
        let tables: Vec<Vec<[f64; AZIMUTHS]>> = cos_at
            .iter()
            .map(|&cos_i| {
                let start = halfspace::entry_direction(m.eta, cos_i);
                let mut h = vec![[0f64; AZIMUTHS]; chords];
                for p in 0..photons {
                    let seed = 0xba11 ^ p.wrapping_mul(0x9E37_79B9_7F4A_7C15);
                    sphere::trace_sphere(albedo, m.eta, radius, start, 1, (seed, 100_000), |e| {
                        let k = (e.position.length() / sigma_t / (2.0 * r_mm) * chords as f64) as usize;
                        let q = (e.position.y.atan2(e.position.x).abs() / PI * AZIMUTHS as f64) as usize;
                        if e.scatterings >= 2 && k < chords {
                            h[k][q.min(AZIMUTHS - 1)] += 1.0;
                        }
                    });
                }
                for (k, row) in h.iter_mut().enumerate() {
                    let (c0, c1) = (k as f64 / chords as f64 * 2.0 * r_mm, (k + 1) as f64 / chords as f64 * 2.0 * r_mm);
                    let area = PI * (c1 * c1 - c0 * c0) / AZIMUTHS as f64;
                    row.iter_mut().for_each(|v| *v /= photons as f64 * area);
                }
                h
            })
            .collect();
        let azimuth = |q: usize| (q as f64 + 0.5) / AZIMUTHS as f64 * PI;
        let first_harmonic: Vec<Vec<[f64; AZIMUTHS]>> = tables
            .iter()
            .map(|t| {
                t.iter()
                    .map(|row| {
                        let a0 = row.iter().sum::<f64>() / AZIMUTHS as f64;
                        let a1 = 2.0 * (0..AZIMUTHS).map(|q| row[q] * azimuth(q).cos()).sum::<f64>() / AZIMUTHS as f64;
                        std::array::from_fn(|q| (a0 + a1 * azimuth(q).cos()).max(0.0))
                    })
                    .collect()
            })
            .collect();
        let sum = |table: &Vec<Vec<[f64; AZIMUTHS]>>| -> Vec<f64> {
            ring_sums(&m, r_mm, 300, true, |cos_i, chord, cos_phi| {
                let k = (chord / (2.0 * r_mm) * chords as f64) as usize;
                if k >= chords {
                    return 0.0;
                }
                let j = cos_at.iter().position(|&x| x <= cos_i).unwrap_or(cos_at.len() - 1).max(1);
                let wj = ((cos_at[j - 1] - cos_i) / (cos_at[j - 1] - cos_at[j])).clamp(0.0, 1.0);
                let q = ((cos_phi.clamp(-1.0, 1.0).acos() / PI * AZIMUTHS as f64) as usize).min(AZIMUTHS - 1);
                (1.0 - wj) * table[j - 1][k][q] + wj * table[j][k][q]
            })
            .into_iter()
            .map(|(ratio, _)| ratio)
            .collect()
        };
        let (full, cut) = (sum(&tables), sum(&first_harmonic));
        let mut line = format!("{material} channel {c}, the ball's beams / walk (cut to the first harmonic):");
        for k in 0..RINGS {
            line += &format!(" {}°: {:.3} ({:.3})", 5 + 10 * k, full[k], cut[k]);
        }
        println!("{line}");
    }
}

/// The light of two or more scatterings around an oblique beam, by sector of azimuth from the
/// refracted beam's way along the surface (ahead 0–60°, the sides 60–120°, behind 120–180°) and
/// band of chord: the model's M(r) f(θt) lean(r, φ) C(r; κ) over the exact walk's, for `photons`
/// photons entering at cos θi (the ball of radius `r_mm` when given, else the flat half-space).
fn sector_ratios(
    m: &Medium,
    cos_i: f64,
    ball: Option<(&curvature_profile::CurvatureChannel, f64)>,
    bands: &[(f64, f64)],
    photons: u64,
) -> Vec<[Option<f64>; 3]> {
    let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
    let albedo = m.sigma_s * (1.0 - m.g) / sigma_t;
    let start = halfspace::entry_direction(m.eta, cos_i);
    let profile = McProfile::of(m);
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).sqrt();
    let sin_t = (1.0 - cos_t * cos_t).sqrt();
    let mut counts = vec![[0u64; 3]; bands.len()];
    for p in 0..photons {
        let seed = 0x5ec7 ^ p.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let mut tally = |x: DVec3, n: u32| {
            let chord = x.length() / sigma_t;
            let sector = ((x.y.atan2(x.x).abs() / PI * 3.0) as usize).min(2);
            if let Some(b) = bands.iter().position(|&(a, z)| chord >= a && chord < z) {
                if n >= 2 {
                    counts[b][sector] += 1;
                }
            }
        };
        match ball {
            Some((_, r_mm)) => sphere::trace_sphere(albedo, m.eta, r_mm * sigma_t, start, 1, (seed, 100_000), |e| {
                tally(e.position, e.scatterings)
            }),
            None => halfspace::trace_half_space(albedo, m.eta, start, 1, (seed, 100_000), |e| {
                tally(DVec3::new(e.x, e.y, 0.0), e.scatterings)
            }),
        };
    }
    let steps = 48;
    bands
        .iter()
        .zip(&counts)
        .map(|(&(c0, c1), count)| {
            std::array::from_fn(|sector| {
                let mut model = 0.0;
                for i in 0..steps {
                    for j in 0..steps {
                        let r = c0 + (i as f64 + 0.5) / steps as f64 * (c1 - c0);
                        let phi = (sector as f64 + (j as f64 + 0.5) / steps as f64) * PI / 3.0;
                        let ratio = ball.map_or(1.0, |(c, r_mm)| c.ratio(r, 1.0 / r_mm, 1.0 - cos_i * cos_i));
                        // Both halves of the sector (φ and −φ): 2 r dr dφ.
                        model += profile.exitance(r)
                            * profile.incidence_factor(cos_t)
                            * profile.lean(r, sin_t * phi.cos(), sin_t * sin_t)
                            * ratio
                            * 2.0
                            * r
                            * (c1 - c0)
                            / steps as f64
                            * (PI / 3.0)
                            / steps as f64;
                    }
                }
                (count[sector] >= 50).then(|| model / (count[sector] as f64 / photons as f64))
            })
        })
        .collect()
}

/// An oblique beam's light has the shape around it that the model gives: on the flat
/// half-space, per chord band, the model's light over the walk's is the same ahead of the beam,
/// to its sides and behind it within 20% (the largest sector over the smallest; Skin1, every
/// channel, entering at cos θi 0.2 and 0.5, chords 0.6–1.25 and 1.25–3.1 mm). Light entering
/// obliquely is peaked ahead of its beam and flat behind it. With the first harmonic alone
/// (1 + b sin θt cos φ) the sectors were 0.81–0.97 of the walk ahead, 1.09–1.30 to the sides
/// and 0.68–0.90 behind, spreads 1.26–1.87. With the second and third harmonics
/// (McProfile::harmonics) the spreads are 1.02–1.07 in red and green and 1.05–1.17 in blue
/// (its sides 0.82–0.85 at 1.25–3.1 mm: higher harmonics). And the mean of the three sectors
/// (the azimuthal mean, the three being as wide) within 4% of the walk's in every band: the
/// radial profile at oblique incidence, which the model took as the normal beam's times f(θt)
/// until it gained the radial change with incidence (1 + a sin²θt, `McProfile::radial`): the
/// means were 0.88–0.97 at 1.25–3.1 mm (blue at cos θi 0.2 the lowest) and 0.94–1.02 nearer,
/// now 0.98–1.01 and 0.98–1.03.
#[test]
fn an_oblique_beam_s_light_follows_the_walk_around_it() {
    let media = skin1();
    let bands = [(0.6, 1.25), (1.25, 3.1)];
    for cos_i in [0.2, 0.5] {
        for (c, m) in media.iter().enumerate() {
            let ratios = sector_ratios(m, cos_i, None, &bands, 300_000);
            for (b, r) in ratios.iter().enumerate() {
                let r: Vec<f64> = r.iter().map(|v| v.expect("escapes in every sector")).collect();
                let spread = r.iter().cloned().fold(f64::MIN, f64::max) / r.iter().cloned().fold(f64::MAX, f64::min);
                println!(
                    "cos θi {cos_i} channel {c} band {:?}: ahead / sides / behind {:.3?} (spread {spread:.3})",
                    bands[b], r
                );
                assert!(spread < 1.2, "cos θi {cos_i} channel {c} band {:?}: {:.3?}", bands[b], r);
                let mean = r.iter().sum::<f64>() / r.len() as f64;
                assert!((mean - 1.0).abs() < 0.04, "cos θi {cos_i} channel {c} band {:?}: mean {mean:.3}", bands[b]);
            }
        }
    }
}

/// The same on a 10 mm ball too, every band out to its diameter (a diagnostic, printed):
/// `cargo test --release --test curvature_profile -- --ignored --nocapture an_oblique_beam`
/// (a few minutes). Measured with the lean's first harmonic alone (Skin1, cos θi 0.4): near the
/// entry as the flat half-space; past 7 mm (toward the entry's antipode) red's ahead was
/// 1.25–1.9 of the walk. A beam's shift along the surface lengthens or shortens only the chord's part
/// along the surface, and a chord toward the antipode runs through the ball.
#[test]
#[ignore]
fn an_oblique_beam_s_light_by_sector_on_a_ball() {
    let media = skin1();
    let curvature = curvature_profile::of_channels(&media);
    let bands = [(0.0, 0.6), (0.6, 1.25), (1.25, 3.1), (3.1, 6.0), (6.0, 8.0), (8.0, 10.0)];
    for cos_i in [0.2, 0.4, 0.8] {
        for c in 0..3 {
            for ball in [None, Some((&*curvature[c], 5.0))] {
                let ratios = sector_ratios(&media[c], cos_i, ball, &bands, 1_000_000);
                let mut line = format!("cos θi {cos_i} channel {c} {}:", if ball.is_some() { "ball" } else { "flat" });
                for (&(c0, c1), r) in bands.iter().zip(&ratios) {
                    let shown: Vec<String> =
                        r.iter().map(|v| v.map_or("  -  ".into(), |x| format!("{x:.2}"))).collect();
                    line += &format!(" | {c0}-{c1} mm {}", shown.join(" "));
                }
                println!("{line}");
            }
        }
    }
}
