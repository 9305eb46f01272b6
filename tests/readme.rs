//! The README's numeric limits against the code (issue #28): each sentence that states a limit is
//! looked for with the number the code's constant (or its behaviour) gives, so a test fails when
//! either changes alone. The sample count's bounds and lavapipe's shadow-map layers are measured
//! on the device (lavapipe, validation on).

mod common;

use clap::Parser;
use translucent::cli::Cli;

fn readme() -> String {
    std::fs::read_to_string(common::repo_path("README.md")).expect("README.md")
}

/// Asserts that the README says `text`.
#[track_caller]
fn states(readme: &str, text: &str) {
    assert!(readme.contains(text), "the README no longer says {text:?} (a limit changed in the code or the text)");
}

/// Whether `translucent render ARGS` parses.
fn parses(args: &[&str]) -> bool {
    Cli::try_parse_from(["translucent", "render"].iter().chain(args)).is_ok()
}

/// The README's range in the row of `flag` in the render options: the numbers either side of the
/// first " … " in it.
fn stated_range(readme: &str, flag: &str) -> (u64, u64) {
    let row = readme.lines().find(|l| l.starts_with(&format!("| `{flag}"))).unwrap_or_else(|| panic!("no row {flag}"));
    let (before, after) = row.split_once(" … ").unwrap_or_else(|| panic!("{flag}: no range in {row}"));
    let digits = |s: &str| s.chars().filter(|c| c.is_ascii_digit()).collect::<String>().parse::<u64>().unwrap();
    let lo = before.rsplit(|c: char| !(c.is_ascii_digit() || c == ',')).next().unwrap();
    let hi = after.split(|c: char| !(c.is_ascii_digit() || c == ',')).next().unwrap();
    (digits(lo), digits(hi))
}

#[test]
fn environment_samples_match_the_flag_and_the_script() {
    use translucent::environment::{DEFAULT_SAMPLES, MAX_SAMPLES};
    let r = readme();
    states(&r, &format!("(default {DEFAULT_SAMPLES}, 1 … {MAX_SAMPLES})"));
    states(&r, &format!("(K 1 … {MAX_SAMPLES})"));
    let (max, over) = (MAX_SAMPLES.to_string(), (MAX_SAMPLES + 1).to_string());
    assert!(parses(&["--env-samples", "1"]) && parses(&["--env-samples", &max]));
    assert!(!parses(&["--env-samples", "0"]) && !parses(&["--env-samples", &over]));
    assert!(translucent::view::controls::parse_line(&format!("env samples {max}")).is_ok());
    assert!(translucent::view::controls::parse_line(&format!("env samples {over}")).is_err());
}

#[test]
fn shadow_resolution_and_fitted_maps_match() {
    use translucent::budget::{FrameSizes, FITTED_ABOVE_LIGHTS, SHADOW_MAP_BUDGET};
    use translucent::frame_desc::SHADOW_RESOLUTION_RANGE;
    let r = readme();
    let (lo, hi) = SHADOW_RESOLUTION_RANGE;
    assert_eq!(stated_range(&r, "--shadow-resolution"), (lo as u64, hi as u64));
    assert!(parses(&["--shadow-resolution", &lo.to_string()]) && parses(&["--shadow-resolution", &hi.to_string()]));
    assert!(!parses(&["--shadow-resolution", &(lo - 1).to_string()]));
    assert!(!parses(&["--shadow-resolution", &(hi + 1).to_string()]));
    // "Beyond 8 lights the shadow maps' resolution is halved while one object's maps would pass
    // 768 MiB (64 lights: 1024², 256: 512²)".
    states(&r, &format!("Beyond {FITTED_ABOVE_LIGHTS} lights the shadow maps' resolution is halved"));
    states(&r, &format!("would pass {} MiB (64 lights: 1024², 256: 512²)", SHADOW_MAP_BUDGET >> 20));
    let dirs = |n: usize| vec![common::dir_light([0.0, 1.0, 0.0], [1.0; 3]); n];
    let default = translucent::frame_desc::DEFAULT_SHADOW_RESOLUTION;
    assert_eq!(default, 1024, "the example in the README is of the default resolution");
    assert_eq!(FrameSizes::fitted_shadow_resolution(default, &dirs(FITTED_ABOVE_LIGHTS)), default);
    assert_eq!(FrameSizes::fitted_shadow_resolution(8192, &dirs(FITTED_ABOVE_LIGHTS)), 8192, "taken as given");
    assert_eq!(FrameSizes::fitted_shadow_resolution(default, &dirs(64)), 1024);
    assert_eq!(FrameSizes::fitted_shadow_resolution(default, &dirs(256)), 512);
}

/// "as many as the device has shadow-map layers: 2048 on lavapipe, 6 per point light", a spot's
/// cube "when ANGLE > 60°", and the sample count's "4096 … 262144".
#[test]
fn shadow_layers_and_sample_counts_match_the_device() {
    use translucent::scene::{Light, SPOT_CUBE_ABOVE_DEG};
    let r = readme();
    let point = common::point_light([0.0, 2.0, 0.0], [1.0; 3]);
    let spot = |cone_deg| Light::Spot {
        position: glam::Vec3::Y,
        axis: glam::Vec3::NEG_Y,
        cone_deg,
        delta_deg: 0.0,
        intensity: glam::Vec3::ONE,
    };
    assert_eq!(point.shadow_layers(), 6);
    assert_eq!((spot(SPOT_CUBE_ABOVE_DEG).shadow_layers(), spot(SPOT_CUBE_ABOVE_DEG + 1.0).shadow_layers()), (1, 6));
    states(&r, &format!("six cube faces when both are wider than {SPOT_CUBE_ABOVE_DEG}°"));
    let (ctx, counts) = common::validated_context();
    if ctx.info.name.contains("llvmpipe") {
        let usage = ash::vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | ash::vk::ImageUsageFlags::SAMPLED;
        let props = ctx.image_format_properties(translucent::passes::shadow::SHADOW_FORMAT, usage).unwrap();
        states(
            &r,
            &format!(
                "as many as the device has shadow-map layers: {} on lavapipe, 6 per point light",
                props.max_array_layers
            ),
        );
    }
    // The default sample count's bounds: a huge mesh gets the upper, a tiny one the lower, and
    // two objects share the upper.
    let (lo, hi) = stated_range(&r, "--samples");
    let mesh = translucent::mesh::Mesh::sphere(1.0, 16);
    let skin = translucent::materials::Material::find("skin1").unwrap();
    let count = |mm: f32, objects: u32| translucent::hierarchy::default_point_count(&ctx, &mesh, mm, &skin, 0, objects);
    assert_eq!((count(1e-3, 1) as u64, count(1e4, 1) as u64), (lo, hi), "the README's --samples range");
    assert_eq!(count(1e4, 2) as u64, hi / 2, "shared among the translucent objects");
    drop(ctx);
    common::assert_clean(&counts);
}

#[test]
fn other_stated_limits_match_the_constants() {
    let r = readme();
    let mib = |b: u64| b >> 20;
    states(&r, &format!("in draws of {} points", translucent::passes::shade::POINTS_PER_DRAW));
    states(&r, &format!("a regular file of at most {} MiB", mib(translucent::mesh::MAX_MESH_BYTES)));
    assert_eq!(translucent::mesh::MAX_ELEMENTS, 1 << 25);
    states(&r, "against 2^25 vertices, faces and triangles");
    use translucent::pbrt::scene::{MAX_INCLUDE_DEPTH, MAX_NESTING, MAX_SCENE_BYTES, MAX_TOKENS};
    assert_eq!(MAX_TOKENS, 1 << 23);
    states(
        &r,
        &format!(
            "{MAX_INCLUDE_DEPTH} deep; each file a regular file of at most {} MiB, 2^23 tokens",
            mib(MAX_SCENE_BYTES)
        ),
    );
    states(&r, &format!("nested at most {MAX_NESTING} deep"));
    let (lo, hi) = translucent::world::SIZE_MM_LIMITS;
    states(&r, &format!("the mesh must come out between {lo:e} and {hi:e} mm across"));
    states(&r, &format!("must be within ±{:e}", translucent::frame_desc::MAX_COORDINATE));
    states(
        &r,
        &format!(
            "coordinates within ±{:e} and an extent of at least {:e}",
            translucent::mesh::MAX_COORDINATE,
            translucent::mesh::MIN_EXTENT
        ),
    );
    states(&r, &format!("at least\n{}", translucent::pbrt::MIN_ROUGHNESS));
    states(&r, &format!("α = R² (default {})", translucent::frame_desc::DEFAULT_ROUGHNESS));
    states(&r, &format!("(default {}: ", translucent::frame_desc::DEFAULT_EPSILON));
    use translucent::bssrdf_csv::{BATCH_ROWS, GPU_MAX_SIGMA_T, MAX_LINE_BYTES};
    assert_eq!((BATCH_ROWS, MAX_LINE_BYTES), (65_536, 64 << 10));
    states(&r, "in batches\nof 65,536");
    states(&r, "a line is at most 64 KiB");
    states(&r, &format!("σa + σs above {GPU_MAX_SIGMA_T:e} /mm"));
    // Flags whose limits are clap's ranges.
    assert!(parses(&["--fov", "0.001"]) && !parses(&["--deform-period", "0"]));
    let default_period = Cli::try_parse_from(["translucent", "render"]).unwrap();
    let translucent::cli::Command::Render(args) = default_period.command else { unreachable!() };
    states(&r, &format!("(none, full, none; default {})", args.deform_period));
}
