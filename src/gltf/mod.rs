//! glTF 2.0 scenes: `translucent render scene.gltf` (or `.glb`). [`load`] reads a file (its
//! buffers and images too) into a [`GltfScene`], a plain description in the file's world space
//! (metres, y up, right-handed): every primitive of every mesh instance as world-space
//! triangles with its material, the lights, the first perspective camera, the warnings.
//! [`render_settings`] is the one place that turns it into what the renderer draws; it decides
//! which materials are translucent and maps them (see the README, "glTF 2.0 scenes").
//!
//! `accessor.rs` (accessors from bytes, every size checked), `read.rs` (the file, the GLB
//! container, buffers, images, materials, the node hierarchy).

pub mod accessor;
pub mod read;

use std::path::Path;

use glam::{DVec3, Vec3};

use crate::bad_input;
use crate::error::Result;
use crate::mesh::RawMesh;
use crate::world::Texture;
pub use read::{load, split_glb, triangles, UvTransform, MAX_FILE_BYTES, MAX_JSON_BYTES, SUPPORTED_EXTENSIONS};

/// glTF's metres as millimetres per scene unit, unless `--scale` is typed.
pub const MM_PER_METRE: f32 = 1000.0;
/// KHR_materials_ior's default index of refraction.
pub const DEFAULT_IOR: f64 = 1.5;

/// Whether a path names a glTF file (`.gltf` or `.glb`, any case).
pub fn is_gltf(path: &Path) -> bool {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    matches!(ext.as_deref(), Some("gltf" | "glb"))
}

/// The first perspective camera, in world space.
#[derive(Clone, Debug)]
pub struct CameraDesc {
    pub eye: DVec3,
    /// Unit: the node's −z.
    pub forward: DVec3,
    /// Unit: the node's +y.
    pub up: DVec3,
    /// `yfov` in degrees.
    pub yfov_deg: f64,
    pub aspect: Option<f64>,
    /// `cameras[i] (nodes[j])`.
    pub path: String,
}

/// A light as the renderer takes it, with where it came from.
#[derive(Clone, Debug)]
pub struct LightDesc {
    pub light: crate::scene::Light,
    pub path: String,
}

/// KHR_materials_volume's values, as the file gives them.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    pub thickness: f64,
    /// Scene units; infinite when not given.
    pub attenuation_distance: f64,
    pub attenuation_color: [f64; 3],
}

/// A material as the file describes it (what [`render_settings`] needs of it).
#[derive(Clone, Debug)]
pub struct MaterialDesc {
    /// `None`: glTF's default material (a primitive without one).
    pub index: Option<usize>,
    pub name: Option<String>,
    /// `materials[i] ("name")`, for messages.
    pub path: String,
    /// baseColorFactor's rgb (linear).
    pub base_color: [f64; 3],
    /// The base colour texture decoded to linear, its texels × baseColorFactor.
    pub texture: Option<Texture>,
    /// The texture's coordinate set and KHR_texture_transform (applied to the uvs on load).
    pub uv_set: Option<(u32, UvTransform)>,
    pub roughness: f64,
    pub volume: Option<Volume>,
    /// KHR_materials_transmission's factor (a textured one counts as positive).
    pub transmission: Option<f64>,
    /// KHR_materials_diffuse_transmission's factor (likewise).
    pub diffuse_transmission: Option<f64>,
    /// KHR_materials_ior (1.5 when absent).
    pub ior: f64,
    /// KHR_materials_volume_scatter's multiscatterColor, when the extension is there.
    pub multiscatter: Option<[f64; 3]>,
    /// KHR_materials_volume_scatter's scatterAnisotropy (g).
    pub anisotropy: f64,
}

impl Default for MaterialDesc {
    /// glTF's default material: white, fully rough.
    fn default() -> Self {
        MaterialDesc {
            index: None,
            name: None,
            path: "the default material".into(),
            base_color: [1.0; 3],
            texture: None,
            uv_set: None,
            roughness: 1.0,
            volume: None,
            transmission: None,
            diffuse_transmission: None,
            ior: DEFAULT_IOR,
            multiscatter: None,
            anisotropy: 0.0,
        }
    }
}

impl MaterialDesc {
    /// KHR_materials_volume with a thickness or an attenuation, and a transmission (specular or
    /// diffuse) above 0.
    pub fn is_translucent(&self) -> bool {
        // A colour without a distance attenuates nothing (the distance's default is infinite).
        let volume = self.volume.as_ref().is_some_and(|v| v.thickness > 0.0 || v.attenuation_distance.is_finite());
        let transmits =
            self.transmission.is_some_and(|t| t > 0.0) || self.diffuse_transmission.is_some_and(|t| t > 0.0);
        volume && transmits
    }

    /// The reflectance the translucent material reproduces: multiscatterColor when
    /// KHR_materials_volume_scatter gives one, else the base colour (the texture's mean when
    /// there is one; the factor is in its texels).
    pub fn reflectance(&self) -> [f64; 3] {
        match (&self.multiscatter, &self.texture) {
            (Some(c), _) => *c,
            // As a pbrt scene's texture reflectance takes it (`Reflectance::mean`, in f32).
            (None, Some(t)) => t.mean().map(|c| c as f32 as f64),
            (None, None) => self.base_color,
        }
    }

    /// The reduced mean free path per channel in scene units: with d the attenuation distance
    /// (the thickness when no distance is given) and c the attenuation colour,
    /// mfp = d / (1 − ln c): σ't = 1/d + σa, where σa = −ln(c)/d is KHR_materials_volume's own
    /// absorption and 1/d a scattering that gives white a mean free path of d.
    pub fn mfp(&self) -> Option<[f64; 3]> {
        let v = self.volume.as_ref()?;
        let d = if v.attenuation_distance.is_finite() { v.attenuation_distance } else { v.thickness };
        (d.is_finite() && d > 0.0).then(|| v.attenuation_color.map(|c| d / (1.0 - c.max(1e-6).ln())))
    }
}

/// One primitive of one mesh instance.
#[derive(Clone, Debug)]
pub struct Object {
    /// World space, wound counter-clockwise seen from outside; `uvs` as the renderer takes them
    /// (KHR_texture_transform applied, v up the image) when its material has a texture.
    pub mesh: RawMesh,
    /// Index into [`GltfScene::materials`].
    pub material: usize,
    /// `nodes[i] (meshes[j].primitives[k])`.
    pub path: String,
}

#[derive(Clone, Debug, Default)]
pub struct GltfScene {
    pub camera: Option<CameraDesc>,
    pub objects: Vec<Object>,
    /// The materials the objects use.
    pub materials: Vec<MaterialDesc>,
    /// Every material's name in the file (used or not), for `--gltf-material`.
    pub material_names: Vec<String>,
    pub lights: Vec<LightDesc>,
    /// `FILE: PATH: …` lines: what is read past.
    pub warnings: Vec<String>,
}

/// `--gltf-material NAME=PRESET`: the material's name and the preset's.
fn parse_override(spec: &str) -> Result<(&str, &str)> {
    spec.rsplit_once('=').filter(|(n, p)| !n.is_empty() && !p.is_empty()).ok_or_else(|| {
        bad_input!(
            "--gltf-material {spec}: give NAME=PRESET (a material of the file, a preset of `translucent materials`)"
        )
    })
}

/// A translucent glTF material as the renderer takes it (the flags' preset or coefficients
/// override it as they override a pbrt scene's).
fn material_of(
    shown: &str,
    desc: &MaterialDesc,
    preset: Option<&str>,
    mm_per_unit: f32,
    args: &crate::cli::RenderArgs,
    given: &dyn Fn(&str) -> bool,
) -> Result<crate::materials::Material> {
    let m = &args.material;
    if given("--material") {
        return m.material();
    }
    let mut mat = match preset {
        Some(p) => crate::materials::Material::find(p).map_err(|_| {
            bad_input!(
                "--gltf-material {}={p}: unknown preset; `translucent materials` lists them",
                desc.name.as_deref().unwrap_or("")
            )
        })?,
        None => {
            let mfp =
                desc.mfp().ok_or_else(|| bad_input!("{shown}: {}: no attenuation distance or thickness", desc.path))?;
            let mfp_mm = mfp.map(|l| l * mm_per_unit as f64);
            // The largest reflectance the dipole reaches for this η (from_reflectance refuses it).
            let top = crate::pbrt::max_reflectance(desc.ior);
            let wanted = desc.reflectance();
            let reflectance = wanted.map(|r| r.min(top * 0.999));
            if reflectance != wanted {
                crate::note!(
                    "warning: {shown}: {}: reflectance {wanted:?} is above what the dipole reaches for ior {} ({top:.4}); rendered at {:.4}",
                    desc.path,
                    desc.ior,
                    top * 0.999
                );
            }
            let (sigma_a, sigma_s) = crate::pbrt::from_reflectance(reflectance, mfp_mm, desc.anisotropy, desc.ior)
                .map_err(|e| bad_input!("{shown}: {}: {e}", desc.path))?;
            let mut mat = crate::materials::Material::custom(sigma_a, sigma_s, [desc.anisotropy; 3], desc.ior)
                .map_err(|e| bad_input!("{shown}: {}: {e}", desc.path))?;
            mat.name = format!("glTF {}", desc.path);
            mat
        }
    };
    mat.sigma_a = m.sigma_a.unwrap_or(mat.sigma_a);
    mat.sigma_s = m.sigma_s.unwrap_or(mat.sigma_s);
    mat.g = m.g.unwrap_or(mat.g);
    mat.eta = m.eta.unwrap_or(mat.eta);
    mat.validate()?;
    Ok(mat)
}

/// The renderer's settings for a glTF scene: every primitive of a translucent material (or
/// every one with `--material`, or of a material named by `--gltf-material`) a translucent
/// object, every other one an opaque object (Lambertian, its base colour or texture); the
/// punctual lights; the first perspective camera, or the default framing. glTF's metres are
/// 1000 mm per unit unless `--scale` is typed. Flags typed on the command line (`given`)
/// override the scene as they do a pbrt scene's. Returns the arguments with the image's size
/// filled in from the camera's aspect ratio when it has one.
pub fn render_settings(
    path: &Path,
    args: &crate::cli::RenderArgs,
    given: &dyn Fn(&str) -> bool,
) -> Result<(crate::cli::RenderArgs, crate::settings::RenderSettings)> {
    use crate::scene::{Camera, Light};
    if args.mesh.is_some() {
        return Err(bad_input!("--mesh: a scene file gives its own shapes; leave out --mesh or the scene"));
    }
    let overrides: Vec<(&str, &str)> = args.gltf_material.iter().map(|s| parse_override(s)).collect::<Result<_>>()?;
    let scene = load(path, args.gltf_scene)?;
    for w in &scene.warnings {
        crate::note!("warning: {w}");
    }
    let shown = path.display();
    for (name, preset) in &overrides {
        if !scene.material_names.iter().any(|n| n == name) {
            return Err(bad_input!(
                "--gltf-material {name}={preset}: {shown} has no material named \"{name}\" (its materials: {})",
                scene.material_names.iter().map(|n| format!("\"{n}\"")).collect::<Vec<_>>().join(", ")
            ));
        }
        crate::materials::Material::find(preset).map_err(|_| {
            bad_input!("--gltf-material {name}={preset}: unknown preset; `translucent materials` lists them")
        })?;
    }
    let preset_of = |m: &MaterialDesc| {
        let name = m.name.as_deref()?;
        overrides.iter().rev().find(|(n, _)| *n == name).map(|(_, p)| *p)
    };
    let translucent_material = |m: &MaterialDesc| given("--material") || preset_of(m).is_some() || m.is_translucent();
    let mm_per_unit = if given("--scale") { args.scale } else { MM_PER_METRE };

    // The base settings from the flags, on a stand-in mesh, then the scene's in its place.
    let mut out = args.clone();
    let mut stand_in = args.clone();
    stand_in.mesh = Some("sphere".into());
    let mut settings = crate::settings::RenderSettings::from_args(&stand_in)?;

    let mut objects = Vec::new();
    let mut opaque = Vec::new();
    let mut first_translucent: Option<&MaterialDesc> = None;
    let mut translucent_paths = Vec::new();
    let mut made = std::collections::HashMap::new();
    for o in &scene.objects {
        let desc = &scene.materials[o.material];
        let shown_object = format!("{shown}: {}", o.path);
        let uvs = o.mesh.uvs.clone();
        let mesh = crate::mesh::Mesh::from_raw(o.mesh.clone(), &shown_object, crate::mesh::MeshFormat::Ply)?;
        if translucent_material(desc) {
            first_translucent.get_or_insert(desc);
            translucent_paths.push(&o.path);
            let preset = preset_of(desc);
            // Once per material (its warnings too), however many primitives use it.
            let material = match made.get(&o.material) {
                Some(m) => Clone::clone(m),
                None => {
                    let m = material_of(&shown.to_string(), desc, preset, mm_per_unit, args, given)?;
                    made.insert(o.material, m.clone());
                    m
                }
            };
            // The texture, carried for the shading to use per point, whatever gives the
            // material (not where KHR_materials_volume_scatter's colour gives the reflectance):
            // a preset keeps its mean free path and takes the texture's mean as its albedo.
            let texture = desc.texture.as_ref().filter(|_| desc.multiscatter.is_none());
            let texture = texture.map(|t| crate::world::Reflectance::Image(t.clone()));
            let material = match &texture {
                Some(t) if given("--material") || preset.is_some() => crate::world::textured_material(&material, t)?,
                _ => material,
            };
            let mut object = crate::world::Object::new(mesh, material);
            object.samples = args.samples;
            if texture.is_some() {
                (object.texture, object.uvs) = (texture, uvs);
            }
            objects.push(object);
        } else {
            let reflectance = match &desc.texture {
                Some(t) => crate::world::Reflectance::Image(t.clone()),
                None => crate::world::Reflectance::Constant(Vec3::from(desc.base_color.map(|c| c as f32))),
            };
            opaque.push(crate::world::Opaque { uvs, ..crate::world::Opaque::new(mesh, reflectance) });
        }
    }
    if objects.is_empty() {
        if opaque.is_empty() {
            return Err(bad_input!("{shown}: the scene has no mesh (nothing to render)"));
        }
        crate::note!(
            "warning: {shown}: no translucent material (KHR_materials_volume with a transmission; or --material, --gltf-material): nothing in the scene is translucent; its meshes are rendered opaque"
        );
    }

    // Lights: the file's, unless the flags give some (or it has none: the default light).
    let mut lights: Vec<Light> = scene.lights.iter().map(|l| l.light).collect();
    let flags_light = given("--light") || given("--light-dir") || given("--light-intensity") || given("--env");
    if flags_light || lights.is_empty() {
        if lights.is_empty() && !flags_light {
            crate::note!("warning: {shown}: no KHR_lights_punctual light: the default light is used");
        }
        lights = settings.desc.lights.clone();
    } else {
        settings.desc.environment = None;
    }

    // The camera: the file's, or the default framing of everything drawn.
    let all: Vec<Vec3> = objects
        .iter()
        .flat_map(|o: &crate::world::Object| o.mesh.positions.iter().copied())
        .chain(opaque.iter().flat_map(|o: &crate::world::Opaque| o.mesh.positions.iter().copied()))
        .collect();
    let (centre, radius) = crate::scene::bounding_sphere(&all);
    let mut cam = match &scene.camera {
        Some(c) => {
            // Looking at the point of its axis nearest the scene's centre (at least a radius away).
            let along = (centre.as_dvec3() - c.eye).dot(c.forward).max(radius as f64).max(1e-6);
            Camera {
                eye: c.eye.as_vec3(),
                target: (c.eye + c.forward * along).as_vec3(),
                up: c.up.as_vec3(),
                fov_y_deg: c.yfov_deg as f32,
            }
        }
        None => Camera::framing(centre, radius, args.fov, Vec3::new(0.3, 0.3, 1.0)),
    };
    if let Some(aspect) = scene.camera.as_ref().and_then(|c| c.aspect) {
        match (given("--width"), given("--height")) {
            (false, false) => out.width = ((out.height as f64 * aspect).round() as u32).clamp(1, 1 << 14),
            (true, false) => out.height = ((out.width as f64 / aspect).round() as u32).clamp(1, 1 << 14),
            (false, true) => out.width = ((out.height as f64 * aspect).round() as u32).clamp(1, 1 << 14),
            (true, true) => {}
        }
    }
    (settings.desc.width, settings.desc.height) = (out.width, out.height);
    if given("--eye") || (scene.camera.is_none() && args.eye.is_some()) {
        cam.eye = args.eye.unwrap_or(cam.eye);
    }
    if given("--target") || (scene.camera.is_none() && args.target.is_some()) {
        cam.target = args.target.unwrap_or(cam.target);
    }
    if given("--up") || scene.camera.is_none() {
        cam.up = settings.desc.camera.up;
    }
    if given("--fov") {
        cam.fov_y_deg = args.fov;
    }
    if let Some(m) = first_translucent.filter(|_| !given("--roughness")) {
        // glTF's and ours: GGX α = roughness².
        settings.desc.roughness = (m.roughness as f32).clamp(crate::pbrt::MIN_ROUGHNESS, 1.0);
    }
    crate::frame_desc::check_camera(&cam)?;
    crate::frame_desc::check_lights(&lights)?;
    let mut world = crate::world::World { objects, opaque, mm_per_unit };
    for (o, path) in world.objects.iter().zip(&translucent_paths) {
        crate::world::check_geometry(&o.mesh, mm_per_unit).map_err(|e| bad_input!("{shown}: {path}: {e}"))?;
    }
    if world.objects.is_empty() && world.opaque.is_empty() {
        return Err(bad_input!("{shown}: the scene has no mesh"));
    }
    crate::settings::rescale_world(&mut world, &mut cam, &mut lights);
    settings.world = world;
    (settings.desc.camera, settings.desc.lights) = (cam, lights);
    settings.desc.validate()?;
    settings.world.validate()?;
    Ok((out, settings))
}
