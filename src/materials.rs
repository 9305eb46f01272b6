//! Measured scattering parameters (per mm) and user-defined materials.
//!
//! Table A: Jensen et al. 2001 (reduced scattering only: g = 0, σs = σ's; η = 1.3, marble 1.5).
//! Table B: Narasimhan et al. 2006, diluted media with a Henyey–Greenstein g per channel; the paper
//! gives no index of refraction, so η = 1.3 (water-based liquids are close to 1.33).

use crate::bad_input;
use crate::error::Result;
use crate::physics::beam_diffusion::{self, BeamMedium};
use crate::physics::{dipole, dirpole, Diffusion, Medium, Model};

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub sigma_a: [f64; 3],
    pub sigma_s: [f64; 3],
    pub g: [f64; 3],
    pub eta: f64,
}

type Row = (&'static str, [f64; 3], [f64; 3]);
/// name, σs, σa, g.
type RowWithG = (&'static str, [f64; 3], [f64; 3], [f64; 3]);

/// Jensen et al. 2001: name, σ's, σa.
const JENSEN: [Row; 12] = [
    ("Apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    ("Chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    ("Chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    ("Cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    ("Ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    ("Marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    ("Potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    ("Skimmilk", [0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    ("Skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    ("Skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    ("Spectralon", [11.6, 20.4, 14.9], [0.00, 0.00, 0.00]),
    ("Wholemilk", [2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
];

/// Narasimhan et al. 2006: name, σs, σa, g.
const NARASIMHAN: [RowWithG; 35] = [
    ("Lowfat Milk", [0.9124, 1.0744, 1.2492], [0.0002, 0.0004, 0.0008], [0.932, 0.902, 0.859]),
    ("Reduced Milk", [1.0748, 1.2209, 1.3931], [0.0002, 0.0004, 0.0010], [0.819, 0.797, 0.746]),
    ("Regular Milk", [1.1873, 1.3293, 1.4589], [0.0001, 0.0003, 0.0013], [0.750, 0.714, 0.681]),
    ("Espresso", [0.2707, 0.2828, 0.2970], [0.1669, 0.2287, 0.3078], [0.907, 0.896, 0.880]),
    ("Mint Mocha Coffee", [0.0916, 0.1081, 0.1460], [0.0984, 0.1519, 0.2040], [0.910, 0.907, 0.914]),
    ("Lowfat Soy Milk", [0.1418, 0.1620, 0.2715], [0.0001, 0.0005, 0.0025], [0.850, 0.853, 0.842]),
    ("Regular Soy Milk", [0.2433, 0.2714, 0.4563], [0.0001, 0.0005, 0.0034], [0.873, 0.858, 0.832]),
    ("Lowfat Chocolate Milk", [0.4277, 0.4998, 0.5723], [0.0005, 0.0016, 0.0068], [0.934, 0.927, 0.916]),
    ("Regular Chocolate Milk", [0.7352, 0.9142, 1.0588], [0.0007, 0.0030, 0.0100], [0.862, 0.838, 0.806]),
    ("Coke", [0.0177, 0.0208, 0.0000], [0.6966, 1.1480, 1.7169], [0.965, 0.972, 0.000]),
    ("Pepsi", [0.0058, 0.0141, 0.0000], [0.6375, 0.9849, 1.4420], [0.926, 0.979, 0.000]),
    ("Sprite", [0.0069, 0.0089, 0.0089], [0.1230, 0.1194, 0.1306], [0.943, 0.953, 0.952]),
    ("Gatorade", [0.2392, 0.2927, 0.3745], [0.1617, 0.1258, 0.0579], [0.933, 0.933, 0.935]),
    ("Chardonnay", [0.0030, 0.0047, 0.0069], [0.1547, 0.1701, 0.3443], [0.914, 0.958, 0.975]),
    ("White Zinfandel", [0.0031, 0.0048, 0.0066], [0.1732, 0.2322, 0.2847], [0.919, 0.943, 0.972]),
    ("Merlot", [0.0053, 0.0000, 0.0000], [0.7586, 1.6429, 1.9196], [0.974, 0.000, 0.000]),
    ("Budweiser Beer", [0.0037, 0.0069, 0.0074], [0.1449, 0.3141, 0.7286], [0.917, 0.956, 0.982]),
    ("Coors Light Beer", [0.0027, 0.0055, 0.0000], [0.0268, 0.0608, 0.1521], [0.918, 0.966, 0.000]),
    ("Clorox", [0.1425, 0.1723, 0.1928], [0.0175, 0.0777, 0.1372], [0.912, 0.905, 0.892]),
    ("Apple Juice", [0.0201, 0.0243, 0.0323], [0.1014, 0.1858, 0.4084], [0.947, 0.949, 0.945]),
    ("Cranberry Juice", [0.0128, 0.0155, 0.0196], [0.2572, 0.6145, 0.8104], [0.947, 0.951, 0.974]),
    ("Grape Juice", [0.0072, 0.0000, 0.0000], [0.5428, 1.2500, 1.5300], [0.961, 0.000, 0.000]),
    ("Ruby Grapefruit Juice", [0.1617, 0.1606, 0.1669], [0.0896, 0.1911, 0.2636], [0.929, 0.929, 0.931]),
    ("White Grapefruit Juice", [0.3513, 0.3669, 0.5237], [0.0096, 0.0131, 0.0395], [0.548, 0.545, 0.565]),
    ("Shampoo", [0.0104, 0.0114, 0.0147], [0.0184, 0.0596, 0.0805], [0.910, 0.905, 0.920]),
    ("Strawberry Shampoo", [0.0028, 0.0032, 0.0033], [0.0189, 0.0756, 0.0989], [0.927, 0.935, 0.994]),
    ("Head & Shoulders Shampoo", [0.2791, 0.2890, 0.3086], [0.0883, 0.1637, 0.2125], [0.911, 0.896, 0.884]),
    ("Lemon Tea", [0.0798, 0.0898, 0.1073], [0.2602, 0.4902, 0.7727], [0.946, 0.946, 0.949]),
    ("Orange Juice Powder", [0.1928, 0.2132, 0.2259], [0.1449, 0.3441, 0.7863], [0.919, 0.918, 0.922]),
    ("Pink Lemonade", [0.1235, 0.1334, 0.1305], [0.1165, 0.2366, 0.3195], [0.902, 0.902, 0.904]),
    ("Cappuccino Powder", [0.0654, 0.0882, 0.1568], [0.1920, 0.2654, 0.3272], [0.849, 0.843, 0.926]),
    ("Salt Powder", [0.2485, 0.2822, 0.3216], [0.5115, 0.5863, 0.6147], [0.802, 0.793, 0.821]),
    ("Sugar Powder", [0.0145, 0.0162, 0.0202], [0.0650, 0.1597, 0.2578], [0.921, 0.919, 0.931]),
    ("Suisse Mocha", [0.3223, 0.3583, 0.4148], [0.1875, 0.2893, 0.3796], [0.907, 0.894, 0.888]),
    ("Pacific Ocean Surface Water", [0.1800, 0.1834, 0.2281], [3.1845, 3.1324, 3.0147], [0.902, 0.825, 0.914]),
];

/// Lower case with spaces, underscores, hyphens and '&' removed: "Regular Milk" = "regular-milk".
fn key(name: &str) -> String {
    name.chars().filter(|c| c.is_alphanumeric()).flat_map(char::to_lowercase).collect()
}

/// The relative indices of refraction accepted: beyond these the Fresnel and diffusion terms
/// lose their meaning (and, at 1e-100, their finiteness).
/// The largest σa or σs accepted (1/mm): far past any measured material (those are below 1e4),
/// and where σt² stays finite in f64.
pub const MAX_SIGMA: f64 = 1e100;
/// The smallest non-zero σa or σs accepted (1/mm): below it the diffusion lengths' squares
/// overflow f64 (σ = 1e-154 gave NaN).
pub const MIN_SIGMA: f64 = 1e-100;

pub const ETA_RANGE: (f64, f64) = (0.1, 10.0);

impl Material {
    pub fn presets() -> Vec<Material> {
        let jensen = JENSEN.iter().map(|(name, s_reduced, a)| Material {
            name: name.to_string(),
            sigma_a: *a,
            sigma_s: *s_reduced,
            g: [0.0; 3],
            eta: if *name == "Marble" { 1.5 } else { 1.3 },
        });
        let narasimhan = NARASIMHAN.iter().map(|(name, s, a, g)| Material {
            name: name.to_string(),
            sigma_a: *a,
            sigma_s: *s,
            g: *g,
            eta: 1.3,
        });
        jensen.chain(narasimhan).collect()
    }

    /// A preset by name, ignoring case, spaces, underscores and hyphens.
    pub fn find(name: &str) -> Result<Material> {
        let k = key(name);
        Material::presets()
            .into_iter()
            .find(|m| key(&m.name) == k)
            .ok_or_else(|| bad_input!("--material {name}: unknown material; `translucent materials` lists the presets"))
    }

    /// A material from user coefficients (per mm), validated.
    pub fn custom(sigma_a: [f64; 3], sigma_s: [f64; 3], g: [f64; 3], eta: f64) -> Result<Material> {
        let m = Material { name: "custom".into(), sigma_a, sigma_s, g, eta };
        m.validate()?;
        Ok(m)
    }

    /// Rejects values the models cannot take, naming the offending one.
    pub fn validate(&self) -> Result<()> {
        // Each message names the value and the flag that sets it.
        for (what, flag, values) in [("sigma_a", "--sigma-a", self.sigma_a), ("sigma_s", "--sigma-s", self.sigma_s)] {
            for (ch, v) in values.iter().enumerate() {
                if !v.is_finite() || *v < 0.0 {
                    return Err(bad_input!(
                        "{}: {what} = {v} in channel {ch} must be finite and ≥ 0 ({flag})",
                        self.name
                    ));
                }
                if *v > MAX_SIGMA || (*v > 0.0 && *v < MIN_SIGMA) {
                    return Err(bad_input!(
                        "{}: {what} = {v:e} in channel {ch} must be 0 or within [{MIN_SIGMA:e}, {MAX_SIGMA:e}] /mm ({flag})",
                        self.name
                    ));
                }
            }
        }
        for (ch, g) in self.g.iter().enumerate() {
            if !g.is_finite() || g.abs() >= 1.0 {
                return Err(bad_input!("{}: g = {g} in channel {ch} must lie in (−1, 1) (--g)", self.name));
            }
        }
        if !(ETA_RANGE.0..=ETA_RANGE.1).contains(&self.eta) {
            return Err(bad_input!(
                "{}: eta = {} must be finite and within [{}, {}] (--eta)",
                self.name,
                self.eta,
                ETA_RANGE.0,
                ETA_RANGE.1
            ));
        }
        Ok(())
    }

    /// Per channel, the total diffuse reflectance Rd(α') of the classical dipole at the
    /// channel's reduced albedo (Jensen et al. 2001, eq. 5 integrated): what pbrt-v4's
    /// `subsurface "reflectance"` states and [`crate::pbrt::from_reflectance`] inverts.
    pub fn reflectance(&self) -> [f64; 3] {
        [0, 1, 2].map(|ch| {
            let c = self.channel(ch).constants(Diffusion::Classical);
            if c.transports {
                dipole::total_rd(c.alpha_reduced, c.a_dipole)
            } else {
                0.0
            }
        })
    }

    /// This material with the total diffuse reflectance `rho` per channel (each below the
    /// classical dipole's Rd at albedo 1, else held just under it) and the same mean free path,
    /// g and η: the inversion of [`crate::pbrt::from_reflectance`], per channel.
    pub fn with_reflectance(&self, rho: [f64; 3]) -> Result<Material> {
        let top = crate::pbrt::max_reflectance(self.eta) * 0.999;
        let mut m = self.clone();
        for ch in 0..3 {
            let c = self.channel(ch).constants(Diffusion::Classical);
            let mfp = [1.0 / c.sigma_t_reduced.max(MIN_SIGMA); 3];
            let (a, s) = crate::pbrt::from_reflectance([rho[ch].clamp(0.0, top); 3], mfp, self.g[ch], self.eta)
                .map_err(|why| bad_input!("{}: {why}", self.name))?;
            (m.sigma_a[ch], m.sigma_s[ch]) = (a[ch], s[ch]);
        }
        m.validate()?;
        Ok(m)
    }

    pub fn channel(&self, ch: usize) -> Medium {
        Medium { sigma_a: self.sigma_a[ch], sigma_s: self.sigma_s[ch], g: self.g[ch], eta: self.eta }
    }

    /// Coefficients per scene unit, for a scene of `mm_per_unit` millimetres per unit.
    pub fn per_scene_unit(&self, mm_per_unit: f64) -> Material {
        Material {
            sigma_a: self.sigma_a.map(|v| v * mm_per_unit),
            sigma_s: self.sigma_s.map(|v| v * mm_per_unit),
            ..self.clone()
        }
    }

    /// Channels where σ's = 0: diffusion does not apply and they get no subsurface light.
    pub fn pure_absorber_channels(&self) -> Vec<usize> {
        (0..3).filter(|&ch| !self.channel(ch).constants(Diffusion::Classical).transports).collect()
    }

    /// A warning for pure-absorber channels, if any.
    pub fn warning(&self) -> Option<String> {
        let channels = self.pure_absorber_channels();
        (!channels.is_empty()).then(|| {
            let names: Vec<&str> = channels.iter().map(|&c| ["red", "green", "blue"][c]).collect();
            format!(
                "{}: no scattering in the {} channel(s) (σs = 0): no subsurface transport there",
                self.name,
                names.join(", ")
            )
        })
    }
}

/// The `translucent materials` table: per channel σ's, σa, α', mean free path, 1/σtr and Rd.
pub fn materials_table() -> String {
    let mut out = format!(
        "{:<28} {:>4}  {:>24}  {:>24}  {:>20}  {:>24}  {:>24}  {:>20}\n",
        "material",
        "eta",
        "sigma_s' [1/mm] R G B",
        "sigma_a [1/mm] R G B",
        "alpha' R G B",
        "mfp [mm] R G B",
        "1/sigma_tr [mm] R G B",
        "Rd R G B"
    );
    let fmt3 = |v: [f64; 3], prec: usize| v.map(|x| format!("{x:.prec$}")).join(" ");
    for m in Material::presets() {
        let c: Vec<_> = (0..3).map(|ch| m.channel(ch).constants(Diffusion::Classical)).collect();
        let pick = |f: &dyn Fn(&crate::physics::ChannelConstants) -> f64| [f(&c[0]), f(&c[1]), f(&c[2])];
        let inv = |v: f64| if v > 0.0 { 1.0 / v } else { f64::INFINITY };
        out += &format!(
            "{:<28} {:>4.2}  {:>24}  {:>24}  {:>20}  {:>24}  {:>24}  {:>20}\n",
            m.name,
            m.eta,
            fmt3(pick(&|c| c.sigma_s_reduced), 4),
            fmt3(pick(&|c| c.sigma_a), 4),
            fmt3(pick(&|c| c.alpha_reduced), 3),
            fmt3(pick(&|c| inv(c.sigma_t_reduced)), 3),
            fmt3(pick(&|c| inv(c.dipole_sigma_tr)), 2),
            fmt3(pick(&|c| if c.transports { dipole::total_rd(c.alpha_reduced, c.a_dipole) } else { 0.0 }), 3),
        );
    }
    out
}

/// How a texture's reflectance weighs a translucent material under one model.
///
/// A textured translucent object keeps its material's coefficients and weighs each source
/// point's irradiance and each pixel's sum by the scatter weight of the texture there,
/// √(T(α'(ρ)) / T(α')) per channel: α'(ρ) the reduced albedo whose classical-dipole Rd is the
/// texture's reflectance ρ (what pbrt-v4's `reflectance` states, inverted as
/// [`crate::pbrt::from_reflectance`] does, with the material's mean free path), T the model's own
/// total diffuse reflectance at normal incidence, α' the material's. A pair (xi, xo) is so weighed
/// by √(w(xi) w(xo)): the geometric mean of the entry's and the exit's ratio, symmetric as the
/// BSSRDF is. Where the texture is uniform the object reflects in total what a material of that
/// colour reflects, and across a change of colour the weight blends over the profile's width.
/// What it leaves out: the profile's width stays the material's (a darker colour would also
/// shorten the diffusion length); tests/texture.rs measures both.
///
/// T is the classical dipole's Rd (closed form) for `dipole`, the directional dipole's plane
/// integral for `directional`, photon beam diffusion's for `pbd` and, standing in for the Monte
/// Carlo table's (measured per material, a second or two each), for `mc` too: tabulated over α'
/// here (their error is measured in tests/texture.rs).
pub struct ScatterWeight {
    /// Per channel, (Rd(α'_k), T(α'_k)) at nodes ascending in α'; empty where the material does
    /// not scatter.
    curves: [Vec<(f64, f64)>; 3],
    /// T at the material's own reflectance, through the same curve (so its own colour weighs 1).
    own: [f64; 3],
}

/// α' nodes of the directional dipole's curve: denser toward 1, where Rd climbs steeply.
const WEIGHT_NODES: usize = 48;

impl ScatterWeight {
    pub fn new(material: &Material, model: Model, diffusion: Diffusion) -> ScatterWeight {
        let rd = material.reflectance();
        // Beam diffusion's plane integral costs milliseconds a node: half the nodes (the
        // two-colour slab's halves in tests/texture.rs moved by at most 0.07%; a textured pbd
        // bunny's whole process 1.83x -> 1.31x an untextured one's, with the channels in threads).
        let nodes = match model {
            Model::Pbd | Model::Mc => WEIGHT_NODES / 2,
            Model::Directional | Model::Dipole => WEIGHT_NODES,
        };
        let curve = |ch: usize| -> Vec<(f64, f64)> {
            let m = material.channel(ch);
            let c = m.constants(Diffusion::Classical);
            if !c.transports {
                return Vec::new();
            }
            let at = |alpha: f64| Medium {
                sigma_a: (1.0 - alpha) * c.sigma_t_reduced,
                sigma_s: alpha * c.sigma_t_reduced / (1.0 - m.g),
                g: m.g,
                eta: m.eta,
            };
            (0..=nodes)
                .map(|k| {
                    let x = k as f64 / nodes as f64;
                    // From 1e-3 to 0.9995: at α' = 1 nothing is absorbed and σtr is 0.
                    let alpha = 1e-3 + (0.9995 - 1e-3) * (1.0 - (1.0 - x) * (1.0 - x));
                    let medium = at(alpha);
                    let classical = dipole::total_rd(alpha, c.a_dipole);
                    let total = match model {
                        Model::Directional => directional_total(&medium.constants(diffusion)),
                        Model::Dipole => classical,
                        // The Monte Carlo table's exact transport is measured per material (a
                        // second or two): beam diffusion, its closest closed form, stands in.
                        Model::Pbd | Model::Mc => {
                            let b = BeamMedium::new(&medium);
                            if b.transports() {
                                beam_diffusion::disc_integral(&b, 40.0 / b.sigma_tr.max(1e-9 * c.sigma_t_reduced))
                            } else {
                                0.0
                            }
                        }
                    };
                    (classical, total)
                })
                .collect()
        };
        // The channels side by side (each a few hundred plane integrals).
        let curves = std::thread::scope(|s| {
            let handles = [0, 1, 2].map(|ch| s.spawn(move || curve(ch)));
            handles.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
        });
        let own = [0, 1, 2].map(|ch| total_at(&curves[ch], rd[ch]));
        ScatterWeight { curves, own }
    }

    /// The scatter weight of reflectance `rho` (per channel; 0 where the material or the
    /// colour reflects nothing).
    pub fn of(&self, rho: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|ch| {
            if self.own[ch] > 0.0 {
                (total_at(&self.curves[ch], rho[ch]) / self.own[ch]).sqrt()
            } else {
                0.0
            }
        })
    }
}

/// T at classical reflectance `rho` on a curve of (Rd, T) nodes ascending: linear between nodes,
/// through 0 below the first, held above the last.
fn total_at(curve: &[(f64, f64)], rho: f64) -> f64 {
    let Some(&(first_rd, first_t)) = curve.first() else { return 0.0 };
    let rho = rho.max(0.0);
    if rho <= first_rd {
        return if first_rd > 0.0 { first_t * rho / first_rd } else { 0.0 };
    }
    // The first node at or above ρ (a binary search: a 4096² texture asks 50M times).
    let k = curve.partition_point(|&(rd, _)| rd < rho);
    match curve.get(k) {
        Some(&(r1, t1)) => {
            let (r0, t0) = curve[k - 1];
            t0 + (t1 - t0) * (rho - r0) / (r1 - r0).max(f64::MIN_POSITIVE)
        }
        None => curve.last().map_or(0.0, |&(_, t)| t),
    }
}

/// The directional dipole's total diffuse reflectance at normal incidence, 2π∫Sd(r) r dr over
/// the plane (it is radially symmetric there), on log-spaced radii from 1e-6 to 40 diffusion
/// lengths (midpoint rule in ln r; 400 nodes hold it to 1e-4).
fn directional_total(c: &crate::physics::ChannelConstants) -> f64 {
    use glam::DVec3;
    if !c.transports || c.sigma_tr.is_nan() || c.sigma_tr <= 0.0 {
        return 0.0;
    }
    let (lo, hi) = (1e-6f64.ln(), (40.0 / c.sigma_tr).ln());
    let nodes = 400;
    let h = (hi - lo) / nodes as f64;
    let n = DVec3::Y;
    (0..nodes)
        .map(|i| {
            let r = (lo + (i as f64 + 0.5) * h).exp();
            dirpole::sd(c, DVec3::new(r, 0.0, 0.0), n, n, DVec3::ZERO, n) * std::f64::consts::TAU * r * r * h
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weight of the material's own colour is 1 in every model; it rises with the colour;
    /// for the classical dipole it is √(ρ/Rd) (the curve's interpolation within 1e-3); and the
    /// material made of a colour (`with_reflectance`) reflects that colour.
    #[test]
    fn scatter_weights_are_the_models_reflectance_ratios() {
        let skin = Material::find("skin1").unwrap();
        let own = skin.reflectance();
        for model in [Model::Directional, Model::Dipole, Model::Pbd, Model::Mc] {
            let w = ScatterWeight::new(&skin, model, Diffusion::Classical);
            assert_eq!(w.of(own), [1.0; 3], "{model:?}");
            let steps: Vec<[f64; 3]> = (0..=20).map(|k| w.of([k as f64 * 0.04; 3])).collect();
            for pair in steps.windows(2) {
                assert!((0..3).all(|c| pair[1][c] > pair[0][c]), "{model:?}: {steps:?}");
            }
            assert_eq!(w.of([0.0; 3]), [0.0; 3]);
        }
        let dipole = ScatterWeight::new(&skin, Model::Dipole, Diffusion::Classical);
        for rho in [0.05, 0.2, 0.5, 0.8] {
            let w = dipole.of([rho; 3]);
            for c in 0..3 {
                let exact = (rho / own[c]).sqrt();
                assert!((w[c] / exact - 1.0).abs() < 1e-3, "ρ {rho} channel {c}: {} against {exact}", w[c]);
            }
        }
        let coloured = skin.with_reflectance([0.6, 0.3, 0.1]).unwrap();
        for (c, rho) in coloured.reflectance().iter().enumerate() {
            assert!((rho - [0.6, 0.3, 0.1][c]).abs() < 1e-9, "channel {c}: {rho}");
        }
    }
}
