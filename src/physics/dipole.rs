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

/// Entries of [`SdTable`] (shared with bssrdf.glsl).
pub const TABLE_SIZE: usize = crate::gpu::DIPOLE_TABLE_SIZE as usize;

/// The classical dipole's Sd for three channels, tabulated for the shade pass: entry i holds Sd
/// (1/mm²) at u = i/(TABLE_SIZE − 1) of the map u = r/(r + reach), r in mm, and the last entry
/// (r = ∞) is 0. One lookup gives the three channels for a few operations where the closed form
/// costs 6 square roots, 6 exponentials and 6 divisions; linear interpolation between entries
/// stays within 1e-4 of the closed form wherever Sd matters (tested).
#[derive(Clone, Debug, PartialEq)]
pub struct SdTable {
    /// 1/σtr of the channel that reaches farthest, in mm: the map's scale.
    pub reach: f64,
    /// RGB and a zero, per entry (one RGBA32 texel).
    pub values: Vec<[f32; 4]>,
}

impl SdTable {
    pub fn new(channels: &[ChannelConstants; 3]) -> SdTable {
        let sigma_tr =
            channels.iter().filter(|c| c.transports).map(|c| c.dipole_sigma_tr).fold(f64::INFINITY, f64::min);
        let reach = if sigma_tr.is_finite() && sigma_tr > 0.0 { 1.0 / sigma_tr } else { 1.0 };
        let values = (0..TABLE_SIZE)
            .map(|i| {
                if i == TABLE_SIZE - 1 {
                    return [0.0; 4];
                }
                let u = i as f64 / (TABLE_SIZE - 1) as f64;
                let r = reach * u / (1.0 - u);
                let v = |c: usize| sd(&channels[c], r) as f32;
                [v(0), v(1), v(2), 0.0]
            })
            .collect();
        SdTable { reach, values }
    }

    /// Sd per channel at distance `r` (mm), as the shade pass reads it: `dipole_sd_table` in
    /// shaders/include/bssrdf.glsl.
    pub fn lookup(&self, r: f64) -> [f64; 3] {
        let x = r / (r + self.reach) * (TABLE_SIZE - 1) as f64;
        let i = (x.floor() as usize).min(TABLE_SIZE - 2);
        let f = x - i as f64;
        let (a, b) = (self.values[i], self.values[i + 1]);
        [0, 1, 2].map(|c| a[c] as f64 * (1.0 - f) + b[c] as f64 * f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::Material;
    use crate::physics::Diffusion;

    /// Against the closed form for every preset material, from r = 0 to where Sd has fallen
    /// below 1e-6 of its value at 0: within 1e-4 of Sd(0) absolute and 2e-3 relative.
    #[test]
    fn table_matches_the_closed_form() {
        for material in Material::presets() {
            let channels = [0, 1, 2].map(|c| material.channel(c).constants(Diffusion::Classical));
            let table = SdTable::new(&channels);
            for (c, constants) in channels.iter().enumerate() {
                if !constants.transports {
                    continue;
                }
                let at_zero = sd(constants, 0.0);
                let mut worst: f64 = 0.0;
                for k in 0..20_000 {
                    let r = table.reach * 40.0 * (k as f64 / 20_000.0).powi(2);
                    let exact = sd(constants, r);
                    if exact < 1e-6 * at_zero {
                        break;
                    }
                    let err = (table.lookup(r)[c] - exact).abs();
                    assert!(
                        err <= 1e-4 * at_zero + 2e-3 * exact,
                        "{} channel {c} r {r} mm: {} vs {exact}",
                        material.name,
                        table.lookup(r)[c]
                    );
                    worst = worst.max(err / exact);
                }
                assert!(worst < 2e-3, "{}: {worst}", material.name);
            }
        }
    }
}
