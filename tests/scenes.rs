//! Worlds of several objects: each translucent object has its own material, points and tree, and
//! light does not scatter from one into another (validation on).

mod common;

use glam::{Mat4, Vec3};
use translucent::frame::Renderer;
use translucent::frame_desc::FrameDesc;
use translucent::materials::Material;
use translucent::mesh::Mesh;
use translucent::output::HdrImage;
use translucent::scene::{Camera, Light};
use translucent::world::{Object, World};

fn render(world: &World, desc: &FrameDesc) -> HdrImage {
    let (ctx, counts) = common::validated_context();
    let mut renderer = Renderer::new(ctx, false).expect("renderer");
    renderer.render_frame(world, desc).expect("frame");
    let image = renderer.image().expect("image");
    drop(renderer);
    common::assert_clean(&counts);
    image
}

fn placed(mesh: Mesh, material: &str, at: Vec3, samples: u32) -> Object {
    let mut o = Object::new(mesh, Material::find(material).unwrap());
    o.transform = Mat4::from_translation(at);
    o.samples = Some(samples);
    o
}

/// A marble sphere and a skin torus side by side, lit from above (neither shadows the other):
/// every pixel of each equals that object rendered alone, bit for bit, for the tree and for brute
/// force, with the camera and lights unchanged.
#[test]
fn two_objects_side_by_side_equal_each_alone() {
    let sphere = placed(Mesh::sphere(0.8, 24), "marble", Vec3::new(-1.1, 0.0, 0.0), 4096);
    let torus = placed(Mesh::torus(0.6, 0.25, 32, 16), "skin1", Vec3::new(1.1, 0.0, 0.0), 3000);
    let camera = Camera { eye: Vec3::new(0.0, 0.6, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 };
    let light = Light::Directional { toward: Vec3::new(0.1, 1.0, 0.3).normalize(), irradiance: Vec3::ONE };
    let mut desc = FrameDesc::new(camera, vec![light]);
    (desc.width, desc.height, desc.shadow_resolution) = (96, 48, 512);
    for brute_force in [false, true] {
        desc.integration.brute_force = brute_force;
        let both = render(
            &World { objects: vec![sphere.clone(), torus.clone()], opaque: Vec::new(), mm_per_unit: 10.0 },
            &desc,
        );
        let alone = [&sphere, &torus]
            .map(|o| render(&World { objects: vec![o.clone()], opaque: Vec::new(), mm_per_unit: 10.0 }, &desc));
        let mut covered = [0usize; 2];
        for (i, p) in both.pixels.iter().enumerate() {
            let owners: Vec<usize> = (0..2).filter(|&k| alone[k].pixels[i][3] > 0.0).collect();
            match owners.as_slice() {
                [] => assert_eq!(p[3], 0.0, "pixel {i}: covered in the pair, by neither alone"),
                [k] => {
                    covered[*k] += 1;
                    let q = alone[*k].pixels[i];
                    assert!(
                        p.map(f32::to_bits) == q.map(f32::to_bits),
                        "brute force {brute_force}, object {k}, pixel {i}: {p:?} vs {q:?} alone"
                    );
                }
                _ => panic!("pixel {i}: the objects overlap on screen; move them apart"),
            }
        }
        assert!(covered[0] > 100 && covered[1] > 100, "both objects in view: {covered:?}");
    }
}

/// An object in the light's way shadows the one behind it: a slab held above a sphere darkens it,
/// and the sphere's own points see the slab in their shadow maps.
#[test]
fn an_object_between_the_light_and_another_shadows_it() {
    let sphere = placed(Mesh::sphere(0.8, 24), "marble", Vec3::ZERO, 4096);
    let slab = placed(Mesh::slab(3.0, 3.0, 0.2), "ketchup", Vec3::new(0.0, 1.6, 0.0), 4096);
    let camera = Camera { eye: Vec3::new(0.0, 0.3, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
    let light = Light::Directional { toward: Vec3::Y, irradiance: Vec3::ONE };
    let mut desc = FrameDesc::new(camera, vec![light]);
    (desc.width, desc.height, desc.specular) = (64, 64, false);
    let alone = render(&World { objects: vec![sphere.clone()], opaque: Vec::new(), mm_per_unit: 10.0 }, &desc);
    let shaded = render(&World { objects: vec![sphere, slab], opaque: Vec::new(), mm_per_unit: 10.0 }, &desc);
    // The sphere's pixels: those below the slab's projection in the image (the lower half).
    let mean = |img: &HdrImage| {
        let rows = img.height / 2 + 8..img.height;
        let px: Vec<_> = rows.flat_map(|y| (0..img.width).map(move |x| (y * img.width + x) as usize)).collect();
        let lit: Vec<_> = px.iter().map(|&i| img.pixels[i]).filter(|p| p[3] > 0.0).collect();
        lit.iter().map(|p| p[0] as f64).sum::<f64>() / lit.len().max(1) as f64
    };
    let (a, s) = (mean(&alone), mean(&shaded));
    assert!(a > 0.0 && s < 0.2 * a, "the slab's shadow must darken the sphere: {s} vs {a} alone");
}

/// A floor quad of side `size` at height `y`, facing up, with uv over [0, 1]².
fn floor(size: f32, y: f32) -> (Mesh, Vec<glam::Vec2>) {
    let h = size / 2.0;
    let positions = vec![Vec3::new(-h, y, -h), Vec3::new(h, y, -h), Vec3::new(h, y, h), Vec3::new(-h, y, h)];
    let uvs = vec![
        glam::Vec2::new(0.0, 0.0),
        glam::Vec2::new(1.0, 0.0),
        glam::Vec2::new(1.0, 1.0),
        glam::Vec2::new(0.0, 1.0),
    ];
    // Counter-clockwise seen from above.
    let mesh = Mesh { positions, normals: vec![Vec3::Y; 4], indices: vec![0, 2, 1, 0, 3, 2] };
    (mesh, uvs)
}

/// A translucent sphere on an opaque checkerboard floor under a light from above: the sphere's
/// pixels equal the sphere alone (the floor is below it: no shadow, no scattering into it); the
/// floor shows both squares of the checker, with the radiance ρ E/π where lit, and the sphere's
/// shadow under it.
#[test]
fn a_sphere_on_a_checker_floor() {
    use translucent::world::{Opaque, Reflectance};
    let sphere = placed(Mesh::sphere(0.8, 24), "marble", Vec3::new(0.0, 0.8, 0.0), 4096);
    let (mesh, uvs) = floor(6.0, 0.0);
    let (dark, light) = (Vec3::splat(0.1), Vec3::new(0.8, 0.7, 0.6));
    let mut floor = Opaque::new(mesh, Reflectance::Checkerboard { uscale: 6.0, vscale: 6.0, tex1: dark, tex2: light });
    floor.uvs = Some(uvs);
    let camera =
        Camera { eye: Vec3::new(0.0, 3.0, 5.0), target: Vec3::new(0.0, 0.3, 0.0), up: Vec3::Y, fov_y_deg: 45.0 };
    let e = 2.0;
    let light_dir = Vec3::new(0.0, 1.0, 0.0);
    let mut desc = FrameDesc::new(camera, vec![Light::Directional { toward: light_dir, irradiance: Vec3::splat(e) }]);
    (desc.width, desc.height, desc.shadow_resolution) = (96, 72, 1024);
    let alone = render(&World { objects: vec![sphere.clone()], opaque: Vec::new(), mm_per_unit: 10.0 }, &desc);
    let scene = render(&World { objects: vec![sphere], opaque: vec![floor], mm_per_unit: 10.0 }, &desc);
    let path = common::output_dir().join("sphere-on-checkers.png");
    translucent::output::write_image(&path, &scene, translucent::output::Exposure::Stops(0.0)).unwrap();
    let (mut sphere_pixels, mut floor_values) = (0, Vec::new());
    for (i, (p, q)) in scene.pixels.iter().zip(&alone.pixels).enumerate() {
        if q[3] > 0.0 {
            sphere_pixels += 1;
            assert!(p.map(f32::to_bits) == q.map(f32::to_bits), "sphere pixel {i}: {p:?} on the floor, {q:?} alone");
        } else if p[3] > 0.0 {
            floor_values.push((i, p[0]));
        }
    }
    assert!(sphere_pixels > 300, "{sphere_pixels}");
    // Lit floor: ρ E / π exactly for each square (f32 rounding aside); shadowed: 0.
    let (lit_dark, lit_light) = (dark.x * e / std::f32::consts::PI, light.x * e / std::f32::consts::PI);
    let close = |v: f32, want: f32| (v - want).abs() <= 1e-5 * want;
    let count = |want: f32| floor_values.iter().filter(|&&(_, v)| close(v, want)).count();
    let shadowed = floor_values.iter().filter(|&&(_, v)| v == 0.0).count();
    assert!(
        count(lit_dark) > 200 && count(lit_light) > 200,
        "both squares lit: {} {}",
        count(lit_dark),
        count(lit_light)
    );
    assert!(shadowed > 30, "the sphere's shadow on the floor: {shadowed} pixels");
    let other = floor_values.len() - count(lit_dark) - count(lit_light) - shadowed;
    // Only the shadow's edge (the map's texels) lies in between.
    assert!(
        other < floor_values.len() / 10,
        "{other} of {} floor pixels neither lit nor in shadow",
        floor_values.len()
    );
}

/// pbrt-v4's spot falloff (SpotLight::I with its SmoothStep) at cos θ off the axis, in f64.
fn spot_falloff(cos_theta: f64, cone_deg: f64, delta_deg: f64) -> f64 {
    let (a, b) = (cone_deg.to_radians().cos(), (cone_deg - delta_deg).to_radians().cos());
    if a == b {
        return if cos_theta < a { 0.0 } else { 1.0 };
    }
    let t = ((cos_theta - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// A spot aimed straight down at a large grey floor, seen from straight above: the floor shows
/// ρ E / π with E = I f(θ) cos θ / d² (f: pbrt's smoothstep falloff), full inside the radius
/// h tan(cone − delta), nothing beyond h tan(cone); the lit disc ends, and the full disc ends,
/// within a pixel of those radii. Once with a 30° cone (one perspective shadow layer) and once
/// with a 75° cone (the six cube faces).
#[test]
fn a_spot_lights_a_disc_of_the_floor_ending_where_its_cone_meets_it() {
    use translucent::world::{Opaque, Reflectance};
    let (size, px) = (96u32, 96.0f64);
    // Seen from 12 above with tan(fov/2) = 5/12: the image spans the floor's −5..5.
    let (eye_height, half_span) = (12.0f64, 5.0f64);
    let fov = 2.0 * (half_span / eye_height).atan().to_degrees();
    let camera = Camera {
        eye: Vec3::new(0.0, eye_height as f32, 0.0),
        target: Vec3::ZERO,
        up: Vec3::NEG_Z,
        fov_y_deg: fov as f32,
    };
    let pixel = 2.0 * half_span / px; // floor units per pixel
    let rho = 0.5f32;
    let (mesh, _) = floor(20.0, 0.0);
    let floor = Opaque::new(mesh, Reflectance::Constant(Vec3::splat(rho)));
    // A translucent object the world needs, out of view and out of the cone.
    let aside = placed(Mesh::sphere(0.3, 16), "marble", Vec3::new(9.0, 0.3, 9.0), 1024);
    for (cone, delta, h, intensity) in [(30.0f64, 10.0f64, 6.0f64, 40.0f64), (75.0, 15.0, 1.0, 2.0)] {
        let spot = Light::spot(
            Vec3::new(0.0, h as f32, 0.0),
            Vec3::ZERO,
            cone as f32,
            delta as f32,
            Vec3::splat(intensity as f32),
        )
        .unwrap();
        let mut desc = FrameDesc::new(camera, vec![spot]);
        (desc.width, desc.height, desc.shadow_resolution, desc.specular) = (size, size, 1024, false);
        let world = World { objects: vec![aside.clone()], opaque: vec![floor.clone()], mm_per_unit: 10.0 };
        let image = render(&world, &desc);
        let path = common::output_dir().join(format!("spot-{cone}-on-floor.png"));
        translucent::output::write_image(&path, &image, translucent::output::Exposure::Stops(0.0)).unwrap();
        let (r_edge, r_full) = (h * cone.to_radians().tan(), h * (cone - delta).to_radians().tan());
        let peak = rho as f64 * intensity / (std::f64::consts::PI * h * h);
        let (mut max_lit, mut max_full, mut full_pixels) = (0.0f64, 0.0f64, 0);
        for (i, p) in image.pixels.iter().enumerate() {
            assert!(p[3] > 0.0, "pixel {i}: the floor fills the view");
            let (x, y) = ((i as u32 % size) as f64, (i as u32 / size) as f64);
            let ndc = ((x + 0.5) / px * 2.0 - 1.0, (y + 0.5) / px * 2.0 - 1.0);
            let r = half_span * (ndc.0 * ndc.0 + ndc.1 * ndc.1).sqrt();
            let d = (h * h + r * r).sqrt();
            let cos = h / d;
            let full = rho as f64 * intensity * cos / (d * d) / std::f64::consts::PI;
            let want = full * spot_falloff(cos, cone, delta);
            let v = p[0] as f64;
            assert!((v - want).abs() <= 2e-3 * peak, "cone {cone}: pixel {i} at r {r:.3}: {v} vs {want}");
            if r > r_edge + 0.5 * pixel {
                assert_eq!(v, 0.0, "cone {cone}: pixel {i} at r {r:.3} beyond the cone's edge {r_edge:.3}");
            }
            if r < r_full - 0.5 * pixel {
                assert!((v - full).abs() <= 1e-5 * full, "cone {cone}: pixel {i} at r {r:.3} inside: {v} vs {full}");
                full_pixels += 1;
            }
            if v > 0.0 {
                max_lit = max_lit.max(r);
            }
            if (v - full).abs() <= 1e-5 * full {
                max_full = max_full.max(r);
            }
        }
        assert!(full_pixels > 500, "cone {cone}: {full_pixels} fully lit pixels");
        assert!(
            (max_lit - r_edge).abs() < pixel,
            "cone {cone}: the lit disc ends at {max_lit:.3}, the cone meets the floor at {r_edge:.3} (pixel {pixel:.3})"
        );
        assert!(
            (max_full - r_full).abs() < 2.0 * pixel,
            "cone {cone}: the full disc ends at {max_full:.3}, the falloff begins at {r_full:.3} (pixel {pixel:.3})"
        );
    }
}

/// A spot with a 180° cone and no falloff is a point light: the same image, bit for bit, of a
/// translucent sphere (irradiance, specular) on an opaque floor (diffuse, shadows).
#[test]
fn a_180_degree_spot_is_a_point_light() {
    use translucent::world::{Opaque, Reflectance};
    let sphere = placed(Mesh::sphere(0.8, 24), "marble", Vec3::new(0.0, 0.8, 0.0), 4096);
    let (mesh, _) = floor(6.0, 0.0);
    let floor = Opaque::new(mesh, Reflectance::Constant(Vec3::new(0.6, 0.5, 0.4)));
    let world = World { objects: vec![sphere], opaque: vec![floor], mm_per_unit: 10.0 };
    let camera =
        Camera { eye: Vec3::new(0.0, 3.0, 5.0), target: Vec3::new(0.0, 0.3, 0.0), up: Vec3::Y, fov_y_deg: 45.0 };
    let (position, intensity) = (Vec3::new(1.5, 3.0, 1.0), Vec3::new(8.0, 7.0, 6.0));
    let images = [
        Light::Point { position, intensity },
        Light::spot(position, Vec3::new(1.0, -2.0, 0.3), 180.0, 0.0, intensity).unwrap(),
    ]
    .map(|light| {
        let mut desc = FrameDesc::new(camera, vec![light]);
        (desc.width, desc.height) = (80, 60);
        render(&world, &desc)
    });
    let lit = images[0].pixels.iter().filter(|p| p[0] > 0.0).count();
    assert!(lit > 2000, "{lit} lit pixels");
    for (i, (p, q)) in images[0].pixels.iter().zip(&images[1].pixels).enumerate() {
        assert!(p.map(f32::to_bits) == q.map(f32::to_bits), "pixel {i}: point {p:?}, 180° spot {q:?}");
    }
}
