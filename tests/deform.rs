//! Meshes that change between frames: built-in deformations and `{frame}` sequences, through the
//! one frame path (validation on).

mod common;

use common::{assert_clean, output_dir, stderr, translucent, validated_context};
use glam::Vec3;
use translucent::deform::{Animation, Deformation};
use translucent::frame::Renderer;
use translucent::frame_desc::{FrameDesc, Integration};
use translucent::materials::Material;
use translucent::mesh::Mesh;
use translucent::output::{self, Exposure};
use translucent::physics::Model;
use translucent::scene::{Camera, Light};
use translucent::world::World;

/// Marble at 24x24 with `points` points, ε = 0.1, 64² shadow maps, exposure 0.
fn frame_for(camera: Camera, lights: Vec<Light>) -> FrameDesc {
    let mut desc = FrameDesc::new(camera, lights);
    desc.integration = Integration { epsilon: 0.1, ..Integration::default() };
    (desc.width, desc.height, desc.shadow_resolution, desc.exposure) = (24, 24, 64, Exposure::Stops(0.0));
    desc
}

#[test]
fn each_frame_samples_the_deformed_surface() {
    let (ctx, counts) = validated_context();
    let base = Mesh::slab(1.0, 1.0, 2.0);
    let camera = Camera::framing(Vec3::ZERO, 2.0, 40.0, Vec3::new(0.3, 0.3, 1.0));
    let lights = vec![Light::Directional { toward: Vec3::new(0.2, 1.0, 0.5), irradiance: Vec3::ONE }];
    let mut world = World::single(base.clone(), Material::find("marble").unwrap(), 10.0);
    let points = 2048;
    world.objects[0].samples = Some(points);
    let desc = frame_for(camera, lights);
    let mut renderer = Renderer::new(ctx, false).expect("renderer");
    for deformation in [Deformation::Squash(0.25), Deformation::Twist(120.0)] {
        let animation = Animation::new("box", &base, Some(deformation), 4, Vec3::Y).unwrap().expect("animated");
        let mut areas = Vec::new();
        for frame in 0..4 {
            world.objects[0].mesh = animation.mesh(frame).unwrap();
            renderer.render_frame(&world, &desc).unwrap();
            let snapshot = renderer.hierarchy().unwrap().download(&renderer.ctx).unwrap();
            assert_eq!(snapshot.points.len(), points as usize);
            // The points' areas add up to the deformed mesh's area, and the points lie within it.
            let sampled: f64 = snapshot.points.iter().map(|p| p.area as f64).sum();
            let area = world.objects[0].mesh.surface_area() as f64;
            assert!((sampled / area - 1.0).abs() < 1e-3, "{deformation:?} frame {frame}: {sampled} vs {area}");
            let (lo, hi) = world.objects[0].mesh.bounds();
            for p in &snapshot.points {
                assert!(p.position.cmpge(lo - 1e-4).all() && p.position.cmple(hi + 1e-4).all(), "{p:?}");
            }
            areas.push(area);
        }
        if let Deformation::Squash(_) = deformation {
            // The 1×2×1 box squashed to a quarter of its height (widths × 2): area 10 → 12.
            assert!((areas[2] / areas[0] - 1.0).abs() > 0.05, "{areas:?}");
        }
        assert!((areas[1] - areas[3]).abs() < 1e-4 * areas[1], "the period's two halves mirror: {areas:?}");
    }
    drop(renderer);
    assert_clean(&counts);
}

/// The grid of an object's inside (which the Monte Carlo table reads) is made once per mesh: a
/// change of material, or to another model and back, keeps it; a new mesh makes one again.
#[test]
fn the_inside_grid_is_made_once_per_mesh() {
    let (ctx, counts) = validated_context();
    let base = Mesh::torus(1.0, 0.4, 32, 16);
    let camera = Camera::framing(Vec3::ZERO, 2.0, 40.0, Vec3::new(0.3, 0.3, 1.0));
    let lights = vec![Light::Directional { toward: Vec3::new(0.2, 1.0, 0.5), irradiance: Vec3::ONE }];
    let mut world = World::single(base.clone(), Material::find("marble").unwrap(), 10.0);
    world.objects[0].samples = Some(1024);
    let mut desc = frame_for(camera, lights);
    desc.integration.model = Model::Mc;
    let mut renderer = Renderer::new(ctx, false).expect("renderer");
    let mut frame = |world: &World, desc: &FrameDesc| {
        renderer.render_frame(world, desc).unwrap();
        renderer.inside_grids_made()
    };
    assert_eq!(frame(&world, &desc), 1, "the first frame makes the grid");
    world.objects[0].material = Material::find("skin1").unwrap();
    assert_eq!(frame(&world, &desc), 1, "a new material keeps it");
    let mut other = desc.clone();
    other.integration.model = Model::Directional;
    assert_eq!(frame(&world, &other), 1, "a model without the grid needs none");
    assert_eq!(frame(&world, &desc), 1, "back to the Monte Carlo table: the same grid");
    world.objects[0].mesh = Animation::new("torus", &base, Some(Deformation::Squash(0.5)), 2, Vec3::Y)
        .unwrap()
        .expect("animated")
        .mesh(1)
        .unwrap();
    assert_eq!(frame(&world, &desc), 2, "a new mesh makes it again");
    drop(renderer);
    assert_clean(&counts);
}

/// Renders `args` with validation at 64x64 into `{name}-{frame}.png` files; returns their paths.
fn render_frames(name: &str, args: &[&str], frames: u32) -> Vec<std::path::PathBuf> {
    let out = output_dir().join(format!("{name}-{{frame}}.png"));
    let frames_arg = frames.to_string();
    let mut full = vec!["render", "--validation", "--width", "64", "--height", "64", "--samples", "4096"];
    full.extend_from_slice(&["--exposure", "0", "--frames", &frames_arg, "--out", out.to_str().unwrap()]);
    full.extend_from_slice(args);
    let result = translucent(&full);
    assert!(result.status.success(), "{name}: {}", stderr(&result));
    assert!(!stderr(&result).contains("vulkan"), "{name}: validation messages:\n{}", stderr(&result));
    (0..frames).map(|i| output_dir().join(format!("{name}-{i:04}.png"))).collect()
}

fn load(path: &std::path::Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).into_rgba8()
}

#[test]
fn twisted_then_untwisted_renders_like_the_original() {
    // Period 2: frame 0 is the box, frame 1 twisted 90°, frame 2 untwisted again.
    let paths = render_frames("twist", &["--mesh", "box", "--deform", "twist:90", "--deform-period", "2"], 3);
    let [original, twisted, untwisted] = [0, 1, 2].map(|i| load(&paths[i]));
    let moved = output::compare(&original, &twisted).unwrap();
    assert!(moved.differing_fraction > 0.05, "the twist must show: {moved:?}");
    let back = output::compare(&original, &untwisted).unwrap();
    assert!(back.rmse < 0.5 && back.differing_fraction < 0.002, "{back:?}");
}

#[test]
fn a_frame_sequence_plays_one_file_per_frame() {
    let dir = output_dir().join("sequence");
    std::fs::create_dir_all(&dir).unwrap();
    // A cube, then the same cube twice as tall.
    let cube = |height: f32| {
        let mut obj = String::new();
        for &(x, y, z) in &[(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)] {
            obj += &format!("v {} {} {}\n", x as f32 - 0.5, y as f32 * height - 0.5, z as f32 - 0.5);
        }
        for f in ["1 4 3 2", "5 6 7 8", "1 2 6 5", "2 3 7 6", "3 4 8 7", "4 1 5 8"] {
            obj += &format!("f {f}\n");
        }
        obj
    };
    std::fs::write(dir.join("cube-0.obj"), cube(1.0)).unwrap();
    std::fs::write(dir.join("cube-1.obj"), cube(2.0)).unwrap();
    let pattern = dir.join("cube-{frame}.obj");
    // The camera and lights stay those framing frame 0 (--eye, so the framing is the same).
    let common = ["--eye", "2,2,4", "--target", "0,0,0", "--light-dir", "0.3,1,0.5"];
    let mut args = vec!["--mesh", pattern.to_str().unwrap()];
    args.extend_from_slice(&common);
    let played = render_frames("sequence", &args, 2);
    for (i, path) in played.iter().enumerate() {
        let file = dir.join(format!("cube-{i}.obj"));
        let mut single = vec!["--mesh", file.to_str().unwrap()];
        single.extend_from_slice(&common);
        let alone = render_frames(&format!("sequence-alone-{i}"), &single, 1);
        let diff = output::compare(&load(path), &load(&alone[0])).unwrap();
        assert!(diff.rmse < 0.5, "frame {i} of the sequence differs from its file rendered alone: {diff:?}");
    }
    let change = output::compare(&load(&played[0]), &load(&played[1])).unwrap();
    assert!(change.differing_fraction > 0.05, "the two frames must differ: {change:?}");
}

#[test]
fn bad_deformations_are_bad_input() {
    for (value, needle) in [("bend:3", "twist or squash"), ("squash:0", "positive"), ("twist:x", "not a number")] {
        let out = translucent(&["render", "--mesh", "sphere", "--deform", value]);
        assert_eq!(out.status.code(), Some(2), "{value}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{value}: {}", stderr(&out));
    }
    let out = translucent(&["render", "--mesh", "/nonexistent/frame-{frame}.obj"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("frame-{frame}.obj"), "{}", stderr(&out));
}

/// A `{frame}` sequence whose files differ in triangle count (UV spheres of 16×8, 256×128 and
/// 512×256 segments): every frame equals its file rendered alone. The prefix sum of triangle
/// areas was once re-allocated at a quarter of its size when the count changed, and every frame
/// after the first came out almost black with no error.
#[test]
fn a_sequence_whose_topology_changes_renders_each_frame_as_its_file_alone() {
    let dir = output_dir().join("topology");
    std::fs::create_dir_all(&dir).unwrap();
    for (i, rings) in [8, 128, 256].into_iter().enumerate() {
        let mesh = Mesh::sphere(1.0, rings);
        let mut obj = String::new();
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            obj += &format!("v {} {} {}\nvn {} {} {}\n", p.x, p.y, p.z, n.x, n.y, n.z);
        }
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0] + 1, t[1] + 1, t[2] + 1];
            obj += &format!("f {a}//{a} {b}//{b} {c}//{c}\n");
        }
        std::fs::write(dir.join(format!("s-{i:04}.obj")), obj).unwrap();
    }
    let pattern = dir.join("s-{frame}.obj");
    let common = ["--eye", "0.6,0.6,3", "--target", "0,0,0", "--light-dir", "0.3,1,0.5"];
    let mut args = vec!["--mesh", pattern.to_str().unwrap()];
    args.extend_from_slice(&common);
    let played = render_frames("topology", &args, 3);
    for (i, path) in played.iter().enumerate() {
        let file = dir.join(format!("s-{i:04}.obj"));
        let mut single = vec!["--mesh", file.to_str().unwrap()];
        single.extend_from_slice(&common);
        let alone = render_frames(&format!("topology-alone-{i}"), &single, 1);
        let (a, b) = (load(path), load(&alone[0]));
        let mean = |img: &image::RgbaImage| img.pixels().map(|p| p[1] as f64).sum::<f64>() / img.pixels().len() as f64;
        assert!(a == b, "frame {i}: mean green {:.1} in the sequence, {:.1} alone", mean(&a), mean(&b));
    }
}
