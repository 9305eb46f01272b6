//! The Monte Carlo table (`--model mc`, src/physics/mc_profile.rs) against Chandrasekhar's exact
//! half-space where the index matches (η = 1): its escape fraction, its incidence factor and its
//! exit factor, each within the Monte Carlo's own noise. The table holds two or more scatterings
//! (the shade pass adds the first): the closed forms less their first order, which at η = 1 is
//! (ϖ/2)(1 − μ0 ln(1 + 1/μ0)) of the light entering, and radiance ϖ/(4π(μ + μ0)) per unit
//! irradiance. No GPU. (Its render of a thick slab is
//! tests/subsurface.rs; against the path tracer, tests/ground_truth.rs.)

mod common;

use translucent::physics::halfspace::{h_function, index_matched_plane_albedo};
use translucent::physics::mc_profile::{self, McProfile, EXIT_BINS, INCIDENCE_NODES};
use translucent::physics::Medium;

/// An index-matched medium of albedo `albedo` (σ't = 1/mm).
fn matched(albedo: f64) -> McProfile {
    (*McProfile::of(&Medium { sigma_a: 1.0 - albedo, sigma_s: albedo, g: 0.0, eta: 1.0 })).clone()
}

/// Orders ≥ 2 of the plane albedo at incidence μ0: 1 − H(μ0)√(1 − ϖ) − (ϖ/2)(1 − μ0 ln(1 + 1/μ0)).
fn multiple(albedo: f64, mu0: f64) -> f64 {
    index_matched_plane_albedo(albedo, mu0) - single(albedo, mu0)
}

/// The first order: 2π∫ ϖ/(4π(μ + μ0)) μ dμ = (ϖ/2)(1 − μ0 ln(1 + 1/μ0)).
fn single(albedo: f64, mu0: f64) -> f64 {
    0.5 * albedo * (1.0 - mu0 * (1.0 + 1.0 / mu0).ln())
}

/// Escape at normal incidence (orders ≥ 2, and the first order apart); at each incidence node μ0
/// (= cos θt at η = 1) the factor f = multiple(μ0) / multiple(1). Within 4σ of the escapes counted.
#[test]
fn escape_and_incidence_factor_match_chandrasekhar() {
    for albedo in [0.5, 0.9, 0.99] {
        let p = matched(albedo);
        let exact = multiple(albedo, 1.0);
        let sigma = |escapes: u64| 1.0 / (escapes as f64).sqrt();
        let first = single(albedo, 1.0);
        println!("ϖ {albedo}: escape {:.5} vs {exact:.5}, single {:.5} vs {first:.5}", p.escape, p.single_escape);
        assert!(
            (p.single_escape / first - 1.0).abs() < 4.0 * sigma(mc_profile::ESCAPES_NORMAL) / first.sqrt(),
            "ϖ {albedo}: single {} vs {first}",
            p.single_escape
        );
        assert!(
            (p.escape / exact - 1.0).abs() < 4.0 * sigma(mc_profile::ESCAPES_NORMAL),
            "ϖ {albedo}: {} vs {exact}",
            p.escape
        );
        for k in 0..INCIDENCE_NODES - 1 {
            let mu0 = mc_profile::incidence_node(p.cos_t_min, k);
            let expected = multiple(albedo, mu0) / exact;
            let tolerance = 4.0 * sigma(mc_profile::ESCAPES_OBLIQUE) + 4.0 * sigma(mc_profile::ESCAPES_NORMAL);
            println!("  μ0 {mu0:.3}: f {:.4} vs {expected:.4}", p.incidence[k]);
            assert!(
                (p.incidence[k] / expected - 1.0).abs() < tolerance,
                "ϖ {albedo} μ0 {mu0}: {} vs {expected}",
                p.incidence[k]
            );
        }
    }
}

/// The exit factor against Chandrasekhar's reflection function less its first order: radiance per
/// unit irradiance L(μ) = ϖ (H(μ) H(μ0) − 1) / (4π(μ + μ0)), over the lobe the renderer puts on
/// the escaping light (Ft = 1 and ∫Ft cos θ dω = π at η = 1): h = L·π / escape, averaged over each bin of cos²θo;
/// at normal incidence and at the most grazing node. Within 4σ of the bin's count.
#[test]
fn exit_factor_matches_chandrasekhar() {
    let albedo = 0.9;
    let p = matched(albedo);
    for (k, escapes) in [(INCIDENCE_NODES - 1, mc_profile::ESCAPES_NORMAL), (0, mc_profile::ESCAPES_OBLIQUE)] {
        let mu0 = mc_profile::incidence_node(p.cos_t_min, k);
        let escape = multiple(albedo, mu0);
        let h0 = h_function(albedo, mu0);
        for b in 0..EXIT_BINS {
            let sub = 16;
            let expected = (0..sub)
                .map(|j| {
                    let mu = ((b as f64 + (j as f64 + 0.5) / sub as f64) / EXIT_BINS as f64).sqrt();
                    albedo * (h_function(albedo, mu) * h0 - 1.0) / (4.0 * (mu + mu0)) / escape
                })
                .sum::<f64>()
                / sub as f64;
            // A bin holds about h/EXIT_BINS of the escapes.
            let tolerance = 4.0 / (expected * escapes as f64 / EXIT_BINS as f64).sqrt() + 4.0 / (escapes as f64).sqrt();
            println!("μ0 {mu0:.3} bin {b}: h {:.4} vs {expected:.4}", p.exit[k][b]);
            assert!(
                (p.exit[k][b] / expected - 1.0).abs() < tolerance,
                "μ0 {mu0} bin {b}: {} vs {expected}",
                p.exit[k][b]
            );
        }
    }
}

/// The profile is deterministic (fixed seeds) and its plane integral is its escape fraction.
#[test]
fn profile_is_reproducible_and_integrates_to_its_escape() {
    let m = Medium { sigma_a: 0.17, sigma_s: 0.88, g: 0.0, eta: 1.3 };
    let a = McProfile::of(&m);
    assert_eq!(*a, McProfile::of_channels(&[m; 3])[0].as_ref().clone());
    let plane = translucent::physics::halfspace::plane_integral(|x| a.exitance(x.length()), 1e-7, 400.0, 1);
    assert!((plane / a.escape - 1.0).abs() < 5e-3, "{plane} vs {}", a.escape);
}

/// Media at the edges render, finite and in bounded time (the render exits 1 on any non-finite
/// pixel): no absorption (α' = 1, whose walks home have no finite mean: the scattering budget
/// ends the measuring), a pure absorber, and η < 1 (light beyond the critical angle does not enter:
/// its single scattering once divided by a refracted cosine of 0).
#[test]
fn edge_media_render_finite() {
    for args in [
        ["--sigma-a", "0,0,0", "--sigma-s", "1,1,1", "--eta", "1.3"],
        ["--sigma-a", "1,1,1", "--sigma-s", "0,0,0", "--eta", "1.3"],
        ["--sigma-a", "1,1,1", "--sigma-s", "1,1,1", "--eta", "0.7"],
    ] {
        let out = common::output_dir().join("mc-edge.exr");
        let started = std::time::Instant::now();
        let mut all = vec!["render", "--validation", "--model", "mc", "--width", "16", "--height", "16"];
        all.extend(args);
        all.extend(["--out", out.to_str().unwrap()]);
        let run = common::translucent(&all);
        assert_eq!(run.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&run.stderr));
        println!("{args:?}: {:.1} s", started.elapsed().as_secs_f64());
        assert!(started.elapsed().as_secs() < 120, "{args:?}");
    }
}
