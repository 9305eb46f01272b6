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

/// A translucent sphere, and the bunny when installed, on an opaque checkerboard floor under a
/// light from above: the object's pixels equal the object alone (the floor is below it: no
/// shadow, no scattering into it); the floor shows both squares of the checker, with the radiance
/// ρ E/π where lit, and the object's shadow under it.
#[test]
fn an_object_on_a_checker_floor() {
    use translucent::world::{Opaque, Reflectance};
    let mut meshes = vec![("sphere", Mesh::sphere(0.8, 24), 4096)];
    if std::path::Path::new(translucent::settings::BUNNY).exists() {
        meshes.push(("bunny", Mesh::from_spec(translucent::settings::BUNNY).unwrap(), 16384));
    }
    for (name, mesh, samples) in meshes {
        // Standing on the floor at y = 0, 0.8 high.
        let (lo, hi) = mesh.bounds();
        let scale = 1.6 / (hi.y - lo.y);
        let mesh = mesh.scaled(scale);
        let object = placed(mesh, "marble", Vec3::new(0.0, -lo.y * scale + 1e-3, 0.0), samples);
        let (floor_mesh, uvs) = floor(6.0, 0.0);
        let (dark, light) = (Vec3::splat(0.1), Vec3::new(0.8, 0.7, 0.6));
        let checks = Reflectance::Checkerboard { uscale: 6.0, vscale: 6.0, tex1: dark, tex2: light };
        let mut floor = Opaque::new(floor_mesh, checks);
        floor.uvs = Some(uvs);
        let camera =
            Camera { eye: Vec3::new(0.0, 3.0, 5.0), target: Vec3::new(0.0, 0.3, 0.0), up: Vec3::Y, fov_y_deg: 45.0 };
        let e = 2.0;
        let mut desc = FrameDesc::new(camera, vec![Light::Directional { toward: Vec3::Y, irradiance: Vec3::splat(e) }]);
        (desc.width, desc.height, desc.shadow_resolution) = (96, 72, 1024);
        let alone = render(&World { objects: vec![object.clone()], opaque: Vec::new(), mm_per_unit: 10.0 }, &desc);
        let scene = render(&World { objects: vec![object], opaque: vec![floor], mm_per_unit: 10.0 }, &desc);
        let path = common::output_dir().join(format!("{name}-on-checkers.png"));
        translucent::output::write_image(&path, &scene, translucent::output::Exposure::Stops(0.0)).unwrap();
        let (mut object_pixels, mut floor_values) = (0, Vec::new());
        for (i, (p, q)) in scene.pixels.iter().zip(&alone.pixels).enumerate() {
            if q[3] > 0.0 {
                object_pixels += 1;
                assert!(
                    p.map(f32::to_bits) == q.map(f32::to_bits),
                    "{name} pixel {i}: {p:?} on the floor, {q:?} alone"
                );
            } else if p[3] > 0.0 {
                floor_values.push(p[0]);
            }
        }
        assert!(object_pixels > 300, "{name}: {object_pixels}");
        // Lit floor: ρ E / π for each square (f32 rounding aside); shadowed: 0.
        let (lit_dark, lit_light) = (dark.x * e / std::f32::consts::PI, light.x * e / std::f32::consts::PI);
        let count = |want: f32| floor_values.iter().filter(|&&v| (v - want).abs() <= 1e-5 * want).count();
        let shadowed = floor_values.iter().filter(|&&v| v == 0.0).count();
        let (d, l) = (count(lit_dark), count(lit_light));
        assert!(d > 200 && l > 200, "{name}: both squares lit: {d} {l}");
        assert!(shadowed > 30, "{name}: its shadow on the floor: {shadowed} pixels");
        // Only the shadow's edge (the map's texels) lies in between.
        let other = floor_values.len() - d - l - shadowed;
        assert!(
            other < floor_values.len() / 10,
            "{name}: {other} of {} floor pixels neither lit nor in shadow",
            floor_values.len()
        );
    }
}

/// A pbrt-v4 scene file and the same scene given by flags render the same image, bit for bit: a
/// PLY torus of Skin1 under a distant light (`Scale -1 1 1` before `LookAt` makes pbrt's camera
/// right-handed, as ours is, so nothing is mirrored).
#[test]
fn a_scene_file_renders_as_the_same_scene_given_by_flags() {
    let dir = common::output_dir().join("scene-vs-flags");
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = Mesh::torus(1.0, 0.35, 48, 24);
    let mut ply = format!(
        "ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.indices.len() / 3
    );
    for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
        ply += &format!("{} {} {} {} {} {}\n", p.x, p.y, p.z, n.x, n.y, n.z);
    }
    for t in mesh.indices.chunks_exact(3) {
        ply += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    std::fs::write(dir.join("torus.ply"), ply).unwrap();
    let scene = r#"Scale -1 1 1
LookAt 0.5 2 4  0 0 0  0 1 0
Camera "perspective" "float fov" [ 35 ]
Film "rgb" "integer xresolution" [ 64 ] "integer yresolution" [ 64 ]
WorldBegin
LightSource "distant" "point3 from" [ -0.3 0.7 -0.65 ] "point3 to" [ 0 0 0 ] "rgb L" [ 1.5 1.5 1.5 ]
Material "subsurface" "string name" "Skin1" "float scale" 10 "float eta" 1.3
Shape "plymesh" "string filename" "torus.ply"
"#;
    std::fs::write(dir.join("torus.pbrt"), scene).unwrap();
    let (from_file, from_flags) = (dir.join("file.exr"), dir.join("flags.exr"));
    let common = ["--validation", "--samples", "4096", "--roughness", "0.35"];
    let scene_path = dir.join("torus.pbrt");
    let mut args = vec!["render", scene_path.to_str().unwrap(), "--out", from_file.to_str().unwrap()];
    args.extend_from_slice(&common);
    let out = common::translucent(&args);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let ply_path = dir.join("torus.ply");
    #[rustfmt::skip]
    let mut flags = vec![
        "render", "--mesh", ply_path.to_str().unwrap(), "--material", "skin1", "--eye", "0.5,2,4", "--target", "0,0,0",
        "--fov", "35", "--width", "64", "--height", "64", "--light", "dir:-0.3,0.7,-0.65:1.5",
        "--out", from_flags.to_str().unwrap(),
    ];
    flags.extend_from_slice(&common);
    let out = common::translucent(&flags);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let (a, b) = (image::open(&from_file).unwrap().into_rgba32f(), image::open(&from_flags).unwrap().into_rgba32f());
    assert!(a.pixels().filter(|p| p[3] > 0.0).count() > 500, "the torus is in view");
    let differing = a.pixels().zip(b.pixels()).filter(|(p, q)| p.0.map(f32::to_bits) != q.0.map(f32::to_bits)).count();
    assert_eq!(differing, 0, "pixels differing between the scene file and the flags");
}

/// pbrt-v4's `imagemap` on an opaque floor: an sRGB PNG of four quadrants (decoded to linear),
/// over the shape's uv with v running up the image: each quadrant's lit floor is ρ E/π, and the
/// quadrants land where pbrt puts them (u along +x, v along +z; the image's top row at v = 1).
#[test]
fn an_image_reflectance_on_a_floor() {
    let dir = common::output_dir().join("imagemap");
    std::fs::create_dir_all(&dir).unwrap();
    // Top-left red, top-right green, bottom-left blue, bottom-right grey (128: 0.2158605 linear).
    let img = image::RgbImage::from_fn(64, 64, |x, y| match (x < 32, y < 32) {
        (true, true) => image::Rgb([255, 0, 0]),
        (false, true) => image::Rgb([0, 255, 0]),
        (true, false) => image::Rgb([0, 0, 255]),
        (false, false) => image::Rgb([128, 128, 128]),
    });
    img.save(dir.join("quadrants.png")).unwrap();
    let scene = r#"LookAt 0 6 4  0 0 0  0 1 0
Camera "perspective" "float fov" [ 60 ]
Film "rgb" "integer xresolution" [ 96 ] "integer yresolution" [ 96 ]
WorldBegin
LightSource "distant" "point3 from" [ 0 1 0 ] "point3 to" [ 0 0 0 ] "rgb L" [ 2 2 2 ]
AttributeBegin
  Material "subsurface" "string name" "Skin1" "float scale" 10
  Translate 0 3 0
  Shape "sphere" "float radius" 0.2
AttributeEnd
Texture "quads" "spectrum" "imagemap" "string filename" "quadrants.png"
Material "diffuse" "texture reflectance" "quads"
Shape "trianglemesh" "integer indices" [ 0 2 1 0 3 2 ] "point3 P" [ -4 0 -4 4 0 -4 4 0 4 -4 0 4 ] "point2 uv" [ 0 0 1 0 1 1 0 1 ]
"#;
    let path = dir.join("floor.pbrt");
    std::fs::write(&path, scene).unwrap();
    let exr = dir.join("floor.exr");
    let out = common::translucent(&[
        "render",
        "--validation",
        path.to_str().unwrap(),
        "--samples",
        "2000",
        "--out",
        exr.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let img = image::open(&exr).unwrap().into_rgba32f();
    let lit = 2.0 / std::f32::consts::PI;
    let grey = 0.2158605 * lit;
    let quadrants =
        [("red", [lit, 0.0, 0.0]), ("green", [0.0, lit, 0.0]), ("blue", [0.0, 0.0, lit]), ("grey", [grey; 3])];
    let mut found = Vec::new();
    for (name, want) in quadrants {
        let px: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| (0..3).all(|c| (p[c] - want[c]).abs() <= 1e-4 * lit))
            .map(|(x, y, _)| (x, y))
            .collect();
        assert!(px.len() > 200, "{name}: {} pixels of its lit reflectance", px.len());
        let mean = |f: fn(&(u32, u32)) -> u32| px.iter().map(f).sum::<u32>() as f64 / px.len() as f64;
        found.push((name, mean(|p| p.0), mean(|p| p.1)));
    }
    let (red, green, blue, grey) = (found[0], found[1], found[2], found[3]);
    // The camera looks down −z from above +z, −z at the image's top; pbrt's camera x is
    // LookAt's up × direction, world −x here, so −x (u < 0.5) is on the image's right in pbrt and here.
    assert!(red.1 > 48.0 && blue.1 > 48.0 && green.1 < 48.0 && grey.1 < 48.0, "u along +x: {found:?}");
    assert!(blue.2 < red.2 && grey.2 < green.2, "the image's bottom row at v = 0 (−z, far): {found:?}");
    // A missing image, and one that is not an image: exit 2 naming the scene's line and the file.
    std::fs::write(dir.join("garbage.png"), [0x89u8, b'P', b'N', b'G', 0, 1, 2, 3]).unwrap();
    // A header that claims 100,000 × 100,000 texels, and no data: refused before anything is
    // allocated for it.
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut c = (data.len() as u32).to_be_bytes().to_vec();
        c.extend_from_slice(kind);
        c.extend_from_slice(data);
        let crc = crc32(&c[4..]);
        c.extend_from_slice(&crc.to_be_bytes());
        c
    };
    let mut huge = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut header = 100_000u32.to_be_bytes().to_vec();
    header.extend_from_slice(&100_000u32.to_be_bytes());
    header.extend_from_slice(&[8, 2, 0, 0, 0]);
    huge.extend(chunk(b"IHDR", &header));
    huge.extend(chunk(b"IEND", &[]));
    std::fs::write(dir.join("huge.png"), huge).unwrap();
    for (file, needle) in [("missing.png", "missing.png"), ("garbage.png", "not an image"), ("huge.png", "huge.png")] {
        let bad = dir.join(format!("bad-{file}.pbrt"));
        std::fs::write(&bad, scene.replace("quadrants.png", file)).unwrap();
        let out = common::translucent(&["render", bad.to_str().unwrap(), "--out", exr.to_str().unwrap()]);
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{file}: {err}");
        assert!(err.contains(&format!("bad-{file}.pbrt:13:1: ")) && err.contains(needle), "{file}: {err}");
    }
}

/// `--profile`'s work counters per object: each object's pixel count is the pixels it covers,
/// and the frame's counters are theirs together.
#[test]
fn work_is_counted_per_object() {
    let sphere = placed(Mesh::sphere(0.8, 24), "marble", Vec3::new(-1.1, 0.0, 0.0), 4096);
    let torus = placed(Mesh::torus(0.6, 0.25, 32, 16), "skin1", Vec3::new(1.1, 0.0, 0.0), 3000);
    let camera = Camera { eye: Vec3::new(0.0, 0.6, 5.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 };
    let light = Light::Directional { toward: Vec3::Y, irradiance: Vec3::ONE };
    let mut desc = FrameDesc::new(camera, vec![light]);
    (desc.width, desc.height, desc.count_work) = (96, 48, true);
    let world = World { objects: vec![sphere.clone(), torus.clone()], opaque: Vec::new(), mm_per_unit: 10.0 };
    let (ctx, counts) = common::validated_context();
    let mut renderer = Renderer::new(ctx, false).unwrap();
    renderer.render_frame(&world, &desc).unwrap();
    let (per_object, all, image) =
        (renderer.work_per_object().unwrap(), renderer.work().unwrap(), renderer.image().unwrap());
    drop(renderer);
    common::assert_clean(&counts);
    let alone: Vec<usize> = [sphere, torus]
        .into_iter()
        .map(|o| {
            let img = render(&World { objects: vec![o], opaque: Vec::new(), mm_per_unit: 10.0 }, &desc);
            img.pixels.iter().filter(|p| p[3] > 0.0).count()
        })
        .collect();
    assert_eq!(per_object.iter().map(|w| w.pixels as usize).collect::<Vec<_>>(), alone);
    assert_eq!(all.pixels as usize, image.pixels.iter().filter(|p| p[3] > 0.0).count());
    assert_eq!(all.point_sum, per_object[0].point_sum + per_object[1].point_sum);
    assert!(per_object.iter().all(|w| w.evaluation_sum > 0));
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

/// CRC-32 (PNG's) of `bytes`.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xffff_ffffu32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
        }
    }
    !crc
}
