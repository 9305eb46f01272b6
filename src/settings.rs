//! What a frame is made from, whoever asks for it: `render` and `view` (from their flags, see
//! [`RenderSettings::from_args`]), `bench` and the tests (from code). One builder turns settings
//! into the scene and the renderer's [`FrameOptions`], so that every caller derives the same
//! values the same way (η from the material, the default sample count, the checks).

use glam::Vec3;

use crate::bad_input;
use crate::cli::{DeviceArgs, MaterialArgs, RenderArgs, ShowArg};
use crate::error::Result;
use crate::frame::{FrameOptions, Show, SubsurfaceOptions, DEFAULT_EPSILON};
use crate::hierarchy::HierarchyOptions;
use crate::materials::Material;
use crate::mesh::safe_normalize;
use crate::output::Exposure;
use crate::physics::{Diffusion, Model};
use crate::scene::{Camera, Light, Scene};
use crate::vk::{Context, ContextOptions};

/// The sizes (mm across) a mesh may have once --scale is applied: from a micrometre to a thousand
/// kilometres, so that areas in mm² and the powers summed over them stay finite in f32.
pub const SIZE_MM_LIMITS: (f64, f64) = (1e-3, 1e9);

/// The largest coordinate accepted for --eye, --target and point lights: squared distances must
/// stay finite in f32.
pub const MAX_COORDINATE: f32 = 1e15;

/// The Stanford bunny of Debian's glmark2-data, the default mesh when installed.
pub const BUNNY: &str = "/usr/share/glmark2/models/bunny.obj";

/// The default roughness of the microfacet reflection (`--roughness`).
pub const DEFAULT_ROUGHNESS: f32 = 0.35;

/// Refuses a roughness outside (0, 1]; `what` names it in the message (`--roughness`, `roughness`).
pub fn check_roughness(roughness: f32, what: &str) -> Result<()> {
    if !(roughness > 0.0 && roughness <= 1.0) {
        return Err(bad_input!("{what} {roughness}: must be in (0, 1]"));
    }
    Ok(())
}

impl MaterialArgs {
    /// The preset with the coefficients given overridden, validated; prints the material's warning.
    pub fn material(&self) -> Result<Material> {
        let mut m = Material::find(&self.material)?;
        let custom = self.sigma_a.is_some() || self.sigma_s.is_some() || self.g.is_some() || self.eta.is_some();
        m.sigma_a = self.sigma_a.unwrap_or(m.sigma_a);
        m.sigma_s = self.sigma_s.unwrap_or(m.sigma_s);
        m.g = self.g.unwrap_or(m.g);
        m.eta = self.eta.unwrap_or(m.eta);
        if custom {
            m.name = format!("{} (modified)", m.name);
        }
        m.validate()?;
        if let Some(w) = m.warning() {
            crate::note!("warning: {w}");
        }
        Ok(m)
    }
}

impl DeviceArgs {
    /// The device and validation asked for, by flag or by TRANSLUCENT_VALIDATION.
    pub fn options(&self) -> ContextOptions {
        let from_env = std::env::var("TRANSLUCENT_VALIDATION").map(|v| v != "0" && !v.is_empty()).unwrap_or(false);
        ContextOptions { validation: self.validation || from_env, device: self.device.clone() }
    }
}

/// The scene's inputs: a mesh, the camera and the lights, with the command line's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneSettings {
    /// `sphere`, `box`, `slab`, `torus` or an OBJ path (`None`: the bunny when installed, else the
    /// sphere); `{frame}` names a sequence, whose first file is the scene's mesh.
    pub mesh: Option<String>,
    /// Millimetres per scene unit.
    pub scale: f32,
    /// Camera position (`None`: framing the mesh).
    pub eye: Option<Vec3>,
    /// Point looked at (`None`: the mesh's centre).
    pub target: Option<Vec3>,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov: f32,
    /// The default light's direction (toward it) and irradiance, used when `lights` is empty.
    pub light_dir: Vec3,
    pub light_intensity: Vec3,
    pub lights: Vec<Light>,
}

impl Default for SceneSettings {
    fn default() -> Self {
        SceneSettings {
            mesh: None,
            scale: 10.0,
            eye: None,
            target: None,
            up: Vec3::Y,
            fov: 40.0,
            light_dir: Vec3::new(-0.3, 0.7, -0.65),
            light_intensity: Vec3::ONE,
            lights: Vec::new(),
        }
    }
}

impl SceneSettings {
    pub fn from_args(args: &RenderArgs) -> SceneSettings {
        SceneSettings {
            mesh: args.mesh.clone(),
            scale: args.scale,
            eye: args.eye,
            target: args.target,
            up: args.up,
            fov: args.fov,
            light_dir: args.light_dir,
            light_intensity: args.light_intensity,
            lights: args.lights.clone(),
        }
    }

    /// The mesh given, or the default: the bunny when installed, else the sphere.
    pub fn mesh_spec(&self) -> String {
        match &self.mesh {
            Some(m) => m.clone(),
            None if std::path::Path::new(BUNNY).exists() => BUNNY.to_string(),
            None => "sphere".to_string(),
        }
    }

    /// Loads the mesh and places the camera and lights; every input is checked, with the flag it
    /// comes from named.
    pub fn build(&self) -> Result<Scene> {
        let mesh = crate::deform::first_mesh(&self.mesh_spec())?;
        let (centre, radius) = crate::scene::bounding_sphere(&mesh.positions);
        // The object's size in millimetres must stay where f32 areas and powers are finite.
        let size_mm = 2.0 * radius as f64 * self.scale as f64;
        if !(SIZE_MM_LIMITS.0..=SIZE_MM_LIMITS.1).contains(&size_mm) {
            return Err(bad_input!(
                "--scale {}: the mesh would be {size_mm:.3e} mm across; it must be within [{:e}, {:e}] mm",
                self.scale,
                SIZE_MM_LIMITS.0,
                SIZE_MM_LIMITS.1
            ));
        }
        let mut camera = Camera::framing(centre, radius, self.fov, Vec3::new(0.3, 0.3, 1.0));
        // Directions are normalised here, safely: (1e20, 1e20, 0) is a fine direction whose squared
        // length overflows f32, and would otherwise turn into NaN on the GPU.
        camera.up =
            safe_normalize(self.up).ok_or_else(|| bad_input!("--up {}: must be finite and non-zero", self.up))?;
        for (flag, p) in [("--eye", self.eye), ("--target", self.target)] {
            if let Some(p) = p.filter(|p| p.abs().max_element() > MAX_COORDINATE) {
                return Err(bad_input!("{flag} {p}: coordinates must be within ±{MAX_COORDINATE:e}"));
            }
        }
        if let Some(target) = self.target {
            camera.target = target;
        }
        if let Some(eye) = self.eye {
            camera.eye = eye;
        }
        let lights = if self.lights.is_empty() {
            let toward = safe_normalize(self.light_dir).ok_or_else(|| {
                bad_input!("--light-dir {}: light direction must be finite and non-zero", self.light_dir)
            })?;
            vec![Light::Directional { toward, irradiance: self.light_intensity }]
        } else {
            self.lights.clone()
        };
        for light in &lights {
            if let Light::Point { position, .. } = light {
                if position.abs().max_element() > MAX_COORDINATE {
                    return Err(bad_input!("--light point:{position}: coordinates must be within ±{MAX_COORDINATE:e}"));
                }
            }
        }
        if lights.len() > crate::gpu::MAX_LIGHTS {
            return Err(bad_input!("--light: at most {} lights, {} given", crate::gpu::MAX_LIGHTS, lights.len()));
        }
        let scene = Scene { mesh, camera, lights, mm_per_unit: self.scale };
        scene.validate()?;
        Ok(rescaled(scene, radius))
    }
}

/// A scene whose mesh is far from unit size (a 1e-9-unit cube, a 1e8-unit terrain) re-expressed in
/// units a power of two larger or smaller, so that its radius is near 1: the picture is the same
/// (millimetres per unit change by the inverse factor, exactly), but the hierarchy's half-float
/// node bounds and the depth range keep their precision.
fn rescaled(mut scene: Scene, radius: f32) -> Scene {
    if (1.0 / 64.0..=64.0).contains(&radius) || radius.is_nan() || radius <= 0.0 {
        return scene;
    }
    let factor = (-radius.log2().round()).exp2();
    scene.mesh = scene.mesh.scaled(factor);
    scene.mm_per_unit /= factor;
    scene.camera.eye *= factor;
    scene.camera.target *= factor;
    for light in &mut scene.lights {
        if let Light::Point { position, .. } = light {
            *position *= factor;
        }
    }
    scene
}

/// A frame's settings: the scene, how the subsurface term is integrated, and the image. Built
/// from flags ([`RenderSettings::from_args`]) or in code ([`RenderSettings::new`] and fields);
/// [`RenderSettings::frame_options`] makes the renderer's options from them.
pub struct RenderSettings {
    pub scene: Scene,
    pub subsurface: SubsurfaceOptions,
    pub width: u32,
    pub height: u32,
    /// Sample points (`None`: from the material's length scales and the mesh's area).
    pub samples: Option<u32>,
    /// Shadow-map resolution per light (per cube face for point lights).
    pub shadow_resolution: u32,
    pub show: Show,
    pub exposure: Exposure,
    /// Time every pass with GPU timestamps.
    pub profile: bool,
    /// Count the shading work per pixel on the GPU.
    pub count_work: bool,
}

impl RenderSettings {
    /// `scene` with `material` and the command line's defaults for everything else (directional
    /// dipole, classical diffusion, the default ε, specular on, 512×512, timed, work not counted).
    pub fn new(scene: Scene, material: Material) -> RenderSettings {
        RenderSettings {
            scene,
            subsurface: SubsurfaceOptions {
                material,
                model: Model::Directional,
                diffusion: Diffusion::Classical,
                epsilon: DEFAULT_EPSILON,
                brute_force: false,
                specular: true,
                roughness: DEFAULT_ROUGHNESS,
            },
            width: 512,
            height: 512,
            samples: None,
            shadow_resolution: 1024,
            show: Show::Shading,
            exposure: Exposure::Auto,
            profile: true,
            count_work: false,
        }
    }

    /// The settings of `render` and `view` from their flags, checked in the order the user reads
    /// them: roughness, then the scene, then the material (which may print a warning).
    pub fn from_args(args: &RenderArgs) -> Result<RenderSettings> {
        check_roughness(args.roughness, "--roughness")?;
        let scene = SceneSettings::from_args(args).build()?;
        let material = args.material.material()?;
        Ok(RenderSettings {
            scene,
            subsurface: SubsurfaceOptions {
                material,
                model: args.model.into(),
                diffusion: args.diffusion.into(),
                epsilon: args.epsilon,
                brute_force: args.brute_force,
                specular: !args.no_specular,
                roughness: args.roughness,
            },
            width: args.width,
            height: args.height,
            samples: args.samples,
            shadow_resolution: args.shadow_resolution,
            show: match args.show {
                ShowArg::Shading => Show::Shading,
                ShowArg::Samples => Show::Samples,
                ShowArg::Tree => Show::Tree(args.level),
            },
            exposure: args.exposure.map(Exposure::Stops).unwrap_or(Exposure::Auto),
            profile: true,
            count_work: args.profile,
        })
    }

    /// The sample count: the one given (checked against the device), else the default for the
    /// material and the mesh (printed).
    pub fn point_count(&self, ctx: &Context) -> Result<u32> {
        match self.samples {
            Some(n) => {
                crate::hierarchy::check_point_count(ctx, n, self.scene.lights.len() as u32)?;
                Ok(n)
            }
            None => Ok(default_point_count(ctx, &self.scene, &self.subsurface.material)),
        }
    }

    /// The renderer's options for `point_count` points; the hierarchy's η is the material's.
    pub fn frame_options(&self, point_count: u32) -> FrameOptions {
        let s = &self.subsurface;
        FrameOptions {
            subsurface: SubsurfaceOptions { material: s.material.clone(), ..*s },
            width: self.width,
            height: self.height,
            profile: self.profile,
            count_work: self.count_work,
            hierarchy: HierarchyOptions {
                point_count,
                shadow_resolution: self.shadow_resolution,
                eta: s.material.eta as f32,
            },
            show: self.show,
            exposure: self.exposure,
        }
    }
}

/// Sample count from the material's shortest length scale (mean free path 1/σ't or diffusion
/// length 1/σtr) and the mesh's area (in mm), within a budget; prints the choice and warns when
/// points are farther apart than that length.
pub fn default_point_count(ctx: &Context, scene: &Scene, material: &Material) -> u32 {
    let mm = scene.mm_per_unit;
    let area_mm2 = scene.mesh.surface_area() * mm * mm;
    let shortest = (0..3)
        .map(|ch| material.channel(ch).constants(Diffusion::Classical))
        .filter(|c| c.transports && c.sigma_tr > 0.0)
        .map(|c| (1.0 / c.sigma_tr).min(1.0 / c.sigma_t_reduced))
        .fold(f64::INFINITY, f64::min) as f32;
    let budget = crate::hierarchy::max_points(ctx, scene.lights.len() as u32).min(1 << 18);
    let (n, spacing) = crate::hierarchy::choose_point_count(area_mm2, shortest, budget);
    crate::note!(
        "samples: {n} points, {spacing:.3} mm apart on {area_mm2:.0} mm² (shortest of mean free path and diffusion length: {shortest:.3} mm)"
    );
    if spacing > shortest {
        crate::note!("warning: points are spaced wider than the mean free path or diffusion length; raise --samples for accuracy");
    }
    n
}
