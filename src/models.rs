//! The BSSRDF models, each registered once: its name (flags, scripts, the panel), its GPU code (the
//! shade pipeline's specialisation constant and `bssrdf --gpu`'s push constant) and where its
//! physics is. Adding a model is its physics module (src/physics/), its GLSL include
//! (shaders/include/) or a tabulated profile (`gpu::SdTable`, as photon beam diffusion), a `Model`
//! variant and one entry in [`MODELS`].

use crate::gpu::{MODEL_DIPOLE, MODEL_DIRECTIONAL, MODEL_MC, MODEL_PBD};
use crate::physics::Model;

/// One model's registration.
#[derive(Debug)]
pub struct ModelEntry {
    pub model: Model,
    /// The name flags and scripts take (`--model NAME`, `set model NAME`).
    pub name: &'static str,
    /// Other names scripts take.
    pub aliases: &'static [&'static str],
    /// What the panel calls it.
    pub label: &'static str,
    /// How the GPU code names it (`gpu_constants.glsl`).
    pub gpu_code: u32,
    /// Whose model it is, for `--help`.
    pub about: &'static str,
}

/// Every model, in the order the panel and `--help` list them; the first is the default.
pub const MODELS: &[ModelEntry] = &[
    ModelEntry {
        model: Model::Directional,
        name: "directional",
        aliases: &[],
        label: "directional",
        gpu_code: MODEL_DIRECTIONAL,
        about: "the directional dipole (Frisvad, Hachisuka, Kjeldsen 2014)",
    },
    ModelEntry {
        model: Model::Dipole,
        name: "dipole",
        aliases: &["classical"],
        label: "classical",
        gpu_code: MODEL_DIPOLE,
        about: "the classical dipole (Jensen, Marschner, Levoy, Hanrahan 2001)",
    },
    ModelEntry {
        model: Model::Pbd,
        name: "pbd",
        aliases: &["beam-diffusion"],
        label: "beam diffusion",
        gpu_code: MODEL_PBD,
        about: "photon beam diffusion, multiple and single scattering (Habel, Christensen, Jarosz 2013)",
    },
    ModelEntry {
        model: Model::Mc,
        name: "mc",
        aliases: &["monte-carlo"],
        label: "Monte Carlo table",
        gpu_code: MODEL_MC,
        about: "the flat half-space's exact transport, tabulated by Monte Carlo (radial profile, incidence and exit factors), and a flat slab's for light across the object",
    },
];

impl Model {
    /// This model's registration.
    pub fn entry(self) -> &'static ModelEntry {
        MODELS.iter().find(|e| e.model == self).unwrap_or(&MODELS[0])
    }

    pub fn name(self) -> &'static str {
        self.entry().name
    }

    /// How the GPU names the model.
    pub fn gpu_code(self) -> u32 {
        self.entry().gpu_code
    }

    /// The model of a name or alias.
    pub fn from_name(name: &str) -> Option<Model> {
        MODELS.iter().find(|e| e.name == name || e.aliases.contains(&name)).map(|e| e.model)
    }

    /// The next model in [`MODELS`], round: what the viewer's `d` key switches to.
    pub fn next(self) -> Model {
        let i = MODELS.iter().position(|e| e.model == self).unwrap_or(0);
        MODELS[(i + 1) % MODELS.len()].model
    }

    /// Every model's name, for messages: `directional or dipole`.
    pub fn names() -> String {
        let names: Vec<&str> = MODELS.iter().map(|e| e.name).collect();
        match names.split_last() {
            Some((last, [])) => last.to_string(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
            None => String::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names and GPU codes are unique, and each registered model finds itself by name.
    #[test]
    fn every_model_is_registered_once() {
        for (i, e) in MODELS.iter().enumerate() {
            assert_eq!(Model::from_name(e.name), Some(e.model));
            assert_eq!(e.model.entry().name, e.name);
            for other in &MODELS[i + 1..] {
                assert_ne!(e.name, other.name);
                assert_ne!(e.gpu_code, other.gpu_code);
                assert_ne!(e.model, other.model);
            }
        }
        assert_eq!(Model::from_name("classical"), Some(Model::Dipole));
        assert_eq!(Model::from_name("beam-diffusion"), Some(Model::Pbd));
        assert_eq!(Model::Directional.next(), Model::Dipole);
        assert_eq!(Model::Dipole.next(), Model::Pbd);
        assert_eq!(Model::Pbd.next(), Model::Mc);
        assert_eq!(Model::Mc.next(), Model::Directional);
        assert_eq!(Model::from_name("monte-carlo"), Some(Model::Mc));
        assert_eq!(Model::names(), "directional, dipole, pbd or mc");
    }
}
