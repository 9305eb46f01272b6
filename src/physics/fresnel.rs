//! Fresnel terms for a smooth dielectric boundary, and the moments the diffusion models need.

/// Unpolarised Fresnel reflectance for light arriving with cosine `cos_i` (to the normal) on a
/// boundary with relative index `eta` = n_other/n_this (η > 1 entering a denser medium):
/// R = ½(r_s² + r_p²), r_s = (cosθi − η cosθt)/(cosθi + η cosθt), r_p = (η cosθi − cosθt)/(η cosθi + cosθt),
/// with Snell's sinθt = sinθi/η; R = 1 beyond the critical angle (total internal reflection).
pub fn reflectance(eta: f64, cos_i: f64) -> f64 {
    let cos_i = cos_i.abs().min(1.0);
    let sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Ft = 1 − Fr.
pub fn transmittance(eta: f64, cos_i: f64) -> f64 {
    1.0 - reflectance(eta, cos_i)
}

/// Diffuse Fresnel reflectance for η ≥ 1 with the coefficients as printed in Jensen et al. 2001,
/// Fdr(η) = −1.440/η² + 0.710/η + 0.668 + 0.0636η. The reference values (`dirpole-check.csv`,
/// column `sd_dipole`) use exactly these: the longer fit −1.4399/η² + 0.7099/η + 0.6681 + 0.0636η
/// differs from them by up to 1.8e-4 relative in Sd. For η < 1 the Egan–Hilgeman fit
/// −0.4399 + 0.7099/η − 0.3319/η² + 0.0636/η³.
pub fn fdr(eta: f64) -> f64 {
    if eta >= 1.0 {
        -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
    } else {
        -0.4399 + 0.7099 / eta - 0.3319 / (eta * eta) + 0.0636 / (eta * eta * eta)
    }
}

/// Classical dipole boundary constant A = (1 + Fdr)/(1 − Fdr).
pub fn dipole_a(eta: f64) -> f64 {
    let f = fdr(eta);
    (1.0 + f) / (1.0 - f)
}

/// 2C1(n), d'Eon and Irving's polynomial fit of twice the first Fresnel moment.
/// η = 1 exactly takes the first branch, as the authors' program does.
pub fn two_c1(n: f64) -> f64 {
    if n <= 1.0 {
        0.919317 - 3.4793 * n + 6.75335 * n.powi(2) - 7.80989 * n.powi(3) + 4.98554 * n.powi(4) - 1.36881 * n.powi(5)
    } else {
        -9.23372 + 22.2272 * n - 20.9292 * n.powi(2) + 10.2291 * n.powi(3) - 2.54396 * n.powi(4) + 0.254913 * n.powi(5)
    }
}

/// 3C2(n), d'Eon and Irving's fit of three times the second Fresnel moment (n ≥ 1). Its terms
/// cancel from ≈1600 to ≈0.4: evaluate in f64 only.
pub fn three_c2(n: f64) -> f64 {
    -1641.1 + 135.926 / n.powi(3) - 656.175 / n.powi(2) + 1376.53 / n + 1213.67 * n - 568.556 * n.powi(2)
        + 164.798 * n.powi(3)
        - 27.0181 * n.powi(4)
        + 1.91826 * n.powi(5)
}

/// Cφ(n) = (1 − 2C1(n))/4.
pub fn c_phi(n: f64) -> f64 {
    (1.0 - two_c1(n)) / 4.0
}

/// CE(n) = (1 − 3C2(n))/2.
pub fn c_e(n: f64) -> f64 {
    (1.0 - three_c2(n)) / 2.0
}
