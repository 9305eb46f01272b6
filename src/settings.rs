//! What a frame is made from, whoever asks for it: `render` and `view` (from their flags, see
//! [`RenderSettings::from_args`]), `bench` and the tests (from code). One builder turns settings
//! into a [`World`] and a [`FrameDesc`], so that every caller derives the same values the same
//! way (the mesh's framing and scale, the lights, the material's overrides, the checks).

use glam::Vec3;

use crate::bad_input;
use crate::cli::{DeviceArgs, MaterialArgs, RenderArgs, ShowArg};
use crate::error::Result;
use crate::frame_desc::{check_roughness, FrameDesc, Integration, Show};
use crate::materials::Material;
use crate::mesh::safe_normalize;
use crate::output::Exposure;
use crate::scene::{Camera, Light, Scene};
use crate::vk::ContextOptions;
use crate::world::World;

/// The Stanford bunny of Debian's glmark2-data, the default mesh when installed.
pub const BUNNY: &str = "/usr/share/glmark2/models/bunny.obj";

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
        // The scale, the mesh and its size in millimetres, before anything is derived from them.
        crate::world::check_geometry(&mesh, self.scale)?;
        let mut camera = Camera::framing(centre, radius, self.fov, Vec3::new(0.3, 0.3, 1.0));
        // Directions are normalised here, safely: (1e20, 1e20, 0) is a fine direction whose squared
        // length overflows f32, and would otherwise turn into NaN on the GPU.
        camera.up =
            safe_normalize(self.up).ok_or_else(|| bad_input!("--up {}: must be finite and non-zero", self.up))?;
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
        // Checked as every frame's camera and lights are (`FrameDesc::validate`).
        crate::frame_desc::check_camera(&camera)?;
        crate::frame_desc::check_lights(&lights)?;
        let scene = Scene { mesh, camera, lights, mm_per_unit: self.scale };
        Ok(rescaled(scene, radius))
    }
}

/// A world far from unit size (its first object's bounding sphere) re-expressed in power-of-two
/// units, as scenes from flags are: every mesh, the camera and the lights' positions scaled, the
/// millimetres per unit divided by the same factor (scene files, pbrt-v4's and glTF's).
pub(crate) fn rescale_world(world: &mut crate::world::World, camera: &mut Camera, lights: &mut [Light]) {
    let first = world.objects.first().map(|o| &o.mesh).or(world.opaque.first().map(|o| &o.mesh));
    let Some(first) = first else { return };
    let (_, radius) = crate::scene::bounding_sphere(&first.positions);
    let Some(factor) = rescale_factor(radius) else { return };
    for mesh in world.objects.iter_mut().map(|o| &mut o.mesh).chain(world.opaque.iter_mut().map(|o| &mut o.mesh)) {
        mesh.positions.iter_mut().for_each(|p| *p *= factor);
    }
    world.mm_per_unit /= factor;
    camera.eye *= factor;
    camera.target *= factor;
    for light in lights {
        light.in_units_scaled_by(factor);
    }
}

/// The power of two that brings a radius far from 1 (outside [1/64, 64]) near it, if it is.
pub(crate) fn rescale_factor(radius: f32) -> Option<f32> {
    if (1.0 / 64.0..=64.0).contains(&radius) || radius.is_nan() || radius <= 0.0 {
        return None;
    }
    Some((-radius.log2().round()).exp2())
}

/// A scene whose mesh is far from unit size (a 1e-9-unit cube, a 1e8-unit terrain) re-expressed in
/// units a power of two larger or smaller, so that its radius is near 1: the picture is the same
/// (millimetres per unit change by the inverse factor, exactly), but the hierarchy's half-float
/// node bounds and the depth range keep their precision.
pub(crate) fn rescaled(mut scene: Scene, radius: f32) -> Scene {
    let Some(factor) = rescale_factor(radius) else { return scene };
    scene.mesh = scene.mesh.scaled(factor);
    scene.mm_per_unit /= factor;
    scene.camera.eye *= factor;
    scene.camera.target *= factor;
    for light in &mut scene.lights {
        light.in_units_scaled_by(factor);
    }
    scene
}

/// A frame's settings: the world (one object from the flags) and the frame's description, and
/// whether to time the passes. Built from flags ([`RenderSettings::from_args`]) or in code
/// ([`RenderSettings::new`] and fields).
pub struct RenderSettings {
    pub world: World,
    pub desc: FrameDesc,
    /// Time every pass with GPU timestamps.
    pub profile: bool,
}

impl RenderSettings {
    /// `scene` as a world of one object in `material`, with the command line's defaults for
    /// everything else ([`FrameDesc::new`]), timed.
    pub fn new(scene: Scene, material: Material) -> RenderSettings {
        let Scene { mesh, camera, lights, mm_per_unit } = scene;
        RenderSettings {
            world: World::single(mesh, material, mm_per_unit),
            desc: FrameDesc::new(camera, lights),
            profile: true,
        }
    }

    /// The settings of `render` and `view` from their flags, checked in the order the user reads
    /// them: roughness, then the scene, then the material (which may print a warning), then the
    /// rest of the frame and the world.
    pub fn from_args(args: &RenderArgs) -> Result<RenderSettings> {
        check_roughness(args.roughness, "--roughness")?;
        let gltf = args.scene.as_deref().is_some_and(crate::gltf::is_gltf);
        if !gltf && (args.gltf_scene.is_some() || !args.gltf_material.is_empty()) {
            let flag = if args.gltf_scene.is_some() { "--gltf-scene" } else { "--gltf-material" };
            return Err(bad_input!("{flag}: only for a glTF scene file (render SCENE.gltf|SCENE.glb …)"));
        }
        let mut scene = SceneSettings::from_args(args).build()?;
        let environment = match &args.env {
            Some(spec) => {
                let env = environment_from_args(spec, args)?;
                if args.lights.is_empty() {
                    scene.lights.clear(); // the environment replaces the default light
                }
                scene.lights.extend(env.lights()?);
                if scene.lights.is_empty() {
                    return Err(bad_input!("--env {spec}: the map is black everywhere: nothing lights the scene"));
                }
                Some(std::sync::Arc::new(env))
            }
            None => None,
        };
        let material = args.material.material()?;
        let spec = SceneSettings::from_args(args).mesh_spec();
        let texture = obj_texture(&spec)?;
        // A colour map: the material's albedo is the map's mean (its mean free path is kept).
        let material = match &texture {
            Some((map, _)) => crate::world::textured_material(&material, map)?,
            None => material,
        };
        let mut s = RenderSettings::new(scene, material);
        if let Some((map, uvs)) = texture {
            (s.world.objects[0].texture, s.world.objects[0].uvs) = (Some(map), Some(uvs));
        }
        s.desc.environment = environment;
        s.world.objects[0].samples = args.samples;
        let d = &mut s.desc;
        d.integration = Integration {
            model: args.model,
            diffusion: args.diffusion.into(),
            epsilon: args.epsilon,
            brute_force: args.brute_force,
            near_field: args.near_field.into(),
            far_field: !args.no_far_field,
            reentry: args.reentry,
        };
        (d.width, d.height) = (args.width, args.height);
        (d.specular, d.roughness) = (!args.no_specular, args.roughness);
        d.scattering = args.scattering.into();
        // The re-entry needs the object's inside: an open mesh has none.
        if args.reentry && s.world.objects.iter().any(|o| !o.mesh.is_closed()) {
            crate::note!(
                "warning: --reentry: the mesh is not closed (no inside to tell air from): no light enters again"
            );
        }
        d.shadow_resolution = args.shadow_resolution;
        d.show = match args.show {
            ShowArg::Shading => Show::Shading,
            ShowArg::Samples => Show::Samples,
            ShowArg::Tree => Show::Tree(args.level),
        };
        d.exposure = args.exposure.map(Exposure::Stops).unwrap_or(Exposure::Auto);
        d.count_work = args.profile;
        s.desc.validate()?;
        s.world.validate()?;
        Ok(s)
    }
}

/// The colour map of an OBJ mesh file (`map_Kd` × `Kd` of its first textured material, through
/// its `mtllib`) and the file's uv per vertex; `None` for other meshes and OBJ files without one.
fn obj_texture(spec: &str) -> Result<Option<(crate::world::Reflectance, Vec<glam::Vec2>)>> {
    use crate::mesh::MeshFormat;
    let path = std::path::Path::new(spec);
    let is_obj = MeshFormat::of(path).0 == MeshFormat::Obj && !spec.contains("{frame}");
    if !is_obj || !path.is_file() {
        return Ok(None);
    }
    let Some((map, factor)) = crate::mesh::obj_diffuse_map(path)? else { return Ok(None) };
    let shown = format!("mesh {spec}: map_Kd {}", map.display());
    let uvs = crate::mesh::read_raw(path)?
        .uvs
        .ok_or_else(|| bad_input!("{shown}: a colour map needs the mesh's texture coordinates (vt on every vertex)"))?;
    let mut texture = crate::world::Texture::load(&map, &shown)?;
    if factor != Vec3::ONE {
        let texels = texture.texels.iter().map(|t| [t[0] * factor.x, t[1] * factor.y, t[2] * factor.z, 1.0]);
        texture.texels = std::sync::Arc::new(texels.collect());
    }
    Ok(Some((crate::world::Reflectance::Image(texture), uvs)))
}

/// `--env FILE | const:L` with its scale, rotation and sample count.
fn environment_from_args(spec: &str, args: &RenderArgs) -> Result<crate::environment::Environment> {
    use crate::environment::{rotation_about_up, Environment};
    let env = Environment {
        name: format!("--env {spec}"),
        radiance: environment_radiance(spec)?,
        scale: args.env_scale,
        to_world: rotation_about_up(args.env_rotate),
        samples: args.env_samples,
    };
    env.validate()?;
    Ok(env)
}

/// The radiance `--env SPEC` names (FILE, const:L or sky[:E:A]); the viewer's `env` line too.
pub fn environment_radiance(spec: &str) -> Result<crate::environment::Radiance> {
    use crate::environment::{Environment, Radiance};
    let sky = |rest: &str| -> Result<Radiance> {
        let v: Vec<f32> = rest
            .split(':')
            .filter(|p| !p.is_empty())
            .map(crate::cli::finite_f32)
            .collect::<std::result::Result<_, _>>()
            .map_err(|e| bad_input!("--env {spec}: {e}"))?;
        match v.as_slice() {
            [] => Ok(crate::environment::sky(30.0, 30.0)),
            [e, a] if (-90.0..=90.0).contains(e) => Ok(crate::environment::sky(*e, *a)),
            _ => Err(bad_input!("--env {spec}: expected sky[:ELEVATION:AZIMUTH] (degrees, elevation within ±90)")),
        }
    };
    let radiance = if let Some(l) = spec.strip_prefix("const:") {
        Radiance::Constant(crate::cli::rgb(l).map_err(|e| bad_input!("--env {spec}: {e}"))?)
    } else if spec == "sky" || spec.starts_with("sky:") {
        sky(&spec[3..])?
    } else {
        Environment::load(std::path::Path::new(spec), &format!("--env {spec}"))?
    };
    Ok(radiance)
}

/// The settings of a scene file, `render SCENE` or `view SCENE`: glTF 2.0 (`.gltf`, `.glb`) or
/// pbrt-v4 (anything else), with the flags typed on the command line (`given`) overriding it.
pub fn scene_file_settings(
    path: &std::path::Path,
    args: &RenderArgs,
    given: &dyn Fn(&str) -> bool,
) -> Result<(RenderArgs, RenderSettings)> {
    if crate::gltf::is_gltf(path) {
        crate::gltf::render_settings(path, args, given)
    } else {
        crate::pbrt::render_settings(path, args, given)
    }
}
