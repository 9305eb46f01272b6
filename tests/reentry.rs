//! Light that leaves the object and enters it again (passes::reentry, `--model mc --reentry` on
//! closed meshes), through the one frame path with validation on.

mod common;

use common::{assert_clean, validated_context};
use glam::{DVec3, Vec3};
use translucent::frame::Renderer;
use translucent::frame_desc::{FrameDesc, Integration};
use translucent::materials::Material;
use translucent::mesh::occupancy::Occupancy;
use translucent::mesh::Mesh;
use translucent::output::Exposure;
use translucent::passes::reentry::Patches;
use translucent::physics::mc_profile::McProfile;
use translucent::physics::{fresnel, Model};
use translucent::scene::{Camera, Light};
use translucent::world::World;

/// Skin1 at 32x32 with `points` points through the Monte Carlo table with the re-entry; the
/// patches and the sorted points after it.
fn render(mesh: Mesh, mm_per_unit: f32, toward: Vec3, points: u32) -> (Patches, Vec<translucent::gpu::SurfacePoint>) {
    let (ctx, counts) = validated_context();
    let camera = Camera::framing(Vec3::ZERO, 2.0, 40.0, Vec3::new(0.3, 0.5, 1.0));
    let mut desc = FrameDesc::new(camera, vec![Light::Directional { toward, irradiance: Vec3::ONE }]);
    desc.integration = Integration { model: Model::Mc, reentry: true, ..Integration::default() };
    (desc.width, desc.height, desc.shadow_resolution, desc.exposure) = (32, 32, 512, Exposure::Stops(0.0));
    let mut world = World::single(mesh, Material::find("skin1").unwrap(), mm_per_unit);
    world.objects[0].samples = Some(points);
    let mut renderer = Renderer::new(ctx, false).expect("renderer");
    renderer.render_frame(&world, &desc).unwrap();
    let patches = renderer.reentry_patches(0).unwrap().expect("a closed mesh with the Monte Carlo table");
    let sorted = renderer.hierarchy().unwrap().download(&renderer.ctx).unwrap().sorted_points;
    drop(renderer);
    assert_clean(&counts);
    (patches, sorted)
}

/// A patch in the middle of a slab's top face, lit at normal incidence, leaves what enters it
/// times the profile's escaping fraction, multiple scattering's (the half-space's ∫ M dA,
/// `McProfile::escape`) and single scattering's: the exitance stage's sum over the tree and its
/// own part add up to the flat profile's total. Measured 0.9979 0.9985 0.9993 of it.
#[test]
fn a_flat_lit_face_leaves_the_profiles_escaping_fraction() {
    let (patches, sorted) = render(Mesh::slab(4.0, 4.0, 1.0), 20.0, Vec3::Y, 65536);
    let m = Material::find("skin1").unwrap();
    let profiles = [0, 1, 2].map(|c| McProfile::of(&m.channel(c)));
    let (mut sums, mut count) = ([0.0f64; 3], 0);
    for (k, &i) in patches.points.iter().enumerate() {
        let p = &sorted[i as usize];
        // The top face's middle: 80 x 80 mm, a margin of 20 mm (many diffusion lengths).
        if p.normal.y < 0.99 || p.position.x.abs() > 1.0 || p.position.z.abs() > 1.0 {
            continue;
        }
        for (c, sum) in sums.iter_mut().enumerate() {
            *sum += (patches.exitance[k][c] / p.irradiance[c]) as f64;
        }
        count += 1;
    }
    assert!(count > 10, "{count} patches in the middle of the top face");
    for c in 0..3 {
        let expected = profiles[c].escape + profiles[c].single_escape;
        let ratio = sums[c] / count as f64 / expected;
        println!("channel {c}: M/E {:.4} against {expected:.4}: {ratio:.4}", sums[c] / count as f64);
        assert!((ratio - 1.0).abs() < 0.01, "channel {c}: {ratio}");
    }
    // Nothing faces the top face: it receives nothing.
    assert!(patches
        .received
        .iter()
        .zip(&patches.points)
        .all(|(r, &i)| sorted[i as usize].normal.y < 0.99 || r[0][..3] == [0.0; 3]));
}

/// No two points of a convex object face each other: a sphere's patches receive nothing, lit
/// as they are.
#[test]
fn a_convex_object_receives_nothing() {
    let (patches, _) = render(Mesh::sphere(1.0, 48), 5.0, Vec3::new(-0.3, 0.7, -0.65), 16384);
    assert!(patches.exitance.iter().any(|m| m[0] > 0.0), "the sphere leaves light");
    for (k, r) in patches.received.iter().enumerate() {
        assert_eq!(r[0][..3], [0.0; 3], "patch {k}");
    }
}

/// A torus's inside of the ring faces itself across the hole: those patches receive light, its
/// outside none; the light received is the gather's sum over the patches that face each other
/// with the chord through the air, which a sum here in f64 repeats (the same formula, the same
/// grid), and less than the light that left (the form factors sum to at most 1).
#[test]
fn a_torus_s_inside_receives_what_its_other_side_leaves() {
    let mesh = Mesh::torus(1.0, 0.35, 64, 32);
    let (patches, sorted) = render(mesh.clone(), 8.0, Vec3::new(-0.3, 0.7, -0.65), 16384);
    let c = patches.constants;
    let grid = Occupancy::of(&mesh).expect("a closed torus");
    let at = |k: usize| &sorted[patches.points[k] as usize];
    let (mut left, mut received) = (0.0f64, 0.0f64);
    let (mut inner_lit, mut outer) = (0, 0);
    for k in 0..patches.points.len() {
        let (xk, nk) = (at(k).position.as_dvec3(), at(k).normal.as_dvec3());
        let mut expected = DVec3::ZERO;
        for j in 0..patches.points.len() {
            let e = patches.exitance[j];
            let m = DVec3::new(e[0] as f64, e[1] as f64, e[2] as f64);
            if j == k || m == DVec3::ZERO {
                continue;
            }
            let d = at(j).position.as_dvec3() - xk;
            let r2 = d.length_squared();
            let (cos_k, cos_j) = (nk.dot(d) / r2.sqrt(), -at(j).normal.as_dvec3().dot(d) / r2.sqrt());
            if cos_k <= 0.05 || cos_j <= 0.05 {
                continue;
            }
            let cells = (d.as_vec3() / grid.cell).length_squared();
            let air = cells < 4.0
                || [0.25f32, 0.5, 0.75].iter().all(|t| !grid.centre_inside(xk.as_vec3() + *t * d.as_vec3()));
            if !air {
                continue;
            }
            let area = c.patch_area as f64;
            expected += m
                * (area * cos_k * cos_j / (std::f64::consts::PI * r2 + area))
                * fresnel::transmittance(c.eta as f64, cos_k);
        }
        let got = DVec3::new(
            patches.received[k][0][0] as f64,
            patches.received[k][0][1] as f64,
            patches.received[k][0][2] as f64,
        );
        assert!((got - expected).length() <= 1e-3 * expected.length() + 1e-9, "patch {k}: {got} against {expected}");
        left += patches.exitance[k][0] as f64;
        received += got.x;
        // Inside the ring: the normal points toward the axis.
        let radial = DVec3::new(xk.x, 0.0, xk.z).normalize();
        if nk.dot(radial) < -0.7 && got.x > 0.0 {
            inner_lit += 1;
        }
        if nk.dot(radial) > 0.3 {
            outer += 1;
            assert_eq!(got, DVec3::ZERO, "patch {k} outside the ring");
        }
    }
    println!(
        "{inner_lit} patches inside the ring receive light; {outer} outside none; received / left {:.4}",
        received / left
    );
    assert!(inner_lit > 20 && outer > 100, "{inner_lit} inside, {outer} outside");
    assert!(received > 0.0 && received < left, "received {received}, left {left}");
}
