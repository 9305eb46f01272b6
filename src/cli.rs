//! The command line: `translucent render | devices | …`. Parsing only; work is done by the library.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use glam::Vec3;

use crate::error::Result;
use crate::frame::Renderer;
use crate::mesh::Mesh;
use crate::output::{self, Exposure};
use crate::scene::{Camera, Light, Scene};
use crate::vk::{self, Context, ContextOptions};
use crate::{bad_input, runtime};

#[derive(Parser, Debug)]
#[command(name = "translucent", version, about = "Subsurface scattering with the directional dipole on Vulkan")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene to an image (PNG: tone-mapped sRGB; EXR: linear radiance).
    Render(Box<RenderArgs>),
    /// List the Vulkan devices with their type, driver, API version and timestamp support.
    Devices,
}

/// Options shared by every command that creates a Vulkan device.
#[derive(Args, Debug, Clone)]
pub struct DeviceArgs {
    /// Device to use: an index from `translucent devices` or a substring of its name.
    #[arg(long, value_name = "INDEX|NAME")]
    pub device: Option<String>,
    /// Enable VK_LAYER_KHRONOS_validation with synchronization validation; any warning or error
    /// makes the exit code non-zero. Also enabled by TRANSLUCENT_VALIDATION=1.
    #[arg(long)]
    pub validation: bool,
}

impl DeviceArgs {
    pub fn options(&self) -> ContextOptions {
        let from_env = std::env::var("TRANSLUCENT_VALIDATION").map(|v| v != "0" && !v.is_empty()).unwrap_or(false);
        ContextOptions { validation: self.validation || from_env, device: self.device.clone() }
    }
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Mesh: `sphere`, `box`, `slab`, `torus`, or the path of an OBJ file.
    #[arg(long, default_value = "sphere")]
    pub mesh: String,
    /// Output image; the extension picks the format (.png or .exr).
    #[arg(long, short, default_value = "out.png")]
    pub out: PathBuf,
    #[arg(long, allow_hyphen_values = true, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    #[arg(long, allow_hyphen_values = true, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Frames to render (for timing; the image is the last frame).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: u32,
    /// Millimetres per scene unit (materials are given per mm).
    #[arg(long, allow_hyphen_values = true, default_value_t = 10.0, value_parser = positive_f32)]
    pub scale: f32,
    /// Camera position (default: framing the mesh).
    #[arg(long, allow_hyphen_values = true, value_parser = vec3, value_name = "X,Y,Z")]
    pub eye: Option<Vec3>,
    /// Point the camera looks at (default: the mesh's centre).
    #[arg(long, allow_hyphen_values = true, value_parser = vec3, value_name = "X,Y,Z")]
    pub target: Option<Vec3>,
    #[arg(long, allow_hyphen_values = true, value_parser = vec3, value_name = "X,Y,Z", default_value = "0,1,0")]
    pub up: Vec3,
    /// Vertical field of view in degrees.
    #[arg(long, allow_hyphen_values = true, default_value_t = 40.0, value_parser = finite_f32)]
    pub fov: f32,
    /// Direction toward the directional light.
    #[arg(long, allow_hyphen_values = true, value_parser = vec3, value_name = "X,Y,Z", default_value = "-0.5,0.8,0.6")]
    pub light_dir: Vec3,
    /// Irradiance at normal incidence: one value or R,G,B.
    #[arg(long, allow_hyphen_values = true, value_parser = rgb, value_name = "I|R,G,B", default_value = "1")]
    pub light_intensity: Vec3,
    /// Exposure in stops (default: automatic from the image).
    #[arg(long, allow_hyphen_values = true, value_parser = finite_f32)]
    pub exposure: Option<f32>,
    /// Print per-pass GPU times (mean, min, max, share of the frame).
    #[arg(long)]
    pub profile: bool,
    /// Write the GPU timings as Chrome trace-event JSON (opens in Perfetto / chrome://tracing).
    #[arg(long, value_name = "FILE.json")]
    pub profile_out: Option<PathBuf>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

fn finite_f32(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s.trim().parse().map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() {
        return Err(format!("'{s}' is not finite"));
    }
    Ok(v)
}

fn positive_f32(s: &str) -> std::result::Result<f32, String> {
    let v = finite_f32(s)?;
    if v <= 0.0 {
        return Err(format!("'{s}' must be positive"));
    }
    Ok(v)
}

fn numbers(s: &str) -> std::result::Result<Vec<f32>, String> {
    s.split(',').map(finite_f32).collect()
}

fn vec3(s: &str) -> std::result::Result<Vec3, String> {
    match numbers(s)?.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(format!("'{s}' is not three comma-separated numbers X,Y,Z")),
    }
}

fn rgb(s: &str) -> std::result::Result<Vec3, String> {
    let v = match numbers(s)?.as_slice() {
        [i] => Vec3::splat(*i),
        [r, g, b] => Vec3::new(*r, *g, *b),
        _ => return Err(format!("'{s}' is neither one number nor R,G,B")),
    };
    if v.min_element() < 0.0 {
        return Err(format!("'{s}' must not be negative"));
    }
    Ok(v)
}

/// Runs a parsed command; `Ok(code)` is the exit code when it finished without an error.
pub fn run(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Render(args) => render(&args),
        Command::Devices => devices(),
    }
}

fn devices() -> Result<i32> {
    let list = vk::list_devices()?;
    println!("{:<5} {:<40} {:<15} {:<9} {:<10} driver", "index", "name", "type", "api", "timestamps");
    for d in list {
        let usable = match &d.usable {
            Ok(()) => String::new(),
            Err(why) => format!("  (unusable: {why})"),
        };
        println!(
            "{:<5} {:<40} {:<15} {:<9} {:<10} {}{usable}",
            d.index,
            d.name,
            d.type_name(),
            d.api_string(),
            if d.timestamps { "yes" } else { "no" },
            d.driver
        );
    }
    Ok(0)
}

pub fn build_scene(args: &RenderArgs) -> Result<Scene> {
    let mesh = Mesh::from_spec(&args.mesh)?;
    let (centre, radius) = crate::scene::bounding_sphere(&mesh.positions);
    let mut camera = Camera::framing(centre, radius, args.fov, Vec3::new(0.3, 0.3, 1.0));
    camera.up = args.up;
    if let Some(target) = args.target {
        camera.target = target;
    }
    if let Some(eye) = args.eye {
        camera.eye = eye;
    }
    let lights = vec![Light::Directional { toward: args.light_dir, irradiance: args.light_intensity }];
    let scene = Scene { mesh, camera, lights, mm_per_unit: args.scale };
    scene.validate()?;
    Ok(scene)
}

fn check_output_path(path: &std::path::Path, flag: &str, allowed: &[&str]) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    if !allowed.contains(&ext.as_str()) {
        return Err(bad_input!("{flag} {}: the extension must be one of .{}", path.display(), allowed.join(", .")));
    }
    Ok(())
}

fn render(args: &RenderArgs) -> Result<i32> {
    // Check everything the user typed before the (slow) device start.
    check_output_path(&args.out, "--out", &["png", "exr"])?;
    if let Some(p) = &args.profile_out {
        check_output_path(p, "--profile-out", &["json"])?;
    }
    let scene = build_scene(args)?;
    let ctx = Context::new(&args.device.options())?;
    let counts = ctx.validation_counts();
    let validating = ctx.validation;
    let profiling = args.profile || args.profile_out.is_some();
    let device_name = format!("{} ({})", ctx.info.name, ctx.info.driver);

    let mut renderer = Renderer::new(ctx, &scene, args.width, args.height, profiling)?;
    let mut frames = Vec::new();
    for _ in 0..args.frames {
        frames.push(renderer.render_frame(&scene)?);
    }
    let image = renderer.image()?;
    drop(renderer);

    let exposure = args.exposure.map(Exposure::Stops).unwrap_or(Exposure::Auto);
    output::write_image(&args.out, &image, exposure)?;
    eprintln!("wrote {} ({}x{}, {} frame(s))", args.out.display(), args.width, args.height, args.frames);

    if profiling && frames.iter().any(|f| !f.is_empty()) {
        report_profile(&device_name, frames, args)?;
    }
    Ok(validation_exit_code(validating, &counts))
}

fn report_profile(device: &str, frames: Vec<Vec<vk::TimedScope>>, args: &RenderArgs) -> Result<()> {
    use crate::profiling::{ProfileReport, Scope};
    let report = ProfileReport {
        device: device.to_string(),
        frames: frames
            .into_iter()
            .map(|f| f.into_iter().map(|s| Scope { name: s.name, begin_ns: s.begin_ns, end_ns: s.end_ns }).collect())
            .collect(),
    };
    if args.profile {
        print!("{}", crate::profiling::format_table(&report));
    }
    if let Some(path) = &args.profile_out {
        std::fs::write(path, crate::profiling::chrome_trace_json(&report))
            .map_err(|e| runtime!("--profile-out {}: {e}", path.display()))?;
    }
    Ok(())
}

/// Exit code 1 (with a summary on stderr) when the validation layer reported anything.
pub fn validation_exit_code(validating: bool, counts: &vk::ValidationCounts) -> i32 {
    use std::sync::atomic::Ordering;
    let (w, e) = (counts.warnings.load(Ordering::SeqCst), counts.errors.load(Ordering::SeqCst));
    if w + e > 0 {
        eprintln!("error: validation reported {e} error(s) and {w} warning(s)");
        return 1;
    }
    if validating {
        log::info!("validation: no messages");
    }
    0
}
