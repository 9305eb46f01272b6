//! Image-quality checks that a mean or an RMSE does not make (issue #27): no negative pixel in any
//! render, no more isolated dots (a pixel under half or over twice its 3×3 neighbourhood's median)
//! with the near field than without it, and lights that add. The near field's control variate
//! once left 115 negative pixels and 98 dark dots (17 without it) on the default Skin1 bunny, and
//! made 16 lights differ from 8 + 8 by 8.5%: a far source (a node's sigma point across the
//! object) whose tangent plane met the pixel's near the pixel was "unfolded" onto the pixel.

mod common;

use common::{assert_clean, validated_context};
use glam::Vec3;
use translucent::frame::Renderer;
use translucent::frame_desc::NearField;
use translucent::image_quality::{inspect, Quality};
use translucent::materials::Material;
use translucent::output::{relative_rmse, HdrImage};
use translucent::physics::Model;
use translucent::scene::Light;
use translucent::settings::{RenderSettings, SceneSettings};

const BUNNY: &str = "/usr/share/glmark2/models/bunny.obj";

fn bunny() -> String {
    // CI installs glmark2-data (scripts/setup-debian); elsewhere a torus has thin parts too.
    if std::path::Path::new(BUNNY).exists() {
        BUNNY.into()
    } else {
        "torus".into()
    }
}

fn settings(material: &str, lights: Vec<Light>, model: Model, samples: Option<u32>, size: u32) -> RenderSettings {
    let scene = SceneSettings { mesh: Some(bunny()), lights, ..Default::default() };
    let mut s = RenderSettings::new(scene.build().expect("scene"), Material::find(material).expect("preset"));
    (s.desc.width, s.desc.height, s.world.objects[0].samples) = (size, size, samples);
    s.desc.integration.model = model;
    s
}

fn render(renderer: &mut Renderer, s: &RenderSettings) -> HdrImage {
    renderer.render_frame(&s.world, &s.desc).expect("frame");
    renderer.image().expect("image")
}

fn light(toward: [f32; 3]) -> Light {
    Light::Directional { toward: Vec3::from(toward).normalize(), irradiance: Vec3::ONE }
}

/// Front, back (`render`'s default) and grazing light.
fn lightings() -> [(&'static str, Light); 3] {
    [("front", light([0.3, 0.5, 0.8])), ("back", light([-0.3, 0.7, -0.65])), ("grazing", light([1.0, 0.05, 0.1]))]
}

/// Every preset family (skin, marble, a vegetable, a sauce, milk, meat) × the four models ×
/// front, back and grazing light at the default sample count, and for Skin1 at two more counts:
/// not one negative pixel, and no more isolated dots in all with the near field than without.
/// Measured (48², lavapipe): 0 negative pixels in 84 renders; dots with and without printed.
#[test]
fn no_render_has_negative_pixels_or_more_dots_than_the_plain_sum() {
    let (ctx, counts) = validated_context();
    let mut renderer = Renderer::new(ctx, false).expect("renderer");
    let mut cases = vec![];
    for material in ["skin1", "marble", "potato", "ketchup", "wholemilk", "chicken1"] {
        for model in [Model::Directional, Model::Dipole, Model::Pbd, Model::Mc] {
            for (name, l) in lightings() {
                cases.push((material, model, name, l, None));
            }
        }
    }
    for samples in [4096, 65536] {
        for (name, l) in lightings() {
            cases.push(("skin1", Model::Directional, name, l, Some(samples)));
        }
    }
    let (mut with_dots, mut without_dots, mut negative) = (0, 0, vec![]);
    for (material, model, name, l, samples) in cases {
        let mut s = settings(material, vec![l], model, samples, 48);
        let with: Quality = inspect(&render(&mut renderer, &s));
        s.desc.integration.near_field = NearField::Off;
        let without = inspect(&render(&mut renderer, &s));
        println!(
            "{material} {model:?} {name} {samples:?}: {} negative (lowest {:.4}), dots {} (near field off: {}, {} negative)",
            with.negative,
            with.lowest,
            with.dots(),
            without.dots(),
            without.negative
        );
        if with.negative + without.negative > 0 {
            negative.push(format!("{material} {model:?} {name} {samples:?}"));
        }
        (with_dots, without_dots) = (with_dots + with.dots(), without_dots + without.dots());
    }
    drop(renderer);
    assert_clean(&counts);
    println!("dots in all: {with_dots} with the near field, {without_dots} without");
    assert!(negative.is_empty(), "negative pixels in: {negative:?}");
    assert!(with_dots <= without_dots, "{with_dots} isolated dots with the near field, {without_dots} without");
}

/// `k` directional lights spread over the upper hemisphere (a golden-angle spiral), each of
/// irradiance 1/4.
fn hemisphere_lights(k: usize) -> Vec<Light> {
    (0..k)
        .map(|i| {
            let y = 1.0 - (i as f32 + 0.5) / k as f32;
            let (r, phi) = ((1.0 - y * y).sqrt(), i as f32 * 2.399_963);
            Light::Directional { toward: Vec3::new(r * phi.cos(), y, r * phi.sin()), irradiance: Vec3::splat(0.25) }
        })
        .collect()
}

/// 16 lights against the same lights as two sets of 8, rendered alone and summed, at the default
/// settings (the near field on): within 0.5%. The control variate made it 8.5% (its far sources
/// turned onto the pixel multiplied the merged records' small non-linearity a hundredfold);
/// measured 0.053% before the 4x4 list tiles, 0.41% with them (directional dipole; its default
/// image is bit for bit what it was before issue #30's work), 0.34% for the Monte Carlo table.
#[test]
fn sixteen_lights_equal_eight_plus_eight() {
    let (ctx, counts) = validated_context();
    let mut renderer = Renderer::new(ctx, false).expect("renderer");
    let all = hemisphere_lights(16);
    let (a, b): (Vec<_>, Vec<_>) = all.iter().enumerate().partition(|(i, _)| i % 2 == 0);
    let strip = |v: Vec<(usize, &Light)>| v.into_iter().map(|(_, l)| *l).collect::<Vec<_>>();
    // The Monte Carlo table too: its oblique lean (1 + b m·d̂) is linear in the lights through
    // the merged records' mean direction (issue #30).
    let mut errors = Vec::new();
    for model in [Model::Directional, Model::Mc] {
        let mut frame = |lights: Vec<Light>| {
            let mut s = settings("skin1", lights, model, Some(16384), 128);
            s.desc.specular = false;
            render(&mut renderer, &s)
        };
        let whole = frame(all.clone());
        let mut sum = frame(strip(a.clone()));
        let second = frame(strip(b.clone()));
        for (p, q) in sum.pixels.iter_mut().zip(&second.pixels) {
            for c in 0..3 {
                p[c] += q[c];
            }
        }
        errors.push((model, relative_rmse(&whole.pixels, &sum.pixels)));
    }
    drop(renderer);
    assert_clean(&counts);
    for (model, e) in errors {
        println!("{model:?}: 16 lights against 8 + 8: {:.4}% relative RMSE", 100.0 * e);
        assert!(e < 0.005, "{model:?}: 16 lights against 8 + 8: {:.3}%", 100.0 * e);
    }
}
