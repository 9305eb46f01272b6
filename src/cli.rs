//! The command line: `translucent render | devices | …`. Parsing only: the flags and their value
//! parsers. The commands themselves are in src/commands/, the settings they make in src/settings.rs.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use glam::Vec3;

use crate::mesh::safe_normalize;
use crate::physics::{Diffusion, Model};
use crate::scene::Light;
use crate::vk::PresentMode;

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
    View(Box<ViewArgs>),
    /// Compare a linear EXR (A) with a reference (B): per channel the ratio of means, relative
    /// RMSE and largest error over the pixels both cover, FLIP, an error image.
    Compare(CompareArgs),
    /// Write what `render` would draw as another renderer's scene (`export mitsuba`).
    Export(ExportArgs),
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image to judge (linear EXR, alpha = coverage).
    pub a: PathBuf,
    /// The reference (linear EXR, alpha = coverage), e.g. a path tracer's.
    pub b: PathBuf,
    /// Compare only where this image (PNG or EXR, same size) is at least 0.5 (mean of R, G, B)
    /// instead of where both are fully covered.
    #[arg(long, value_name = "FILE")]
    pub mask: Option<PathBuf>,
    /// Write the error image: max over channels of |A − B| / mean B, false colour, scale drawn under it.
    #[arg(long, value_name = "FILE.png")]
    pub error_image: Option<PathBuf>,
    /// Full scale of the error image, as a fraction of B's mean (default: B's 99th percentile, rounded up to 1, 2 or 5 × 10^k).
    #[arg(long, allow_hyphen_values = true, value_parser = positive_f64_arg)]
    pub error_scale: Option<f64>,
    /// Exposure in stops of the tone mapping both go through for FLIP (default: B's automatic exposure).
    #[arg(long, allow_hyphen_values = true, value_parser = finite_f32)]
    pub exposure: Option<f32>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    #[command(subcommand)]
    pub format: ExportFormat,
}

#[derive(Subcommand, Debug)]
pub enum ExportFormat {
    /// A Mitsuba 3 scene (scene.xml, meshes as PLY) of exactly what `render` with these options would draw.
    Mitsuba(Box<MitsubaArgs>),
}

#[derive(Args, Debug)]
pub struct MitsubaArgs {
    /// Angular radius of the disks that stand in for directional lights (a delta light behind a
    /// smooth dielectric is black in Mitsuba's unidirectional integrators).
    #[arg(long, allow_hyphen_values = true, default_value_t = 5.0, value_parser = finite_f32, value_name = "DEG")]
    pub light_radius: f32,
    /// Samples per pixel written as the scene's default (scripts/reference overrides it).
    #[arg(long, allow_hyphen_values = true, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..))]
    pub spp: u32,
    /// The render options: what `render` takes; `--out DIR` is the folder the scene is written
    /// into (created when missing).
    #[command(flatten)]
    pub render: RenderArgs,
}

#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    #[command(flatten)]
    pub render: RenderArgs,
    /// How frames wait for the screen: fifo (vertical blank; always offered), fifo-relaxed,
    /// mailbox, immediate.
    #[arg(long, value_enum, default_value = "fifo")]
    pub present_mode: PresentModeArg,
    /// Write the last presented image (PNG) when the viewer exits.
    #[arg(long, value_name = "FILE.png")]
    pub screenshot: Option<PathBuf>,
    /// Leave out the panel (settings and timings drawn over the image; `h` toggles it).
    #[arg(long)]
    pub no_panel: bool,
    /// Run the commands of this file, one per line (orbit, pan, zoom, light, material, set,
    /// frames, screenshot, resize, pause, trace, quit; see README "View").
    #[arg(long, value_name = "FILE")]
    pub script: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum PresentModeArg {
    Fifo,
    FifoRelaxed,
    Mailbox,
    Immediate,
}

impl From<PresentModeArg> for PresentMode {
    fn from(m: PresentModeArg) -> PresentMode {
        match m {
            PresentModeArg::Fifo => PresentMode::Fifo,
            PresentModeArg::FifoRelaxed => PresentMode::FifoRelaxed,
            PresentModeArg::Mailbox => PresentMode::Mailbox,
            PresentModeArg::Immediate => PresentMode::Immediate,
        }
    }
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
    /// Image width of the per-pass table [default: 512]; typed, it (or --height) also sizes the
    /// pbrt-v2 comparison and the scene of several objects unless their own sizes are typed.
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub width: Option<u32>,
    /// Image height of the per-pass table [default: 512].
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(1..=16384))]
    pub height: Option<u32>,
    /// Frames per configuration (the first is a warm-up).
    #[arg(long, allow_hyphen_values = true, default_value_t = 3, value_parser = clap::value_parser!(u32).range(2..=1000))]
    pub frames: u32,
    /// Light counts of the lights table (directional lights on a spiral); the sky row is sampled
    /// in the largest of them, at most 64 directions.
    #[arg(long, allow_hyphen_values = true, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=4096), default_values = ["1", "8", "64", "256"], conflicts_with = "no_lights")]
    pub lights: Vec<u32>,
    /// Leave out the lights table.
    #[arg(long)]
    pub no_lights: bool,
    /// Image size (square) of the comparison with pbrt-v2 on its own scene (it builds the UV
    /// sphere itself); 0 skips it [default: 1024, or the larger of --width and --height when
    /// either is typed].
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(0..=16384))]
    pub peer_size: Option<u32>,
    /// Image size (square) of a scene of several objects (two translucent, an opaque floor); 0
    /// skips it [default: 512, or the larger of --width and --height when either is typed].
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32).range(0..=16384))]
    pub scene_size: Option<u32>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShowArg {
    Shading,
    Samples,
    Tree,
}

/// `--model NAME`: a model registered in src/models.rs, by its name or an alias.
fn model_arg() -> impl clap::builder::TypedValueParser<Value = Model> {
    use clap::builder::{PossibleValue, TypedValueParser};
    let names: Vec<PossibleValue> =
        crate::models::MODELS.iter().map(|e| PossibleValue::new(e.name).aliases(e.aliases.iter().copied())).collect();
    clap::builder::PossibleValuesParser::new(names).map(|name| Model::from_name(&name).unwrap_or_default())
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

/// Which of the Monte Carlo table's terms a render draws (`--scattering`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ScatteringArg {
    /// Single and multiple scattering: the image.
    All,
    /// Light scattered once inside, alone (to check it against a path tracer limited to one
    /// scattering, `scripts/reference --max-depth 4`).
    Single,
    /// Light scattered twice or more, alone.
    Multiple,
}

impl From<ScatteringArg> for crate::frame_desc::Scattering {
    fn from(s: ScatteringArg) -> Self {
        use crate::frame_desc::Scattering;
        match s {
            ScatteringArg::All => Scattering::All,
            ScatteringArg::Single => Scattering::Single,
            ScatteringArg::Multiple => Scattering::Multiple,
        }
    }
}

/// When the near-field split applies (`--near-field`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum NearFieldArg {
    /// With the tree; brute force stays the exact point sum.
    Auto,
    /// Always, brute force too (to see the split's own error).
    On,
    /// Never: every source summed at its full weight, however near (the sum before the split).
    Off,
}

impl From<NearFieldArg> for crate::frame_desc::NearField {
    fn from(n: NearFieldArg) -> Self {
        use crate::frame_desc::NearField;
        match n {
            NearFieldArg::Auto => NearField::Auto,
            NearFieldArg::On => NearField::On,
            NearFieldArg::Off => NearField::Off,
        }
    }
}

#[derive(Args, Debug)]
pub struct BssrdfArgs {
    #[arg(long, value_parser = model_arg(), default_value = "directional")]
    pub model: Model,
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

#[derive(Args, Debug)]
pub struct ProfileArgs {
    #[command(flatten)]
    pub material: MaterialArgs,
    /// Models to plot.
    #[arg(long, value_parser = model_arg(), value_delimiter = ',', default_values = ["directional", "dipole"])]
    pub model: Vec<Model>,
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

#[derive(Args, Debug, Clone)]
pub struct RenderArgs {
    /// A scene file: pbrt-v4 (`scene.pbrt`: its camera, film, shapes, materials and lights) or
    /// glTF 2.0 (`scene.gltf`, `scene.glb`: its meshes, materials, punctual lights and camera);
    /// flags typed here override them (see README, "Scenes and mesh files").
    #[arg(value_name = "SCENE.pbrt|SCENE.gltf|SCENE.glb")]
    pub scene: Option<PathBuf>,
    /// The scene of a glTF file to render, numbered from 0 (default: the file's `scene`, else 0).
    #[arg(long, value_name = "N")]
    pub gltf_scene: Option<usize>,
    /// Render the glTF material named NAME translucent, as the preset PRESET (repeatable; the
    /// coefficient flags still apply).
    #[arg(long, value_name = "NAME=PRESET")]
    pub gltf_material: Vec<String>,
    /// Mesh: `sphere`, `box`, `slab`, `torus`, or the path of a mesh file: `.obj`, `.ply`, `.off`,
    /// any of them gzip-compressed (`.ply.gz`) (default: the Stanford bunny from glmark2-data when
    /// installed, else the sphere). A `{frame}` in the path plays a sequence of files, one per
    /// frame (numbered from 0 or 1, plain or padded to 4 digits).
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
    /// A light (repeatable, as many as the device has shadow-map layers; replaces the default light): `dir:X,Y,Z[:I]` (direction toward
    /// the light; I = irradiance at normal incidence, one value or R,G,B), `point:X,Y,Z[:I]`
    /// (position; I = radiant intensity, falling off with the squared distance) or
    /// `spot:X,Y,Z:TX,TY,TZ:ANGLE[:DELTA[:I]]` (a point light at X,Y,Z aimed at TX,TY,TZ, lighting a
    /// cone of ANGLE degrees from its axis, in (0, 180]; its intensity falls to 0 over the cone's
    /// outer DELTA degrees, in [0, ANGLE], default 5 (pbrt-v4's spot: a smoothstep in cos θ); I =
    /// radiant intensity along the axis).
    /// An environment light: an EXR, Radiance HDR or PNG map (2:1 latitude-longitude, +y up, as
    /// Mitsuba 3's envmap; or square equal-area octahedral, z up, as pbrt-v4's infinite light) or
    /// `const:L` (one value or R,G,B) or `sky[:ELEVATION:AZIMUTH]` (a synthetic sky with a sun
    /// at ELEVATION degrees above the horizon, AZIMUTH from −z toward +x; default 30:30). It is sampled in --env-samples directions stratified by
    /// its energy, each a shadowed directional light, and shows behind the objects. It replaces
    /// the default light; --light adds lights to it.
    #[arg(long, value_name = "FILE | const:L | sky[:E:A]")]
    pub env: Option<String>,
    /// Multiplies the environment's radiance.
    #[arg(long, allow_hyphen_values = true, default_value_t = 1.0, value_parser = finite_f32)]
    pub env_scale: f32,
    /// Turns the environment about the up axis (+y), in degrees.
    #[arg(long, allow_hyphen_values = true, default_value_t = 0.0, value_parser = finite_f32)]
    pub env_rotate: f32,
    /// Directions the environment is sampled in (each a directional light with its own shadow
    /// map). Measured against 1024 directions (tests/environment.rs): see the README.
    #[arg(long, default_value_t = crate::environment::DEFAULT_SAMPLES, value_parser = clap::value_parser!(u32).range(1..=crate::environment::MAX_SAMPLES as i64))]
    pub env_samples: u32,
    #[arg(long = "light", value_parser = light_spec, value_name = "dir:X,Y,Z[:I] | point:X,Y,Z[:I] | spot:X,Y,Z:TX,TY,TZ:ANGLE[:DELTA[:I]]")]
    pub lights: Vec<Light>,
    /// Sample points on the surface (default: from the material's diffusion length and the mesh's area).
    #[arg(long, allow_hyphen_values = true, value_parser = clap::value_parser!(u32))]
    pub samples: Option<u32>,
    /// Shadow-map resolution per light (per cube face for point lights and spots wider than 60°).
    /// With more than 8 lights (an environment's samples) it is halved while one object's maps
    /// would take more than 768 MiB (depth, normals and curvature), down to 128.
    #[arg(long, allow_hyphen_values = true, default_value_t = crate::frame_desc::DEFAULT_SHADOW_RESOLUTION, value_parser = clap::value_parser!(u32).range(16..=8192))]
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
    #[arg(long, value_parser = model_arg(), default_value = "directional")]
    pub model: Model,
    #[arg(long, value_enum, default_value = "classical")]
    pub diffusion: DiffusionArg,
    /// Use a tree node whole (two sigma points per light) when its area / squared distance is below
    /// this. Measured against brute force (`translucent bench`, back-lit bunny, 16k points):
    /// relative RMSE 1.9% at 0.4, 0.95% at 0.2, 0.56% at 0.1, 0.28% at 0.05, with no bias; the
    /// shading time grows about 1.7× per halving.
    #[arg(long, allow_hyphen_values = true, default_value_t = crate::frame_desc::DEFAULT_EPSILON, value_parser = finite_f32)]
    pub epsilon: f32,
    /// Visit every sample point for every pixel (the reference for the tree).
    #[arg(long)]
    pub brute_force: bool,
    /// The near field: the few points nearest a pixel sample the BSSRDF's peak badly, so each lit
    /// pixel adds a control variate: its own irradiance over its tangent plane, integrated by a
    /// fixed quadrature of ∫(1 − w) Sd dA (w rising from 0 within one point spacing to 1 at
    /// four), less the points' estimate of the same. Costs about 1.6x the shade pass. `auto`:
    /// with the tree, not with --brute-force (the exact point sum, the reference).
    #[arg(long, value_enum, default_value = "auto")]
    pub near_field: NearFieldArg,
    /// Evaluate every source at every pixel: by default the sources far from an 8x8 tile of the
    /// image (where its pixels are finer than the sample points) are summed at nine of its pixels
    /// and interpolated, within about 0.1% of each source's contribution.
    #[arg(long)]
    pub no_far_field: bool,
    /// Draw light that leaves the object and enters it again (an ear lit through glowing onto
    /// the other, a paw onto the chest): `--model mc` on a closed mesh, with the tree (not with
    /// --brute-force), by a gather over 1024 patches of the surface before the shade pass. Costs
    /// about 2x the shade pass on a back-lit object, whose shadowed side it lights.
    #[arg(long)]
    pub reentry: bool,
    /// Leave out the surface's own (microfacet) reflection: subsurface scattering alone.
    #[arg(long)]
    pub no_specular: bool,
    /// Draw single scattering alone, multiple scattering alone, or both (`--model mc` only: the
    /// other models' profiles hold both in one).
    #[arg(long, value_enum, default_value = "all")]
    pub scattering: ScatteringArg,
    /// Roughness of the microfacet reflection, in (0, 1] (GGX α = roughness²).
    #[arg(long, allow_hyphen_values = true, default_value_t = crate::frame_desc::DEFAULT_ROUGHNESS, value_parser = finite_f32)]
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

pub(crate) fn triple(s: &str) -> std::result::Result<[f64; 3], String> {
    let v: Vec<f64> = s.split(',').map(any_f64).collect::<std::result::Result<_, _>>()?;
    match v.as_slice() {
        [x] => Ok([*x; 3]),
        [r, g, b] => Ok([*r, *g, *b]),
        _ => Err(format!("'{s}' is neither one number nor R,G,B")),
    }
}

/// The forms of `--light` (and of the viewer's `light` lines).
pub(crate) const LIGHT_FORMS: &str = "dir:X,Y,Z[:I], point:X,Y,Z[:I] or spot:X,Y,Z:TX,TY,TZ:ANGLE[:DELTA[:I]]";

/// A spot light's falloff width when `spot:` leaves it out: pbrt-v4's `conedeltaangle` default.
pub const SPOT_DEFAULT_DELTA_DEG: f32 = 5.0;

pub(crate) fn light_spec(s: &str) -> std::result::Result<Light, String> {
    if let Some(rest) = s.strip_prefix("spot:") {
        return spot_spec(s, rest);
    }
    let mut parts = s.splitn(3, ':');
    let kind = parts.next().unwrap_or("");
    let at = parts.next().ok_or_else(|| format!("'{s}': expected {LIGHT_FORMS}"))?;
    let v = vec3(at)?;
    let intensity = parts.next().map(rgb).transpose()?.unwrap_or(Vec3::ONE);
    let light = match kind {
        "dir" => Light::Directional {
            toward: safe_normalize(v).ok_or_else(|| format!("'{s}': light direction {v} must be non-zero"))?,
            irradiance: intensity,
        },
        "point" => Light::Point { position: v, intensity },
        _ => return Err(format!("'{s}': the kind must be dir, point or spot, not '{kind}'")),
    };
    light.validate().map_err(|e| e.to_string())?;
    Ok(light)
}

/// `spot:X,Y,Z:TX,TY,TZ:ANGLE[:DELTA[:I]]`: the position, the point it is aimed at, the cone's
/// half-angle in degrees (0, 180], the falloff's width inside its edge in degrees [0, ANGLE]
/// (default pbrt's 5°, or ANGLE when that is smaller) and the intensity along the axis.
fn spot_spec(s: &str, rest: &str) -> std::result::Result<Light, String> {
    let parts: Vec<&str> = rest.split(':').collect();
    if !(3..=5).contains(&parts.len()) {
        return Err(format!("'{s}': expected spot:X,Y,Z:TX,TY,TZ:ANGLE[:DELTA[:I]]"));
    }
    let position = vec3(parts[0])?;
    let target = vec3(parts[1])?;
    let cone = finite_f32(parts[2]).map_err(|e| format!("'{s}': cone angle: {e}"))?;
    let delta = match parts.get(3) {
        Some(d) => finite_f32(d).map_err(|e| format!("'{s}': falloff width: {e}"))?,
        None => SPOT_DEFAULT_DELTA_DEG.min(cone.max(0.0)),
    };
    let intensity = parts.get(4).map(|i| rgb(i)).transpose()?.unwrap_or(Vec3::ONE);
    Light::spot(position, target, cone, delta, intensity).map_err(|e| format!("'{s}': {e}"))
}

pub(crate) fn finite_f32(s: &str) -> std::result::Result<f32, String> {
    let v: f32 = s.trim().parse().map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() {
        return Err(format!("'{s}' is not finite"));
    }
    Ok(v)
}

fn positive_f64_arg(s: &str) -> std::result::Result<f64, String> {
    let v = any_f64(s)?;
    if !(v.is_finite() && v > 0.0) {
        return Err(format!("'{s}' must be a positive number"));
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

pub(crate) fn rgb(s: &str) -> std::result::Result<Vec3, String> {
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

/// What a clap error becomes: `--help` and `--version` print to stdout and exit 0 (1 when stdout
/// cannot be written); a usage error prints `error: …` naming the flag and exits 2, and so does a
/// bare `translucent` (clap would print only the help there, with no `error:` line).
pub fn usage_exit(e: clap::Error) -> i32 {
    use clap::error::ErrorKind;
    match e.kind() {
        // Help that cannot be written is a failure named like every other write to stdout.
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => match e.print() {
            Ok(()) => 0,
            Err(err) => {
                crate::note!("error: stdout: {err}");
                1
            }
        },
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand | ErrorKind::MissingSubcommand => {
            crate::note!(
                "error: a command is required: render, view, devices, materials, bssrdf, profile, bench, compare or export\n\n{}",
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
