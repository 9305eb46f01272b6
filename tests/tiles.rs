//! Shading in tiles is seamless: every pixel's shader sees the same inputs whatever the tiling, so
//! the image must be the same bit for bit, for the tree walk and for brute force (which also
//! splits the points into draws added by blending).

mod common;

use glam::Vec3;
use translucent::frame::{FrameOptions, Renderer, Show, SubsurfaceOptions};
use translucent::hierarchy::HierarchyOptions;
use translucent::mesh::Mesh;
use translucent::output::Exposure;
use translucent::scene::{bounding_sphere, Camera, Light, Scene};

fn render(brute_force: bool, tiles: &[u32]) -> Vec<Vec<[f32; 4]>> {
    let (ctx, counts) = common::validated_context();
    let mesh = Mesh::from_spec("torus").unwrap();
    let (centre, radius) = bounding_sphere(&mesh.positions);
    let camera = Camera::framing(centre, radius, 40.0, Vec3::new(0.3, 0.6, 1.0));
    let lights = vec![Light::Directional { toward: Vec3::new(-0.3, 0.7, -0.65), irradiance: Vec3::ONE }];
    let scene = Scene { mesh, camera, lights, mm_per_unit: 10.0 };
    let options = FrameOptions {
        subsurface: SubsurfaceOptions {
            material: translucent::materials::Material::find("skin1").unwrap(),
            model: translucent::physics::Model::Directional,
            diffusion: translucent::physics::Diffusion::Classical,
            epsilon: 0.1,
            brute_force,
            specular: true,
            roughness: 0.35,
        },
        width: 70,
        height: 45,
        profile: false,
        count_work: false,
        hierarchy: HierarchyOptions { point_count: 9000, shadow_resolution: 512, eta: 1.3 },
        show: Show::Shading,
        exposure: Exposure::Auto,
    };
    let mut renderer = Renderer::new(ctx, &scene, options).unwrap();
    let images = tiles
        .iter()
        .map(|&tile| {
            renderer.set_tile_size(tile);
            renderer.render_frame(&scene).unwrap();
            renderer.image().unwrap().pixels
        })
        .collect();
    drop(renderer);
    common::assert_clean(&counts);
    images
}

#[test]
fn tiles_leave_no_seams() {
    for brute_force in [false, true] {
        let images = render(brute_force, &[128, 16, 7]);
        let covered = images[0].iter().filter(|p| p[3] > 0.0).count();
        assert!(covered > 500, "the torus covers pixels: {covered}");
        for (k, image) in images.iter().enumerate().skip(1) {
            let differing = image.iter().zip(&images[0]).filter(|(a, b)| a != b).count();
            assert_eq!(differing, 0, "brute force {brute_force}: tiling {k} differs in {differing} pixels");
        }
    }
}
