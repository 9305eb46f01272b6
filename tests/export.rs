//! `translucent export mitsuba`: the scene written is parsed back and its numbers checked against
//! what `render` would draw (no GPU and no Mitsuba needed).

mod common;

use std::path::PathBuf;

use common::{output_dir, repo_path, translucent};
use glam::{DVec3, Vec3};
use translucent::export::mitsuba::{
    disk_radiance, homogeneous, read_ply, write_scene, Camera, Light, Medium, Object, Options, Surface, NO_ROULETTE,
};
use translucent::materials::Material;
use translucent::mesh::Mesh;

fn export(name: &str, args: &[&str]) -> (PathBuf, String) {
    let dir = output_dir().join(format!("export-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    let mut all = vec!["export", "mitsuba", "--out", dir.to_str().unwrap()];
    all.extend_from_slice(args);
    let out = translucent(&all);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let xml = std::fs::read_to_string(dir.join("scene.xml")).expect("scene.xml");
    (dir, xml)
}

/// The `value` (or another attribute) of the first element of `tag` with `name="NAME"` in `xml`
/// after the first occurrence of `after`.
fn attr(xml: &str, after: &str, element: &str, attribute: &str) -> String {
    let start = xml.find(after).unwrap_or_else(|| panic!("{after} not in the scene"));
    let rest = &xml[start..];
    let at = rest.find(element).unwrap_or_else(|| panic!("{element} not after {after}"));
    let el = &rest[at..at + rest[at..].find('>').unwrap()];
    let key = format!("{attribute}=\"");
    let v = &el[el.find(&key).unwrap_or_else(|| panic!("no {attribute} in {el}")) + key.len()..];
    v[..v.find('"').unwrap()].to_string()
}

fn numbers(s: &str) -> Vec<f64> {
    s.split(',').map(|v| v.trim().parse::<f64>().unwrap_or_else(|_| panic!("'{v}' in '{s}'"))).collect()
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(1e-300)
}

#[test]
fn a_translucent_sphere_with_a_directional_light() {
    let (dir, xml) = export(
        "sphere",
        &[
            "--mesh",
            "sphere",
            "--material",
            "skin1",
            "--no-specular",
            "--scale",
            "10",
            "--width",
            "80",
            "--height",
            "60",
            "--eye",
            "0,0,5",
            "--target",
            "0,0,0",
            "--fov",
            "30",
            "--light-dir",
            "0,0,2",
            "--light-intensity",
            "2,3,4",
        ],
    );
    let m = Material::find("skin1").unwrap();
    // The medium: σt = σa + σs per mm as scale × normalised rgb, albedo σs/σt, isotropic.
    let sigma_t = numbers(&attr(&xml, "<medium", "name=\"sigma_t\"", "value"));
    let scale: f64 = attr(&xml, "<medium", "name=\"scale\"", "value").parse().unwrap();
    let albedo = numbers(&attr(&xml, "<medium", "name=\"albedo\"", "value"));
    for c in 0..3 {
        let st = m.sigma_a[c] + m.sigma_s[c];
        assert!(close(sigma_t[c] * scale, st, 1e-12), "σt {c}: {} vs {st}", sigma_t[c] * scale);
        assert!((0.0..=1.0).contains(&sigma_t[c]));
        assert!(close(albedo[c], m.sigma_s[c] / st, 1e-12));
    }
    assert!(xml.contains("<phase type=\"isotropic\"/>"));
    // The boundary: a smooth dielectric of η around it, the medium inside.
    assert_eq!(attr(&xml, "<bsdf type=\"dielectric\"", "name=\"int_ior\"", "value").parse::<f64>().unwrap(), m.eta);
    assert_eq!(attr(&xml, "<bsdf type=\"dielectric\"", "name=\"ext_ior\"", "value"), "1.0");
    assert!(xml.contains("<ref name=\"interior\" id=\"medium0\"/>"));
    // The camera in mm: the eye 5 units = 50 mm away, vertical fov 30°, the film's size, box filter, alpha.
    assert_eq!(numbers(&attr(&xml, "<sensor", "<lookat", "origin")), vec![0.0, 0.0, 50.0]);
    assert_eq!(numbers(&attr(&xml, "<sensor", "<lookat", "target")), vec![0.0, 0.0, 0.0]);
    assert_eq!(numbers(&attr(&xml, "<sensor", "<lookat", "up")), vec![0.0, 1.0, 0.0]);
    assert_eq!(attr(&xml, "<sensor", "name=\"fov_axis\"", "value"), "y");
    assert_eq!(attr(&xml, "<sensor", "name=\"fov\"", "value").parse::<f64>().unwrap(), 30.0);
    assert_eq!(attr(&xml, "<film", "name=\"width\"", "value"), "80");
    assert_eq!(attr(&xml, "<film", "name=\"height\"", "value"), "60");
    assert_eq!(attr(&xml, "<film", "name=\"pixel_format\"", "value"), "rgba");
    assert!(xml.contains("<rfilter type=\"box\"/>"));
    let far: f64 = attr(&xml, "<sensor", "name=\"far_clip\"", "value").parse().unwrap();
    // The light: a disk toward +z (the direction is normalised), of angular radius 5°, emitting
    // E/(π sin²5°), beyond the far clip.
    let radiance = numbers(&attr(&xml, "<shape type=\"disk\"", "name=\"radiance\"", "value"));
    for (c, e) in [2.0, 3.0, 4.0].iter().enumerate() {
        let expected = e / (std::f64::consts::PI * 5f64.to_radians().sin().powi(2));
        assert!(close(radiance[c], expected, 1e-12), "{} vs {expected}", radiance[c]);
    }
    let origin = numbers(&attr(&xml, "<shape type=\"disk\"", "<lookat", "origin"));
    let radius: f64 = attr(&xml, "<shape type=\"disk\"", "<scale", "value").parse().unwrap();
    assert!(origin[0].abs() < 1e-9 && origin[1].abs() < 1e-9 && origin[2] > 10.0 * far, "{origin:?}");
    assert!(close(radius / origin[2], 5f64.to_radians().tan(), 1e-12));
    assert_eq!(numbers(&attr(&xml, "<shape type=\"disk\"", "<lookat", "target")), vec![0.0, 0.0, 0.0]);
    // --no-specular: scripts/reference is told to subtract the boundary's reflection.
    let info: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("reference.json")).unwrap()).unwrap();
    assert_eq!(info["subsurface_only"], true);
    assert_eq!(info["width"], 80);
    assert!(xml.contains("name=\"specular_transmittance\" value=\"$transmittance\""));
    // Unbounded depth and no Russian roulette (it darkened high-albedo media; see NO_ROULETTE).
    assert!(xml.contains("<default name=\"max_depth\" value=\"-1\"/>"), "{xml}");
    assert!(xml.contains(&format!("<default name=\"rr_depth\" value=\"{NO_ROULETTE}\"/>")), "{xml}");
    // The mesh: the renderer's sphere in mm, normals and triangles unchanged.
    let ply = read_ply(&dir.join("object0.ply")).expect("PLY");
    let sphere = Mesh::sphere(1.0, 48);
    assert_eq!(ply.indices, sphere.indices);
    assert_eq!(ply.positions.len(), sphere.positions.len());
    for (p, q) in ply.positions.iter().zip(&sphere.positions) {
        assert!((*p - *q * 10.0).length() < 1e-5, "{p} vs {}", *q * 10.0);
    }
    assert_eq!(ply.normals, sphere.normals);
}

#[test]
fn point_lights_and_the_default_camera_are_in_millimetres() {
    let (_, xml) = export(
        "point",
        &[
            "--mesh",
            "box",
            "--scale",
            "4",
            "--light",
            "point:1,2,3:5",
            "--light",
            "dir:0,1,0:1",
            "--material",
            "marble",
        ],
    );
    // E = I / d² with d in scene units: in mm the intensity is I × 4². A delta point light behind
    // the smooth boundary renders black in Mitsuba, so it is a sphere of radius ρ (seen from the
    // box's centre, the origin, at 5°) emitting I/(πρ²): intensity I toward every direction.
    let sphere = "<shape type=\"sphere\" id=\"light0\"";
    assert_eq!(numbers(&attr(&xml, sphere, "<point", "x")), vec![4.0]);
    assert_eq!(numbers(&attr(&xml, sphere, "<point", "y")), vec![8.0]);
    assert_eq!(numbers(&attr(&xml, sphere, "<point", "z")), vec![12.0]);
    let rho = numbers(&attr(&xml, sphere, "name=\"radius\"", "value"))[0];
    assert!(close(rho, 224f64.sqrt() * 5f64.to_radians().sin(), 1e-9), "radius {rho}");
    for radiance in numbers(&attr(&xml, sphere, "name=\"radiance\"", "value")) {
        assert!(close(radiance * std::f64::consts::PI * rho * rho, 80.0, 1e-9), "radiance {radiance}");
    }
    assert!(!xml.contains("<emitter type=\"point\""));
    // The camera render would use (framing the box), scaled to mm.
    let settings = translucent::settings::RenderSettings::new(
        translucent::settings::SceneSettings { mesh: Some("box".into()), scale: 4.0, ..Default::default() }
            .build()
            .unwrap(),
        Material::find("marble").unwrap(),
    );
    let eye = settings.desc.camera.eye.as_dvec3() * 4.0;
    let origin = numbers(&attr(&xml, "<sensor", "<lookat", "origin"));
    for c in 0..3 {
        assert!(close(origin[c], eye[c], 1e-7), "{origin:?} vs {eye}");
    }
    assert_eq!(attr(&xml, "<sensor", "name=\"fov\"", "value").parse::<f64>().unwrap(), 40.0);
    // Marble's η = 1.5.
    assert_eq!(attr(&xml, "<bsdf type=\"dielectric\"", "name=\"int_ior\"", "value"), "1.5");
}

/// A spot light: Mitsuba's `spot` at the position in mm, looking along the axis, its cutoff the
/// cone angle and its beam the cone less the falloff width; a warning says that the two falloffs
/// differ over that rim.
#[test]
fn spot_lights_are_mitsubas_spot_emitters() {
    let dir = output_dir().join("export-spot");
    let _ = std::fs::remove_dir_all(&dir);
    let out = translucent(&[
        "export",
        "mitsuba",
        "--out",
        dir.to_str().unwrap(),
        "--mesh",
        "box",
        "--scale",
        "4",
        "--light",
        "spot:0,3,0:0,0,0:30:5:2",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("spot") && err.contains("smoothstep in cos θ"), "the falloff warned about: {err}");
    assert!(err.contains("lights no translucent object"), "the delta spot's black subsurface warned about: {err}");
    let xml = std::fs::read_to_string(dir.join("scene.xml")).unwrap();
    assert_eq!(numbers(&attr(&xml, "<emitter type=\"spot\"", "<lookat", "origin")), vec![0.0, 12.0, 0.0]);
    assert_eq!(numbers(&attr(&xml, "<emitter type=\"spot\"", "<lookat", "target")), vec![0.0, 11.0, 0.0]);
    assert_eq!(numbers(&attr(&xml, "<emitter type=\"spot\"", "name=\"intensity\"", "value")), vec![32.0; 3]);
    assert_eq!(numbers(&attr(&xml, "<emitter type=\"spot\"", "name=\"cutoff_angle\"", "value")), vec![30.0]);
    assert_eq!(numbers(&attr(&xml, "<emitter type=\"spot\"", "name=\"beam_width\"", "value")), vec![25.0]);
}

#[test]
fn a_mesh_far_from_unit_size_comes_out_in_the_same_millimetres() {
    // A 20000-unit slab at 0.01 mm per unit is 200 mm across; the renderer re-expresses it in
    // units near 1 internally, the export must still write millimetres.
    let obj = std::fs::read_to_string(repo_path("tests/data/wide-slab.obj")).unwrap();
    let big: String = obj
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(v) => {
                let p: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
                format!("v {} {} {}\n", p[0] * 1000.0, p[1] * 1000.0, p[2] * 1000.0)
            }
            None => format!("{l}\n"),
        })
        .collect();
    let path = output_dir().join("export-big-slab.obj");
    std::fs::write(&path, big).unwrap();
    let (dir, _) = export("big", &["--mesh", path.to_str().unwrap(), "--scale", "0.01", "--material", "potato"]);
    let ply = read_ply(&dir.join("object0.ply")).unwrap();
    let (lo, hi) = ply
        .positions
        .iter()
        .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    assert!((hi - Vec3::new(100.0, 5.0, 100.0)).abs().max_element() < 1e-3, "{hi}");
    assert!((lo + Vec3::new(100.0, 5.0, 100.0)).abs().max_element() < 1e-3, "{lo}");
}

#[test]
fn g_per_channel_and_one_g() {
    // Narasimhan's media have a g per channel; Mitsuba's hg has one: the reduced σ's with g = 0.
    let m = Material::find("regular milk").unwrap();
    let h = homogeneous(&Medium { sigma_a: m.sigma_a, sigma_s: m.sigma_s, g: m.g, eta: m.eta });
    assert!(h.warning.is_some() && h.g.is_none());
    for c in 0..3 {
        let reduced = m.sigma_s[c] * (1.0 - m.g[c]);
        assert!(close(h.sigma_t[c] * h.scale, m.sigma_a[c] + reduced, 1e-12));
        assert!(close(h.albedo[c], reduced / (m.sigma_a[c] + reduced), 1e-12));
    }
    let (_, xml) = export("milk", &["--mesh", "sphere", "--material", "regular milk"]);
    assert!(xml.contains("<phase type=\"isotropic\"/>"));
    // One g for all channels is written as it is.
    let (_, xml) = export("hg", &["--mesh", "sphere", "--material", "skin1", "--g", "0.8", "--sigma-s", "5"]);
    assert_eq!(attr(&xml, "<phase type=\"hg\"", "name=\"g\"", "value"), "0.8");
    let albedo = numbers(&attr(&xml, "<medium", "name=\"albedo\"", "value"));
    assert!(close(albedo[0], 5.0 / (5.0 + 0.032), 1e-12));
}

#[test]
fn opaque_objects_are_diffuse_and_every_number_is_finite() {
    let dir = output_dir().join("export-library");
    std::fs::create_dir_all(&dir).unwrap();
    let floor = Mesh::slab(10.0, 10.0, 0.1);
    let ball = Mesh::sphere(1.0, 8);
    let objects = [
        Object {
            name: "floor".into(),
            mesh: &floor,
            mm_per_unit: 2.0,
            surface: Surface::Diffuse { reflectance: [0.5, 0.25, 0.125] },
        },
        Object {
            name: "ball".into(),
            mesh: &ball,
            mm_per_unit: 3.0,
            surface: Surface::Translucent(Medium { sigma_a: [0.1; 3], sigma_s: [1.0; 3], g: [0.0; 3], eta: 1.4 }),
        },
    ];
    let camera = Camera { eye: DVec3::new(0.0, 10.0, 30.0), target: DVec3::ZERO, up: DVec3::Y, fov_y_deg: 35.0 };
    let lights = [Light::Directional { toward: DVec3::new(0.0, 3.0, 4.0), irradiance: [1.0; 3] }];
    let written =
        write_scene(&dir, &camera, (&lights, None), &objects, &Options { light_radius_deg: 2.0, ..Options::default() })
            .unwrap();
    let xml = std::fs::read_to_string(&written.scene).unwrap();
    assert_eq!(written.meshes.len(), 2);
    assert_eq!(numbers(&attr(&xml, "<!-- floor", "name=\"reflectance\"", "value")), vec![0.5, 0.25, 0.125]);
    assert!(xml.contains("<ref name=\"interior\" id=\"medium1\"/>"));
    let floor_ply = read_ply(&written.meshes[0]).unwrap();
    assert!((floor_ply.positions[0] - floor.positions[0] * 2.0).length() < 1e-6);
    let ball_ply = read_ply(&written.meshes[1]).unwrap();
    assert!((ball_ply.positions[5] - ball.positions[5] * 3.0).length() < 1e-6);
    // The disk: along (0, 0.6, 0.8) from the objects' centre, radiance E/(π sin²2°).
    let origin = DVec3::from_slice(&numbers(&attr(&xml, "<shape type=\"disk\"", "<lookat", "origin")));
    let target = DVec3::from_slice(&numbers(&attr(&xml, "<shape type=\"disk\"", "<lookat", "target")));
    assert!(((origin - target).normalize() - DVec3::new(0.0, 0.6, 0.8)).length() < 1e-12);
    let radiance = numbers(&attr(&xml, "<shape type=\"disk\"", "name=\"radiance\"", "value"));
    assert!(close(radiance[0], disk_radiance(1.0, 2.0), 1e-15));
    assert!(!xml.contains("NaN") && !xml.contains("inf"));
    // Nothing to export, a light radius out of range: bad input.
    assert!(write_scene(&dir, &camera, (&lights, None), &[], &Options::default()).is_err());
    assert!(write_scene(
        &dir,
        &camera,
        (&lights, None),
        &objects,
        &Options { light_radius_deg: 90.0, ..Options::default() }
    )
    .is_err());
}

#[test]
fn a_disk_of_that_radiance_gives_the_irradiance() {
    // E = ∫ over the cone of half-angle δ of L cos θ dω = π L sin²δ, by quadrature.
    for deg in [0.5, 5.0, 20.0] {
        let delta = f64::to_radians(deg);
        let l = disk_radiance(1.0, deg);
        let n = 20_000;
        let e: f64 = (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) / n as f64 * delta;
                l * t.cos() * t.sin() * 2.0 * std::f64::consts::PI * delta / n as f64
            })
            .sum();
        assert!((e - 1.0).abs() < 1e-6, "{deg}°: {e}");
    }
}

fn expect_bad(args: &[&str], says: &str) {
    let out = translucent(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(says), "{stderr} should say {says}");
}

#[test]
fn bad_export_options_exit_2_naming_the_flag() {
    let dir = output_dir().join("export-bad");
    expect_bad(&["export", "mitsuba", "--mesh", "sphere"], "--out");
    expect_bad(&["export", "mitsuba", "--mesh", "sphere", "--out", "x.png"], "--out");
    expect_bad(
        &["export", "mitsuba", "--mesh", "sphere", "--out", dir.to_str().unwrap(), "--light-radius", "90"],
        "--light-radius",
    );
    expect_bad(&["export", "mitsuba", "--mesh", "nope.obj", "--out", dir.to_str().unwrap()], "nope.obj");
    expect_bad(
        &["export", "mitsuba", "--mesh", "sphere", "--material", "nope", "--out", dir.to_str().unwrap()],
        "nope",
    );
}

/// An environment is exported whole, not as its samples: a constant one as Mitsuba's `constant`
/// emitter, a map as an `envmap` of a latitude-longitude EXR in Mitsuba's convention (the sky's
/// sun lands in the texel whose direction is the sun's).
#[test]
fn environments_are_exported_whole() {
    let (dir, xml) = export("env-const", &["--mesh", "sphere", "--env", "const:0.5", "--env-samples", "16"]);
    assert!(
        xml.contains("<emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.5, 0.5, 0.5\"/></emitter>"),
        "{xml}"
    );
    assert_eq!(xml.matches("type=\"disk\"").count(), 0, "the environment's samples are not exported as lights");
    assert!(!dir.join("environment.exr").exists());
    let (dir, xml) = export("env-sky", &["--mesh", "sphere", "--env", "sky:30:90", "--light", "dir:0,1,0:0.5"]);
    assert!(
        xml.contains("<emitter type=\"envmap\"><string name=\"filename\" value=\"environment.exr\"/></emitter>"),
        "{xml}"
    );
    assert_eq!(xml.matches("type=\"disk\"").count(), 1, "the one --light");
    let img = image::open(dir.join("environment.exr")).unwrap().into_rgb32f();
    assert_eq!(img.dimensions(), (512, 256));
    // The sun at elevation 30°, azimuth 90° (toward +x): Mitsuba's u = atan2(x, −z)/2π = 0.25.
    let (x, y) = (img.width() / 4, (img.height() as f32 * (60.0 / 180.0)) as u32);
    assert!(img.get_pixel(x, y)[0] > 100.0, "{:?}", img.get_pixel(x, y));
    assert!(img.get_pixel(img.width() * 3 / 4, y)[0] < 1.0);
}

/// A textured translucent object is a heterogeneous medium: its albedo a grid over the mesh's box
/// whose voxels hold the texture at their nearest surface point inverted to α' (the reduced
/// albedo whose classical-dipole Rd is that colour, with the material's mean free path), its σt
/// one voxel over the same box (the reduced σ't: g = 0).
#[test]
fn a_textured_object_is_a_heterogeneous_medium_of_its_colours() {
    use glam::Vec2;
    use translucent::export::mitsuba::albedo_grid;
    use translucent::world::Reflectance;
    let mesh = Mesh::slab(100.0, 100.0, 20.0);
    let uvs: Vec<Vec2> = mesh.positions.iter().map(|p| Vec2::new((p.x / 100.0 + 0.5) * 1.9999, 0.0)).collect();
    let (bright, dark) = (Vec3::new(0.62, 0.42, 0.30), Vec3::new(0.25, 0.12, 0.06));
    let texture = Reflectance::Checkerboard { uscale: 1.0, vscale: 0.0, tex1: bright, tex2: dark };
    let skin = Material::find("skin1").unwrap();
    let medium = Medium { sigma_a: skin.sigma_a, sigma_s: skin.sigma_s, g: skin.g, eta: skin.eta };
    let grid = albedo_grid(&mesh, &uvs, &texture, &medium, 2.0, 32).unwrap();
    assert_eq!(grid.resolution, [32, 7, 32]);
    assert_eq!((grid.lo, grid.hi), (DVec3::new(-100.0, -20.0, -100.0), DVec3::new(100.0, 20.0, 100.0)));
    let at = |x: usize| grid.albedo[(16 * 7 + 3) * 32 + x];
    for (x, colour) in [(4, bright), (27, dark)] {
        // The material of that colour, with Skin1's mean free path: its α' is the voxel's.
        let own = skin.with_reflectance(colour.as_dvec3().to_array()).unwrap();
        for c in 0..3 {
            let m = own.channel(c);
            let alpha = m.sigma_s * (1.0 - m.g) / (m.sigma_a + m.sigma_s * (1.0 - m.g));
            assert!((at(x)[c] as f64 - alpha).abs() < 2e-3, "voxel {x} channel {c}: {:?} against {alpha}", at(x));
        }
    }
    // Written: a heterogeneous medium with both volumes, each file a version 3 float grid.
    let dir = output_dir().join("export-textured");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let object = Object {
        name: "slab".into(),
        mesh: &mesh,
        mm_per_unit: 2.0,
        surface: Surface::TexturedTranslucent { medium, albedo: grid },
    };
    let camera = Camera { eye: DVec3::new(0.0, 500.0, 0.0), target: DVec3::ZERO, up: DVec3::Z, fov_y_deg: 30.0 };
    let light = Light::Directional { toward: DVec3::Y, irradiance: [1.0; 3] };
    write_scene(&dir, &camera, (&[light], None), &[object], &Options::default()).unwrap();
    let xml = std::fs::read_to_string(dir.join("scene.xml")).unwrap();
    assert!(xml.contains("<medium type=\"heterogeneous\""), "{xml}");
    for name in ["sigma_t", "albedo"] {
        assert!(xml.contains(&format!("<volume name=\"{name}\" type=\"gridvolume\">")), "{xml}");
        let bytes = std::fs::read(dir.join(format!("object0-{name}.vol"))).unwrap();
        assert_eq!(&bytes[..4], b"VOL\x03");
        let count: i32 = (0..3).map(|k| i32::from_le_bytes(bytes[8 + 4 * k..12 + 4 * k].try_into().unwrap())).product();
        assert_eq!(bytes.len(), 48 + count as usize * 12, "{name}");
    }
}

/// A scene file is exported as `render` reads it (its camera, its translucent and opaque shapes),
/// not the default bunny: a pbrt-v4 box of Skin1 on a grey floor.
#[test]
fn a_scene_file_is_exported_as_render_reads_it() {
    let dir = output_dir().join("export-scene-file");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("scene.pbrt");
    std::fs::write(
        &scene,
        "LookAt 0 3 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\n\
         Film \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 48\nWorldBegin\n\
         LightSource \"distant\" \"point3 from\" [0 1 0] \"point3 to\" [0 0 0]\n\
         Material \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 10\n\
         Shape \"sphere\" \"float radius\" 1\n\
         Material \"diffuse\" \"rgb reflectance\" [0.5 0.4 0.3]\n\
         Shape \"trianglemesh\" \"point3 P\" [-4 -1 -4  4 -1 -4  4 -1 4  -4 -1 4] \"integer indices\" [0 2 1 0 3 2]\n",
    )
    .unwrap();
    let (out, xml) = export("scene-file-out", &[scene.to_str().unwrap(), "--no-specular"]);
    assert!(xml.contains("<medium type=\"homogeneous\""), "{xml}");
    assert!(xml.contains("<rgb name=\"reflectance\" value=\"0.5"), "the floor: {xml}");
    assert!(out.join("object1.ply").is_file());
    assert!(xml.contains("<integer name=\"width\" value=\"64\"/>"), "the film's size: {xml}");
}
