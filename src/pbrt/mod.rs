//! pbrt-v4 scene files: `translucent render scene.pbrt`. [`load`] reads a file (and its includes)
//! into a [`PbrtScene`], a plain description in pbrt's world space: the camera, the film, every
//! shape as world-space triangles with its material, the lights, the warnings. [`render_settings`]
//! is the one place that turns it into what the renderer draws today (one translucent object);
//! everything else in this module knows nothing of the renderer.
//!
//! `tokenizer.rs` (tokens with file:line:column), `params.rs` (typed parameter lists),
//! `scene.rs` (the directives and the graphics state).

pub mod params;
pub mod scene;
pub mod tokenizer;

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

use crate::bad_input;
use crate::error::Result;
use crate::mesh::RawMesh;
pub use tokenizer::Loc;

#[derive(Clone, Debug)]
pub struct CameraDesc {
    pub eye: DVec3,
    pub target: DVec3,
    pub up: DVec3,
    /// pbrt's `fov`: the angle spanned by the image's shorter side.
    pub fov_deg: f64,
    /// Whether the camera's frame is pbrt's left-handed one (x right, y up, z forward); a
    /// right-handed camera at the same place sees the scene mirrored unless it is mirrored too.
    pub left_handed: bool,
    pub loc: Loc,
}

#[derive(Clone, Debug)]
pub struct FilmDesc {
    pub xresolution: u32,
    pub yresolution: u32,
    pub filename: Option<String>,
    pub loc: Option<Loc>,
}

impl Default for FilmDesc {
    fn default() -> Self {
        FilmDesc { xresolution: 1280, yresolution: 720, filename: None, loc: None }
    }
}

/// Which of pbrt-v4's four forms a `subsurface` material was given in.
#[derive(Clone, Debug, PartialEq)]
pub enum SubsurfaceSource {
    /// `"string name"`: pbrt-v4's measured table ([`PBRT_MEDIA`]).
    Named(String),
    /// `sigma_a` and `sigma_s`.
    Coefficients,
    /// `reflectance` and `mfp`, inverted with the classical dipole ([`from_reflectance`]).
    Reflectance { reflectance: [f64; 3], mfp: [f64; 3] },
    /// `"texture reflectance"` and `mfp`: the material is the texture's mean reflectance inverted,
    /// and the texture weighs it per point (`world::Object::texture`).
    Texture { texture: Reflectance, mfp: [f64; 3] },
    /// Nothing given: pbrt's default (its whole milk).
    Default,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Subsurface {
    /// As the file gives them (pbrt multiplies them by `scale`, in 1/scene unit).
    pub sigma_a: [f64; 3],
    pub sigma_s: [f64; 3],
    pub scale: f64,
    pub g: f64,
    pub eta: f64,
    /// pbrt's roughness and whether it is remapped (α = √roughness) or α itself.
    pub roughness: f64,
    pub remap_roughness: bool,
    pub source: SubsurfaceSource,
    pub loc: Loc,
}

/// A diffuse reflectance: constant or textured.
#[derive(Clone, Debug, PartialEq)]
pub enum Reflectance {
    Constant([f64; 3]),
    Checkerboard { uscale: f64, vscale: f64, tex1: Box<Reflectance>, tex2: Box<Reflectance> },
    ImageMap { path: PathBuf },
}

#[derive(Clone, Debug, PartialEq)]
pub enum MaterialDesc {
    Subsurface(Subsurface),
    Diffuse {
        reflectance: Reflectance,
    },
    /// `interface`: no surface (a medium boundary); its shapes are not kept.
    Interface,
}

impl Default for MaterialDesc {
    /// pbrt-v4's default: diffuse, reflectance 0.5.
    fn default() -> Self {
        MaterialDesc::Diffuse { reflectance: Reflectance::Constant([0.5; 3]) }
    }
}

#[derive(Clone, Debug)]
pub struct Object {
    /// World space, wound counter-clockwise seen from outside by pbrt's orientation rule.
    pub mesh: RawMesh,
    pub material: MaterialDesc,
    /// `trianglemesh`, `plymesh`, `sphere`.
    pub shape: String,
    pub loc: Loc,
}

/// Lights in world space; `scale` as given (the renderer multiplies).
#[derive(Clone, Debug)]
pub enum LightDesc {
    Distant {
        from: DVec3,
        to: DVec3,
        l: [f64; 3],
        scale: f64,
        loc: Loc,
    },
    Point {
        from: DVec3,
        i: [f64; 3],
        scale: f64,
        loc: Loc,
    },
    Spot {
        from: DVec3,
        to: DVec3,
        coneangle: f64,
        conedelta: f64,
        i: [f64; 3],
        scale: f64,
        loc: Loc,
    },
    /// `frame`: the light's transform (the map's frame in the world; pbrt's maps are z up).
    Infinite {
        filename: Option<PathBuf>,
        l: Option<[f64; 3]>,
        scale: f64,
        frame: glam::DMat3,
        loc: Loc,
    },
}

#[derive(Clone, Debug, Default)]
pub struct PbrtScene {
    pub camera: Option<CameraDesc>,
    pub film: FilmDesc,
    pub objects: Vec<Object>,
    pub lights: Vec<LightDesc>,
    /// `FILE:LINE:COLUMN: …` lines: ignored directives and parameters.
    pub warnings: Vec<String>,
}

/// Reads a pbrt-v4 scene file and what it includes. Every refusal is bad input (exit 2) with
/// `FILE:LINE:COLUMN: …` naming the directive or parameter and what is supported.
pub fn load(path: &Path) -> Result<PbrtScene> {
    scene::load(path).map_err(|e| bad_input!("{e}"))
}

/// pbrt-v4's measured media (`GetMediumScatteringProperties` in pbrt-v4's src/pbrt/media.cpp,
/// copied as data): name, σ's (reduced scattering), σa, in 1/mm. The first 12 are Jensen et al.
/// 2001 (the same as [`crate::materials`]'s table A); the rest are pbrt-v4's own conversion of
/// Narasimhan et al. 2006, which differs from the paper's table we ship (table B).
pub const PBRT_MEDIA: [(&str, [f64; 3], [f64; 3]); 47] = [
    ("Apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    ("Chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    ("Chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    ("Cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    ("Ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    ("Marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    ("Potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    ("Skimmilk", [0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    ("Skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    ("Skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    ("Spectralon", [11.6, 20.4, 14.9], [0.00, 0.00, 0.00]),
    ("Wholemilk", [2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
    ("Lowfat Milk", [0.89187, 1.5136, 2.532], [0.002875, 0.00575, 0.0115]),
    ("Reduced Milk", [2.4858, 3.1669, 4.5214], [0.0025556, 0.0051111, 0.012778]),
    ("Regular Milk", [4.5513, 5.8294, 7.136], [0.0015333, 0.0046, 0.019933]),
    ("Espresso", [0.72378, 0.84557, 1.0247], [4.7984, 6.5751, 8.8493]),
    ("Mint Mocha Coffee", [0.31602, 0.38538, 0.48131], [3.772, 5.8228, 7.82]),
    ("Lowfat Soy Milk", [0.30576, 0.34233, 0.61664], [0.0014375, 0.0071875, 0.035937]),
    ("Regular Soy Milk", [0.59223, 0.73866, 1.4693], [0.0019167, 0.0095833, 0.065167]),
    ("Lowfat Chocolate Milk", [0.64925, 0.83916, 1.1057], [0.0115, 0.0368, 0.1564]),
    ("Regular Chocolate Milk", [1.4585, 2.1289, 2.9527], [0.010063, 0.043125, 0.14375]),
    ("Coke", [8.9053e-05, 8.372e-05, 0.0], [0.10014, 0.16503, 0.2468]),
    ("Pepsi", [6.1697e-05, 4.2564e-05, 0.0], [0.091641, 0.14158, 0.20729]),
    ("Sprite", [6.0306e-06, 6.4139e-06, 6.5504e-06], [0.001886, 0.0018308, 0.0020025]),
    ("Gatorade", [0.0024574, 0.003007, 0.0037325], [0.024794, 0.019289, 0.008878]),
    ("Chardonnay", [1.7982e-05, 1.3758e-05, 1.2023e-05], [0.010782, 0.011855, 0.023997]),
    ("White Zinfandel", [1.7501e-05, 1.9069e-05, 1.288e-05], [0.012072, 0.016184, 0.019843]),
    ("Merlot", [2.1129e-05, 0.0, 0.0], [0.11632, 0.25191, 0.29434]),
    ("Budweiser Beer", [2.4356e-05, 2.4079e-05, 1.0564e-05], [0.011492, 0.024911, 0.057786]),
    ("Coors Light Beer", [5.0922e-05, 4.301e-05, 0.0], [0.006164, 0.013984, 0.034983]),
    ("Clorox", [0.0024035, 0.0031373, 0.003991], [0.0033542, 0.014892, 0.026297]),
    ("Apple Juice", [0.00013612, 0.00015836, 0.000227], [0.012957, 0.023741, 0.052184]),
    ("Cranberry Juice", [0.00010402, 0.00011646, 7.8139e-05], [0.039437, 0.094223, 0.12426]),
    ("Grape Juice", [5.382e-05, 0.0, 0.0], [0.10404, 0.23958, 0.29325]),
    ("Ruby Grapefruit Juice", [0.011002, 0.010927, 0.011036], [0.085867, 0.18314, 0.25262]),
    ("White Grapefruit Juice", [0.22826, 0.23998, 0.32748], [0.0138, 0.018831, 0.056781]),
    ("Shampoo", [0.0007176, 0.0008303, 0.0009016], [0.014107, 0.045693, 0.061717]),
    ("Strawberry Shampoo", [0.00015671, 0.00015947, 1.518e-05], [0.01449, 0.05796, 0.075823]),
    ("Head & Shoulders Shampoo", [0.023805, 0.028804, 0.034306], [0.084621, 0.15688, 0.20365]),
    ("Lemon Tea Powder", [0.040224, 0.045264, 0.051081], [2.4288, 4.5757, 7.2127]),
    ("Orange Powder", [0.00015617, 0.00017482, 0.0001762], [0.001449, 0.003441, 0.007863]),
    ("Pink Lemonade Powder", [0.00012103, 0.00013073, 0.00012528], [0.001165, 0.002366, 0.003195]),
    ("Cappuccino Powder", [1.8436, 2.5851, 2.1662], [35.844, 49.547, 61.084]),
    ("Salt Powder", [0.027333, 0.032451, 0.031979], [0.28415, 0.3257, 0.34148]),
    ("Sugar Powder", [0.00022272, 0.00025513, 0.000271], [0.012638, 0.031051, 0.050124]),
    ("Suisse Mocha Powder", [2.7979, 3.5452, 4.3365], [17.502, 27.004, 35.433]),
    ("Pacific Ocean Surface Water", [0.0001764, 0.00032095, 0.00019617], [0.031845, 0.031324, 0.030147]),
];

/// A medium of pbrt-v4's table by name (pbrt matches exactly; here also ignoring case, spaces
/// and punctuation, as `--material` does): (σa, σs) with g = 0.
pub fn pbrt_medium(name: &str) -> Option<([f64; 3], [f64; 3])> {
    let key = |s: &str| s.chars().filter(|c| c.is_alphanumeric()).flat_map(char::to_lowercase).collect::<String>();
    PBRT_MEDIA
        .iter()
        .find(|(n, _, _)| *n == name)
        .or_else(|| PBRT_MEDIA.iter().find(|(n, _, _)| key(n) == key(name)))
        .map(|(_, s, a)| (*a, *s))
}

/// `reflectance` + `mfp` as coefficients: per channel, the reduced albedo α' whose classical-dipole
/// total diffuse reflectance Rd(α') (Jensen et al. 2001, with η's A) is the reflectance, found by
/// bisection in f64; then σ't = 1/mfp (mfp the reduced mean free path), σ's = α'σ't, σa = σ't − σ's
/// and σs = σ's/(1 − g). pbrt-v4 inverts its own photon-beam-diffusion table instead, so its
/// coefficients differ slightly; the reflectance is what both reproduce.
pub fn from_reflectance(
    reflectance: [f64; 3],
    mfp: [f64; 3],
    g: f64,
    eta: f64,
) -> std::result::Result<([f64; 3], [f64; 3]), String> {
    if g.is_nan() || g.abs() >= 1.0 {
        return Err(format!("g = {g} must lie in (−1, 1)"));
    }
    if !(crate::materials::ETA_RANGE.0..=crate::materials::ETA_RANGE.1).contains(&eta) {
        return Err(format!("eta = {eta} must be within [0.1, 10]"));
    }
    let a = crate::physics::Medium { sigma_a: 0.1, sigma_s: 1.0, g: 0.0, eta }
        .constants(crate::physics::Diffusion::Classical)
        .a_dipole;
    let rd = |alpha: f64| crate::physics::dipole::total_rd(alpha, a);
    let mut sigma_a = [0.0; 3];
    let mut sigma_s = [0.0; 3];
    for ch in 0..3 {
        let (r, l) = (reflectance[ch], mfp[ch]);
        if !(l.is_finite() && l > 0.0) {
            return Err(format!("mfp = {l} in channel {ch} must be positive"));
        }
        let top = rd(1.0);
        if !(0.0..=1.0).contains(&r) || r >= top {
            return Err(format!("reflectance {r} in channel {ch} must be within [0, {top:.4}) (the dipole's Rd at albedo 1 for eta {eta})"));
        }
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if rd(mid) < r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let alpha = 0.5 * (lo + hi);
        let sigma_t_reduced = 1.0 / l;
        sigma_s[ch] = alpha * sigma_t_reduced / (1.0 - g);
        sigma_a[ch] = (1.0 - alpha) * sigma_t_reduced;
    }
    Ok((sigma_a, sigma_s))
}

/// The largest reflectance [`from_reflectance`] inverts: the classical dipole's Rd at albedo 1.
pub fn max_reflectance(eta: f64) -> f64 {
    let a = crate::physics::Medium { sigma_a: 0.1, sigma_s: 1.0, g: 0.0, eta }
        .constants(crate::physics::Diffusion::Classical)
        .a_dipole;
    crate::physics::dipole::total_rd(1.0, a)
}

/// Whether `flag` (`--width`) was typed on the command line `argv` (as `--width V` or
/// `--width=V`; `--out` also as `-o`).
pub fn flag_given(argv: &[String], flag: &str) -> bool {
    argv.iter().any(|a| a == flag || a.starts_with(&format!("{flag}=")) || (flag == "--out" && a.starts_with("-o")))
}

/// The smallest roughness the specular lobe is given for pbrt's smooth (roughness 0) surface.
pub const MIN_ROUGHNESS: f32 = 0.05;

/// The renderer's settings for a pbrt scene: every `subsurface` shape a translucent object (at
/// least one), every `diffuse` one an opaque object, the distant, point and spot lights, the
/// `infinite` ones summed into one environment, and a perspective camera; anything else is
/// refused, naming its file:line:column. Flags typed on the command line
/// (`given`) override the scene: --width, --height, --out, --eye, --target, --up, --fov, the
/// lights, the material flags, --scale, --roughness; the others (--model, --epsilon, --samples, …)
/// apply as always. Returns the arguments with the film's size and file filled in, for the rest of
/// `render`. The one piece of glue to the renderer: re-point it at a World of objects later.
pub fn render_settings(
    path: &Path,
    args: &crate::cli::RenderArgs,
    given: &dyn Fn(&str) -> bool,
) -> Result<(crate::cli::RenderArgs, crate::settings::RenderSettings)> {
    use crate::scene::{Camera, Light};
    let scene = load(path)?;
    for w in &scene.warnings {
        crate::note!("warning: {w}");
    }
    if args.mesh.is_some() {
        return Err(bad_input!("--mesh: a scene file gives its own shapes; leave out --mesh or the scene"));
    }
    let shown = path.display();
    let mut translucent = Vec::new();
    let mut opaque = Vec::new();
    for o in &scene.objects {
        match &o.material {
            MaterialDesc::Subsurface(s) => translucent.push((o, s)),
            MaterialDesc::Diffuse { reflectance } => opaque.push((o, reflectance_of(reflectance, &o.loc)?)),
            MaterialDesc::Interface => {}
        }
    }
    let sub = translucent.first().map(|&(_, s)| s);
    if sub.is_none() {
        if opaque.is_empty() {
            return Err(bad_input!("{shown}: no shape with a subsurface or diffuse material (nothing to render)"));
        }
        crate::note!(
            "warning: {shown}: no shape with a subsurface material: nothing in the scene is translucent; its diffuse shapes are rendered under its lights"
        );
    }
    let mut lights = Vec::new();
    // Every `infinite` light, summed into one environment below (pbrt-v4 adds them).
    let mut environments: Vec<crate::environment::Environment> = Vec::new();
    for l in &scene.lights {
        let rgb = |c: [f64; 3], s: f64| Vec3::new((c[0] * s) as f32, (c[1] * s) as f32, (c[2] * s) as f32);
        match l {
            LightDesc::Distant { from, to, l, scale, loc } => {
                // Normalised in f32 as `--light dir:` is, so that the same light gives the same bits.
                let toward = crate::mesh::safe_normalize((*from - *to).as_vec3())
                    .ok_or_else(|| bad_input!("{loc}: LightSource \"distant\": from and to are the same point"))?;
                lights.push(Light::Directional { toward, irradiance: rgb(*l, *scale) });
            }
            LightDesc::Point { from, i, scale, .. } => {
                lights.push(Light::Point { position: from.as_vec3(), intensity: rgb(*i, *scale) })
            }
            LightDesc::Spot { from, to, coneangle, conedelta, i, scale, loc } => lights.push(
                Light::spot(from.as_vec3(), to.as_vec3(), *coneangle as f32, *conedelta as f32, rgb(*i, *scale))
                    .map_err(|e| bad_input!("{loc}: LightSource \"spot\": {e}"))?,
            ),
            LightDesc::Infinite { filename, l, scale, frame, loc } => {
                let shown = format!("{loc}: LightSource \"infinite\"");
                let radiance = match (filename, l) {
                    (Some(f), _) => crate::environment::Environment::load(f, &format!("{shown} \"{}\"", f.display()))?,
                    (None, l) => crate::environment::Radiance::Constant(rgb(l.unwrap_or([1.0; 3]), 1.0)),
                };
                // Orthonormal columns: the map's frame (pbrt allows any transform; a scale or
                // shear of directions has no meaning for an environment).
                let f = frame.as_mat3();
                let ortho = [f.x_axis, f.y_axis, f.z_axis].iter().all(|c| (c.length() - 1.0).abs() < 1e-3)
                    && f.x_axis.dot(f.y_axis).abs() < 1e-3
                    && f.y_axis.dot(f.z_axis).abs() < 1e-3
                    && f.x_axis.dot(f.z_axis).abs() < 1e-3;
                if !ortho {
                    return Err(bad_input!("{shown}: its transform must be a rotation"));
                }
                environments.push(crate::environment::Environment {
                    name: shown,
                    radiance,
                    scale: *scale as f32,
                    to_world: f,
                    samples: args.env_samples,
                });
            }
        }
    }
    let mut environment = match environments.len() {
        0 => None,
        _ => Some(crate::environment::Environment::sum(&environments)?),
    };
    let camera = scene.camera.clone().unwrap_or_else(|| CameraDesc {
        eye: DVec3::ZERO,
        target: DVec3::Z,
        up: DVec3::Y,
        fov_deg: 90.0,
        left_handed: true,
        loc: Loc { file: std::rc::Rc::from(shown.to_string()), line: 1, column: 1 },
    });

    // The arguments as the rest of `render` reads them: the film's size and file unless typed.
    let mut out = args.clone();
    if !given("--width") {
        out.width = scene.film.xresolution;
    }
    if !given("--height") {
        out.height = scene.film.yresolution;
    }
    if let (false, Some(f)) = (given("--out"), &scene.film.filename) {
        let ext = Path::new(f).extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
        if matches!(ext.as_deref(), Some("png" | "exr")) {
            out.out = PathBuf::from(f);
        } else {
            crate::note!(
                "warning: {}: Film filename \"{f}\": translucent writes .png or .exr; writing {}",
                scene.film.loc.as_ref().map(|l| l.to_string()).unwrap_or_default(),
                out.out.display()
            );
        }
    }
    // The base settings from the flags, on a stand-in mesh, then the scene's in its place.
    let mut stand_in = args.clone();
    stand_in.mesh = Some("sphere".into());
    let mut settings = crate::settings::RenderSettings::from_args(&stand_in)?;
    (settings.desc.width, settings.desc.height) = (out.width, out.height);

    // The objects, the lights and the camera; mirrored when pbrt's camera is left-handed.
    let (eye, target, up) = (camera.eye, camera.target, camera.up);
    let n = (target - eye).cross(up).normalize();
    let mirror = |p: DVec3| p - 2.0 * (p - eye).dot(n) * n;
    let mirror_v = |v: DVec3| v - 2.0 * v.dot(n) * n;
    // Each shape's mesh as the renderer takes it, and its uv.
    let mesh_of = |o: &Object| -> Result<(crate::mesh::Mesh, Option<Vec<glam::Vec2>>)> {
        let mut raw = o.mesh.clone();
        if camera.left_handed {
            for p in &mut raw.positions {
                *p = mirror(p.as_dvec3()).as_vec3();
            }
            if let Some(ns) = &mut raw.normals {
                for v in ns.iter_mut() {
                    *v = mirror_v(v.as_dvec3()).as_vec3();
                }
            }
            for t in raw.indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        let uvs = raw.uvs.clone().filter(|uv| uv.len() == raw.positions.len());
        let shown = format!("{} (Shape \"{}\")", o.loc, o.shape);
        Ok((crate::mesh::Mesh::from_raw(raw, &shown, crate::mesh::MeshFormat::Ply)?, uvs))
    };
    if camera.left_handed {
        for l in &mut lights {
            match l {
                Light::Directional { toward, .. } => *toward = mirror_v(toward.as_dvec3()).as_vec3(),
                Light::Point { position, .. } => *position = mirror(position.as_dvec3()).as_vec3(),
                Light::Spot { position, axis, .. } => {
                    *position = mirror(position.as_dvec3()).as_vec3();
                    *axis = mirror_v(axis.as_dvec3()).normalize().as_vec3();
                }
            }
        }
    }
    let (w, h) = (out.width as f64, out.height as f64);
    // pbrt's fov spans the shorter side; ours is vertical.
    let fov = if w >= h {
        camera.fov_deg
    } else {
        2.0 * ((camera.fov_deg.to_radians() / 2.0).tan() * h / w).atan().to_degrees()
    };
    let mut cam =
        Camera { eye: eye.as_vec3(), target: target.as_vec3(), up: up.normalize().as_vec3(), fov_y_deg: fov as f32 };
    if given("--eye") {
        cam.eye = args.eye.unwrap_or(cam.eye);
    }
    if given("--target") {
        cam.target = args.target.unwrap_or(cam.target);
    }
    if given("--up") {
        cam.up = settings.desc.camera.up;
    }
    if given("--fov") {
        cam.fov_y_deg = args.fov;
    }
    if given("--env") {
        environment = None; // the flag's environment replaces the scene's
    }
    if let Some(env) = environment.as_mut() {
        if camera.left_handed {
            let m = glam::DMat3::from_cols(mirror_v(DVec3::X), mirror_v(DVec3::Y), mirror_v(DVec3::Z));
            env.to_world = (m * env.to_world.as_dmat3()).as_mat3();
        }
        lights.extend(env.lights()?);
    }
    let flags_light = given("--light") || given("--light-dir") || given("--light-intensity") || given("--env");
    if flags_light || lights.is_empty() {
        // The flags' lights (and environment) replace the scene's.
        environment = None;
        if lights.is_empty() && !given("--light") && !given("--light-dir") && !given("--env") {
            crate::note!("warning: {shown}: no distant or point light: the default light is used");
        }
        lights = settings.desc.lights.clone();
    }
    // One scale for the world: the first subsurface material's `scale` (or --scale); other
    // materials' coefficients are multiplied by their scale over it, which is what pbrt does.
    let mm_per_unit = match sub {
        Some(sub) if !given("--scale") => sub.scale as f32,
        _ => args.scale,
    };
    let mut objects = Vec::new();
    for &(o, sub) in &translucent {
        let mut material = material_of(sub, args, given)?;
        if !given("--scale") && sub.scale as f32 != mm_per_unit {
            let f = sub.scale / mm_per_unit as f64;
            material.sigma_a = material.sigma_a.map(|v| v * f);
            material.sigma_s = material.sigma_s.map(|v| v * f);
        }
        let (mesh, uvs) = mesh_of(o)?;
        let textured = match &sub.source {
            SubsurfaceSource::Texture { texture, mfp } => Some((reflectance_of(texture, &sub.loc)?, mfp)),
            _ => None,
        };
        if let Some((texture, mfp)) = &textured {
            if uvs.is_none() {
                return Err(bad_input!(
                    "{}: Shape \"{}\": a reflectance texture needs the shape's \"point2 uv\"",
                    o.loc,
                    o.shape
                ));
            }
            // The material is the texture's mean colour; the texture weighs it per point. A preset
            // typed keeps its mean free path and takes the texture's mean as its albedo.
            if given("--material") {
                material = crate::world::textured_material(&material, texture)?;
            } else if !["--sigma-a", "--sigma-s", "--g"].iter().any(|f| given(f)) {
                let mean = texture.mean();
                let top = max_reflectance(sub.eta) * 0.999;
                let mean = [0, 1, 2].map(|c| (mean[c] as f64).min(top));
                let (a, s) = from_reflectance(mean, **mfp, sub.g, sub.eta)
                    .map_err(|why| bad_input!("{}: subsurface: {why}", sub.loc))?;
                let f = sub.scale / mm_per_unit as f64;
                (material.sigma_a, material.sigma_s) = (a.map(|v| v * f), s.map(|v| v * f));
                material.g = [sub.g; 3];
                material.validate()?;
            }
        }
        let mut object = crate::world::Object::new(mesh, material);
        object.samples = args.samples;
        if let Some((texture, _)) = textured {
            (object.texture, object.uvs) = (Some(texture), uvs);
        }
        objects.push(object);
    }
    let mut opaque_objects = Vec::new();
    for (o, reflectance) in opaque {
        let (mesh, uvs) = mesh_of(o)?;
        let textured = !matches!(reflectance, crate::world::Reflectance::Constant(_));
        if textured && uvs.is_none() {
            return Err(bad_input!("{}: Shape \"{}\": a texture needs the shape's \"point2 uv\"", o.loc, o.shape));
        }
        opaque_objects.push(crate::world::Opaque { uvs, ..crate::world::Opaque::new(mesh, reflectance) });
    }
    if let Some(sub) = sub.filter(|_| !given("--roughness")) {
        // pbrt: α = √roughness when remapped, else α = roughness; ours: α = roughness².
        let alpha = if sub.remap_roughness { sub.roughness.max(0.0).sqrt() } else { sub.roughness };
        let r = (alpha.max(0.0).sqrt() as f32).clamp(MIN_ROUGHNESS, 1.0);
        if alpha.sqrt() < MIN_ROUGHNESS as f64 {
            crate::note!(
                "warning: {}: subsurface roughness {} (a smooth surface) is rendered with roughness {MIN_ROUGHNESS}",
                sub.loc,
                sub.roughness
            );
        }
        settings.desc.roughness = r;
    }

    crate::frame_desc::check_camera(&cam)?;
    crate::frame_desc::check_lights(&lights)?;
    let mut world = crate::world::World { objects, opaque: opaque_objects, mm_per_unit };
    for (o, &(_, sub)) in world.objects.iter().zip(&translucent) {
        o.mesh.validate()?;
        let (_, radius) = crate::scene::bounding_sphere(&o.mesh.positions);
        let size_mm = 2.0 * radius as f64 * mm_per_unit as f64;
        let limits = crate::world::SIZE_MM_LIMITS;
        if !(limits.0..=limits.1).contains(&size_mm) {
            return Err(bad_input!("{}: the object is {size_mm:.3e} mm across at scale {mm_per_unit} mm per unit; it must be within [{:e}, {:e}] mm", sub.loc, limits.0, limits.1));
        }
    }
    if world.objects.is_empty() && world.opaque.is_empty() {
        return Err(bad_input!("{}: no shape with a subsurface or diffuse material", path.display()));
    }
    crate::settings::rescale_world(&mut world, &mut cam, &mut lights);
    settings.world = world;
    (settings.desc.camera, settings.desc.lights) = (cam, lights);
    if let Some(env) = environment {
        settings.desc.environment = Some(std::sync::Arc::new(env));
    }
    settings.desc.validate()?;
    settings.world.validate()?;
    Ok((out, settings))
}

/// A subsurface material as the renderer takes it: the scene's, unless a preset is typed;
/// coefficient flags override either.
fn material_of(
    sub: &Subsurface,
    args: &crate::cli::RenderArgs,
    given: &dyn Fn(&str) -> bool,
) -> Result<crate::materials::Material> {
    let m = &args.material;
    if given("--material") {
        return m.material();
    }
    let mut mat = crate::materials::Material::custom(sub.sigma_a, sub.sigma_s, [sub.g; 3], sub.eta)
        .map_err(|e| bad_input!("{}: subsurface: {e}", sub.loc))?;
    mat.name = match &sub.source {
        SubsurfaceSource::Named(n) => format!("{n} (pbrt-v4's table)"),
        SubsurfaceSource::Coefficients => format!("{} subsurface", sub.loc),
        SubsurfaceSource::Reflectance { .. } => format!("{} subsurface (from reflectance)", sub.loc),
        SubsurfaceSource::Texture { .. } => format!("{} subsurface (from a reflectance texture)", sub.loc),
        SubsurfaceSource::Default => "pbrt-v4's default subsurface".into(),
    };
    mat.sigma_a = m.sigma_a.unwrap_or(mat.sigma_a);
    mat.sigma_s = m.sigma_s.unwrap_or(mat.sigma_s);
    mat.g = m.g.unwrap_or(mat.g);
    mat.eta = m.eta.unwrap_or(mat.eta);
    mat.validate()?;
    Ok(mat)
}

/// A diffuse reflectance as the renderer takes it: a constant, or a checkerboard of two constants.
fn reflectance_of(r: &Reflectance, loc: &Loc) -> Result<crate::world::Reflectance> {
    let rgb = |c: &[f64; 3]| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32);
    match r {
        Reflectance::Constant(c) => Ok(crate::world::Reflectance::Constant(rgb(c))),
        Reflectance::Checkerboard { uscale, vscale, tex1, tex2 } => match (tex1.as_ref(), tex2.as_ref()) {
            (Reflectance::Constant(a), Reflectance::Constant(b)) => Ok(crate::world::Reflectance::Checkerboard {
                uscale: *uscale as f32,
                vscale: *vscale as f32,
                tex1: rgb(a),
                tex2: rgb(b),
            }),
            _ => Err(bad_input!("{loc}: a checkerboard of textures (not of two constants) is not rendered yet")),
        },
        Reflectance::ImageMap { path } => {
            let shown = format!("{loc}: \"imagemap\" {}", path.display());
            Ok(crate::world::Reflectance::Image(crate::world::Texture::load(path, &shown)?))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pbrt_table_names_and_values() {
        // Jensen's entries equal ours; pbrt's Narasimhan conversion does not.
        let (a, s) = pbrt_medium("Skin1").unwrap();
        let ours = crate::materials::Material::find("skin1").unwrap();
        assert_eq!((a, s), (ours.sigma_a, ours.sigma_s));
        let (a, s) = pbrt_medium("Lowfat Milk").unwrap();
        assert_eq!((a, s), ([0.002875, 0.00575, 0.0115], [0.89187, 1.5136, 2.532]));
        assert!(pbrt_medium("lowfat-milk").is_some());
        assert!(pbrt_medium("Unobtainium").is_none());
    }

    #[test]
    fn reflectance_inverts_the_dipole() {
        let (a, s) = from_reflectance([0.8, 0.5, 0.1], [1.0, 2.0, 0.5], 0.0, 1.33).unwrap();
        let aa = crate::physics::Medium { sigma_a: 0.1, sigma_s: 1.0, g: 0.0, eta: 1.33 }
            .constants(crate::physics::Diffusion::Classical)
            .a_dipole;
        for ch in 0..3 {
            let st = a[ch] + s[ch];
            let rd = crate::physics::dipole::total_rd(s[ch] / st, aa);
            assert!((rd - [0.8, 0.5, 0.1][ch]).abs() < 1e-12, "{rd}");
            assert!((1.0 / st - [1.0, 2.0, 0.5][ch]).abs() < 1e-12);
        }
        assert!(from_reflectance([1.5; 3], [1.0; 3], 0.0, 1.33).unwrap_err().contains("must be within"));
        assert!(from_reflectance([0.5; 3], [0.0; 3], 0.0, 1.33).unwrap_err().contains("mfp"));
    }

    #[test]
    fn flags_are_found_in_argv() {
        let argv: Vec<String> =
            ["translucent", "render", "s.pbrt", "--width=64", "-oout.png"].map(String::from).to_vec();
        assert!(flag_given(&argv, "--width") && flag_given(&argv, "--out") && !flag_given(&argv, "--height"));
    }
}
