//! `translucent bench`: GPU time per pass (timestamps) as Markdown tables:
//! 1. every pass of the frame for several sample counts and meshes, with the shading work per
//!    pixel and peak memory;
//! 2. the hierarchy against brute force (speed-up of the shade pass and relative RMSE);
//! 3. an epsilon sweep (shade time and error), which justifies the default.
//!
//! Frame 1 of each configuration warms the pipelines up; tables report the mean over the rest.

use glam::Vec3;

use crate::error::Result;
use crate::frame::Renderer;
use crate::frame_desc::{Integration, DEFAULT_EPSILON};
use crate::gpu::WorkCounters;
use crate::hierarchy;
use crate::mesh::Mesh;
use crate::output::{relative_rmse, HdrImage};
use crate::profiling::{summary, PassStats, ProfileReport};
use crate::scene::{bounding_sphere, Camera, Light, Scene};
use crate::settings::RenderSettings;
use crate::vk::{Context, ContextOptions};

pub struct BenchOptions {
    pub meshes: Vec<String>,
    pub samples: Vec<u32>,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    /// Image size (square) of the brute-force comparison and the epsilon sweep; 0 skips them.
    pub accuracy_size: u32,
    /// Sample counts of the brute-force comparison.
    pub accuracy_samples: Vec<u32>,
    pub epsilons: Vec<f32>,
    /// Light counts of the lights table; empty leaves it out.
    pub lights: Vec<u32>,
    /// Image size (square) of the pbrt-v2 comparison; 0 skips it.
    pub peer_size: u32,
    /// Image size (square) of the several-object scene; 0 skips it.
    pub scene_size: u32,
    pub context: ContextOptions,
}

/// pbrt-v2's DipoleSubsurfaceIntegrator (Jensen–Buhler octree, CPU) on this machine kind (2 cores):
/// a 10 mm skin1 sphere at 512×512 and 4 samples per pixel, about 3,100 irradiance points,
/// maxerror 0.05, in 15.5 s for 764,696 lookups (issue #10).
const PBRT_V2_SECONDS: f64 = 15.5;
const PBRT_V2_LOOKUPS: f64 = 764_696.0;

/// pbrt-v2's scene: a 256×128 UV sphere of radius 1 (10 mm), skin1 with the classical dipole, a
/// distant light toward (0.5, 1, 1) with L = 3, camera at (0, 0, 4) looking at the origin, fov 30°.
fn peer_scene() -> Scene {
    let camera = Camera { eye: Vec3::new(0.0, 0.0, 4.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 30.0 };
    let toward = Vec3::new(0.333_333_3, 0.666_666_7, 0.666_666_7);
    let lights = vec![Light::Directional { toward, irradiance: Vec3::splat(3.0) }];
    Scene { mesh: Mesh::sphere(1.0, 128), camera, lights, mm_per_unit: 10.0 }
}

/// The pbrt-v2 comparison: the whole frame (rebuild included) at `size`², its lookups (shaded
/// pixels) per second against pbrt-v2's, and the tree's error against brute force at the same
/// settings (the same size, points and ε).
fn peer_comparison(options: &BenchOptions) -> Result<String> {
    let size = options.peer_size;
    let scene = peer_scene();
    let material = crate::materials::Material::find("skin1")?;
    let model = crate::physics::Model::Dipole;
    let (n, epsilon) = (3100, 0.05);
    let started = std::time::Instant::now();
    let run = run_with(&options.context, &scene, (&material, model), n, (size, size), 2, epsilon, false, false)?;
    let wall = started.elapsed().as_secs_f64();
    let frame_s = pass_ms(&run, "frame") / 1e3;
    let lookups = run.work.pixels as f64;
    let per_pixel = |sum: u32| if run.work.pixels > 0 { sum as f64 / lookups } else { 0.0 };
    let pbrt_rate = PBRT_V2_LOOKUPS / PBRT_V2_SECONDS;
    let rate = lookups / frame_s;
    // One frame of brute force: only its image is used.
    let brute = run_with(&options.context, &scene, (&material, model), n, (size, size), 1, epsilon, true, false)?;
    crate::note!("bench: pbrt-v2 scene done");
    Ok(format!(
        "\n### Against pbrt-v2\n\npbrt-v2's dipole integrator scene (10 mm skin1 sphere, classical dipole, {n} points, ε = {epsilon}); pbrt-v2: {PBRT_V2_LOOKUPS} lookups in {PBRT_V2_SECONDS} s on this machine kind ({pbrt_rate:.0}/s). Frame: GPU timestamps of one frame after a warm-up, rebuild included; process: both frames, context and pipelines included.\n\n| size | lookups | frame s | lookups/s | × pbrt-v2 | nodes visited/px | Sd evaluations/px | process s | relative RMSE vs brute force (same settings) |\n|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n| {size}² | {lookups:.0} | {frame_s:.2} | {rate:.0} | {:.2}× | {:.1} | {:.1} | {wall:.1} | {:.3}% |\n",
        rate / pbrt_rate,
        per_pixel(run.work.node_sum),
        per_pixel(run.work.evaluation_sum),
        100.0 * relative_rmse(&run.image.pixels, &brute.image.pixels)
    ))
}

/// The default scene's set-up (back-lit marble) for `mesh`.
fn scene(spec: &str) -> Result<Scene> {
    let mesh = Mesh::from_spec(spec)?;
    let (centre, radius) = bounding_sphere(&mesh.positions);
    let camera = Camera::framing(centre, radius, 40.0, Vec3::new(0.3, 0.3, 1.0));
    let lights = vec![Light::Directional { toward: Vec3::new(-0.3, 0.7, -0.65), irradiance: Vec3::ONE }];
    Ok(Scene { mesh, camera, lights, mm_per_unit: 10.0 })
}

struct Run {
    device: String,
    passes: Vec<PassStats>,
    work: WorkCounters,
    image: HdrImage,
}

/// Renders `frames` frames (the first a warm-up) and returns the mean pass times of the rest.
#[allow(clippy::too_many_arguments)]
fn run_one(
    context: &ContextOptions,
    scene: &Scene,
    n: u32,
    size: (u32, u32),
    frames: u32,
    epsilon: f32,
    brute_force: bool,
    specular: bool,
) -> Result<Run> {
    let material = crate::materials::Material::find("marble")?;
    let model = crate::physics::Model::Directional;
    run_with(context, scene, (&material, model), n, size, frames, epsilon, brute_force, specular)
}

/// `run_one` with a material and model of its own.
#[allow(clippy::too_many_arguments)]
fn run_with(
    context: &ContextOptions,
    scene: &Scene,
    (material, model): (&crate::materials::Material, crate::physics::Model),
    n: u32,
    size: (u32, u32),
    frames: u32,
    epsilon: f32,
    brute_force: bool,
    specular: bool,
) -> Result<Run> {
    let ctx = Context::new(context)?;
    let device = format!("{} ({})", ctx.info.name, ctx.info.driver);
    let RenderSettings { mut world, mut desc, profile } = RenderSettings::new(scene.clone(), material.clone());
    world.objects[0].samples = Some(n);
    desc.integration = Integration { model, epsilon, brute_force, ..desc.integration };
    (desc.specular, desc.width, desc.height, desc.count_work) = (specular, size.0, size.1, true);
    let mut renderer = Renderer::new(ctx, profile)?;
    let mut timed = Vec::new();
    for _ in 0..frames.max(2) {
        timed.push(renderer.render_frame(&world, &desc)?);
    }
    timed.remove(0);
    let passes = summary(&ProfileReport::from_frames(&device, timed));
    Ok(Run { device, passes, work: renderer.work()?, image: renderer.image()? })
}

fn pass_ms(run: &Run, name: &str) -> f64 {
    run.passes.iter().find(|p| p.name == name).map(|p| p.mean_ms).unwrap_or(0.0)
}

/// Peak resident memory of this process (VmHWM) in MiB; on lavapipe GPU memory is host memory.
fn peak_rss_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

fn mesh_name(spec: &str) -> &str {
    std::path::Path::new(spec).file_stem().and_then(|s| s.to_str()).unwrap_or(spec)
}

pub fn run(options: &BenchOptions) -> Result<String> {
    // Everything the user typed is checked before the first (long) configuration runs.
    {
        let ctx = Context::new(&options.context)?;
        for &n in options.samples.iter().chain(&options.accuracy_samples) {
            hierarchy::check_point_count(&ctx, n, 1)?;
            let sizes = crate::budget::FrameSizes {
                width: options.width,
                height: options.height,
                shadow_resolution: 1024,
                shadow_layers: 2,
                point_count: n,
                per_light_count: 1,
            };
            crate::budget::check_frame(&ctx, &sizes)?;
        }
        if let Some(e) = options.epsilons.iter().find(|e| !(e.is_finite() && **e >= 0.0)) {
            return Err(crate::bad_input!("--epsilons: {e} must be a finite number ≥ 0"));
        }
        for spec in &options.meshes {
            Mesh::from_spec(spec)?;
        }
    }
    let mut out = String::new();
    let per_pixel = |w: &WorkCounters, sum: u32| if w.pixels > 0 { sum as f64 / w.pixels as f64 } else { 0.0 };

    // 1. Every pass, per mesh and sample count.
    let mut header_done = false;
    for spec in &options.meshes {
        let scene = scene(spec)?;
        for &n in &options.samples {
            let size = (options.width, options.height);
            // An error (a bad --device, too many --samples for the device) ends the command with
            // its exit code, rather than becoming a row of the table.
            let run = run_one(&options.context, &scene, n, size, options.frames, DEFAULT_EPSILON, false, true)?;
            if !header_done {
                out += &format!(
                    "### Every pass\n\nDevice: {}; {}x{}, back-lit marble, directional dipole, ε = {DEFAULT_EPSILON}; mean of {} frame(s) after one warm-up frame. Peak RSS is the process's high-water mark so far (on lavapipe GPU memory is host memory).\n\n",
                    run.device,
                    options.width,
                    options.height,
                    options.frames.max(2) - 1
                );
                out += "| mesh | points | ";
                out += &run.passes.iter().map(|r| format!("{} ms", r.name)).collect::<Vec<_>>().join(" | ");
                out += " | nodes/px | points/px | hierarchy MiB | peak RSS MiB |\n|---|---:|";
                out += &"---:|".repeat(run.passes.len() + 4);
                out += "\n";
                header_done = true;
            }
            out += &format!("| {} | {n} | ", mesh_name(spec));
            out += &run.passes.iter().map(|r| format!("{:.2}", r.mean_ms)).collect::<Vec<_>>().join(" | ");
            out += &format!(
                " | {:.1} | {:.1} | {:.1} | {:.0} |\n",
                per_pixel(&run.work, run.work.node_sum),
                per_pixel(&run.work, run.work.point_sum),
                hierarchy::bytes_used(n, 1) as f64 / (1 << 20) as f64,
                peak_rss_mib().unwrap_or(f64::NAN)
            );
            crate::note!("bench: {} N={n} done", mesh_name(spec));
        }
    }
    if options.accuracy_size == 0 {
        if options.peer_size > 0 {
            out += &peer_comparison(options)?;
        }
        if options.scene_size > 0 {
            out += &scene_of_objects(options)?;
        }
        return Ok(out);
    }

    // 2. The hierarchy against brute force, and 3. the epsilon sweep, on the first mesh.
    let spec = &options.meshes[0];
    let scene = scene(spec)?;
    let size = (options.accuracy_size, options.accuracy_size);
    out += &format!(
        "\n### Hierarchy against brute force\n\n{} at {s}x{s}, subsurface term only, ε = {DEFAULT_EPSILON}; shade pass time (mean of {} frame(s) after a warm-up), relative RMSE over covered pixels.\n\n| points | brute force ms | hierarchy ms | speed-up | BSSRDF evaluations/px (brute / tree) | nodes visited/px | relative RMSE |\n|---:|---:|---:|---:|---:|---:|---:|\n",
        mesh_name(spec),
        options.frames.max(2) - 1,
        s = options.accuracy_size
    );
    let mut sweep_reference = None;
    for &n in &options.accuracy_samples {
        let brute = run_one(&options.context, &scene, n, size, options.frames, DEFAULT_EPSILON, true, false)?;
        let tree = run_one(&options.context, &scene, n, size, options.frames, DEFAULT_EPSILON, false, false)?;
        let (b, t) = (pass_ms(&brute, "shade"), pass_ms(&tree, "shade"));
        let tree_evaluations = per_pixel(&tree.work, tree.work.evaluation_sum);
        out += &format!(
            "| {n} | {b:.1} | {t:.1} | {:.1}× | {:.0} / {:.0} | {:.1} | {:.3}% |\n",
            b / t,
            per_pixel(&brute.work, brute.work.evaluation_sum),
            tree_evaluations,
            per_pixel(&tree.work, tree.work.node_sum),
            100.0 * relative_rmse(&tree.image.pixels, &brute.image.pixels)
        );
        crate::note!("bench: brute force N={n} done");
        if sweep_reference.is_none() {
            sweep_reference = Some((n, brute));
        }
    }
    if let Some((n, brute)) = sweep_reference {
        out += &format!(
            "\n### Epsilon sweep\n\n{} at {s}x{s}, {n} points, subsurface term only; brute force shades in {:.1} ms.\n\n| ε | shade ms | nodes visited/px | points evaluated/px | Sd evaluations/px | relative RMSE |\n|---:|---:|---:|---:|---:|---:|\n",
            mesh_name(spec),
            pass_ms(&brute, "shade"),
            s = options.accuracy_size
        );
        for &eps in &options.epsilons {
            let tree = run_one(&options.context, &scene, n, size, options.frames, eps, false, false)?;
            out += &format!(
                "| {eps} | {:.1} | {:.1} | {:.1} | {:.1} | {:.3}% |\n",
                pass_ms(&tree, "shade"),
                per_pixel(&tree.work, tree.work.node_sum),
                per_pixel(&tree.work, tree.work.point_sum),
                per_pixel(&tree.work, tree.work.evaluation_sum),
                100.0 * relative_rmse(&tree.image.pixels, &brute.image.pixels)
            );
            crate::note!("bench: epsilon {eps} done");
        }
        // 4. Cost against the number of lights: every light in one merged record per point and
        // node; the error against exact per-light brute force at a smaller size (brute force
        // costs pixels × points × lights), up to 64 lights. Only the counts asked for: 256
        // lights' shadow maps dominate a small bench.
        let e = options.accuracy_size.min(32);
        // The sky in as many directions as the most lights asked for, at most 64 (the default's).
        let directions = options.lights.iter().copied().max().unwrap_or(0).min(64);
        let cases: Vec<(String, Vec<Light>)> = if options.lights.is_empty() {
            Vec::new()
        } else {
            let sky = crate::environment::Environment {
                name: "sky".into(),
                radiance: crate::environment::sky(30.0, 30.0),
                scale: 1.0,
                to_world: glam::Mat3::IDENTITY,
                samples: directions,
            };
            options
                .lights
                .iter()
                .map(|&k| (k.to_string(), spiral_lights(k as usize)))
                .chain(std::iter::once((format!("sky, {directions} directions"), sky.lights()?)))
                .collect()
        };
        if !cases.is_empty() {
            out += &format!(
                "\n### Lights\n\n{} at {s}x{s}, {n} points, ε = {DEFAULT_EPSILON}, subsurface term only; directional lights on a spiral over the upper hemisphere (total irradiance 1), or a synthetic sky (`--env sky`) in {directions} directions. Error: relative RMSE at {e}x{e} against brute force, which sums every (point, light) pair exactly.\n\n| lights | shade ms | Sd evaluations/px | error against exact |\n|---:|---:|---:|---:|\n",
                mesh_name(spec),
                s = options.accuracy_size
            );
        }
        for (name, lights) in cases {
            let mut lit = scene.clone();
            lit.lights = lights;
            let run = run_one(&options.context, &lit, n, size, options.frames, DEFAULT_EPSILON, false, false)?;
            let error = if lit.lights.len() <= 64 && e > 0 {
                let tree = run_one(&options.context, &lit, n, (e, e), 1, DEFAULT_EPSILON, false, false)?;
                let exact = run_one(&options.context, &lit, n, (e, e), 1, DEFAULT_EPSILON, true, false)?;
                format!("{:.3}%", 100.0 * relative_rmse(&tree.image.pixels, &exact.image.pixels))
            } else {
                "—".to_string()
            };
            out += &format!(
                "| {name} | {:.1} | {:.1} | {error} |\n",
                pass_ms(&run, "shade"),
                per_pixel(&run.work, run.work.evaluation_sum)
            );
            crate::note!("bench: {name} light(s) done");
        }
    }
    // 5. The peer users would pick instead.
    if options.peer_size > 0 {
        out += &peer_comparison(options)?;
    }
    // 6. A scene of several objects, translucent and opaque.
    if options.scene_size > 0 {
        out += &scene_of_objects(options)?;
    }
    Ok(out)
}

/// The first mesh in marble and a skin sphere beside it on an opaque checkerboard floor, under
/// the default back light and a light from the front: every pass at `scene_size`².
fn scene_of_objects(options: &BenchOptions) -> Result<String> {
    use crate::frame_desc::FrameDesc;
    use crate::world::{Object, Opaque, Reflectance, World};
    let spec = &options.meshes[0];
    let mesh = Mesh::from_spec(spec)?;
    let (lo, hi) = mesh.bounds();
    let (centre, radius) = bounding_sphere(&mesh.positions);
    let marble = Object::new(mesh, crate::materials::Material::find("marble")?);
    let mut skin = Object::new(Mesh::sphere(0.5 * radius, 48), crate::materials::Material::find("skin1")?);
    skin.transform = glam::Mat4::from_translation(Vec3::new(hi.x + 0.7 * radius, lo.y + 0.5 * radius, centre.z));
    let side = 8.0 * radius;
    let floor_mesh = Mesh {
        positions: [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(x, z)| Vec3::new(centre.x + x * side, lo.y, centre.z + z * side))
            .to_vec(),
        normals: vec![Vec3::Y; 4],
        indices: vec![0, 2, 1, 0, 3, 2],
    };
    let mut floor = Opaque::new(
        floor_mesh,
        Reflectance::Checkerboard { uscale: 16.0, vscale: 16.0, tex1: Vec3::splat(0.1), tex2: Vec3::splat(0.7) },
    );
    floor.uvs = Some([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(u, v)| glam::Vec2::new(u, v)).to_vec());
    let world = World { objects: vec![marble, skin], opaque: vec![floor], mm_per_unit: 10.0 };
    let camera = Camera::framing(centre, 1.6 * radius, 40.0, Vec3::new(0.4, 0.35, 1.0));
    let lights = vec![
        Light::Directional { toward: Vec3::new(-0.3, 0.7, -0.65), irradiance: Vec3::ONE },
        Light::Directional { toward: Vec3::new(0.5, 0.8, 0.6), irradiance: Vec3::splat(0.5) },
    ];
    let mut desc = FrameDesc::new(camera, lights);
    (desc.width, desc.height) = (options.scene_size, options.scene_size);
    let ctx = Context::new(&options.context)?;
    let device = format!("{} ({})", ctx.info.name, ctx.info.driver);
    let mut renderer = Renderer::new(ctx, true)?;
    let mut timed = Vec::new();
    for _ in 0..options.frames.max(2) {
        timed.push(renderer.render_frame(&world, &desc)?);
    }
    timed.remove(0);
    let points = renderer.point_counts();
    let passes = summary(&ProfileReport::from_frames(&device, timed));
    let mut out = format!(
        "\n### A scene of several objects\n\nDevice: {device}; {s}x{s}: {} in marble and a skin sphere (translucent, {} points), on an opaque checkerboard floor, two directional lights; mean of {} frame(s) after a warm-up.\n\n| pass | ms | share |\n|---|---:|---:|\n",
        mesh_name(spec),
        points.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" and "),
        options.frames.max(2) - 1,
        s = options.scene_size
    );
    for p in &passes {
        out += &format!("| {} | {:.1} | {:.0}% |\n", p.name, p.mean_ms, 100.0 * p.share);
    }
    crate::note!("bench: the scene of several objects done");
    Ok(out)
}

/// `count` directional lights on a golden-angle spiral over the upper hemisphere (the default
/// back light's side first), of total irradiance 1.
fn spiral_lights(count: usize) -> Vec<Light> {
    (0..count)
        .map(|k| {
            let y = 1.0 - (k as f32 + 0.5) / count as f32 * 0.9; // from near the zenith to 6° up
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = k as f32 * 2.399_963 + 3.6; // the golden angle; 3.6 rad: behind, as the default light
            Light::Directional {
                toward: Vec3::new(r * phi.cos(), y, r * phi.sin()),
                irradiance: Vec3::ONE / count as f32,
            }
        })
        .collect()
}
