//! The classical dipole's Sd as the shade pass reads it: a table of f16 pairs (bssrdf.glsl's
//! `dipole_sd_table`), made from [`crate::physics::dipole::sd`] and tested against it.

use crate::physics::dipole::sd;
use crate::physics::ChannelConstants;

/// Entries of [`SdTable`] (shared with bssrdf.glsl).
pub const TABLE_SIZE: usize = super::DIPOLE_TABLE_SIZE as usize;

/// The classical dipole's Sd for three channels, tabulated for the shade pass: entry i holds Sd
/// at u = i/(TABLE_SIZE − 1) of the map u = r/(r + reach), r in mm, and the last entry (r = ∞)
/// is 0. One lookup gives the three channels for a few operations where the closed form costs 6
/// square roots, 6 exponentials and 6 divisions; linear interpolation between entries stays
/// within 1e-4 of Sd(0) and 2e-3 of the closed form (tested).
#[derive(Clone, Debug, PartialEq)]
pub struct SdTable {
    /// 1/σtr of the channel that reaches farthest, in mm: the map's scale.
    pub reach: f64,
    /// Sd(0)/2^15 per channel (1/mm²): the entries are Sd/scale, in [0, 2^15], so that Sd down
    /// to 2e-9 Sd(0) keeps f16's full precision (normal numbers start at 2^-14).
    pub scale: [f32; 3],
    /// Sd / scale per channel at each entry, rounded to f16 (as the GPU reads it).
    pub values: Vec<[u16; 3]>,
}

impl SdTable {
    pub fn new(channels: &[ChannelConstants; 3]) -> SdTable {
        let sigma_tr =
            channels.iter().filter(|c| c.transports).map(|c| c.dipole_sigma_tr).fold(f64::INFINITY, f64::min);
        let reach = if sigma_tr.is_finite() && sigma_tr > 0.0 { 1.0 / sigma_tr } else { 1.0 };
        let scale = [0, 1, 2].map(|c| (sd(&channels[c], 0.0) / 32768.0) as f32);
        let values = (0..TABLE_SIZE)
            .map(|i| {
                let u = i as f64 / (TABLE_SIZE - 1) as f64;
                let r = reach * u / (1.0 - u);
                [0, 1, 2].map(|c| {
                    let relative = if i == TABLE_SIZE - 1 || scale[c] <= 0.0 {
                        0.0
                    } else {
                        sd(&channels[c], r) / scale[c] as f64
                    };
                    half_bits(relative as f32)
                })
            })
            .collect();
        SdTable { reach, scale, values }
    }

    /// The table as the shade pass's texels (RGBA32UI): texel 0 holds the three scales and the
    /// reach (f32 bits); texel 1 + i holds, per channel, entries i and i + 1 as two f16 (low,
    /// high), so that one fetch gives both ends of the interpolation.
    pub fn texels(&self) -> Vec<[u32; 4]> {
        let mut texels = vec![[
            self.scale[0].to_bits(),
            self.scale[1].to_bits(),
            self.scale[2].to_bits(),
            (self.reach as f32).to_bits(),
        ]];
        texels.extend(self.values.windows(2).map(|w| {
            let pair = |c: usize| w[0][c] as u32 | (w[1][c] as u32) << 16;
            [pair(0), pair(1), pair(2), 0]
        }));
        texels
    }

    /// Sd per channel at distance `r` (mm), as the shade pass reads it: `dipole_sd_table` in
    /// shaders/include/bssrdf.glsl.
    pub fn lookup(&self, r: f64) -> [f64; 3] {
        let x = r / (r + self.reach) * (TABLE_SIZE - 1) as f64;
        let i = (x.floor() as usize).min(TABLE_SIZE - 2);
        let f = x - i as f64;
        let (a, b) = (self.values[i], self.values[i + 1]);
        [0, 1, 2].map(|c| self.scale[c] as f64 * (half_value(a[c]) * (1.0 - f) + half_value(b[c]) * f))
    }
}

/// IEEE binary16 bits of `x`, rounded to nearest even (GLSL's packHalf2x16 for these values).
fn half_bits(x: f32) -> u16 {
    let bits = x.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exponent = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    let mantissa = bits & 0x7f_ffff;
    if !x.is_finite() {
        return sign | 0x7c00 | if x.is_nan() { 0x200 } else { 0 };
    }
    if exponent >= 31 {
        return sign | 0x7c00;
    }
    let (kept, shift) = if exponent <= 0 {
        // A subnormal half: the implicit 1 joins the mantissa.
        if exponent < -10 {
            return sign;
        }
        (mantissa | 0x80_0000, (14 - exponent) as u32)
    } else {
        ((exponent as u32) << 23 | mantissa, 13)
    };
    let truncated = kept >> shift;
    let rest = kept & ((1 << shift) - 1);
    let halfway = 1 << (shift - 1);
    let up = rest > halfway || (rest == halfway && truncated & 1 == 1);
    sign | (truncated + up as u32) as u16
}

/// The value of IEEE binary16 bits (non-negative, finite here).
fn half_value(h: u16) -> f64 {
    let exponent = ((h >> 10) & 0x1f) as i32;
    let mantissa = (h & 0x3ff) as f64;
    if exponent == 0 {
        mantissa * 2f64.powi(-24)
    } else {
        (1.0 + mantissa / 1024.0) * 2f64.powi(exponent - 15)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::materials::Material;
    use crate::physics::Diffusion;

    #[test]
    fn half_conversion_rounds_to_nearest() {
        for x in [0.0f32, 1.0, 0.5, 1e-3, 6.1e-5, 3e-6, 5.9604645e-8, 1e-9, 0.33333334, 0.9999] {
            let h = half_bits(x);
            let back = half_value(h);
            let ulp = if back < 6.1e-5 { 2f64.powi(-24) } else { back * 2f64.powi(-10) };
            assert!((back - x as f64).abs() <= 0.5 * ulp + 1e-30, "{x}: {back}");
        }
        assert_eq!(half_bits(1.0), 0x3c00);
        assert_eq!(half_bits(0.5), 0x3800);
    }

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
