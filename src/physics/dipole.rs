//! Jensen, Marschner, Levoy and Hanrahan's classical dipole (2001).

use super::ChannelConstants;
use std::f64::consts::PI;

/// Rd(r) = (α'/4π)[zr(1 + σtr dr)e^{−σtr dr}/dr³ + zv(1 + σtr dv)e^{−σtr dv}/dv³],
/// dr = √(r² + zr²), dv = √(r² + zv²).
pub fn rd(c: &ChannelConstants, r: f64) -> f64 {
    if !c.transports {
        return 0.0;
    }
    let s = c.dipole_sigma_tr;
    let dr = (r * r + c.zr * c.zr).sqrt();
    let dv = (r * r + c.zv * c.zv).sqrt();
    let term = |z: f64, d: f64| z * (1.0 + s * d) * (-s * d).exp() / (d * d * d);
    c.alpha_reduced / (4.0 * PI) * (term(c.zr, dr) + term(c.zv, dv))
}

/// Sd = Rd(r)/π.
pub fn sd(c: &ChannelConstants, r: f64) -> f64 {
    rd(c, r) / PI
}

/// Total diffuse reflectance ∫Rd dA = (α'/2)(1 + e^{−(4/3)A√(3(1−α'))})e^{−√(3(1−α'))}.
pub fn total_rd(alpha_reduced: f64, a: f64) -> f64 {
    let s = (3.0 * (1.0 - alpha_reduced)).sqrt();
    alpha_reduced / 2.0 * (1.0 + (-(4.0 / 3.0) * a * s).exp()) * (-s).exp()
}
