//! The command line: `translucent render | devices | …`. Parsing only; work is done by the library.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use glam::Vec3;

use crate::error::Result;
use crate::frame::{FrameOptions, Renderer, Show, SubsurfaceOptions};
use crate::hierarchy::HierarchyOptions;
use crate::materials::Material;
use crate::mesh::safe_normalize;
use crate::output::Exposure;
use crate::physics::{Diffusion, Model};
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
    /// List the material presets with their coefficients and derived quantities per channel.
    Materials,
    /// Evaluate Sd for CSV rows on stdin (header: sigma_a,sigma_s,g,eta,xi_x,…,no_z), to stdout.
    Bssrdf(BssrdfArgs),
    /// Plot Sd against distance per RGB channel for a material (PNG, SVG or CSV).
    Profile(Box<ProfileArgs>),
    /// Time every pass (GPU timestamps) for several sample counts and meshes; prints Markdown.
    Bench(BenchArgs),
    /// Show the scene in a window: orbit camera, light and material edits, scripted runs.
    View(Box<crate::view::ViewArgs>),
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Meshes (built-in names or OBJ paths); the bunny is used when installed.
    #[arg(long, value_delimiter = ',')]
    pub meshes: Option<Vec<String>>,
    /// Sample counts of the per-pass table.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..), default_values = ["16384", "65536", "262144"])]
    pub samples: Vec<u32>,
    /// Image size (square) of the brute-force comparison and the epsilon sweep; 0 skips them.
    #[arg(long, allow_hyphen_values = true, default_value_t = 64, value_parser = clap::value_parser!(u32).range(0..=4096))]
    pub accuracy_size: u32,
    /// Sample counts of the brute-force comparison (the first is also the epsilon sweep's).
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..), default_values = ["16384", "65536", "262144"])]
    pub accuracy_samples: Vec<u32>,
    /// Epsilons of the sweep.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, default_values = ["0.4", "0.2", "0.1", "0.05", "0.025"])]
    pub epsilons: Vec<f32>,
    #[arg(long, allow_hyphen_values = true, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: u32,
    #[arg(long, allow_hyphen_values = true, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: u32,
    /// Frames per configuration (the first is a warm-up).
    #[arg(long, allow_hyphen_values = true, default_value_t = 3, value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub frames: u32,
    /// Image size (square) of the comparison with pbrt-v2 on its own scene (it builds the UV
    /// sphere itself); 0 skips it.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(0..=16384))]
    pub peer_size: u32,
    #[command(flatten)]
    pub device: DeviceArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShowArg {
    Shading,
    Samples,
    Tree,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelArg {
    Directional,
    Dipole,
}

impl From<ModelArg> for Model {
    fn from(m: ModelArg) -> Model {
        match m {
            ModelArg::Directional => Model::Directional,
            ModelArg::Dipole => Model::Dipole,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum DiffusionArg {
    /// D = 1/(3σ't), as in the authors' program.
    Classical,
    /// D = (2σa + σ's)/(3σ't²).
    Alternative,
}

impl From<DiffusionArg> for Diffusion {
    fn from(d: DiffusionArg) -> Diffusion {
        match d {
            DiffusionArg::Classical => Diffusion::Classical,
            DiffusionArg::Alternative => Diffusion::Alternative,
        }
    }
}

#[derive(Args, Debug)]
pub struct BssrdfArgs {
    #[arg(long, value_enum, default_value = "directional")]
    pub model: ModelArg,
    #[arg(long, value_enum, default_value = "classical")]
    pub diffusion: DiffusionArg,
    /// Evaluate in a compute shader through the GLSL include instead of the Rust code.
    #[arg(long)]
    pub gpu: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// A material: a preset, with any coefficient overridden (per mm; R,G,B or one value).
#[derive(Args, Debug, Clone)]
pub struct MaterialArgs {
    /// Preset name (case-insensitive; `translucent materials` lists them).
    #[arg(long, default_value = "marble")]
    pub material: String,
    /// Absorption coefficient σa [1/mm], one value or R,G,B.
    #[arg(long, allow_hyphen_values = true, value_parser = triple, value_name = "V|R,G,B")]
    pub sigma_a: Option<[f64; 3]>,
    /// Scattering coefficient σs [1/mm], one value or R,G,B.
    #[arg(long, allow_hyphen_values = true, value_parser = triple, value_name = "V|R,G,B")]
    pub sigma_s: Option<[f64; 3]>,
    /// Mean scattering cosine g, one value or R,G,B.
    #[arg(long, allow_hyphen_values = true, value_parser = triple, value_name = "V|R,G,B")]
    pub g: Option<[f64; 3]>,
    /// Relative index of refraction η (inside/outside).
    #[arg(long, allow_hyphen_values = true, value_parser = any_f64)]
    pub eta: Option<f64>,
}

impl MaterialArgs {
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

#[derive(Args, Debug)]
pub struct ProfileArgs {
    #[command(flatten)]
    pub material: MaterialArgs,
    /// Models to plot.
    #[arg(long, value_enum, value_delimiter = ',', default_values = ["directional", "dipole"])]
    pub model: Vec<ModelArg>,
    /// Angles of incidence in degrees, from the normal.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, default_values = ["0", "60"])]
    pub angles: Vec<f64>,
    /// Shortest distance plotted [mm].
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.01)]
    pub r_min: f64,
    /// Longest distance plotted [mm] (default: 10 diffusion lengths of the most absorbing channel, at most 1000).
    #[arg(long, allow_hyphen_values = true)]
    pub r_max: Option<f64>,
    #[arg(long, value_enum, default_value = "classical")]
    pub diffusion: DiffusionArg,
    /// Points per curve.
    #[arg(long, allow_hyphen_values = true, default_value_t = 200)]
    pub samples: usize,
    /// Output: .png, .svg or .csv.
    #[arg(long, short, default_value = "profile.png")]
    pub out: PathBuf,
}

/// Options shared by every command that creates a Vulkan device.
#[derive(Args, Debug, Clone)]
pub struct DeviceArgs {
    /// Device to use: an index from `translucent devices` or a substring of its name.
    #[arg(long, allow_hyphen_values = true, value_name = "INDEX|NAME")]
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
    /// Mesh: `sphere`, `box`, `slab`, `torus`, or the path of an OBJ file (default: the Stanford
    /// bunny from glmark2-data when installed, else the sphere). A `{frame}` in the path plays a
    /// sequence of files, one per frame (numbered from 0 or 1, plain or padded to 4 digits).
    #[arg(long)]
    pub mesh: Option<String>,
    /// Output image; the extension picks the format (.png or .exr). A `{frame}` in the name
    /// writes every frame, numbered from 0000.
    #[arg(long, short, default_value = "out.png")]
    pub out: PathBuf,
    #[arg(long, allow_hyphen_values = true, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    #[arg(long, allow_hyphen_values = true, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Frames to render, each rebuilding the point cloud and tree (the image is the last frame,
    /// or every frame with `{frame}` in --out).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: u32,
    /// Turn the lights by this many degrees about the vertical axis (--up, through the mesh's
    /// centre) every frame: a turntable of light.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0, value_parser = finite_f32, value_name = "DEG")]
    pub spin_light: f32,
    /// Deform the mesh, animated over --deform-period frames (none, full strength, none):
    /// `twist:DEG` (about the vertical axis, growing with height) or `squash:F` (height × F,
    /// width / √F). Normals are recomputed every frame.
    #[arg(long, value_parser = crate::deform::Deformation::parse, value_name = "twist:DEG | squash:F")]
    pub deform: Option<crate::deform::Deformation>,
    /// Frames per period of --deform.
    #[arg(long, default_value_t = 48, value_parser = clap::value_parser!(u32).range(1..))]
    pub deform_period: u32,
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
    /// Direction toward the directional light (default: behind and above the object, as the
    /// default camera sees it, so that light shines through thin parts).
    #[arg(long, allow_hyphen_values = true, value_parser = vec3, value_name = "X,Y,Z", default_value = "-0.3,0.7,-0.65")]
    pub light_dir: Vec3,
    /// Irradiance at normal incidence: one value or R,G,B.
    #[arg(long, allow_hyphen_values = true, value_parser = rgb, value_name = "I|R,G,B", default_value = "1")]
    pub light_intensity: Vec3,
    /// A light (repeatable, up to 8; replaces the default light): `dir:X,Y,Z[:I]` (direction toward
    /// the light; I = irradiance at normal incidence, one value or R,G,B) or `point:X,Y,Z[:I]`
    /// (position; I = radiant intensity, falling off with the squared distance).
    #[arg(long = "light", value_parser = light_spec, value_name = "dir:X,Y,Z[:I] | point:X,Y,Z[:I]")]
    pub lights: Vec<Light>,
    /// Sample points on the surface (default: from the material's diffusion length and the mesh's area).
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32))]
    pub samples: Option<u32>,
    /// Shadow-map resolution per light (per cube face for point lights).
    #[arg(long, allow_hyphen_values = true, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub shadow_resolution: u32,
    /// Draw a debug view over the mesh: the sample points or the tree's boxes at --level.
    #[arg(long, value_enum, default_value = "shading")]
    pub show: ShowArg,
    /// Tree level for `--show tree` (0 = the root).
    #[arg(long, allow_hyphen_values = true, default_value_t = 4, value_parser = clap::value_parser!(u32).range(0..=64))]
    pub level: u32,
    #[command(flatten)]
    pub material: MaterialArgs,
    /// BSSRDF model.
    #[arg(long, value_enum, default_value = "directional")]
    pub model: ModelArg,
    #[arg(long, value_enum, default_value = "classical")]
    pub diffusion: DiffusionArg,
    /// Use a tree node whole (two sigma points per light) when its area / squared distance is below
    /// this. Measured against brute force (`translucent bench`, back-lit bunny, 16k points):
    /// relative RMSE 1.9% at 0.4, 0.95% at 0.2, 0.56% at 0.1, 0.28% at 0.05, with no bias; the
    /// shading time grows about 1.7× per halving.
    #[arg(long, allow_hyphen_values = true, default_value_t = crate::frame::DEFAULT_EPSILON, value_parser = finite_f32)]
    pub epsilon: f32,
    /// Visit every sample point for every pixel (the reference for the tree).
    #[arg(long)]
    pub brute_force: bool,
    /// Leave out the surface's own (microfacet) reflection: subsurface scattering alone.
    #[arg(long)]
    pub no_specular: bool,
    /// Roughness of the microfacet reflection, in (0, 1] (GGX α = roughness²).
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.35, value_parser = finite_f32)]
    pub roughness: f32,
    /// Exposure in stops (default: automatic from the image).
    #[arg(long, allow_hyphen_values = true, value_parser = finite_f32)]
    pub exposure: Option<f32>,
    /// Also count the shading work per pixel on the GPU (nodes visited, points evaluated). The
    /// per-pass GPU times (mean, min, max, share of the frame) are always printed.
    #[arg(long)]
    pub profile: bool,
    /// Write the GPU timings as Chrome trace-event JSON (opens in Perfetto / chrome://tracing).
    #[arg(long, value_name = "FILE.json")]
    pub profile_out: Option<PathBuf>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

fn any_f64(s: &str) -> std::result::Result<f64, String> {
    // Non-finite values parse here and are refused by Material::validate, which names them.
    s.trim().parse().map_err(|_| format!("'{s}' is not a number"))
}

fn triple(s: &str) -> std::result::Result<[f64; 3], String> {
    let v: Vec<f64> = s.split(',').map(any_f64).collect::<std::result::Result<_, _>>()?;
    match v.as_slice() {
        [x] => Ok([*x; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(format!("'{s}' is neither one number nor R,G,B")),
    }
}

pub(crate) fn light_spec(s: &str) -> std::result::Result<Light, String> {
    let mut parts = s.splitn(3, ':');
    let kind = parts.next().unwrap_or("");
    let at = parts.next().ok_or_else(|| format!("'{s}': expected dir:X,Y,Z[:I] or point:X,Y,Z[:I]"))?;
    let v = vec3(at)?;
    let intensity = parts.next().map(rgb).transpose()?.unwrap_or(Vec3::ONE);
    let light = match kind {
        "dir" => Light::Directional {
            toward: safe_normalize(v).ok_or_else(|| format!("'{s}': light direction {v} must be non-zero"))?,
            irradiance: intensity,
        },
        "point" => Light::Point { position: v, intensity },
        _ => return Err(format!("'{s}': the kind must be dir or point, not '{kind}'")),
    };
    light.validate().map_err(|e| e.to_string())?;
    Ok(light)
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
        Command::Materials => {
            crate::error::write_stdout(&crate::materials::materials_table())?;
            Ok(0)
        }
        Command::Bssrdf(args) => bssrdf(&args),
        Command::Profile(args) => profile(&args),
        Command::View(args) => crate::view::run(&args),
        Command::Bench(args) => {
            let bunny = BUNNY;
            let meshes = args.meshes.clone().unwrap_or_else(|| {
                let mut m = vec!["sphere".to_string()];
                if std::path::Path::new(bunny).exists() {
                    m.insert(0, bunny.to_string());
                }
                m
            });
            let options = crate::bench::BenchOptions {
                meshes,
                samples: args.samples.clone(),
                width: args.width,
                height: args.height,
                frames: args.frames,
                accuracy_size: args.accuracy_size,
                accuracy_samples: args.accuracy_samples.clone(),
                epsilons: args.epsilons.clone(),
                peer_size: args.peer_size,
                context: args.device.options(),
            };
            crate::error::write_stdout(&crate::bench::run(&options)?)?;
            Ok(0)
        }
    }
}

fn bssrdf(args: &BssrdfArgs) -> Result<i32> {
    use std::io::Write;
    let (model, diffusion) = (Model::from(args.model), Diffusion::from(args.diffusion));
    let gpu = if args.gpu {
        let ctx = Context::new(&args.device.options())?;
        let pass = crate::passes::bssrdf_eval::BssrdfEvalPass::new(&ctx)?;
        Some((ctx, pass))
    } else {
        None
    };
    // Streamed: a batch of rows is read, evaluated and written before the next is read, so memory
    // stays bounded and output starts at once, whatever the input's length.
    let stdin = std::io::stdin();
    let mut reader = crate::bssrdf_csv::Reader::new(stdin.lock());
    let mut out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    let start = std::time::Instant::now();
    let mut rows = 0usize;
    let mut header_written = false;
    loop {
        let batch = reader.next_batch(crate::bssrdf_csv::BATCH_ROWS)?;
        if !header_written {
            crate::bssrdf_csv::write_header(&mut out)?;
            header_written = true;
        }
        if batch.is_empty() {
            break;
        }
        let queries: Vec<crate::physics::Query> = batch.iter().map(|(_, q)| *q).collect();
        let sd: Vec<f64> = match &gpu {
            Some((ctx, pass)) => {
                for (line, q) in &batch {
                    crate::bssrdf_csv::gpu_range_check(q).map_err(|why| {
                        bad_input!(
                            "bssrdf --gpu: line {line}: {why}; the GPU evaluates in f32 (leave out --gpu to use f64)"
                        )
                    })?;
                }
                let sd = pass.evaluate(ctx, &queries, model, diffusion)?;
                if let Some(i) = sd.iter().position(|v| !v.is_finite()) {
                    return Err(runtime!(
                        "bssrdf --gpu: line {}: the GPU returned {} (f32 overflow)",
                        batch[i].0,
                        sd[i]
                    ));
                }
                sd.into_iter().map(f64::from).collect()
            }
            None => queries.iter().map(|q| q.sd(model, diffusion)).collect(),
        };
        crate::bssrdf_csv::write_rows(&mut out, &queries, &sd)?;
        out.flush().map_err(|e| runtime!("stdout: {e}"))?;
        rows += queries.len();
    }
    out.flush().map_err(|e| runtime!("stdout: {e}"))?;
    log::info!("evaluated {rows} rows in {:.3} s", start.elapsed().as_secs_f64());
    Ok(match gpu {
        Some((ctx, pass)) => {
            let (counts, validating) = (ctx.validation_counts(), ctx.validation);
            drop(pass);
            drop(ctx);
            validation_exit_code(validating, &counts)
        }
        None => 0,
    })
}

fn profile(args: &ProfileArgs) -> Result<i32> {
    check_output_path(&args.out, "--out", &["png", "svg", "csv"])?;
    let material = args.material.material()?;
    let r_max = match args.r_max {
        Some(r) => r,
        None => {
            // Ten diffusion lengths 1/σtr of the channel that dies out first.
            let sigma_tr = (0..3)
                .map(|ch| material.channel(ch).constants(Diffusion::from(args.diffusion)))
                .filter(|c| c.transports)
                .map(|c| c.sigma_tr)
                .fold(0.0f64, f64::max);
            if sigma_tr > 0.0 {
                (10.0 / sigma_tr).min(1000.0)
            } else {
                100.0
            }
        }
    };
    let spec = crate::plot::ProfileSpec {
        material,
        models: args.model.iter().map(|&m| m.into()).collect(),
        angles_deg: args.angles.clone(),
        r_min_mm: args.r_min,
        r_max_mm: r_max,
        diffusion: args.diffusion.into(),
        samples: args.samples,
    };
    crate::plot::write_profile(&spec, &args.out)?;
    crate::note!("wrote {}", args.out.display());
    Ok(0)
}

fn devices() -> Result<i32> {
    let list = vk::list_devices()?;
    let mut text = format!("{:<5} {:<40} {:<15} {:<9} {:<10} driver\n", "index", "name", "type", "api", "timestamps");
    for d in list {
        let usable = match &d.usable {
            Ok(()) => String::new(),
            Err(why) => format!("  (unusable: {why})"),
        };
        text += &format!(
            "{:<5} {:<40} {:<15} {:<9} {:<10} {}{usable}\n",
            d.index,
            d.name,
            d.type_name(),
            d.api_string(),
            if d.timestamps { "yes" } else { "no" },
            d.driver
        );
    }
    crate::error::write_stdout(&text)?;
    Ok(0)
}

/// The sizes (mm across) a mesh may have once --scale is applied: from a micrometre to a thousand
/// kilometres, so that areas in mm² and the powers summed over them stay finite in f32.
pub const SIZE_MM_LIMITS: (f64, f64) = (1e-3, 1e9);

/// The largest coordinate accepted for --eye, --target and point lights: squared distances must
/// stay finite in f32.
pub const MAX_COORDINATE: f32 = 1e15;

/// The Stanford bunny of Debian's glmark2-data, the default mesh when installed.
pub const BUNNY: &str = "/usr/share/glmark2/models/bunny.obj";

/// `--mesh`, or the default: the bunny when installed, else the sphere.
pub fn mesh_spec(args: &RenderArgs) -> String {
    match &args.mesh {
        Some(m) => m.clone(),
        None if std::path::Path::new(BUNNY).exists() => BUNNY.to_string(),
        None => "sphere".to_string(),
    }
}

pub fn build_scene(args: &RenderArgs) -> Result<Scene> {
    let mesh = crate::deform::first_mesh(&mesh_spec(args))?;
    let (centre, radius) = crate::scene::bounding_sphere(&mesh.positions);
    // The object's size in millimetres must stay where f32 areas and powers are finite.
    let size_mm = 2.0 * radius as f64 * args.scale as f64;
    if !(SIZE_MM_LIMITS.0..=SIZE_MM_LIMITS.1).contains(&size_mm) {
        return Err(bad_input!(
            "--scale {}: the mesh would be {size_mm:.3e} mm across; it must be within [{:e}, {:e}] mm",
            args.scale,
            SIZE_MM_LIMITS.0,
            SIZE_MM_LIMITS.1
        ));
    }
    let mut camera = Camera::framing(centre, radius, args.fov, Vec3::new(0.3, 0.3, 1.0));
    // Directions are normalised here, safely: (1e20, 1e20, 0) is a fine direction whose squared
    // length overflows f32, and would otherwise turn into NaN on the GPU.
    camera.up = safe_normalize(args.up).ok_or_else(|| bad_input!("--up {}: must be finite and non-zero", args.up))?;
    for (flag, p) in [("--eye", args.eye), ("--target", args.target)] {
        if let Some(p) = p.filter(|p| p.abs().max_element() > MAX_COORDINATE) {
            return Err(bad_input!("{flag} {p}: coordinates must be within ±{MAX_COORDINATE:e}"));
        }
    }
    if let Some(target) = args.target {
        camera.target = target;
    }
    if let Some(eye) = args.eye {
        camera.eye = eye;
    }
    let lights = if args.lights.is_empty() {
        let toward = safe_normalize(args.light_dir)
            .ok_or_else(|| bad_input!("--light-dir {}: light direction must be finite and non-zero", args.light_dir))?;
        vec![Light::Directional { toward, irradiance: args.light_intensity }]
    } else {
        args.lights.clone()
    };
    for light in &lights {
        if let Light::Point { position, .. } = light {
            if position.abs().max_element() > MAX_COORDINATE {
                return Err(bad_input!("--light point:{position}: coordinates must be within ±{MAX_COORDINATE:e}"));
            }
        }
    }
    if lights.len() > crate::passes::irradiance::MAX_LIGHTS {
        return Err(bad_input!(
            "--light: at most {} lights, {} given",
            crate::passes::irradiance::MAX_LIGHTS,
            lights.len()
        ));
    }
    let scene = Scene { mesh, camera, lights, mm_per_unit: args.scale };
    scene.validate()?;
    Ok(rescaled(scene, radius))
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

fn check_output_path(path: &std::path::Path, flag: &str, allowed: &[&str]) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
    if !allowed.contains(&ext.as_str()) {
        return Err(bad_input!("{flag} {}: the extension must be one of .{}", path.display(), allowed.join(", .")));
    }
    // Found out before a long render, not after it.
    if path.is_dir() {
        return Err(bad_input!("{flag} {}: is a folder; give a file name", path.display()));
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            return Err(bad_input!("{flag} {}: the folder {} does not exist", path.display(), dir.display()));
        }
    }
    // Can it be written (permissions, a read-only file system)? Opened without truncating; a
    // file created only for this test is removed again.
    let first = frame_path(path, 0);
    let existed = first.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(&first)
        .map_err(|e| bad_input!("{flag} {}: cannot be written: {e}", first.display()))?;
    if !existed {
        std::fs::remove_file(&first).ok();
    }
    Ok(())
}

/// `--out` for frame `index`: `{frame}` replaced by the zero-padded number.
fn frame_path(out: &std::path::Path, index: u32) -> PathBuf {
    PathBuf::from(out.to_string_lossy().replace("{frame}", &format!("{index:04}")))
}

fn render(args: &RenderArgs) -> Result<i32> {
    // Check everything the user typed before the (slow) device start.
    check_output_path(&args.out, "--out", &["png", "exr"])?;
    if let Some(p) = &args.profile_out {
        check_output_path(p, "--profile-out", &["json"])?;
    }
    if !(args.roughness > 0.0 && args.roughness <= 1.0) {
        return Err(bad_input!("--roughness {}: must be in (0, 1]", args.roughness));
    }
    let mut scene = build_scene(args)?;
    let material = args.material.material()?;
    // The GPU shades in f32 (see `bssrdf --gpu`).
    if let Some(ch) = (0..3).find(|&c| material.sigma_a[c] + material.sigma_s[c] > crate::bssrdf_csv::GPU_MAX_SIGMA_T) {
        return Err(bad_input!(
            "--sigma-a/--sigma-s: σa + σs = {:e} /mm in channel {ch} is above {:e}, beyond what rendering in f32 can hold",
            material.sigma_a[ch] + material.sigma_s[ch],
            crate::bssrdf_csv::GPU_MAX_SIGMA_T
        ));
    }
    let ctx = Context::new(&args.device.options())?;
    let counts = ctx.validation_counts();
    let validating = ctx.validation;
    let device_name = format!("{} ({})", ctx.info.name, ctx.info.driver);

    let eta = material.eta as f32;
    let point_count = match args.samples {
        Some(n) => {
            crate::hierarchy::check_point_count(&ctx, n, scene.lights.len() as u32)?;
            n
        }
        None => default_point_count(&ctx, &scene, &material),
    };
    crate::budget::check_frame(
        &ctx,
        &crate::budget::FrameSizes {
            width: args.width,
            height: args.height,
            shadow_resolution: args.shadow_resolution,
            shadow_layers: crate::budget::FrameSizes::shadow_layers(&scene.lights),
            point_count,
            light_count: scene.lights.len() as u32,
        },
    )?;
    let show = match args.show {
        ShowArg::Shading => Show::Shading,
        ShowArg::Samples => Show::Samples,
        ShowArg::Tree => Show::Tree(args.level),
    };
    let options = FrameOptions {
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
        profile: true,
        count_work: args.profile,
        hierarchy: HierarchyOptions { point_count, shadow_resolution: args.shadow_resolution, eta },
        show,
        exposure: args.exposure.map(Exposure::Stops).unwrap_or(Exposure::Auto),
    };
    let mut renderer = Renderer::new(ctx, &scene, options)?;
    // A progress bar over the shading of every frame; indicatif hides it off a terminal.
    let bar = indicatif::ProgressBar::new(Renderer::progress_length(args.frames));
    bar.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}% of {msg}, {eta} left")
            .map_err(|e| runtime!("progress bar: {e}"))?
            .progress_chars("=> "),
    );
    bar.set_message(format!("{} frame(s)", args.frames));
    renderer.progress = Some(bar.clone());

    let every_frame = args.out.to_string_lossy().contains("{frame}");
    let animation =
        crate::deform::Animation::new(&mesh_spec(args), &scene.mesh, args.deform, args.deform_period, args.up)?;
    let base_lights = scene.lights.clone();
    let (centre, _) = crate::scene::bounding_sphere(&scene.mesh.positions);
    let mut frames = Vec::new();
    for index in 0..args.frames {
        let angle = (args.spin_light * index as f32).to_radians();
        scene.lights = base_lights.iter().map(|l| l.rotated(args.up, angle, centre)).collect();
        if let Some(animation) = animation.as_ref().filter(|_| index > 0) {
            scene.mesh = animation.mesh(index)?;
            renderer.set_mesh(&scene.mesh)?;
        }
        frames.push(renderer.render_frame(&scene)?);
        if every_frame {
            let path = frame_path(&args.out, index);
            renderer.write_image(&path)?;
            bar.suspend(|| crate::note!("wrote {}", path.display()));
        }
    }
    bar.finish_and_clear();
    if !every_frame {
        if args.width as u64 * args.height as u64 >= 1 << 22 {
            // Encoding a large image takes seconds after the bar is gone: say what is happening.
            crate::note!("writing {} ({}x{})…", args.out.display(), args.width, args.height);
        }
        renderer.write_image(&args.out)?;
        crate::note!("wrote {} ({}x{}, {} frame(s))", args.out.display(), args.width, args.height, args.frames);
    }
    let work = renderer.work()?;
    drop(renderer);

    if frames.iter().any(|f| !f.is_empty()) {
        report_profile(&device_name, frames, args)?;
    }
    if args.profile && work.pixels > 0 {
        let per_pixel = |sum: u32| sum as f64 / work.pixels as f64;
        crate::error::write_stdout(&format!(
            "work per pixel (last frame, {} pixels): nodes visited mean {:.1} max {}, points evaluated mean {:.1} max {}, Sd evaluations mean {:.1}\n",
            work.pixels,
            per_pixel(work.node_sum),
            work.node_max,
            per_pixel(work.point_sum),
            work.point_max,
            per_pixel(work.evaluation_sum)
        ))?;
    }
    Ok(validation_exit_code(validating, &counts))
}

/// Sample count from the material's shortest length scale (mean free path 1/σ't or diffusion
/// length 1/σtr) and the mesh's area (in mm), within a budget; prints the choice and warns when
/// points are farther apart than that length.
pub(crate) fn default_point_count(ctx: &Context, scene: &Scene, material: &Material) -> u32 {
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

fn report_profile(device: &str, frames: Vec<Vec<vk::TimedScope>>, args: &RenderArgs) -> Result<()> {
    use crate::profiling::{ProfileReport, Scope};
    let report = ProfileReport {
        device: device.to_string(),
        frames: frames
            .into_iter()
            .map(|f| f.into_iter().map(|s| Scope { name: s.name, begin_ns: s.begin_ns, end_ns: s.end_ns }).collect())
            .collect(),
    };
    crate::error::write_stdout(&crate::profiling::format_table(&report))?;
    if let Some(path) = &args.profile_out {
        crate::output::write_file(path, crate::profiling::chrome_trace_json(&report).as_bytes())
            .map_err(|e| runtime!("--profile-out: {e}"))?;
    }
    Ok(())
}

/// Exit code 1 (with a summary on stderr) when the validation layer reported anything.
pub fn validation_exit_code(validating: bool, counts: &vk::ValidationCounts) -> i32 {
    use std::sync::atomic::Ordering;
    let (w, e) = (counts.warnings.load(Ordering::SeqCst), counts.errors.load(Ordering::SeqCst));
    if w + e > 0 {
        crate::note!("error: validation reported {e} error(s) and {w} warning(s)");
        return 1;
    }
    if validating {
        log::info!("validation: no messages");
    }
    0
}

/// What a clap error becomes: `--help` and `--version` print to stdout and exit 0 (1 when stdout
/// cannot be written); a usage error prints `error: …` naming the flag and exits 2, and so does a
/// bare `translucent` (clap would print only the help there, with no `error:` line).
pub fn usage_exit(e: clap::Error) -> i32 {
    use clap::error::ErrorKind;
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => match e.print() {
            Ok(()) => 0,
            Err(_) => 1,
        },
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand | ErrorKind::MissingSubcommand => {
            crate::note!(
                "error: a command is required: render, view, devices, materials, bssrdf, profile or bench\n\n{}",
                e.render()
            );
            2
        }
        _ => {
            let _ = e.print();
            2
        }
    }
}
