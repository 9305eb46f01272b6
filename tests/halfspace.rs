//! The half-space yardstick (src/physics/halfspace.rs): its Monte Carlo against Chandrasekhar's
//! exact answer, against Mitsuba 3's recorded Skin1 thick slab, and what it says about the
//! directional dipole's excess. No GPU.

mod common;

use common::repo_path;
use translucent::materials::Material;
use translucent::physics::{fresnel, halfspace, Diffusion};

/// Index-matched (η = 1): the Monte Carlo's plane albedo is 1 − H(μ0)√(1 − ϖ), within its noise.
#[test]
fn monte_carlo_matches_chandrasekhar_where_the_index_matches() {
    for albedo in [0.5, 0.9, 0.99] {
        for mu0 in [1.0, 0.5] {
            let mc = halfspace::rte_reflectance(albedo, 1.0, mu0, 200_000, 11);
            let exact = halfspace::index_matched_plane_albedo(albedo, mu0);
            println!("ϖ {albedo} μ0 {mu0}: MC {:.4} ± {:.4}, exact {exact:.4}", mc.total, mc.total_error);
            assert!((mc.total - exact).abs() < 4.0 * mc.total_error, "ϖ {albedo} μ0 {mu0}: {} vs {exact}", mc.total);
        }
    }
}

fn recorded_ratios(model: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(repo_path("tests/data/mitsuba-reference.json")).expect("reference data");
    let v: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    v["cases"]["skin1/slab"]["ratio_translucent_over_path_traced"][model]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// The recorded render ratios (translucent / Mitsuba on the thick Skin1 slab, light at normal
/// incidence, seen 20–40° off the normal) follow from the half-space alone: a model's radiance
/// is Ft(0)Ft(θo)∫Sd dA, the path tracer's is the Monte Carlo's, both averaged over cos²θo from
/// cos²40° to cos²20°. Within 3%: the Monte Carlo's 1% and Mitsuba's 0.3–0.6% noise, the image
/// weighting its view angles differently, and its finite slab.
#[test]
fn monte_carlo_reproduces_mitsubas_skin1_slab() {
    let skin = Material::find("skin1").unwrap();
    let (dipole, directional) = (recorded_ratios("dipole"), recorded_ratios("directional"));
    for ch in 0..3 {
        let c = skin.channel(ch).constants(Diffusion::Classical);
        let mc = halfspace::rte_reflectance(c.alpha_reduced, skin.eta, 1.0, 1_000_000, 3 + ch as u64);
        let (pt, ft_out) = mc.radiance_between(40f64.to_radians().cos(), 20f64.to_radians().cos(), |mu| {
            fresnel::transmittance(skin.eta, mu)
        });
        let lo = |plane_sd: f64| fresnel::transmittance(skin.eta, 1.0) * ft_out * plane_sd;
        let predicted_dipole =
            lo(translucent::physics::dipole::total_rd(c.alpha_reduced, c.a_dipole) / std::f64::consts::PI) / pt;
        let predicted_directional = lo(halfspace::dirpole_plane(&c, 1.0)) / pt;
        println!(
            "channel {ch}: classical {predicted_dipole:.3} (Mitsuba {:.3}), directional {predicted_directional:.3} (Mitsuba {:.3})",
            dipole[ch], directional[ch]
        );
        assert!((predicted_dipole / dipole[ch] - 1.0).abs() < 0.03, "classical channel {ch}");
        assert!((predicted_directional / directional[ch] - 1.0).abs() < 0.03, "directional channel {ch}");
    }
}

/// Where the published directional dipole's excess on Skin1 comes from (total diffuse
/// reflectance at normal incidence, model / exact): the ray source's strength α' is missing
/// (×α' still leaves ≥ 1.35×), and the ray source is a first-order expansion about the entry
/// point, so it acts like a source near the surface (between depth 0 and D = zr/3, the depth its
/// regularised distance puts it at), which loses far less to absorption than the beam's real
/// mean depth zr = 1/σ't. The same boundary and exitance with the ray source integrated exactly
/// along the refracted ray come within 16% in every channel (diffusion's own error at α' = 0.68).
#[test]
fn the_directional_dipoles_excess_is_strength_and_depth() {
    let skin = Material::find("skin1").unwrap();
    for ch in 0..3 {
        let c = skin.channel(ch).constants(Diffusion::Classical);
        let mc = halfspace::rte_reflectance(c.alpha_reduced, skin.eta, 1.0, 300_000, 5 + ch as u64).total;
        let published = halfspace::model_total(halfspace::dirpole_plane(&c, 1.0), skin.eta, 1.0) / mc;
        let strength = published * c.alpha_reduced;
        let at =
            |z: f64| halfspace::exitance_total(&c, c.alpha_reduced * halfspace::point_source_plane(&c, z), 1.0) / mc;
        let integrated = halfspace::exitance_total(&c, halfspace::ray_source_plane(&c, 1.0), 1.0) / mc;
        println!(
            "channel {ch}: published {published:.3}×, ×α' {strength:.3}×, point at 0 {:.3}×, at D {:.3}×, at zr {:.3}×, ray integrated {integrated:.3}×",
            at(0.0),
            at(c.d),
            at(c.zr)
        );
        assert!(published > 1.4, "channel {ch}: {published}");
        assert!(strength > 1.35, "channel {ch}: {strength}");
        // ×α' lies between the point source at the surface and at depth D, far above depth zr.
        assert!(strength <= at(0.0) * 1.01 && strength > at(c.d) * 1.01 && strength > 1.3 * at(c.zr), "channel {ch}");
        assert!((integrated - 1.0).abs() < 0.16, "channel {ch}: {integrated}");
    }
}
