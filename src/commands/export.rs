//! `translucent export mitsuba [render options] --out DIR`: what `render` would draw, as a
//! Mitsuba 3 scene (src/export/mitsuba.rs).

use crate::cli::{MitsubaArgs, ShowArg};
use crate::error::Result;
use crate::export::mitsuba::{self, Camera, Light, Medium, Object, Options, Surface};
use crate::scene;
use crate::settings::RenderSettings;
use crate::{bad_input, runtime};

pub(super) fn mitsuba(args: &MitsubaArgs) -> Result<i32> {
    let dir = &args.render.out;
    let ext = dir.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    if matches!(ext.as_str(), "png" | "exr") || dir.is_file() {
        return Err(bad_input!(
            "--out {}: give the folder to write the scene into (export mitsuba … --out DIR)",
            dir.display()
        ));
    }
    if !(args.light_radius > 0.0 && args.light_radius < 90.0) {
        return Err(bad_input!("--light-radius {}: must be within (0, 90) degrees", args.light_radius));
    }
    let r = &args.render;
    // A scene file (pbrt-v4, glTF) as `render` reads it; `--out` stays the folder.
    let settings = match &r.scene {
        Some(scene) => {
            let argv: Vec<String> = std::env::args().collect();
            crate::settings::scene_file_settings(scene, r, &|f| crate::pbrt::flag_given(&argv, f))?.1
        }
        None => RenderSettings::from_args(r)?,
    };
    if !args.render.no_specular {
        crate::note!(
            "warning: render's microfacet reflection (--roughness) is not exported: Mitsuba's boundary is smooth; compare with --no-specular (scripts/reference then subtracts the boundary's reflection)"
        );
    }
    if r.frames > 1 || r.spin_light != 0.0 || r.deform.is_some() {
        crate::note!("warning: --frames, --spin-light and --deform are not exported: the scene is the first frame's");
    }
    if r.show != ShowArg::Shading {
        crate::note!("warning: --show is not exported: the scene is what the shading draws");
    }
    std::fs::create_dir_all(dir).map_err(|e| bad_input!("--out {}: cannot create the folder: {e}", dir.display()))?;

    let (world, desc) = (&settings.world, &settings.desc);
    let mm = world.mm_per_unit as f64;
    let c = &desc.camera;
    let camera = Camera {
        eye: c.eye.as_dvec3() * mm,
        target: c.target.as_dvec3() * mm,
        up: c.up.as_dvec3(),
        fov_y_deg: c.fov_y_deg as f64,
    };
    // An environment's samples are among the lights: it is exported whole instead.
    let sampled = match &desc.environment {
        Some(env) => env.lights()?.len(),
        None => 0,
    };
    let explicit = &desc.lights[..desc.lights.len().saturating_sub(sampled)];
    let lights: Vec<Light> = explicit.iter().map(|l| light_in_mm(l, mm)).collect();
    let meshes: Vec<_> = world.objects.iter().map(|o| o.world_mesh()).collect();
    let mut objects: Vec<Object> = Vec::new();
    for (o, mesh) in world.objects.iter().zip(&meshes) {
        let m = &o.material;
        let medium = Medium { sigma_a: m.sigma_a, sigma_s: m.sigma_s, g: m.g, eta: m.eta };
        // A texture: the medium's albedo as a volume (its nearest surface point's colour).
        let surface = match (&o.texture, &o.uvs) {
            (Some(texture), Some(uvs)) => {
                let albedo = mitsuba::albedo_grid(mesh, uvs, texture, &medium, mm, 128)?;
                Surface::TexturedTranslucent { medium, albedo }
            }
            _ => Surface::Translucent(medium),
        };
        objects.push(Object { name: m.name.clone(), mesh, mm_per_unit: mm, surface });
    }
    // Opaque objects (a scene file's `diffuse` shapes): Lambertian; a textured reflectance is
    // written as its mean, with a warning.
    let opaque_meshes: Vec<_> = world.opaque.iter().map(|o| o.world_mesh()).collect();
    for (k, (o, mesh)) in world.opaque.iter().zip(&opaque_meshes).enumerate() {
        if !matches!(o.reflectance, crate::world::Reflectance::Constant(_)) {
            crate::note!("warning: opaque object {k}: its textured reflectance is exported as its mean");
        }
        let reflectance = o.reflectance.mean().as_dvec3().to_array();
        objects.push(Object {
            name: format!("opaque {k}"),
            mesh,
            mm_per_unit: mm,
            surface: Surface::Diffuse { reflectance },
        });
    }
    let material_name =
        world.objects.first().map_or("none (opaque objects only)".to_string(), |o| o.material.name.clone());
    let options = Options {
        width: desc.width,
        height: desc.height,
        spp: args.spp,
        light_radius_deg: args.light_radius as f64,
        ..Options::default()
    };
    let written = mitsuba::write_scene(dir, &camera, (&lights, desc.environment.as_deref()), &objects, &options)?;
    for w in &written.warnings {
        crate::note!("warning: {w}");
    }
    // What scripts/reference needs to know: the size, and whether the boundary's reflection is to
    // be subtracted (render --no-specular draws the subsurface term alone).
    let command: Vec<String> = std::env::args().collect();
    let info = serde_json::json!({
        "scene": "scene.xml",
        "width": desc.width,
        "height": desc.height,
        "spp": args.spp,
        "subsurface_only": r.no_specular,
        "light_radius_deg": args.light_radius,
        "material": material_name,
        "command": command.join(" "),
    });
    let info_path = dir.join("reference.json");
    let text = serde_json::to_string_pretty(&info).map_err(|e| runtime!("JSON: {e}"))? + "\n";
    crate::output::write_file(&info_path, text.as_bytes())?;
    let directional = lights.iter().filter(|l| matches!(l, Light::Directional { .. })).count();
    let mut out = format!("wrote {}\n", written.scene.display());
    for p in written.meshes.iter().chain(std::iter::once(&info_path)) {
        out += &format!("wrote {}\n", p.display());
    }
    if directional > 0 {
        out += &format!(
            "{directional} directional light(s) written as far disks of angular radius {}° (radiance E/(π sin²δ): irradiance E at normal incidence): a delta light behind a smooth dielectric is black in Mitsuba's unidirectional integrators\n",
            args.light_radius
        );
    }
    crate::error::write_stdout(&out)?;
    Ok(0)
}

/// A light of the scene in mm: positions × mm per unit, point and spot intensities × (mm per unit)² (the
/// renderer's E = I / d² takes d in scene units).
pub fn light_in_mm(light: &scene::Light, mm: f64) -> Light {
    let v = |v: glam::Vec3| [v.x as f64, v.y as f64, v.z as f64];
    match *light {
        scene::Light::Directional { toward, irradiance } => {
            Light::Directional { toward: toward.as_dvec3(), irradiance: v(irradiance) }
        }
        scene::Light::Point { position, intensity } => {
            Light::Point { position: position.as_dvec3() * mm, intensity: v(intensity).map(|i| i * mm * mm) }
        }
        scene::Light::Spot { position, axis, intensity, cone_deg, delta_deg } => Light::Spot {
            position: position.as_dvec3() * mm,
            axis: axis.as_dvec3(),
            intensity: v(intensity).map(|i| i * mm * mm),
            cone_deg: cone_deg as f64,
            delta_deg: delta_deg as f64,
        },
    }
}
