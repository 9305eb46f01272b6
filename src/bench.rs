//! `translucent bench`: GPU time per pass (timestamps) for several sample counts and meshes, as a
//! Markdown table. Frame 1 warms the pipelines up; the table reports the mean over the rest.

use glam::Vec3;

use crate::error::Result;
use crate::frame::{FrameOptions, Renderer, Show, SubsurfaceOptions};
use crate::hierarchy::{self, HierarchyOptions};
use crate::mesh::Mesh;
use crate::profiling::{summary, ProfileReport, Scope};
use crate::scene::{bounding_sphere, Camera, Light, Scene};
use crate::vk::{Context, ContextOptions};

pub struct BenchOptions {
    pub meshes: Vec<String>,
    pub samples: Vec<u32>,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub context: ContextOptions,
}

pub fn run(options: &BenchOptions) -> Result<String> {
    let mut out = String::new();
    let mut header_done = false;
    for spec in &options.meshes {
        let mesh = Mesh::from_spec(spec)?;
        let (centre, radius) = bounding_sphere(&mesh.positions);
        let camera = Camera::framing(centre, radius, 40.0, Vec3::new(0.3, 0.3, 1.0));
        let lights = vec![Light::Directional { toward: Vec3::new(-0.5, 0.8, 0.6), irradiance: Vec3::ONE }];
        let scene = Scene { mesh, camera, lights, mm_per_unit: 10.0 };
        for &n in &options.samples {
            let ctx = Context::new(&options.context)?;
            let device = format!("{} ({})", ctx.info.name, ctx.info.driver);
            if hierarchy::check_point_count(&ctx, n).is_err() {
                out += &format!("| {spec} | {n} | — exceeds this device's storage-buffer range |\n");
                continue;
            }
            let frame_options = FrameOptions {
                subsurface: SubsurfaceOptions {
                    material: crate::materials::Material::find("marble")?,
                    model: crate::physics::Model::Directional,
                    diffusion: crate::physics::Diffusion::Classical,
                    epsilon: 0.1,
                    brute_force: false,
                    specular: true,
                    roughness: 0.35,
                },
                width: options.width,
                height: options.height,
                profile: true,
                count_work: false,
                hierarchy: HierarchyOptions { point_count: n, shadow_resolution: 1024, eta: 1.3 },
                show: Show::Shading,
                exposure: crate::output::Exposure::Auto,
            };
            let mut renderer = Renderer::new(ctx, &scene, frame_options)?;
            let mut frames = Vec::new();
            for _ in 0..options.frames.max(2) {
                let scopes = renderer.render_frame(&scene)?;
                frames.push(
                    scopes
                        .into_iter()
                        .map(|s| Scope { name: s.name, begin_ns: s.begin_ns, end_ns: s.end_ns })
                        .collect(),
                );
            }
            frames.remove(0);
            let rows = summary(&ProfileReport { device: device.clone(), frames });
            if !header_done {
                out += &format!(
                    "Device: {device}; {}x{}, mean of {} frames after one warm-up frame.\n\n",
                    options.width,
                    options.height,
                    options.frames.max(2) - 1
                );
                out += "| mesh | points | ";
                out += &rows.iter().map(|r| format!("{} ms", r.name)).collect::<Vec<_>>().join(" | ");
                out += " | hierarchy MiB |\n|---|---:|";
                out += &"---:|".repeat(rows.len() + 1);
                out += "\n";
                header_done = true;
            }
            let name = std::path::Path::new(spec).file_stem().and_then(|s| s.to_str()).unwrap_or(spec);
            out += &format!("| {name} | {n} | ");
            out += &rows.iter().map(|r| format!("{:.2}", r.mean_ms)).collect::<Vec<_>>().join(" | ");
            out += &format!(" | {:.1} |\n", hierarchy::bytes_used(n) as f64 / (1 << 20) as f64);
            eprintln!("bench: {name} N={n} done");
        }
    }
    Ok(out)
}
