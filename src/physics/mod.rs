//! The BSSRDF physics in f64, the reference for tests and tools. `shaders/include/bssrdf.glsl`
//! mirrors it in f32 for the GPU, and `crate::gpu` carries the constants computed here to it; this
//! module imports nothing of the GPU (src/models.rs registers each model's GPU code).
//!
//! Conventions (see `shared/reference/bssrdf.md`): per colour channel, coefficients in mm⁻¹,
//! lengths in mm, normals outward, ωi from the surface toward the light, η = n_inside/n_outside.

pub mod beam_diffusion;
pub mod curvature_profile;
pub mod dipole;
pub mod dirpole;
pub mod fresnel;
pub mod halfspace;
pub mod mc_profile;
pub mod microfacet;
pub mod slab_profile;
pub mod sphere;
pub mod table_cache;

/// Which diffusion coefficient the directional dipole uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Diffusion {
    /// D = 1/(3σ't), as in the authors' program.
    #[default]
    Classical,
    /// D = (2σa + σ's)/(3σ't²).
    Alternative,
}

/// Which BSSRDF (each registered in src/models.rs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Model {
    /// Frisvad, Hachisuka, Kjeldsen 2014.
    #[default]
    Directional,
    /// Jensen, Marschner, Levoy, Hanrahan 2001.
    Dipole,
    /// Photon beam diffusion, multiple and single scattering: Habel, Christensen, Jarosz 2013.
    Pbd,
    /// The half-space's exact transport, tabulated by Monte Carlo (src/physics/mc_profile.rs).
    Mc,
}

/// One colour channel of a medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub sigma_a: f64,
    pub sigma_s: f64,
    pub g: f64,
    pub eta: f64,
}

/// Everything both models need about one channel, computed once in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelConstants {
    pub eta: f64,
    pub sigma_a: f64,
    /// Unreduced extinction σt = σa + σs (back-lit real-source distance).
    pub sigma_t: f64,
    /// σ's = σs(1 − g).
    pub sigma_s_reduced: f64,
    /// σ't = σa + σ's.
    pub sigma_t_reduced: f64,
    /// α' = σ's/σ't.
    pub alpha_reduced: f64,
    /// Diffusion coefficient of the directional dipole.
    pub d: f64,
    /// σtr = √(σa/D) for the directional dipole.
    pub sigma_tr: f64,
    /// Extrapolation distance de = 2.131 D/√α'.
    pub de: f64,
    /// Directional dipole boundary constant A = (1 − CE(η))/(2Cφ(η)).
    pub a_dirpole: f64,
    pub c_phi: f64,
    pub c_e: f64,
    /// Normalisation N = 1/(4Cφ(1/η)).
    pub n_norm: f64,
    /// Classical dipole: σtr = √(3σaσ't), zr = 1/σ't, zv = zr(1 + 4A/3), A = (1+Fdr)/(1−Fdr).
    pub dipole_sigma_tr: f64,
    pub zr: f64,
    pub zv: f64,
    pub a_dipole: f64,
    /// False for a pure absorber (σ's = 0): diffusion does not apply, Sd = 0 in this channel.
    pub transports: bool,
}

impl Medium {
    pub fn constants(&self, diffusion: Diffusion) -> ChannelConstants {
        let sigma_s_reduced = self.sigma_s * (1.0 - self.g);
        let sigma_t_reduced = self.sigma_a + sigma_s_reduced;
        let transports = sigma_s_reduced > 0.0 && sigma_t_reduced > 0.0;
        // A pure absorber keeps finite placeholders; `transports` makes every Sd zero.
        let safe_t = if transports { sigma_t_reduced } else { 1.0 };
        let alpha_reduced = if transports { sigma_s_reduced / sigma_t_reduced } else { 0.0 };
        let d = match diffusion {
            Diffusion::Classical => 1.0 / (3.0 * safe_t),
            Diffusion::Alternative => (2.0 * self.sigma_a + sigma_s_reduced) / (3.0 * safe_t * safe_t),
        };
        let d = if transports { d } else { 1.0 / 3.0 };
        let c_phi = fresnel::c_phi(self.eta);
        let c_e = fresnel::c_e(self.eta);
        let a_dipole = fresnel::dipole_a(self.eta);
        let zr = 1.0 / safe_t;
        ChannelConstants {
            eta: self.eta,
            sigma_a: self.sigma_a,
            sigma_t: self.sigma_a + self.sigma_s,
            sigma_s_reduced,
            sigma_t_reduced,
            alpha_reduced,
            d,
            sigma_tr: (self.sigma_a / d).sqrt(),
            de: if transports { 2.131 * d / alpha_reduced.sqrt() } else { 1.0 },
            a_dirpole: (1.0 - c_e) / (2.0 * c_phi),
            c_phi,
            c_e,
            n_norm: 1.0 / (4.0 * fresnel::c_phi(1.0 / self.eta)),
            dipole_sigma_tr: (3.0 * self.sigma_a * safe_t).sqrt(),
            zr,
            zv: zr * (1.0 + 4.0 * a_dipole / 3.0),
            a_dipole,
            transports,
        }
    }
}

/// One BSSRDF evaluation: a channel of a medium and the geometry (mm, unit vectors).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Query {
    pub medium: Medium,
    pub xi: glam::DVec3,
    pub ni: glam::DVec3,
    pub wi: glam::DVec3,
    pub xo: glam::DVec3,
    pub no: glam::DVec3,
}

impl Query {
    pub fn sd(&self, model: Model, diffusion: Diffusion) -> f64 {
        let c = self.medium.constants(diffusion);
        match model {
            Model::Directional => dirpole::sd(&c, self.xi, self.ni, self.wi, self.xo, self.no),
            Model::Dipole => dipole::sd(&c, (self.xo - self.xi).length()),
            Model::Pbd => {
                beam_diffusion::sd(&beam_diffusion::BeamMedium::new(&self.medium), (self.xo - self.xi).length())
            }
            // The radial part alone; its incidence and exit factors are the profile's.
            Model::Mc => mc_profile::McProfile::of(&self.medium).sd((self.xo - self.xi).length()),
        }
    }
}
