//! Default images that converge (issue #19 item 5): at the default sample count, the image
//! against a converged brute force (100,000 points), per pixel. The few points nearest a pixel
//! sample the BSSRDF's peak at r → 0 badly; the near field's control variate (shade.frag:
//! the pixel's own irradiance over its tangent plane, integrated by a fixed quadrature, less the
//! points' estimate of that same integral) removes most of that noise. Each case renders the
//! default image with the near field (the default) and without (`NearField::Off`, the sum as it
//! was), and holds the first to a bound the second fails.

mod common;

use common::render_hdr;
use translucent::frame_desc::NearField;
use translucent::materials::Material;
use translucent::output::HdrImage;
use translucent::physics::Model;
use translucent::scene::Light;
use translucent::settings::{RenderSettings, SceneSettings};

const SIZE: u32 = 48;

/// A Skin1 `mesh` 10 mm across (`--scale 5`), lit from behind and above as `render` lights it by
/// default; `samples`: None for the default count.
fn settings(
    mesh: &str,
    model: Model,
    samples: Option<u32>,
    brute_force: bool,
    near_field: NearField,
) -> RenderSettings {
    let toward = glam::Vec3::new(-0.3, 0.7, -0.65).normalize();
    let lights = vec![Light::Directional { toward, irradiance: glam::Vec3::ONE }];
    let scene = SceneSettings { mesh: Some(mesh.into()), lights, scale: 5.0, ..Default::default() };
    let mut s = RenderSettings::new(scene.build().expect("scene"), Material::find("skin1").unwrap());
    (s.desc.width, s.desc.height, s.world.objects[0].samples) = (SIZE, SIZE, samples);
    s.desc.specular = false;
    let i = &mut s.desc.integration;
    (i.model, i.brute_force, i.near_field) = (model, brute_force, near_field);
    s
}

/// Per channel, sqrt(Σ(a − b)² / Σb²) over the pixels both cover (as `translucent compare`).
fn channel_rmse(a: &HdrImage, b: &HdrImage) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let (mut num, mut den) = (0.0f64, 0.0f64);
        for (p, q) in a.pixels.iter().zip(&b.pixels) {
            if p[3] >= 1.0 && q[3] >= 1.0 {
                num += (p[c] as f64 - q[c] as f64).powi(2);
                den += (q[c] as f64).powi(2);
            }
        }
        *o = (num / den).sqrt();
    }
    out
}

fn percent(e: [f64; 3]) -> String {
    format!("{:.2}% / {:.2}% / {:.2}%", 100.0 * e[0], 100.0 * e[1], 100.0 * e[2])
}

/// One case: the default image with and without the near field against the reference; returns
/// (with, without), per channel.
fn case(mesh: &str, model: Model, reference: &HdrImage) -> ([f64; 3], [f64; 3]) {
    let with = render_hdr(&settings(mesh, model, None, false, NearField::Auto));
    let without = render_hdr(&settings(mesh, model, None, false, NearField::Off));
    let (a, b) = (channel_rmse(&with, reference), channel_rmse(&without, reference));
    println!("{mesh}, {model:?}: near field {} (without: {})", percent(a), percent(b));
    (a, b)
}

fn exact_reference(mesh: &str, model: Model) -> HdrImage {
    render_hdr(&settings(mesh, model, Some(100_000), true, NearField::Auto))
}

/// Asserts every channel of `with` within `bound` and the worst channel at most `gain` of the
/// worst without the near field.
fn check(name: &str, (with, without): ([f64; 3], [f64; 3]), bound: [f64; 3], gain: f64) {
    for c in 0..3 {
        assert!(with[c] <= bound[c], "{name}: channel {c}: {:.3}% > {:.3}%", 100.0 * with[c], 100.0 * bound[c]);
    }
    let worst = |e: [f64; 3]| e.into_iter().fold(0.0, f64::max);
    assert!(worst(with) <= gain * worst(without), "{name}: {} against {} without", percent(with), percent(without));
}

/// Beam diffusion's single scattering makes Sd ~ 1/r as r → 0, so a point sum's variance per
/// pixel diverges (logarithmically) however many points: its exact brute force has hot pixels
/// hundreds of times the mean at 100,000 points too. Its reference is brute force with the near
/// field's control variate (`NearField::On`), which takes the peak out of the sum; for the
/// classical dipole that reference is within 0.4% of the exact one (test below).
fn split_reference(mesh: &str, model: Model) -> HdrImage {
    render_hdr(&settings(mesh, model, Some(100_000), true, NearField::On))
}

/// Measured (lavapipe, 48², per channel R / G / B): directional 0.73 / 1.37 / 2.19% (without
/// the near field 1.60 / 4.95 / 13.04%), dipole 0.65 / 1.04 / 1.34% (0.70 / 1.30 / 2.33%), pbd
/// against its split reference 0.63 / 1.10 / 1.64% (5.44 / 15.78 / 33.54%). The goal,
/// 1% in every channel, is not reached yet in the green and blue channels.
#[test]
fn default_images_converge_on_a_sphere() {
    for (model, bound, gain) in
        [(Model::Directional, [0.009, 0.017, 0.027], 0.25), (Model::Dipole, [0.008, 0.013, 0.017], 0.7)]
    {
        let reference = exact_reference("sphere", model);
        check(&format!("sphere, {model:?}"), case("sphere", model, &reference), bound, gain);
    }
    let reference = split_reference("sphere", Model::Pbd);
    check("sphere, pbd", case("sphere", Model::Pbd, &reference), [0.008, 0.014, 0.02], 0.1);
}

/// A flat slab, where the sample pattern showed as a moiré. Measured (48²): directional 1.99 /
/// 3.48 / 7.71% (without 2.77 / 6.02 / 14.04%), dipole 0.71 / 1.17 / 2.02% (0.79 / 1.52 /
/// 3.07%), pbd 3.52 / 7.73 / 14.59% (7.43 / 16.60 / 31.89%). What remains is at the box's edges
/// (where the control variate fades out: the folded face is nearer in 3D than the tangent plane
/// says) and, for the directional dipole, on the unlit front face next to the lit top (the tree
/// at the default ε and the sampling of the lit face's edge, which the pixel's own irradiance,
/// zero, cannot help): a known shortfall of the 1%.
#[test]
fn default_images_converge_on_a_slab() {
    for (model, bound, gain) in
        [(Model::Directional, [0.025, 0.044, 0.095], 0.7), (Model::Dipole, [0.009, 0.015, 0.025], 0.8)]
    {
        let reference = exact_reference("slab", model);
        check(&format!("slab, {model:?}"), case("slab", model, &reference), bound, gain);
    }
    let reference = split_reference("slab", Model::Pbd);
    check("slab, pbd", case("slab", Model::Pbd, &reference), [0.045, 0.097, 0.18], 0.6);
}

/// The split reference against the exact brute force where the latter converges (the classical
/// dipole): the control variate changes brute force's expectation only where the surface bends
/// within its reach.
#[test]
fn split_brute_force_matches_exact_brute_force() {
    let exact = exact_reference("sphere", Model::Dipole);
    let split = split_reference("sphere", Model::Dipole);
    let e = channel_rmse(&split, &exact);
    println!("sphere, dipole: brute force split against exact {}", percent(e));
    // Measured: 0.03 / 0.09 / 0.25% (128²: 0.028 / 0.093 / 0.246%; the slab 0.10 / 0.26 / 0.58%).
    for (c, e) in e.iter().enumerate() {
        assert!(*e <= 0.004, "channel {c}: {:.3}%", 100.0 * e);
    }
}

/// The Monte Carlo table (`--model mc`): its single scattering is computed per pixel (no
/// sampling), its sampled part is multiple scattering alone, whose peak at r → 0 is a logarithm:
/// the default image meets the 1% on the sphere. Measured (48²): sphere 0.36 / 0.46 /
/// 0.50% (without the near field 0.51 / 1.09 / 2.12%), slab 0.60 / 1.09 / 1.93% (0.87 / 1.81 /
/// 3.39%; the box's edges, as for the other models).
#[test]
fn the_monte_carlo_table_converges() {
    for (mesh, bound, gain) in [("sphere", [0.01, 0.01, 0.01], 0.3), ("slab", [0.008, 0.014, 0.024], 0.7)] {
        let reference = exact_reference(mesh, Model::Mc);
        check(&format!("{mesh}, mc"), case(mesh, Model::Mc, &reference), bound, gain);
    }
}
