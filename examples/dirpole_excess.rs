//! Where the directional dipole's excess comes from, in f64: the plane integrals of the models
//! against the exact radiative transfer answer (Monte Carlo in a half-space) for Skin1.
//! `cargo run --release --example dirpole_excess` (about a minute).

use std::f64::consts::PI;
use translucent::materials::Material;
use translucent::physics::{dipole, fresnel, halfspace, ChannelConstants, Diffusion};

/// Grosjean's split: the beam's first scattering (strength α'), the collided part of each such
/// point source diffusing with α' e^{−σtr r}/(4πDg r), Dg = (2σa + σ's)/(3σ't²), under the same
/// boundary; plus exact single scattering (α/2)∫T(μ)μ/(μ + μt)dμ, inside cosines μ.
fn grosjean_plane(c: &ChannelConstants, mu_t: f64) -> (f64, f64) {
    let dg = (2.0 * c.sigma_a + c.sigma_s_reduced) / (3.0 * c.sigma_t_reduced * c.sigma_t_reduced);
    let s = (c.sigma_a / dg).sqrt();
    let zb = c.a_dirpole * 2.131 * dg / c.alpha_reduced.sqrt();
    let k = c.sigma_t_reduced / (c.sigma_t_reduced + s * mu_t);
    let ev = (-s * 2.0 * zb).exp();
    let a = c.alpha_reduced;
    let ms = a * a * k * (c.c_phi / (2.0 * dg * s) * (1.0 - ev) + c.c_e / 2.0 * (1.0 + ev));
    let n = 20_000;
    let ss = (0..n)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n as f64;
            fresnel::transmittance(1.0 / c.eta, mu) * mu / (mu + mu_t)
        })
        .sum::<f64>()
        / n as f64
        * a
        / 2.0;
    (ms, ss)
}

fn main() {
    let skin = Material::find("skin1").unwrap();
    let eta = skin.eta;
    let tcos = halfspace::cosine_weighted_transmittance(eta);
    println!("η = {eta}: ∫Ft cos dω = π·{:.5}; N = {:.5}", tcos / PI, 1.0 / (4.0 * fresnel::c_phi(1.0 / eta)));
    let photons = 400_000;
    let view = (30f64).to_radians().cos();
    for ch in 0..3 {
        let c = skin.channel(ch).constants(Diffusion::Classical);
        println!(
            "\nchannel {ch}: α' {:.4}, σ't {:.4}/mm, σtr {:.4}/mm, D {:.4} mm, de {:.4} mm, zr {:.4}, zv {:.4}",
            c.alpha_reduced, c.sigma_t_reduced, c.sigma_tr, c.d, c.de, c.zr, c.zv
        );
        for deg in [0.0f64, 45.0, 60.0] {
            let cos_i = deg.to_radians().cos();
            let mc = halfspace::rte_reflectance(c.alpha_reduced, eta, cos_i, photons, 7 + ch as u64);
            let ft = fresnel::transmittance(eta, cos_i);
            let classical = ft * dipole::total_rd(c.alpha_reduced, c.a_dipole) * tcos / PI;
            let published = ft * halfspace::dirpole_plane(&c, cos_i) * tcos;
            println!(
                "  θi {deg:>2}°: path traced (RTE MC) {:.4} ± {:.4} | classical {:.4} ({:.3}×) | directional {:.4} ({:.3}×, ×α' {:.3}×)",
                mc.total,
                mc.total_error,
                classical,
                classical / mc.total,
                published,
                published / mc.total,
                published * c.alpha_reduced / mc.total
            );
            // The same boundary and exitance with the source as the derivation has it: the ray
            // source of strength α', a point at the surface, at D, at zr, and integrated exactly.
            let mu_t = (1.0 - (1.0 - cos_i * cos_i) / (eta * eta)).sqrt();
            let norm = ft * tcos / PI / (4.0 * fresnel::c_phi(1.0 / eta));
            let a = c.alpha_reduced;
            println!(
                "    point source α'·M at depth 0: {:.3}×, at D: {:.3}×, at zr: {:.3}×; ray source integrated: {:.3}×",
                norm * a * halfspace::point_source_plane(&c, 0.0) / mc.total,
                norm * a * halfspace::point_source_plane(&c, c.d * mu_t) / mc.total,
                norm * a * halfspace::point_source_plane(&c, c.zr * mu_t) / mc.total,
                norm * halfspace::ray_source_plane(&c, mu_t) / mc.total,
            );
            let alt = skin.channel(ch).constants(Diffusion::Alternative);
            println!(
                "    with D = (2σa+σ's)/(3σ't²): ray source integrated {:.3}×, point source at zr {:.3}×",
                norm * halfspace::ray_source_plane(&alt, mu_t) / mc.total,
                norm * c.alpha_reduced * halfspace::point_source_plane(&alt, c.zr * mu_t) / mc.total
            );
            let (ms, ss) = grosjean_plane(&c, mu_t);
            println!(
                "    Grosjean: multiple {:.3}× + single {:.3}× = {:.3}×",
                norm * ms / mc.total,
                ft * ss / mc.total,
                (norm * ms + ft * ss) / mc.total
            );
            if deg == 0.0 {
                // The thick-slab render: radiance at 30° per unit irradiance.
                let lo = |plane_sd: f64| ft * fresnel::transmittance(eta, view) * plane_sd;
                let mc_lo = mc.radiance_at(view);
                println!(
                    "    radiance at 30°: MC {:.5}; classical/MC {:.3}, directional/MC {:.3}",
                    mc_lo,
                    lo(dipole::total_rd(c.alpha_reduced, c.a_dipole) / PI) / mc_lo,
                    lo(halfspace::dirpole_plane(&c, 1.0)) / mc_lo
                );
            }
        }
    }
}
