//! Frisvad, Hachisuka and Kjeldsen's directional dipole (ACM TOG 2014), as in
//! `shared/reference/bssrdf.md` §2.

use super::ChannelConstants;
use glam::DVec3;
use std::f64::consts::PI;

/// The ray-source term S'(x, w, r):
/// N/(4π²) · e^{−σtr r}/r³ · [Cφ(r²/D + 3(1 + σtr r)(x·w))
///   − CE(3D(1 + σtr r)(w·no) − ((1 + σtr r) + 3D(3(1 + σtr r) + (σtr r)²)/r² · (x·w))(x·no))].
pub fn source_term(c: &ChannelConstants, x: DVec3, w: DVec3, r: f64, no: DVec3) -> f64 {
    let s_r = c.sigma_tr * r;
    let one = 1.0 + s_r;
    let x_dot_w = x.dot(w);
    let d = c.d;
    let phi = c.c_phi * (r * r / d + 3.0 * one * x_dot_w);
    let e =
        c.c_e * (3.0 * d * one * w.dot(no) - (one + 3.0 * d * (3.0 * one + s_r * s_r) / (r * r) * x_dot_w) * x.dot(no));
    c.n_norm / (4.0 * PI * PI) * (-s_r).exp() / (r * r * r) * (phi - e)
}

/// Direction of the light refracted into the medium: ω12 = −(1/η)(ωi − (ωi·ni)ni) − ni√(1 − (1/η)²(1 − (ωi·ni)²)).
pub fn refract_in(wi: DVec3, ni: DVec3, eta: f64) -> DVec3 {
    let cos_i = wi.dot(ni);
    let k = (1.0 - (1.0 - cos_i * cos_i) / (eta * eta)).max(0.0);
    -(wi - cos_i * ni) / eta - ni * k.sqrt()
}

/// The real and virtual source terms (real, virtual); Sd = max(0, real − virtual).
pub fn terms(c: &ChannelConstants, xi: DVec3, ni: DVec3, wi: DVec3, xo: DVec3, no: DVec3) -> (f64, f64) {
    if !c.transports {
        return (0.0, 0.0);
    }
    let x = xo - xi;
    let r2 = x.length_squared();
    let w12 = refract_in(wi, ni, c.eta);

    // Modified tangent plane: ni* = x̂ × normalize(ni × x) = the part of ni normal to x, normalised;
    // ni where x is (numerically) zero or parallel to ni.
    let perp = ni - x * (x.dot(ni) / r2.max(f64::MIN_POSITIVE));
    let ni_star = if r2 > 0.0 && perp.length_squared() > 1e-24 { perp.normalize() } else { ni };

    // Real source: distance with the singularity at r = 0 removed.
    let mu0 = -no.dot(w12);
    let dr2 = if mu0 > 0.0 {
        let along = x.dot(w12);
        let cos_beta = -((r2 - along * along).max(0.0) / (r2 + c.de * c.de)).sqrt();
        r2 + c.d * mu0 * (c.d * mu0 - 2.0 * c.de * cos_beta)
    } else {
        let inv3t = 1.0 / (3.0 * c.sigma_t);
        r2 + inv3t * inv3t
    };
    // Guard the 1/r³ for μ0 → 0⁺ at r = 0 (dr → Dμ0 → 0); far below any sampled distance.
    let dr = dr2.max(1e-24 * c.d * c.d).sqrt();

    // Virtual source, mirrored in the modified tangent plane.
    let xv = xi + 2.0 * c.a_dirpole * c.de * ni_star;
    let wv = w12 - 2.0 * w12.dot(ni_star) * ni_star;
    let xov = xo - xv;
    let dv = xov.length();

    (source_term(c, x, w12, dr, no), source_term(c, xov, wv, dv, no))
}

/// Sd(xi, ωi; xo, no) = max(0, S'(xo − xi, ω12, dr) − S'(xo − xv, ωv, dv)).
pub fn sd(c: &ChannelConstants, xi: DVec3, ni: DVec3, wi: DVec3, xo: DVec3, no: DVec3) -> f64 {
    let (real, virt) = terms(c, xi, ni, wi, xo, no);
    let v = real - virt;
    if v > 0.0 && v.is_finite() {
        v
    } else {
        0.0
    }
}
