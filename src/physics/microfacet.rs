//! The surface's own (specular) reflection: a GGX microfacet BRDF with the exact dielectric
//! Fresnel reflectance. `shaders/include/microfacet.glsl` mirrors it in f32.
//!
//! f(ωi, ωo) = D(h) G2(ωi, ωo) F(η, ωi·h) / (4 |n·ωi| |n·ωo|), h = (ωi + ωo)/|ωi + ωo|, with
//! Trowbridge–Reitz D(h) = α² / (π((n·h)²(α² − 1) + 1)²), α = roughness², and the height-correlated
//! Smith G2 = 1/(1 + Λ(ωi) + Λ(ωo)), Λ(ω) = (√(1 + α² tan²θ) − 1)/2 (Heitz 2014, eqs. 72, 99).

use glam::DVec3;

use super::fresnel;

fn lambda(alpha2: f64, cos_theta: f64) -> f64 {
    let c2 = cos_theta * cos_theta;
    0.5 * ((1.0 + alpha2 * (1.0 - c2) / c2).sqrt() - 1.0)
}

/// The BRDF f(ωi, ωo) [1/sr] for unit vectors in a frame with normal `n`; 0 below the surface.
pub fn brdf(n: DVec3, wi: DVec3, wo: DVec3, roughness: f64, eta: f64) -> f64 {
    let (cos_i, cos_o) = (n.dot(wi), n.dot(wo));
    if cos_i <= 0.0 || cos_o <= 0.0 {
        return 0.0;
    }
    let h = (wi + wo).normalize();
    let alpha2 = roughness.powi(4).max(1e-12);
    let nh = n.dot(h).max(0.0);
    let t = nh * nh * (alpha2 - 1.0) + 1.0;
    let d = alpha2 / (std::f64::consts::PI * t * t);
    let g2 = 1.0 / (1.0 + lambda(alpha2, cos_i) + lambda(alpha2, cos_o));
    d * g2 * fresnel::reflectance(eta, wi.dot(h)) / (4.0 * cos_i * cos_o)
}

/// Directional albedo ∫ f cos θi dωi over the hemisphere for a fixed ωo (midpoint rule in
/// (cos θ, φ)); at most the Fresnel reflectance plus shadowing losses, never above 1.
pub fn albedo(wo: DVec3, roughness: f64, eta: f64, steps: usize) -> f64 {
    let n = DVec3::Z;
    let mut sum = 0.0;
    for i in 0..steps {
        let cos_t = (i as f64 + 0.5) / steps as f64;
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        for k in 0..2 * steps {
            let phi = (k as f64 + 0.5) * std::f64::consts::PI / steps as f64;
            let wi = DVec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
            sum += brdf(n, wi, wo, roughness, eta) * cos_t;
        }
    }
    // dω = d(cos θ) dφ
    sum * (1.0 / steps as f64) * (std::f64::consts::PI / steps as f64)
}
