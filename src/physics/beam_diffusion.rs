//! Photon beam diffusion (Habel, Christensen and Jarosz, "Photon Beam Diffusion: A Hybrid Monte
//! Carlo Method for Subsurface Scattering", EGSR 2013): the radial profile of a semi-infinite
//! medium under a beam at normal incidence, multiple scattering as diffusion dipoles spread along
//! the refracted beam (§3–4 of the paper), plus the exact single-scattering term (§5). The
//! algorithm follows pbrt-v4's `BeamDiffusionMS` / `BeamDiffusionSS` (src/pbrt/bssrdf.cpp; pbrt-v3
//! book §15.5), but integrates in f64 to convergence for the material's own σa, σs, g, η instead of
//! 100 midpoint samples over a table of albedos.
//!
//! Units as the classical dipole (src/physics/dipole.rs): mm and mm⁻¹, per unit power entering the
//! medium.
//!
//! Normalisation. Both terms here are *exitances* M(r): the power per unit area that crosses the
//! boundary outwards, the exit's Fresnel transmission already inside (in Cφ and CE for multiple
//! scattering, explicitly for single scattering). The renderer shades Lo = Ft(ωo) · Sd · E·A with
//! the entry's Ft in E (src/physics/halfspace.rs `model_total`: S = Ft(ωi) Sd Ft(ωo)); the classical
//! dipole's Sd = Rd/π puts an exit Fresnel on top of an Rd that already has one. pbrt's separable
//! BSSRDF instead spreads M over the outgoing directions with the normalised lobe
//! Ft(ωo)/(c π), c π = ∫Ft cos θ dω (`Sw`, c = 1 − 2·FresnelMoment1(1/η)), so that the radiance it
//! emits integrates back to M. The same here: Sd = M(r) / ∫Ft cos θ dω, and the renderer's Ft(ωo)
//! factor is then exactly pbrt's lobe; the total diffuse reflectance a flat half-space renders is
//! Ft(θi)·∫M dA, what the exact transport answers.

use super::{fresnel, halfspace, Medium};
use std::f64::consts::PI;
use std::sync::OnceLock;

/// What the profile needs of one channel, computed once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamMedium {
    pub eta: f64,
    pub g: f64,
    /// σt = σa + σs and the single-scattering albedo ρ = σs/σt (single scattering).
    pub sigma_t: f64,
    pub albedo: f64,
    /// σ't = σa + σs(1 − g) and ρ' = σ's/σ't (the similarity relation, multiple scattering).
    pub sigma_t_reduced: f64,
    pub albedo_reduced: f64,
    /// Grosjean's diffusion coefficient D = (2σa + σ's)/(3σ't²) (d'Eon and Irving 2011, as in the
    /// paper and pbrt).
    pub d: f64,
    /// σtr = √(σa/D).
    pub sigma_tr: f64,
    /// Extrapolation distance zb = 2D(1 + 3C2(η))/(1 − 2C1(η)) (the virtual source sits 2zb above
    /// the boundary; pbrt's `ze` is −zb).
    pub zb: f64,
    /// Exitance weights Cφ = (1 − 2C1(η))/4, CE = (1 − 3C2(η))/2 (Fresnel moments of the inside).
    pub c_phi: f64,
    pub c_e: f64,
    /// ∫ Ft(η, θ) cos θ dω over the outer hemisphere: Sd = M / this (the module's notes).
    pub exit_norm: f64,
}

impl BeamMedium {
    pub fn new(m: &Medium) -> BeamMedium {
        let sigma_s_reduced = m.sigma_s * (1.0 - m.g);
        let sigma_t_reduced = m.sigma_a + sigma_s_reduced;
        let sigma_t = m.sigma_a + m.sigma_s;
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        let d = ratio(2.0 * m.sigma_a + sigma_s_reduced, 3.0 * sigma_t_reduced * sigma_t_reduced);
        BeamMedium {
            eta: m.eta,
            g: m.g,
            sigma_t,
            albedo: ratio(m.sigma_s, sigma_t),
            sigma_t_reduced,
            albedo_reduced: ratio(sigma_s_reduced, sigma_t_reduced),
            d,
            sigma_tr: if d > 0.0 { (m.sigma_a / d).sqrt() } else { 0.0 },
            zb: 2.0 * d * (1.0 + fresnel::three_c2(m.eta)) / (1.0 - fresnel::two_c1(m.eta)),
            c_phi: fresnel::c_phi(m.eta),
            c_e: fresnel::c_e(m.eta),
            exit_norm: exit_normalisation(m.eta),
        }
    }

    /// Whether light scatters at all (σ's > 0); else both terms are 0.
    pub fn transports(&self) -> bool {
        self.albedo_reduced > 0.0 && self.sigma_t_reduced > 0.0
    }

    /// Below this distance (mm) the profile is held at its value here: single scattering grows as
    /// 1/r and multiple scattering as ln(1/r) towards r = 0 (integrable over the plane, but not a
    /// finite value a table or a CSV row can hold). 1e-5 of a mean free path: held there, the disc
    /// inside loses about 2e-5 of single scattering's plane integral.
    pub fn r_floor(&self) -> f64 {
        1e-5 / self.sigma_t.max(f64::MIN_POSITIVE)
    }
}

/// ∫ Ft(η, θ) cos θ dω over the outer hemisphere = 2π∫₀¹ Ft(η, μ) μ dμ (pbrt's c π).
pub fn exit_normalisation(eta: f64) -> f64 {
    // μc = √(1 − η²): below it no light enters a less dense medium (η < 1).
    2.0 * PI * above_critical((1.0 - eta * eta).max(0.0).sqrt(), |mu| fresnel::transmittance(eta, mu) * mu)
}

/// ∫ f(μ) dμ from `mu_c` to 1 where f behaves as √(μ − μc) at μc (Fresnel transmittance beyond
/// the critical angle): Gauss–Legendre in v, μ = μc + (1 − μc)v², which makes it smooth.
fn above_critical(mu_c: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (x, w) = nodes_64();
    x.iter().zip(w).map(|(&v, &w)| w * 2.0 * v * (1.0 - mu_c) * f(mu_c + (1.0 - mu_c) * v * v)).sum()
}

/// The exitance at distance `r` of a unit isotropic point source at depth `z` under the boundary
/// (the paper's dipole, pbrt's "dipole integrand"): M = Cφ φ(r) + CE (−n·E), with
/// φ = (1/4πD)(e^{−σtr dr}/dr − e^{−σtr dv}/dv) and
/// −n·E = (1/4π)(z(1 + σtr dr)e^{−σtr dr}/dr³ + (z + 2zb)(1 + σtr dv)e^{−σtr dv}/dv³),
/// dr = √(r² + z²), dv = √(r² + (z + 2zb)²) (virtual source at height z + 2zb above).
pub fn dipole_exitance(b: &BeamMedium, z: f64, r: f64) -> f64 {
    let zv = z + 2.0 * b.zb;
    let dr = (r * r + z * z).sqrt();
    let dv = (r * r + zv * zv).sqrt();
    let s = b.sigma_tr;
    let (er, ev) = ((-s * dr).exp(), (-s * dv).exp());
    let phi = (er / dr - ev / dv) / (4.0 * PI * b.d);
    let flux = (z * (1.0 + s * dr) * er / (dr * dr * dr) + zv * (1.0 + s * dv) * ev / (dv * dv * dv)) / (4.0 * PI);
    b.c_phi * phi + b.c_e * flux
}

/// Multiple scattering: the exitance at `r` of dipoles along the refracted beam (normal
/// incidence), M_ms(r) = ∫₀^∞ ρ'² σ't e^{−σ't z} κ(z) M_dipole(z, r) dz, where σ't e^{−σ't z} dz is
/// where the beam first collides, one ρ' the source's strength (the part that scatters) and the
/// other Grosjean's: his diffusion Green's function describes only the collided light, α' of it
/// (d'Eon and Irving 2011; pbrt's `rhop * rhop`). κ = 1 − e^{−2σ't(dr + z)} is the paper's
/// correction for sources near the surface, which diffusion overestimates (pbrt's `kappa`).
/// Integrated in ln z with Gauss–Legendre panels: the integrand's scales (r, 1/σ't, 1/σtr) span
/// decades.
pub fn ms_exitance(b: &BeamMedium, r: f64) -> f64 {
    if !b.transports() {
        return 0.0;
    }
    let r = r.max(b.r_floor());
    let st = b.sigma_t_reduced;
    let rho2 = b.albedo_reduced * b.albedo_reduced;
    let integrand = |z: f64| {
        let dr = (r * r + z * z).sqrt();
        let kappa = -(-2.0 * st * (dr + z)).exp_m1();
        rho2 * st * (-st * z).exp() * kappa * dipole_exitance(b, z, r)
    };
    let lo = 1e-6 * r.min(1.0 / st);
    // Below `lo` the integrand is bounded (r > 0): its part there is below 1e-6 of the whole.
    integrand(lo) * lo + log_integral(integrand, lo, 60.0 / st)
}

/// Single scattering, exact for a beam at normal incidence (the paper's §5, pbrt's
/// `BeamDiffusionSS`): light scattered once at depth t travels d = √(r² + t²) to the exit point
/// and leaves with cos θo = t/d inside:
/// M_ss(r) = ∫ σs e^{−σt t} · p(θ) · e^{−σt d} · Ft(1/η, t/d) · (t/d)/d² dt, t from t_c = r√(η² − 1)
/// (nearer the surface the ray meets the boundary beyond the critical angle) to ∞, p the
/// Henyey–Greenstein phase function of g at the scattering angle, cos = −t/d (back toward the
/// surface). Integrated in ln(t − t_c).
pub fn ss_exitance(b: &BeamMedium, r: f64) -> f64 {
    if b.albedo <= 0.0 || b.sigma_t <= 0.0 {
        return 0.0;
    }
    let r = r.max(b.r_floor());
    let st = b.sigma_t;
    let t_c = r * (b.eta * b.eta - 1.0).max(0.0).sqrt();
    let integrand = |x: f64| {
        let t = t_c + x;
        let d = (r * r + t * t).sqrt();
        let cos_o = t / d;
        b.albedo
            * st
            * (-st * (t + d)).exp()
            * henyey_greenstein(b.g, -cos_o)
            * fresnel::transmittance(1.0 / b.eta, cos_o)
            * cos_o
            / (d * d)
    };
    let lo = 1e-9 * (r + 1.0 / st);
    log_integral(integrand, lo, 60.0 / st + r)
}

/// Henyey–Greenstein p(cos θ) = (1 − g²)/(4π(1 + g² − 2g cos θ)^{3/2}), θ the scattering angle.
pub fn henyey_greenstein(g: f64, cos_theta: f64) -> f64 {
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
}

/// Sd of multiple scattering alone (the renderer's normalisation, see the module's notes).
pub fn sd_ms(b: &BeamMedium, r: f64) -> f64 {
    ms_exitance(b, r) / b.exit_norm
}

/// Sd of single scattering alone.
pub fn sd_ss(b: &BeamMedium, r: f64) -> f64 {
    ss_exitance(b, r) / b.exit_norm
}

/// Photon beam diffusion's Sd(r) = (M_ms(r) + M_ss(r)) / ∫Ft cos θ dω (1/mm²).
pub fn sd(b: &BeamMedium, r: f64) -> f64 {
    (ms_exitance(b, r) + ss_exitance(b, r)) / b.exit_norm
}

/// The exact single-scattering diffuse reflectance of a half-space at normal incidence, per unit
/// power entering, isotropic phase function: (ρ/2)∫₀¹ Ft(1/η, μ) μ/(1 + μ) dμ (the beam reaches
/// depth z with e^{−σt z}, scatters σs/4π per solid angle and leaves along μ with e^{−σt z/μ};
/// once reflected at the boundary it heads down and never returns unscattered). The independent
/// check of [`ss_exitance`]'s plane integral.
pub fn single_scattering_total(albedo: f64, eta: f64) -> f64 {
    // The inside's critical cosine √(1 − 1/η²): Ft is 0 below it.
    let mu_c = (1.0 - 1.0 / (eta * eta)).max(0.0).sqrt();
    0.5 * albedo * above_critical(mu_c, |mu| fresnel::transmittance(1.0 / eta, mu) * mu / (1.0 + mu))
}

/// The plane integral ∫M dA of the beam's dipoles with one ρ' and no κ, in closed form:
/// ρ' σ't/(σ't + σtr) · [Cφ(1 − e^{−2σtr zb})/(2Dσtr) + (CE/2)(1 + e^{−2σtr zb})] (each dipole's
/// ∫M dA as in halfspace.rs `point_source_plane`, averaged over the beam's e^{−σ't z}). Extended-
/// source diffusion of *every* order, single scattering included: the diagnostic that shows what
/// beam diffusion's ρ'²κ + exact single scattering counts twice (tests/beam_diffusion.rs).
pub fn extended_source_total(b: &BeamMedium) -> f64 {
    if !b.transports() {
        return 0.0;
    }
    let s = b.sigma_tr;
    let ev = (-2.0 * s * b.zb).exp();
    // (1 − e^{−2σtr zb})/σtr → 2zb as σtr → 0.
    let phi_part = if s > 0.0 { -(-2.0 * s * b.zb).exp_m1() / s } else { 2.0 * b.zb };
    b.albedo_reduced * b.sigma_t_reduced / (b.sigma_t_reduced + s)
        * (b.c_phi * phi_part / (2.0 * b.d) + b.c_e / 2.0 * (1.0 + ev))
}

/// ∫Sd dA over the disc r < `radius`: what the first entry of a table must hold for the first
/// interval's share of the plane integral to come out right (`gpu::SdTable::beam_diffusion`).
pub fn disc_integral(b: &BeamMedium, radius: f64) -> f64 {
    let floor = b.r_floor().min(radius);
    // Held constant inside the floor.
    PI * floor * floor * sd(b, floor) + log_integral(|r| 2.0 * PI * r * sd(b, r), floor, radius)
}

/// ∫ f(x) dx from `lo` to `hi` (0 < lo < hi) in s = ln x: composite 8-point Gauss–Legendre on
/// panels of width ≤ 0.5 in s (an e-fold of x every two panels; tested converged).
fn log_integral(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    let (a, b) = (lo.ln(), hi.ln());
    let panels = ((b - a) / 0.5).ceil().max(1.0) as usize;
    let h = (b - a) / panels as f64;
    let (x, w) = nodes_8();
    let mut sum = 0.0;
    for p in 0..panels {
        let s0 = a + p as f64 * h;
        for (&u, &w) in x.iter().zip(w) {
            let v = (s0 + u * h).exp();
            sum += w * f(v) * v;
        }
    }
    sum * h
}

fn nodes_8() -> &'static (Vec<f64>, Vec<f64>) {
    static NODES: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    NODES.get_or_init(|| halfspace::gauss_legendre_unit(8))
}

fn nodes_64() -> &'static (Vec<f64>, Vec<f64>) {
    static NODES: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    NODES.get_or_init(|| halfspace::gauss_legendre_unit(64))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skin_red() -> BeamMedium {
        BeamMedium::new(&Medium { sigma_a: 0.032, sigma_s: 0.74, g: 0.0, eta: 1.3 })
    }

    /// The Gauss–Legendre normalisation against the 100,000-point midpoint rule of halfspace.rs,
    /// and pbrt's c = 1 − 2C1(1/η) (d'Eon's fit: within its 1e-3).
    #[test]
    fn exit_normalisation_is_the_cosine_weighted_transmittance() {
        for eta in [0.7, 1.0, 1.3, 1.5, 2.0] {
            let gl = exit_normalisation(eta);
            let midpoint = halfspace::cosine_weighted_transmittance(eta);
            assert!((gl - midpoint).abs() < 1e-7, "η {eta}: {gl} vs {midpoint}");
            if eta >= 1.0 {
                let fit = PI * (1.0 - fresnel::two_c1(1.0 / eta));
                assert!((gl / fit - 1.0).abs() < 2e-3, "η {eta}: {gl} vs pbrt's fit {fit}");
            }
        }
        assert!((exit_normalisation(1.0) - PI).abs() < 1e-12);
    }

    /// The quadratures are converged: halving the panels' width (twice the nodes) changes nothing
    /// beyond 1e-9, from a thousandth of a mean free path to far in the tail.
    #[test]
    fn quadratures_are_converged() {
        let b = skin_red();
        let fine = |f: &dyn Fn(f64) -> f64, lo: f64, hi: f64| {
            let (a, bb) = (lo.ln(), hi.ln());
            let n = 4 * ((bb - a) / 0.5).ceil() as usize;
            let h = (bb - a) / n as f64;
            let (x, w) = halfspace::gauss_legendre_unit(16);
            (0..n)
                .flat_map(|p| x.iter().zip(&w).map(move |(&u, &w)| (a + (p as f64 + u) * h, w)))
                .map(|(s, w)| w * f(s.exp()) * s.exp())
                .sum::<f64>()
                * h
        };
        for r in [2e-3, 0.05, 0.5, 3.0, 20.0] {
            let st = b.sigma_t_reduced;
            let ms = |z: f64| {
                let dr = (r * r + z * z).sqrt();
                let kappa = -(-2.0 * st * (dr + z)).exp_m1();
                b.albedo_reduced.powi(2) * st * (-st * z).exp() * kappa * dipole_exitance(&b, z, r)
            };
            let lo = 1e-6 * r.min(1.0 / st);
            let reference = ms(lo) * lo + fine(&ms, lo, 60.0 / st);
            let got = ms_exitance(&b, r);
            assert!((got / reference - 1.0).abs() < 1e-9, "ms r {r}: {got} vs {reference}");
            let t_c = r * (b.eta * b.eta - 1.0).sqrt();
            let ss = |x: f64| {
                let t = t_c + x;
                let d = (r * r + t * t).sqrt();
                b.albedo * b.sigma_t * (-b.sigma_t * (t + d)).exp() / (4.0 * PI)
                    * fresnel::transmittance(1.0 / b.eta, t / d)
                    * (t / d)
                    / (d * d)
            };
            let reference = fine(&ss, 1e-9 * (r + 1.0 / b.sigma_t), 60.0 / b.sigma_t + r);
            let got = ss_exitance(&b, r);
            assert!((got / reference - 1.0).abs() < 1e-9, "ss r {r}: {got} vs {reference}");
        }
    }

    /// The singularities at r → 0: single scattering ∝ 1/r, multiple scattering ∝ ln(1/r).
    #[test]
    fn near_field_grows_as_the_theory_says() {
        let b = skin_red();
        let mfp = 1.0 / b.sigma_t;
        let ss = |r: f64| r * ss_exitance(&b, r * mfp);
        println!("r·M_ss at 2e-3, 4e-3 mean free paths: {} {}", ss(2e-3), ss(4e-3));
        assert!((ss(2e-3) / ss(4e-3) - 1.0).abs() < 0.03, "1/r");
        let ms = |r: f64| ms_exitance(&b, r * mfp);
        let (step, step2) = (ms(2e-3) - ms(4e-3), ms(4e-3) - ms(8e-3));
        println!("multiple scattering per halving: {step} then {step2}");
        assert!((step / step2 - 1.0).abs() < 0.1, "ln(1/r): {step} vs {step2}");
        // Held below the floor.
        assert_eq!(sd(&b, 0.0), sd(&b, b.r_floor()));
    }

    /// Henyey–Greenstein integrates to 1 over the sphere and is isotropic at g = 0.
    #[test]
    fn henyey_greenstein_is_normalised() {
        let (x, w) = halfspace::gauss_legendre_unit(64);
        for g in [0.0, 0.5, -0.3] {
            let total: f64 =
                x.iter().zip(&w).map(|(&u, &w)| 2.0 * w * 2.0 * PI * henyey_greenstein(g, 2.0 * u - 1.0)).sum();
            assert!((total - 1.0).abs() < 1e-10, "g {g}: {total}");
        }
        assert!((henyey_greenstein(0.0, 0.3) - 1.0 / (4.0 * PI)).abs() < 1e-15);
    }

    /// No scattering, no light.
    #[test]
    fn pure_absorber_is_black() {
        let b = BeamMedium::new(&Medium { sigma_a: 1.0, sigma_s: 0.0, g: 0.0, eta: 1.3 });
        assert_eq!(sd(&b, 0.3), 0.0);
    }
}
