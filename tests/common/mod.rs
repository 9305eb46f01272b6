//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};
use std::sync::Arc;

use glam::Vec3;
use translucent::frame::Renderer;
use translucent::mesh::safe_normalize;
use translucent::output::HdrImage;
use translucent::physics::{Medium, Query};
use translucent::scene::Light;
use translucent::settings::RenderSettings;
use translucent::vk::{Context, ContextOptions, ValidationCounts};

/// A context with validation and synchronization validation on. The counts are returned separately
/// so they can be read after the context (and its device) is destroyed.
pub fn validated_context() -> (Context, Arc<ValidationCounts>) {
    let ctx = Context::new(&ContextOptions { validation: true, device: None }).expect("Vulkan context with validation");
    let counts = ctx.validation_counts();
    (ctx, counts)
}

/// Asserts that the validation layer reported nothing (call after dropping the context).
pub fn assert_clean(counts: &ValidationCounts) {
    use std::sync::atomic::Ordering;
    let (w, e) = (counts.warnings.load(Ordering::SeqCst), counts.errors.load(Ordering::SeqCst));
    assert_eq!((w, e), (0, 0), "validation reported {e} error(s) and {w} warning(s); see the log above");
}

/// Renders one frame of `settings` through the library, as `translucent render --validation` does,
/// on a context with validation and synchronization validation (any message fails the test).
/// Returns the renderer, for the image, the tone-mapped image or the work counters; the caller
/// drops it and then calls [`assert_clean`] on the counts.
pub fn render_frame(settings: &RenderSettings) -> (Renderer, Arc<ValidationCounts>) {
    let (ctx, counts) = validated_context();
    let mut renderer = Renderer::new(ctx, settings.profile).expect("renderer");
    renderer.render_frame(&settings.world, &settings.desc).expect("frame");
    (renderer, counts)
}

/// One frame of `settings` (see [`render_frame`]): its linear radiance, validation checked clean.
pub fn render_hdr(settings: &RenderSettings) -> HdrImage {
    let (renderer, counts) = render_frame(settings);
    let image = renderer.image().expect("image");
    drop(renderer);
    assert_clean(&counts);
    image
}

/// A directional light toward `toward` (normalised as `--light dir:X,Y,Z:I` does) with
/// irradiance `irradiance` at normal incidence.
pub fn dir_light(toward: [f32; 3], irradiance: [f32; 3]) -> Light {
    let toward = safe_normalize(Vec3::from(toward)).expect("a light direction");
    Light::Directional { toward, irradiance: Vec3::from(irradiance) }
}

/// A point light at `position` with radiant intensity `intensity` (`--light point:X,Y,Z:I`).
pub fn point_light(position: [f32; 3], intensity: [f32; 3]) -> Light {
    Light::Point { position: Vec3::from(position), intensity: Vec3::from(intensity) }
}

/// Runs the `translucent` binary with `args`.
pub fn translucent(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_translucent")).args(args).output().expect("run translucent")
}

/// Starts `translucent bssrdf ARGS` with piped stdin, stdout and stderr.
pub fn spawn_bssrdf(args: &[&str]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_translucent"))
        .arg("bssrdf")
        .args(args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("start translucent bssrdf")
}

/// Where tests write images (actual and difference images on failure).
pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("translucent-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn repo_path(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Deterministic random queries over σa 1e-4…1 (log-uniform), σs 0.1…30, g −0.3…0.9, η 1.0…1.6,
/// in three geometries taken in turn: coplanar, curved (two points on a sphere) and back-lit
/// (exit on the far side of a slab). The light is in the hemisphere of ni.
pub fn random_queries(n: usize, seed: u64) -> Vec<Query> {
    use glam::DVec3;
    let mut state = seed;
    // splitmix64: small, good enough for test inputs, no dependency.
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let unit = |next: &mut dyn FnMut() -> f64| {
        let z = 2.0 * next() - 1.0;
        let phi = std::f64::consts::TAU * next();
        let s = (1.0 - z * z).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    (0..n)
        .map(|i| {
            let medium = Medium {
                sigma_a: 10f64.powf(-4.0 + 4.0 * next()),
                sigma_s: 0.1 + 29.9 * next(),
                g: -0.3 + 1.2 * next(),
                eta: 1.0 + 0.6 * next(),
            };
            let (xi, ni, xo, no) = match i % 3 {
                0 => {
                    let d = DVec3::new(next() - 0.5, next() - 0.5, 0.0) * 10.0 * next();
                    (DVec3::ZERO, DVec3::Z, d, DVec3::Z)
                }
                1 => {
                    let radius = 0.5 + 20.0 * next();
                    let (a, b) = (unit(&mut next), unit(&mut next));
                    (a * radius, a, b * radius, b)
                }
                _ => {
                    let thickness = 0.1 + 5.0 * next();
                    let d = DVec3::new(next() - 0.5, next() - 0.5, 0.0) * 4.0;
                    (DVec3::ZERO, DVec3::Z, d - DVec3::Z * thickness, -DVec3::Z)
                }
            };
            let mut wi = unit(&mut next);
            if wi.dot(ni) < 0.0 {
                wi -= 2.0 * wi.dot(ni) * ni;
            }
            Query { medium, xi, ni, wi, xo, no }
        })
        .collect()
}

/// ∫Sd dA of the directional dipole over the plane y = 0 (normal +y), light arriving from
/// `toward`, exit at the origin: a polar grid of `radii` log-spaced radii (1e-6 mm to 40
/// diffusion lengths) and `angles` angles, in f64.
pub fn dirpole_plane_integral(
    c: &translucent::physics::ChannelConstants,
    toward: glam::DVec3,
    (radii, angles): (usize, usize),
) -> f64 {
    use glam::DVec3;
    let n = DVec3::Y;
    let (lo, hi) = (1e-6f64.ln(), (40.0 / c.sigma_tr).ln());
    let h = (hi - lo) / radii as f64;
    let mut sum = 0.0;
    for i in 0..radii {
        let r = (lo + (i as f64 + 0.5) * h).exp();
        let mut ring = 0.0;
        for k in 0..angles {
            let phi = (k as f64 + 0.5) * std::f64::consts::TAU / angles as f64;
            // Entry point xi around the exit point xo = 0.
            let xi = DVec3::new(r * phi.cos(), 0.0, r * phi.sin());
            ring += translucent::physics::dirpole::sd(c, xi, n, toward, DVec3::ZERO, n);
        }
        sum += ring / angles as f64 * std::f64::consts::TAU * r * r * h;
    }
    sum
}

/// An OBJ box `2·half` wide (x, z) and `2·thickness` tall (y), 8 shared corners, faces
/// counter-clockwise from outside, using material `painted` of `box.mtl`; with `vt` (u 0.02 at
/// x < 0, 0.98 at x > 0, v 0.5) on every vertex when `uv`.
#[allow(dead_code)]
pub fn box_obj(half: f32, thickness: f32, uv: bool) -> String {
    let mut obj = String::from("mtllib box.mtl\nusemtl painted\n");
    for k in 0..8 {
        let side = |bit: i32, v: f32| if k & bit == 0 { -v } else { v };
        let (x, y, z) = (side(1, half), side(2, thickness), side(4, half));
        obj += &format!("v {x} {y} {z}\n");
        if uv {
            obj += &format!("vt {} 0.5\n", if x < 0.0 { 0.02 } else { 0.98 });
        }
    }
    for f in [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]] {
        let corner = |i: usize| if uv { format!("{0}/{0}", f[i] + 1) } else { (f[i] + 1).to_string() };
        obj += &format!("f {} {} {} {}\n", corner(0), corner(1), corner(2), corner(3));
    }
    obj
}

/// Light along −z on a sphere of radius `r_mm` (centre (0, 0, −R) in mean free paths, the pole at
/// the origin), walked exactly: photons on a stratified grid of `discs` × `angles` over the
/// sphere's disc (equal areas: ring k's radius ∝ √((k + ½)/discs)), each entering refracted and
/// weighted by its Fresnel transmittance; `on_escape(weight, escape)` for each escape. With
/// `dark_side`, past the equator a photon splits in two each ln 2 diffusion lengths further from
/// the pole (up to 1024 copies of as much less weight, `halfspace::Split`), so that the dark
/// half, where an analogue walk counts a handful of photons per ring in a channel that diffuses
/// short, is measured nearly as well as the lit one (Skin1's blue at 145°: noise 28% → 6%), at
/// 2–15× the time; the weight passed is Ft times the escape's. Returns the photons traced (each
/// stands for πR²/photons of the disc).
pub fn front_lit_walk(
    m: &translucent::physics::Medium,
    r_mm: f64,
    (discs, angles): (u64, u64),
    dark_side: bool,
    mut on_escape: impl FnMut(f64, &translucent::physics::sphere::SphereEscape),
) -> u64 {
    let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
    let (albedo, radius) = (m.sigma_s * (1.0 - m.g) / sigma_t, r_mm * sigma_t);
    let centre = glam::DVec3::new(0.0, 0.0, -radius);
    let photons = discs * angles;
    // Geodesic distance from the pole past the equator, in halvings of the diffusion profile
    // (1/σtr = 1/√(3(1 − α')) mean free paths).
    let halving = std::f64::consts::LN_2 / (3.0 * (1.0 - albedo)).sqrt();
    let level = move |chord: f64| {
        let geodesic = 2.0 * radius * (chord / (2.0 * radius)).min(1.0).asin();
        ((geodesic - 0.5 * std::f64::consts::PI * radius).max(0.0) / halving).min(10.0) as u32
    };
    let split = translucent::physics::halfspace::Split { level: &level, allowance: std::cell::Cell::new(u64::MAX) };
    for i in 0..photons {
        let (k, j) = (i / angles, i % angles);
        let rho = radius * ((k as f64 + 0.5) / discs as f64).sqrt();
        let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5 * (k % 2) as f64) / angles as f64;
        let p =
            glam::DVec3::new(rho * phi.cos(), rho * phi.sin(), -radius + (radius * radius - rho * rho).max(0.0).sqrt());
        let n = (p - centre) / radius;
        let cos_i = n.z.clamp(0.0, 1.0);
        let ft = translucent::physics::fresnel::transmittance(m.eta, cos_i);
        let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (m.eta * m.eta)).max(0.0).sqrt();
        let t = ((glam::DVec3::new(0.0, 0.0, -1.0) + cos_i * n) / m.eta - cos_t * n).normalize();
        let seed = 0x1234_5678 ^ i.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        translucent::physics::sphere::trace_from(
            (albedo, m.eta, radius),
            p,
            t,
            (seed, 100_000),
            dark_side.then_some(&split),
            |e| on_escape(ft * e.weight, e),
        );
    }
    photons
}
