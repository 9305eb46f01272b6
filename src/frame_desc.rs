//! What one frame draws of the world: the camera, the lights, the image, how the subsurface term
//! is integrated and what is shown. A plain value with its defaults and one [`FrameDesc::validate`]
//! (every range check of these settings lives there). [`crate::frame::Renderer::begin_frame`]
//! copies it: a frame in flight never sees a later edit.

use glam::Vec3;

use crate::bad_input;
use crate::error::Result;
use crate::output::Exposure;
use crate::physics::{Diffusion, Model};
use crate::scene::{Camera, Light};

/// A node is used whole when its area / squared distance is below this (`--epsilon`): with its two
/// sigma points per light, 0.2 gives 0.95% relative RMSE against brute force on the back-lit bunny
/// and 0.2–0.4% front-lit, unbiased, at about the cost 0.1 had with one source per node (0.65%,
/// biased low by 0.6–1.6%). See the sweep in BENCHMARKS.md.
pub const DEFAULT_EPSILON: f32 = 0.2;

/// The default roughness of the microfacet reflection (`--roughness`).
pub const DEFAULT_ROUGHNESS: f32 = 0.35;

/// The default shadow-map resolution per light (per cube face for point lights).
pub const DEFAULT_SHADOW_RESOLUTION: u32 = 1024;

/// The shadow-map resolutions accepted (`--shadow-resolution`).
pub const SHADOW_RESOLUTION_RANGE: (u32, u32) = (16, 8192);

/// The largest coordinate accepted for --eye, --target and point lights: squared distances must
/// stay finite in f32.
pub const MAX_COORDINATE: f32 = 1e15;

/// What to draw: the shaded mesh, or a debug view instead of it (the subsurface pass is skipped).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Show {
    Shading,
    /// The sample points coloured by irradiance.
    Samples,
    /// The boxes of the tree nodes this many levels below the root.
    Tree(u32),
}

/// How the subsurface term is integrated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Integration {
    pub model: Model,
    pub diffusion: Diffusion,
    /// A node is used whole when its area / squared distance is below this.
    pub epsilon: f32,
    /// Sum over every point instead of walking the tree (the reference).
    pub brute_force: bool,
    /// Whether each pixel's sum is split into the near field (the pixel's own irradiance times a
    /// fixed quadrature of Sd) and the far (the sources, weighted down near the pixel).
    pub near_field: NearField,
    /// Whether the sources far from an 8x8 list tile are summed at nine of its pixels and
    /// interpolated (shaders/far_field.comp) instead of at every pixel. Where it applies: with the
    /// tree, not the Monte Carlo table (whose light across an object is not smooth across a
    /// tile), in tiles that qualify (tile_cut.comp).
    pub far_field: bool,
    /// Whether light that leaves the object and enters it again is drawn (passes::reentry: the
    /// Monte Carlo table on a closed mesh, with the tree). Off by default: it lights the shadowed
    /// side that the tree's cut skipped, about 2x the shade pass on the default back-lit bunny.
    pub reentry: bool,
}

/// The Monte Carlo table's terms a frame draws: the shade pass's single scattering (light
/// scattered once, along the refracted view ray) and its multiple scattering (the table's
/// profile over the sources), or one of them alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Scattering {
    #[default]
    All,
    Single,
    Multiple,
}

impl Scattering {
    /// The name `--scattering` takes.
    pub fn name(self) -> &'static str {
        match self {
            Scattering::All => "all",
            Scattering::Single => "single",
            Scattering::Multiple => "multiple",
        }
    }

    /// Its value in the shade pass's FrameParams.scattering.
    pub fn code(self) -> u32 {
        match self {
            Scattering::All => 0,
            Scattering::Single => 1,
            Scattering::Multiple => 2,
        }
    }
}

/// When the near-field split applies (see [`Integration::near_field`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NearField {
    /// With the tree, not with brute force (which stays the exact point sum: the reference).
    #[default]
    Auto,
    On,
    Off,
}

impl Integration {
    /// Whether this frame sums far sources per tile (see [`Integration::far_field`]).
    pub fn uses_far_field(&self) -> bool {
        self.far_field && !self.brute_force && self.model != Model::Mc
    }

    /// Whether this frame splits off the near field.
    pub fn splits_near_field(&self) -> bool {
        match self.near_field {
            NearField::Auto => !self.brute_force,
            NearField::On => true,
            NearField::Off => false,
        }
    }
}

impl Default for Integration {
    fn default() -> Self {
        Integration {
            model: Model::Directional,
            diffusion: Diffusion::Classical,
            epsilon: DEFAULT_EPSILON,
            brute_force: false,
            near_field: NearField::Auto,
            far_field: true,
            reentry: false,
        }
    }
}

/// One frame's description (see the module's documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameDesc {
    pub camera: Camera,
    /// At least 1; as many as the device's shadow-map layers allow (checked with the frame's
    /// other sizes in [`crate::budget::check_frame`]).
    pub lights: Vec<Light>,
    /// The environment shown behind the objects (its samples are among `lights`).
    pub environment: Option<std::sync::Arc<crate::environment::Environment>>,
    pub width: u32,
    pub height: u32,
    pub integration: Integration,
    /// Add the surface's microfacet reflection (`--no-specular` turns it off).
    pub specular: bool,
    /// The Monte Carlo table's terms drawn (`--scattering`).
    pub scattering: Scattering,
    /// Roughness of the microfacet lobe (α = roughness²), in (0, 1].
    pub roughness: f32,
    pub show: Show,
    /// Of the tone-mapped 8-bit image (PNG); the HDR image is untouched.
    pub exposure: Exposure,
    /// Count nodes visited and points evaluated per pixel on the GPU (costs atomics).
    pub count_work: bool,
    /// Shadow-map resolution per light (per cube face for point lights).
    pub shadow_resolution: u32,
}

impl FrameDesc {
    /// `camera` and `lights` with the command line's defaults for everything else: 512×512, the
    /// directional dipole with classical diffusion at the default ε, specular on, automatic
    /// exposure, work not counted.
    pub fn new(camera: Camera, lights: Vec<Light>) -> FrameDesc {
        FrameDesc {
            camera,
            lights,
            environment: None,
            width: 512,
            height: 512,
            integration: Integration::default(),
            specular: true,
            scattering: Scattering::All,
            roughness: DEFAULT_ROUGHNESS,
            show: Show::Shading,
            exposure: Exposure::Auto,
            count_work: false,
            shadow_resolution: DEFAULT_SHADOW_RESOLUTION,
        }
    }

    /// Every check of these settings, with the flag each comes from named. The device's own
    /// limits (largest image, memory) are checked when the renderer makes what they size.
    pub fn validate(&self) -> Result<()> {
        let e = self.integration.epsilon;
        if !(e.is_finite() && e >= 0.0) {
            return Err(bad_input!("--epsilon {e}: must be a finite number ≥ 0"));
        }
        check_roughness(self.roughness, "--roughness")?;
        if self.scattering != Scattering::All && self.integration.model != Model::Mc {
            return Err(bad_input!(
                "--scattering {}: only --model mc draws single and multiple scattering apart (model {})",
                self.scattering.name(),
                self.integration.model.name()
            ));
        }
        if self.integration.reentry && self.integration.model != Model::Mc {
            return Err(bad_input!(
                "--reentry: only --model mc draws light that enters again (model {})",
                self.integration.model.name()
            ));
        }
        if self.integration.reentry && self.integration.brute_force {
            return Err(bad_input!(
                "--reentry: not with --brute-force (it sums each light's own records, which hold no light that enters again)"
            ));
        }
        if self.width == 0 || self.height == 0 {
            return Err(bad_input!("image size {}x{}: width and height must be at least 1", self.width, self.height));
        }
        let (lo, hi) = SHADOW_RESOLUTION_RANGE;
        if !(lo..=hi).contains(&self.shadow_resolution) {
            return Err(bad_input!("--shadow-resolution {}: must be between {lo} and {hi}", self.shadow_resolution));
        }
        check_camera(&self.camera)?;
        if let Some(env) = &self.environment {
            env.validate()?;
        }
        check_lights(&self.lights)
    }

    /// The view-projection matrix of this frame's camera around `bounds`.
    pub fn view_projection(&self, bounds: (Vec3, Vec3)) -> glam::Mat4 {
        self.camera.view_projection(self.width as f32 / self.height as f32, bounds)
    }
}

/// The camera's own checks, and its coordinates within [`MAX_COORDINATE`].
pub fn check_camera(camera: &Camera) -> Result<()> {
    for (flag, p) in [("--eye", camera.eye), ("--target", camera.target)] {
        if p.abs().max_element() > MAX_COORDINATE {
            return Err(bad_input!("{flag} {p}: coordinates must be within ±{MAX_COORDINATE:e}"));
        }
    }
    camera.validate()
}

/// At least 1 light, each valid, point and spot lights within [`MAX_COORDINATE`].
pub fn check_lights(lights: &[Light]) -> Result<()> {
    for light in lights {
        if let Some(position) = light.position() {
            if position.abs().max_element() > MAX_COORDINATE {
                let kind = if matches!(light, Light::Spot { .. }) { "spot" } else { "point" };
                return Err(bad_input!("--light {kind}:{position}: coordinates must be within ±{MAX_COORDINATE:e}"));
            }
        }
    }
    if lights.is_empty() {
        return Err(bad_input!("--light: at least one light is needed"));
    }
    lights.iter().try_for_each(Light::validate)
}

/// Refuses a roughness outside (0, 1]; `what` names it in the message (`--roughness`, `roughness`).
pub fn check_roughness(roughness: f32, what: &str) -> Result<()> {
    if !(roughness > 0.0 && roughness <= 1.0) {
        return Err(bad_input!("{what} {roughness}: must be in (0, 1]"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn desc() -> FrameDesc {
        let camera = Camera { eye: Vec3::new(0.0, 0.0, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        FrameDesc::new(camera, vec![Light::Directional { toward: Vec3::Y, irradiance: Vec3::ONE }])
    }

    #[test]
    fn the_defaults_are_valid() {
        desc().validate().unwrap();
    }

    /// Each range check refuses, naming its flag.
    #[test]
    fn every_range_is_checked_once_here() {
        type Edit = Box<dyn Fn(&mut FrameDesc)>;
        let cases: Vec<(&str, Edit)> = vec![
            ("--epsilon", Box::new(|d| d.integration.epsilon = f32::NAN)),
            ("--epsilon", Box::new(|d| d.integration.epsilon = -1.0)),
            ("--epsilon", Box::new(|d| d.integration.epsilon = f32::INFINITY)),
            ("--roughness", Box::new(|d| d.roughness = 0.0)),
            ("--roughness", Box::new(|d| d.roughness = 1.5)),
            ("image size", Box::new(|d| d.width = 0)),
            ("--shadow-resolution", Box::new(|d| d.shadow_resolution = 8)),
            ("--eye", Box::new(|d| d.camera.eye = Vec3::splat(1e16))),
            ("--fov", Box::new(|d| d.camera.fov_y_deg = 1e-37)),
            ("--light", Box::new(|d| d.lights.clear())),
            (
                "--light point",
                Box::new(|d| d.lights[0] = Light::Point { position: Vec3::X * 1e16, intensity: Vec3::ONE }),
            ),
            ("light intensity", Box::new(|d| d.lights[0] = Light::Point { position: Vec3::X, intensity: -Vec3::ONE })),
        ];
        for (needle, edit) in cases {
            let mut d = desc();
            edit(&mut d);
            let message = d.validate().expect_err(needle).to_string();
            assert!(message.contains(needle), "{needle}: {message}");
        }
    }
}
