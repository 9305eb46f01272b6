//! pbrt-v4 scene files: transformations checked against meshes transformed by hand, the four forms
//! of the subsurface material, every refusal class (exit 2, FILE:LINE:COLUMN), and renders through
//! the command line (the camera's handedness, flags overriding the scene).

mod common;

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3, Vec3};
use translucent::pbrt::{self, LightDesc, MaterialDesc, Reflectance, SubsurfaceSource};

fn dir(name: &str) -> PathBuf {
    let d = common::output_dir().join("pbrt").join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

const TRI: &str =
    r#"Shape "trianglemesh" "point3 P" [0 0 0  1 0 0  0 1 0] "integer indices" [0 1 2] "normal N" [0 0 1 0 0 1 0 0 1]"#;

fn close(a: Vec3, b: DVec3) -> bool {
    (a.as_dvec3() - b).length() < 1e-5
}

#[test]
fn transformations_match_a_mesh_transformed_by_hand() {
    let d = dir("transforms");
    let text = format!(
        "WorldBegin\nTranslate 1 2 3\nAttributeBegin\n  Rotate 90 0 0 1\n  AttributeBegin\n    Scale 2 2 2\n    {TRI}\n  AttributeEnd\n  {TRI}\nAttributeEnd\n{TRI}\n\
         AttributeBegin\n  Scale -1 1 1\n  {TRI}\nAttributeEnd\nAttributeBegin\n  ReverseOrientation\n  {TRI}\nAttributeEnd\n\
         AttributeBegin\n  CoordinateSystem \"here\"\n  Identity\n  CoordSysTransform \"here\"\n  ConcatTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 0 0 1]\n  {TRI}\nAttributeEnd\n"
    );
    let scene = pbrt::load(&write(&d, "t.pbrt", &text)).unwrap();
    assert_eq!(scene.objects.len(), 6);
    let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
    let t = DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0));
    let r = DMat4::from_axis_angle(DVec3::Z, 90f64.to_radians());
    let expected = [
        (t * r * DMat4::from_scale(DVec3::splat(2.0)), false),
        (t * r, false),
        (t, false),
        (t * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)), true), // handedness swapped: winding turned
        (t, true),                                                 // ReverseOrientation
        (t * DMat4::from_translation(DVec3::new(5.0, 0.0, 0.0)), false),
    ];
    for (k, ((m, turned), object)) in expected.iter().zip(&scene.objects).enumerate() {
        let mesh = &object.mesh;
        let order = if *turned { [0, 2, 1] } else { [0, 1, 2] };
        for (corner, &v) in order.iter().enumerate() {
            let p = mesh.positions[mesh.indices[corner] as usize];
            assert!(close(p, m.transform_point3(tri[v])), "object {k} corner {corner}: {p}");
        }
        // The normals: transformed as normals, and negated by ReverseOrientation.
        let n = mesh.normals.as_ref().unwrap()[0];
        let want = m.inverse().transpose().transform_vector3(DVec3::Z).normalize() * if k == 4 { -1.0 } else { 1.0 };
        assert!(close(n, want), "object {k}: normal {n} vs {want}");
        // The winding's normal agrees with the normals (outward by pbrt's rule).
        let [a, b, c] = [0, 1, 2].map(|i| mesh.positions[mesh.indices[i] as usize]);
        assert!((b - a).cross(c - a).dot(n) > 0.0, "object {k}: winding against its normal");
        assert_eq!(object.loc.file.as_ref(), d.join("t.pbrt").display().to_string());
    }
    assert_eq!(scene.objects[0].loc.line, 7);
}

#[test]
fn materials_lights_textures_and_includes() {
    let d = dir("materials");
    std::fs::create_dir_all(d.join("inc")).unwrap();
    write(
        &d,
        "inc/part.pbrt",
        &format!("Material \"subsurface\" \"rgb reflectance\" [0.6 0.5 0.4] \"rgb mfp\" [1 2 3]\n{TRI}\n"),
    );
    let text = format!(
        "LookAt 0 0 -5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" 45\nFilm \"rgb\" \"integer xresolution\" 64 \"integer yresolution\" 32 \"string filename\" \"x.exr\"\n\
         WorldBegin\nLightSource \"distant\" \"point3 from\" [0 1 0] \"point3 to\" [0 0 0] \"rgb L\" [1 2 3] \"float scale\" 2\n\
         LightSource \"point\" \"point3 from\" [1 2 3] \"spectrum I\" [400 1 700 1]\nLightSource \"spot\" \"float coneangle\" 20\nLightSource \"infinite\" \"rgb L\" [.1 .1 .1]\n\
         MakeNamedMaterial \"milk\" \"string type\" \"subsurface\" \"string name\" \"Lowfat Milk\" \"float g\" 0.5 \"float scale\" 3\n\
         NamedMaterial \"milk\"\n{TRI}\nMaterial \"subsurface\" \"rgb sigma_a\" [1 2 3] \"rgb sigma_s\" [4 5 6] \"float eta\" 1.5 \"float g\" 0.2\n{TRI}\n\
         Material \"subsurface\"\n{TRI}\nInclude \"inc/part.pbrt\"\n\
         Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 4 \"float vscale\" 2 \"rgb tex1\" [1 0 0] \"rgb tex2\" [0 0 1]\n\
         Material \"diffuse\" \"texture reflectance\" \"c\"\n{TRI}\nTexture \"i\" \"spectrum\" \"imagemap\" \"string filename\" \"wood.png\"\nMaterial \"diffuse\" \"texture reflectance\" \"i\"\n{TRI}\n\
         Shape \"sphere\" \"float radius\" 2\n"
    );
    let scene = pbrt::load(&write(&d, "m.pbrt", &text)).unwrap();
    let cam = scene.camera.as_ref().unwrap();
    assert!(cam.left_handed && (cam.eye - DVec3::new(0.0, 0.0, -5.0)).length() < 1e-12 && cam.fov_deg == 45.0);
    assert_eq!(
        (scene.film.xresolution, scene.film.yresolution, scene.film.filename.as_deref()),
        (64, 32, Some("x.exr"))
    );
    assert!(matches!(scene.lights[0], LightDesc::Distant { l: [1.0, 2.0, 3.0], scale: 2.0, .. }));
    assert!(matches!(scene.lights[1], LightDesc::Point { i: [1.0, 1.0, 1.0], .. }));
    assert!(matches!(scene.lights[2], LightDesc::Spot { coneangle: 20.0, .. }));
    assert!(matches!(scene.lights[3], LightDesc::Infinite { l: Some(_), .. }));
    let sub = |k: usize| match &scene.objects[k].material {
        MaterialDesc::Subsurface(s) => s.clone(),
        m => panic!("object {k}: {m:?}"),
    };
    // Named: pbrt's own values (not the Narasimhan paper's), g forced to 0, scale kept.
    let milk = sub(0);
    assert_eq!(
        (milk.sigma_s, milk.sigma_a, milk.g, milk.scale),
        ([0.89187, 1.5136, 2.532], [0.002875, 0.00575, 0.0115], 0.0, 3.0)
    );
    assert_eq!(milk.source, SubsurfaceSource::Named("Lowfat Milk".into()));
    let coeff = sub(1);
    assert_eq!((coeff.sigma_a, coeff.sigma_s, coeff.eta, coeff.g), ([1.0, 2.0, 3.0], [4.0, 5.0, 6.0], 1.5, 0.2));
    let default = sub(2);
    assert_eq!((default.sigma_a, default.sigma_s, default.eta), ([0.0011, 0.0024, 0.014], [2.55, 3.21, 3.77], 1.33));
    let refl = sub(3);
    assert!(matches!(refl.source, SubsurfaceSource::Reflectance { .. }));
    assert!((1.0 / (refl.sigma_a[1] + refl.sigma_s[1]) - 2.0).abs() < 1e-12, "mfp 2 in green");
    assert_eq!(refl.loc.file.as_ref(), d.join("inc/part.pbrt").display().to_string());
    match &scene.objects[4].material {
        MaterialDesc::Diffuse { reflectance: Reflectance::Checkerboard { uscale, vscale, tex1, tex2 } } => {
            assert_eq!((*uscale, *vscale), (4.0, 2.0));
            assert_eq!((**tex1).clone(), Reflectance::Constant([1.0, 0.0, 0.0]));
            assert_eq!((**tex2).clone(), Reflectance::Constant([0.0, 0.0, 1.0]));
        }
        m => panic!("{m:?}"),
    }
    assert!(
        matches!(&scene.objects[5].material, MaterialDesc::Diffuse { reflectance: Reflectance::ImageMap { path } } if path.ends_with("wood.png"))
    );
    // The sphere: radius 2, tessellated, with the material in effect.
    let sphere = &scene.objects[6];
    assert!(sphere.mesh.positions.iter().all(|p| (p.length() - 2.0).abs() < 1e-5));
    assert_eq!(sphere.material, scene.objects[5].material);
}

/// Loads `text` as `name` and asserts a refusal naming `FILE:LINE:COLUMN` and `needle`.
fn refused(d: &Path, name: &str, text: &str, line_col: &str, needle: &str) {
    let path = write(d, name, text);
    let err = pbrt::load(&path).expect_err(name);
    assert_eq!(err.exit_code(), 2);
    let msg = err.to_string();
    let at = format!("{}:{line_col}: ", path.display());
    assert!(msg.starts_with(&at), "{name}: {msg:?} does not start with {at:?}");
    assert!(msg.contains(needle), "{name}: {msg:?} lacks {needle:?}");
}

#[test]
fn every_refusal_names_file_line_and_column() {
    let d = dir("refusals");
    for (name, text, at, needle) in [
        ("directive.pbrt", "WorldBegin\n  Frobnicate 1", "2:3", "unknown or unsupported directive 'Frobnicate'"),
        ("object.pbrt", "ObjectBegin \"a\"", "1:1", "supported: LookAt"),
        ("string.pbrt", "Shape \"sphere", "1:7", "never closed"),
        ("number.pbrt", "Translate 1 2 x3", "1:1", "Translate takes 3 numbers"),
        ("camera.pbrt", "Camera \"orthographic\"", "1:1", "only \"perspective\""),
        ("material.pbrt", "Material \"conductor\"", "1:1", "subsurface, diffuse"),
        ("shape.pbrt", "Shape \"cylinder\"", "1:1", "trianglemesh, plymesh, sphere"),
        ("light.pbrt", "LightSource \"goniometric\"", "1:1", "distant, point, spot, infinite"),
        ("texture.pbrt", "Texture \"t\" \"spectrum\" \"marble\"", "1:1", "constant, checkerboard, imagemap"),
        ("type.pbrt", "Camera \"perspective\" \"integer fov\" 30", "1:22", "expected 'float'"),
        (
            "count.pbrt",
            "LookAt 0 0 0 0 0 1 0 1 0\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1]",
            "2:22",
            "multiple of 3",
        ),
        (
            "indices.pbrt",
            "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 1] \"integer indices\" [0 1 9]",
            "1:1",
            "index 9 is out of range",
        ),
        ("ptype.pbrt", "Shape \"sphere\" \"quaternion q\" [1]", "1:16", "unknown parameter type"),
        ("named.pbrt", "Material \"subsurface\" \"string name\" \"Unobtainium\"", "1:1", "no measured medium"),
        ("half.pbrt", "Material \"subsurface\" \"rgb sigma_a\" [1 1 1]", "1:1", "without \"sigma_s\""),
        ("nested.pbrt", "AttributeEnd", "1:1", "without a matching begin"),
        ("open.pbrt", "AttributeBegin\nWorldBegin", "1:1", "AttributeBegin without AttributeEnd"),
        ("include.pbrt", "Include \"missing.pbrt\"", "1:1", "cannot read"),
        ("self.pbrt", "Include \"self.pbrt\"", "1:1", "nested deeper than 16"),
        ("partial-sphere.pbrt", "Shape \"sphere\" \"float zmax\" 0.5", "1:1", "whole spheres"),
        ("blackbody.pbrt", "LightSource \"point\" \"blackbody I\" [6500]", "1:21", "blackbody"),
        ("plyname.pbrt", "Shape \"plymesh\" \"string filename\" \"a.obj\"", "1:1", "not a .ply"),
        ("badply.pbrt", "Shape \"plymesh\" \"string filename\" \"bad.ply\"", "1:1", "line 1: not a PLY file"),
        ("texref.pbrt", "Material \"diffuse\" \"texture reflectance\" \"nope\"", "1:20", "no texture named"),
        ("stray.pbrt", "WorldBegin\n\"float x\" 1", "2:1", "expected a directive"),
    ] {
        if name == "badply.pbrt" {
            write(&d, "bad.ply", "solid\n");
        }
        refused(&d, name, text, at, needle);
    }
    // Sizes: a huge index count costs what its tokens cost, and a file past the limit is refused unread.
    let big = d.join("big.pbrt");
    std::fs::File::create(&big).unwrap().set_len(pbrt::scene::MAX_SCENE_BYTES + 1).unwrap();
    assert!(pbrt::load(&big).unwrap_err().to_string().contains("larger than the limit"));
}

fn render(args: &[&str]) -> std::process::Output {
    let mut full = vec!["render"];
    full.extend_from_slice(args);
    common::translucent(&full)
}

/// The mean brightness of the left and right halves of an 8-bit image.
fn halves(path: &Path) -> (f64, f64) {
    let img = image::open(path).unwrap().into_rgb8();
    let (w, _) = img.dimensions();
    let (mut l, mut r) = (0.0, 0.0);
    for (x, _, p) in img.enumerate_pixels() {
        let v = p.0.iter().map(|&c| c as f64).sum::<f64>();
        if x < w / 2 {
            l += v;
        } else {
            r += v;
        }
    }
    (l, r)
}

#[test]
fn scenes_render_with_pbrts_handedness_and_flags_override() {
    let d = dir("render");
    let scene = |pre: &str, x: f64| {
        format!(
            "{pre}LookAt 0 0 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 48 \"integer yresolution\" 32 \"string filename\" \"{}\"\n\
             Sampler \"halton\"\nWorldBegin\nLightSource \"distant\" \"point3 from\" [0 0 -1] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n\
             AttributeBegin\nTranslate {x} 0 0\nMaterial \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 10\nShape \"sphere\" \"float radius\" 0.6\nAttributeEnd\n",
            d.join("film.png").display()
        )
    };
    // pbrt's camera is left-handed: +x is on the image's right; `Scale -1 1 1` first mirrors it.
    for (pre, right) in [("", true), ("Scale -1 1 1\n", false)] {
        let path = write(&d, "s.pbrt", &scene(pre, 1.0));
        let out = render(&[path.to_str().unwrap(), "--samples", "4096"]);
        assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
        let err = common::stderr(&out);
        assert_eq!(err.matches("Sampler is ignored").count(), 1, "{err}");
        let img = image::open(d.join("film.png")).unwrap();
        assert_eq!((img.width(), img.height()), (48, 32), "the film's size");
        let (l, r) = halves(&d.join("film.png"));
        assert_eq!(r > l, right, "pre {pre:?}: left {l} right {r}");
    }
    // Flags override the film.
    let path = write(&d, "s.pbrt", &scene("", 0.0));
    let out_png = d.join("flag.png");
    let out = render(&[
        path.to_str().unwrap(),
        "--width",
        "20",
        "--height",
        "24",
        "--out",
        out_png.to_str().unwrap(),
        "--samples",
        "4096",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let img = image::open(&out_png).unwrap();
    assert_eq!((img.width(), img.height()), (20, 24));
    // An `infinite` light of constant L renders as `--env const:L` beside the scene's distant
    // light given as a flag: the same lights in the same order, bit for bit. Its frame follows
    // its transform and pbrt's left-handed camera (both mirror in x here, so the map's samples
    // come out where the flag's are).
    let light = "AttributeBegin\nScale -1 1 1\nLightSource \"infinite\" \"rgb L\" [ 0.5 0.5 0.5 ]\nAttributeEnd\n";
    let infinite = write(&d, "infinite.pbrt", &(scene("", 0.0) + light));
    let plain = write(&d, "plain.pbrt", &scene("", 0.0));
    let (a, b) = (d.join("infinite.exr"), d.join("flags.exr"));
    let small = ["--samples", "4096", "--width", "24", "--height", "16", "--env-samples", "16"];
    let out = render(&[&[infinite.to_str().unwrap(), "--out", a.to_str().unwrap()][..], &small].concat());
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let flags = ["--env", "const:0.5", "--light", "dir:0,0,-1:3", "--out", b.to_str().unwrap()];
    let out = render(&[&[plain.to_str().unwrap()][..], &flags, &small].concat());
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let (ia, ib) = (image::open(&a).unwrap().into_rgba32f(), image::open(&b).unwrap().into_rgba32f());
    assert!(ia.pixels().all(|p| p[3] == 1.0), "the environment covers the background");
    assert!(ia == ib, "an infinite light and --env const: differ");
    let missing =
        write(&d, "missing.pbrt", &(scene("", 0.0) + "LightSource \"infinite\" \"string filename\" \"nope.exr\"\n"));
    let out = render(&[missing.to_str().unwrap()]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("missing.pbrt:12:1: ") && err.contains("nope.exr"), "{err}");
    let sheared = write(&d, "sheared.pbrt", &(scene("", 0.0) + "Scale 2 1 1\nLightSource \"infinite\"\n"));
    let out = render(&[sheared.to_str().unwrap()]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("sheared.pbrt:13:1: ") && err.contains("rotation"), "{err}");
    let bad = write(&d, "bad.pbrt", "WorldBegin\nShape \"cone\"\n");
    let out = render(&[bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(common::stderr(&out).starts_with(&format!("error: {}:2:1: Shape \"cone\"", bad.display())));
}

/// `LightSource "spot"` renders: aimed at the sphere's right half (pbrt's +x, on the image's
/// right), that half is the lit one, on the left once `Scale -1 1 1` mirrors the world (the spot's
/// axis mirrored with the left-handed camera); a cone or falloff out of range, or `from` = `to`,
/// is refused naming the file, line and column.
#[test]
fn spot_lights_render_aimed_and_bad_ones_name_the_line() {
    let d = dir("spot");
    let scene = |pre: &str, light: &str| {
        format!(
            "{pre}LookAt 0 0 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 48 \"integer yresolution\" 32 \"string filename\" \"{}\"\n\
             WorldBegin\n{light}\n\
             Material \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 10\nShape \"sphere\" \"float radius\" 0.6\n",
            d.join("spot.png").display()
        )
    };
    let aimed = "LightSource \"spot\" \"point3 from\" [0 0 -6] \"point3 to\" [0.4 0 0] \"float coneangle\" 3 \"float conedeltaangle\" 0.5 \"rgb I\" [400 400 400]";
    for (pre, right) in [("", true), ("Scale -1 1 1\n", false)] {
        let path = write(&d, "spot.pbrt", &scene(pre, aimed));
        let out = render(&[path.to_str().unwrap(), "--samples", "4096"]);
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(0), "{err}");
        assert!(!err.contains("is not used"), "every spot parameter read: {err}");
        let (l, r) = halves(&d.join("spot.png"));
        assert!(if right { r > 3.0 * l } else { l > 3.0 * r }, "pre {pre:?}: left {l} right {r}");
    }
    for (light, needle) in [
        ("LightSource \"spot\" \"float coneangle\" 200", "LightSource \"spot\": cone angle 200°: must be in (0, 180]"),
        ("LightSource \"spot\" \"float coneangle\" 0", "cone angle 0°"),
        (
            "LightSource \"spot\" \"float coneangle\" 10 \"float conedeltaangle\" 12",
            "falloff width 12°: must be in [0, 10]",
        ),
        ("LightSource \"spot\" \"float conedeltaangle\" -1", "falloff width -1°"),
        ("LightSource \"spot\" \"point3 from\" [0 2 0] \"point3 to\" [0 2 0]", "are the same point"),
    ] {
        let path = write(&d, "bad-spot.pbrt", &scene("", light));
        let out = render(&[path.to_str().unwrap()]);
        let err = common::stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{light}: {err}");
        assert!(err.starts_with(&format!("error: {}:5:1: ", path.display())), "{light}: {err}");
        assert!(err.contains(needle), "{light}: {err}");
    }
}

/// `render_settings` for `translucent render PATH ARGS…`, as the command reads them.
fn settings_of(path: &Path, args: &[&str]) -> translucent::error::Result<translucent::settings::RenderSettings> {
    use clap::Parser;
    let argv: Vec<String> =
        ["translucent", "render", path.to_str().unwrap()].iter().chain(args).map(|s| s.to_string()).collect();
    let translucent::cli::Command::Render(r) = translucent::cli::Cli::try_parse_from(&argv).unwrap().command else {
        unreachable!()
    };
    pbrt::render_settings(path, &r, &|f| pbrt::flag_given(&argv, f)).map(|(_, s)| s)
}

/// A square equal-area map, bright (`bright`) within 25° of its own +z and `dim` elsewhere.
fn capped_map(path: &Path, side: u32, bright: f32, dim: f32) {
    use translucent::environment::{uv_to_direction, Layout};
    let img = image::Rgb32FImage::from_fn(side, side, |x, y| {
        let d = uv_to_direction(Layout::Octahedral, (x as f64 + 0.5) / side as f64, (y as f64 + 0.5) / side as f64);
        image::Rgb([if d.z > 25f64.to_radians().cos() { bright } else { dim }; 3])
    });
    img.save(path).unwrap();
}

/// Two `infinite` lights (pbrt-v4 adds them): a map and a constant `L`, or two maps each under its
/// own transform, become one environment whose radiance is their sum in every direction, and whose
/// samples carry both lights' irradiance. Rendered through the binary, under validation.
#[test]
fn two_infinite_lights_are_summed_each_in_its_own_frame() {
    use translucent::scene::Light;
    let d = dir("two-infinite");
    capped_map(&d.join("a.exr"), 32, 8.0, 0.1);
    capped_map(&d.join("b.exr"), 16, 4.0, 0.2);
    // `Scale -1 1 1` before `LookAt`: pbrt's world is ours unmirrored, so directions read as given.
    let scene = |lights: &str| {
        format!(
            "Scale -1 1 1\nLookAt 0 0 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 16 \"string filename\" \"{}\"\n\
             WorldBegin\n{lights}\nMaterial \"subsurface\" \"string name\" \"Skin1\" \"float scale\" 10\nShape \"sphere\" \"float radius\" 0.6\n",
            d.join("two.png").display()
        )
    };
    let map_a = "AttributeBegin\nRotate 90 1 0 0\nLightSource \"infinite\" \"string filename\" \"a.exr\" \"float scale\" 2\nAttributeEnd";
    let map_b = "AttributeBegin\nRotate -90 0 1 0\nLightSource \"infinite\" \"string filename\" \"b.exr\" \"float scale\" 0.5\nAttributeEnd";
    let constant = "LightSource \"infinite\" \"rgb L\" [0.25 0.5 1] \"float scale\" 2";
    let total = |lights: &[Light]| -> Vec3 {
        lights
            .iter()
            .map(|l| if let Light::Directional { irradiance, .. } = l { *irradiance } else { Vec3::ZERO })
            .sum()
    };
    let env_of = |text: &str, name: &str| {
        let path = write(&d, name, &scene(text));
        let s = settings_of(&path, &["--env-samples", "256"]).unwrap_or_else(|e| panic!("{name}: {e}"));
        (s.desc.environment.clone().expect("an environment"), total(&s.desc.lights))
    };
    let (a, ea) = env_of(map_a, "a.pbrt");
    let (b, eb) = env_of(map_b, "b.pbrt");
    let (c, ec) = env_of(constant, "c.pbrt");
    // Rotate 90 about x takes the map's +z to −y; Rotate −90 about y takes it to −x.
    assert_eq!(a.radiance_toward(Vec3::NEG_Y), Vec3::splat(16.0));
    assert_eq!(b.radiance_toward(Vec3::NEG_X), Vec3::splat(2.0));
    let (ac, eac) = env_of(&format!("{map_a}\n{constant}"), "ac.pbrt");
    let (ab, eab) = env_of(&format!("{map_a}\n{map_b}"), "ab.pbrt");
    let close = |x: Vec3, y: Vec3, tol: f32| (x - y).abs().max_element() <= tol * y.max_element();
    for dir in [Vec3::NEG_Y, Vec3::NEG_X, Vec3::Y, Vec3::Z, Vec3::new(0.6, 0.0, 0.8), Vec3::new(-0.48, 0.6, 0.64)] {
        let (want_ac, got_ac) = (a.radiance_toward(dir) + c.radiance_toward(dir), ac.radiance_toward(dir));
        assert!(close(got_ac, want_ac, 1e-6), "map + constant toward {dir}: {got_ac} vs {want_ac}");
        let (want_ab, got_ab) = (a.radiance_toward(dir) + b.radiance_toward(dir), ab.radiance_toward(dir));
        assert!(close(got_ab, want_ab, 1e-6), "two maps toward {dir}: {got_ab} vs {want_ab}");
    }
    // The samples carry both: the constant exactly, the second map resampled into the first's
    // texels (within 3% of its own integral, the cap's edge on a coarser grid).
    assert!(close(eac, ea + ec, 1e-4), "map + constant: {eac} vs {}", ea + ec);
    assert!(close(eab, ea + eb, 0.03), "two maps: {eab} vs {}", ea + eb);
    for (text, name) in [(format!("{map_a}\n{constant}"), "ac.pbrt"), (format!("{map_b}\n{map_a}"), "ba.pbrt")] {
        let path = write(&d, name, &scene(&text));
        let out = render(&[path.to_str().unwrap(), "--validation", "--samples", "4096", "--env-samples", "16"]);
        assert_eq!(out.status.code(), Some(0), "{name}: {}", common::stderr(&out));
    }
}

/// A scene of `diffuse` shapes only (issue #28): rendered under validation with a warning that
/// nothing in it is translucent, the opaque sphere covering the middle of the image and lit on the
/// side its light comes from (pbrt's +x, the image's right); `--profile` and the work counters cope
/// with no translucent object, `--show tree` and `--deform` say there is none, and a scene of no
/// shape at all is still refused.
#[test]
fn a_scene_of_diffuse_shapes_only_renders_them_lit_with_a_warning() {
    let d = dir("diffuse-only");
    let scene = |shapes: &str| {
        format!(
            "LookAt 0 0 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 48 \"integer yresolution\" 32 \"string filename\" \"{}\"\n\
             WorldBegin\nLightSource \"distant\" \"point3 from\" [1 0 0] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n{shapes}",
            d.join("diffuse.exr").display()
        )
    };
    let sphere = "Material \"diffuse\" \"rgb reflectance\" [0.8 0.4 0.2]\nShape \"sphere\" \"float radius\" 0.6\n";
    let path = write(&d, "diffuse.pbrt", &scene(sphere));
    let out = render(&[path.to_str().unwrap(), "--validation", "--profile"]);
    let err = common::stderr(&out);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(err.contains("warning: ") && err.contains("nothing in the scene is translucent"), "{err}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("diffuse") && stdout.contains("surface"), "the profile's passes: {stdout}");
    let img = image::open(d.join("diffuse.exr")).unwrap().into_rgba32f();
    let (w, h) = img.dimensions();
    assert!(img.get_pixel(w / 2, h / 2)[3] > 0.0 && img.get_pixel(0, 0)[3] == 0.0, "the sphere covers the middle");
    let lum = |x: u32, y: u32| img.get_pixel(x, y).0[..3].iter().sum::<f32>();
    // 4 pixels either side of the centre are on the sphere (its radius is 6 pixels).
    let (l, r) = (w / 2 - 4, w / 2 + 4);
    let (left, right) = (lum(l, h / 2), lum(r, h / 2));
    assert!(right > 0.1 && right > 10.0 * left, "lit from the right: left {left}, right {right}");
    assert!(img.get_pixel(r, h / 2)[0] > 2.0 * img.get_pixel(r, h / 2)[2], "its reflectance: orange");
    // What needs a translucent object says there is none.
    let out = render(&[path.to_str().unwrap(), "--show", "tree"]);
    assert_eq!(out.status.code(), Some(2), "{}", common::stderr(&out));
    assert!(common::stderr(&out).contains("no translucent object"), "{}", common::stderr(&out));
    let out = render(&[path.to_str().unwrap(), "--deform", "twist:30"]);
    assert_eq!(out.status.code(), Some(2), "{}", common::stderr(&out));
    assert!(common::stderr(&out).contains("no translucent object"), "{}", common::stderr(&out));
    // Nothing to draw at all.
    let empty = write(&d, "empty.pbrt", &scene(""));
    let out = render(&[empty.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2), "{}", common::stderr(&out));
    assert!(common::stderr(&out).contains("no shape with a subsurface or diffuse material"));
}

/// A scene far from unit size is re-expressed in power-of-two units with its lights: a spot
/// light's position is scaled with the shapes (it was left where it was, inside the rescaled
/// sphere, and the image came out black), so the same scene at 1/1000 of the size, with its
/// subsurface scale 1000 times larger, renders the same image.
#[test]
fn a_spot_light_scales_with_a_scene_far_from_unit_size() {
    let d = dir("spot-scale");
    let scene = |size: f64| {
        format!(
            "LookAt 0 {} {}  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n\
             Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 32\nWorldBegin\n\
             LightSource \"spot\" \"point3 from\" [0 {} 0] \"point3 to\" [0 0 0] \"float coneangle\" 40 \"rgb I\" [{} {} {}]\n\
             Material \"subsurface\" \"string name\" \"Skin1\" \"float scale\" {}\n\
             Shape \"sphere\" \"float radius\" {}\n",
            2.0 * size,
            4.0 * size,
            4.0 * size,
            16.0 * size * size,
            16.0 * size * size,
            16.0 * size * size,
            10.0 / size,
            size
        )
    };
    let mut means = Vec::new();
    for (name, size) in [("unit", 1.0), ("small", 0.001)] {
        let path = d.join(format!("{name}.pbrt"));
        std::fs::write(&path, scene(size)).unwrap();
        let out = d.join(format!("{name}.exr"));
        let o = render(&[path.to_str().unwrap(), "--out", out.to_str().unwrap(), "--no-specular", "--samples", "4096"]);
        assert!(o.status.success(), "{}", common::stderr(&o));
        let img = image::open(&out).unwrap().into_rgba32f();
        let covered: Vec<_> = img.pixels().filter(|p| p.0[3] > 0.0).map(|p| p.0[0] as f64).collect();
        means.push(covered.iter().sum::<f64>() / covered.len().max(1) as f64);
    }
    assert!(means[0] > 0.0, "{means:?}");
    assert!((means[1] / means[0] - 1.0).abs() < 0.02, "the small scene against the unit one: {means:?}");
}
