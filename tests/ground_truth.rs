//! translucent against the exact solution of the radiative transfer equation: Mitsuba 3's
//! volumetric path tracer on the same scene (`export mitsuba`), whose object means are recorded in
//! tests/data/mitsuba-reference.json with the commands that made them (scripts/accuracy-table,
//! scripts/record-references). The path tracer is not run here; its numbers are data.
//!
//! The ratios are what the models give, not 1: the directional dipole overestimates Skin1's thick
//! slab, the classical dipole is close, photon beam diffusion 8–14% over (README, "Against a path
//! tracer"; its excess is explained in tests/beam_diffusion.rs), and the Monte Carlo table (the
//! half-space's exact transport) within 1.2%, and through the 2 mm slab within 2% (a flat slab's).
//! The test holds the renderer to its measured ratio, so that a change in what it computes shows
//! up here, and the Monte Carlo table to the path tracer.

mod common;

use common::{output_dir, repo_path, translucent};

fn case(name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(repo_path("tests/data/mitsuba-reference.json")).expect("reference data");
    let v: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    v["cases"][name].clone()
}

/// The object's mean per channel over its covered pixels (the slab cases cover every pixel in
/// both renderers, so the selection is the same as compare's).
fn rendered_mean(options: &str, model: &str, name: &str) -> [f64; 3] {
    let out = output_dir().join(format!("ground-truth-{name}-{model}.exr"));
    let mut args: Vec<&str> = vec!["render", "--validation"];
    args.extend(options.split_whitespace());
    let out_s = out.to_str().unwrap().to_string();
    args.extend(["--model", model, "--brute-force", "--samples", "100000", "--out", &out_s]);
    let run = translucent(&args);
    assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    let img = translucent::compare::read_exr(&out).expect("EXR");
    let covered: Vec<_> = img.pixels.iter().filter(|p| p[3] > 0.0).collect();
    assert_eq!(covered.len(), img.pixels.len(), "the slab's view is covered everywhere");
    std::array::from_fn(|c| covered.iter().map(|p| p[c] as f64).sum::<f64>() / covered.len() as f64)
}

#[test]
fn skin1_thick_slab_against_the_path_tracer() {
    // The Monte Carlo table is the half-space's exact transport: within 2% of the path tracer
    // itself (the path tracer's noise of its mean is 0.3-0.6%, the table's Monte Carlo 0.2%;
    // measured 0.5-1.2%).
    against_the_path_tracer("skin1/slab", "skin1-slab", &["directional", "dipole", "pbd", "mc"], 0.02);
}

/// Through Skin1's 2 mm slab lit from behind the Monte Carlo table's light across the object
/// (src/physics/slab_profile.rs, a flat slab's exact transmission) must agree with the path
/// tracer within 5% (its noise of the mean 0.6-0.8%; measured 0.98 0.98 1.00, where the
/// half-space's profile read across gave 0.92 0.52 0.43).
#[test]
fn skin1_thin_slab_against_the_path_tracer() {
    against_the_path_tracer("skin1/thin-slab", "skin1-thin-slab", &["mc"], 0.05);
}

/// Ketchup's 2 mm slab lit from behind: green and blue are mostly single scattering (α' 0.067
/// and 0.020), the rest light scattered more that the slab table carries across. Within 5% (the
/// path tracer's noise of its mean 0.8 / 1.7 / 1.7%); measured 0.989 1.026 0.986 (0.937 in
/// green when the table's measurement ended at its first node, tests/slab_profile.rs).
/// The same slab lit from behind at 60° (refracted in at θt = 42°): its light across read with the
/// slab's change of what it lets through with incidence (src/physics/slab_profile.rs,
/// `oblique_factor`): 1.021 1.056 1.072 of the path tracer (noise of its mean 0.2–0.3%), within
/// 8%; read at normal incidence it was 0.944 1.029 1.135. Green and blue are still over; its
/// multiple scattering alone is 1.03 1.07 1.10 of the path tracer's (README, "Oblique light
/// across a slab").
#[test]
fn skin1_thin_slab_lit_at_60_degrees_against_the_path_tracer() {
    against_the_path_tracer("skin1/thin-slab-60", "skin1-thin-slab-60", &["mc"], 0.08);
}

#[test]
fn ketchup_thin_slab_against_the_path_tracer() {
    against_the_path_tracer("ketchup/thin-slab", "ketchup-thin-slab", &["mc"], 0.05);
}

/// The Monte Carlo table on curved objects against the path tracer's images
/// (tests/data/mitsuba-images: the cases' exports, `scripts/reference --spp 1024 --seeds 4`, the
/// bunnies 4096 × 4), over the pixels both cover fully, as `compare` (at the silhouette the
/// selection moves a back-lit mean by 4%). Each case is held to its measured ratio within 4%
/// so that it fails if the model moves either way: a fix of a
/// deficit updates the numbers here, with its cause.
/// - **The ball's ratio per angle of incidence** (2026-12-07, curvature_profile's
///   INCIDENCE_SIN2: the ratio's and the exit's rows for beams at cos θi 1, 0.6 and 0.2, read
///   per pair at its light's sin²θi and per pixel at the mean of its light's): an oblique beam's
///   light reaches a ball's far side less than a normal beam's (a 10 mm Skin1 ball's red 1.13–1.38
///   of its exact walk past 135° from the light before, 0.98–1.01 to 145° now). Back-lit spheres:
///   Skin1 1.059 1.024 0.992 → 1.006 0.999 0.993, Potato 1.046 1.056 1.078 → 0.995 1.004 1.021,
///   Marble 0.998 1.009 0.999 → 0.990 0.999 0.996, Ketchup (recorded) 1.126 1.041 1.059 → 1.030
///   1.039 1.059; the box 1.165 1.086 1.014 → 1.133 1.039 0.975; the torus back-lit 1.077 1.044
///   1.014 → 1.042 1.014 1.005, front-lit 1.005 0.999 1.007 → 0.999 0.994 1.005; front-lit
///   spheres: Skin1 1.004 1.000 0.999 → 0.997 0.996 0.997, Potato 1.023 1.023 1.002 → 1.017 1.016
///   0.996, Marble 1.014 1.008 1.004 → 1.013 1.007 1.003, Ketchup (recorded) 0.918 0.983 0.976 →
///   0.912 0.980 0.976. The bunnies: Skin1 1.056 0.955 0.913 → 1.008 0.909 0.874 (per-pixel
///   relative RMSE 0.396 0.379 0.402 → 0.386 0.378 0.404; its multiple scattering alone about
///   1.03 0.93 0.90 of the path tracer's, its single 0.84), Marble 1.030 1.003 0.959 → 1.023
///   0.994 0.954; the far point light 1.028 0.979 0.972 → 1.022 0.973 0.968. The slabs and
///   single scattering unchanged (flat: κ = 0).
/// - **The radial profile's change with incidence** (2026-12-07, `McProfile::radial`): an oblique
///   beam's light spreads further than the normal beam's times f(θt), which the flat
///   half-space's walk measures (1.25–3.1 mm from a Skin1 beam at cos θi 0.2 the model was 0.88
///   of it in blue, now 0.98). The Skin1 bunny 1.054 0.935 0.889 → 1.056 0.955 0.913, the
///   back-lit Skin1 sphere 1.056 0.993 0.957 → 1.059 1.024 0.992, Marble's 1.006 1.023 1.014 →
///   0.998 1.009 0.999; but what is too bright far from an oblique entry on a ball (README,
///   "The same rings against a walk that splits") now shows more: the box 1.156 1.057 0.979 →
///   1.165 1.086 1.014, the back-lit torus 1.072 1.027 0.995 → 1.077 1.044 1.014, Potato's
///   back-lit sphere 1.037 1.050 1.049 → 1.046 1.056 1.078, Ketchup's (recorded) 1.102 1.036
///   1.051 → 1.126 1.041 1.059; Marble's bunny 1.037 1.012 0.967 → 1.030 1.003 0.959; the
///   front-lit spheres within 1% (Potato's red and green 1.014 1.018 → 1.023 1.023); the slabs,
///   single scattering and the far point light unchanged.
/// - **The curvature table's photons split as they go far** (2026-12-07, `halfspace::Split`,
///   curvature_profile.rs): its far chords, where the walks counted too few and held a nearer
///   entry's ratio, are measured. The Skin1 bunny 1.053 0.927 0.880 → 1.054 0.935 0.889, the
///   back-lit Skin1 sphere 1.057 0.982 0.953 → 1.056 0.993 0.957, Marble's bunny 1.038 1.015
///   0.969 → 1.037 1.012 0.967, Ketchup's back-lit sphere (recorded) 1.104 1.027 1.051 → 1.102
///   1.036 1.051, the box 1.157 1.055 0.977 → 1.156 1.057 0.979, the back-lit torus 1.072 1.025
///   0.993 → 1.072 1.027 0.995, the back-lit Marble and Potato spheres' blue 1.018 → 1.014 and
///   1.052 → 1.049; the rest within 0.1%, every slab and every single scattering unchanged.
/// - **The lean's second and third harmonics** (2026-12-07, `McProfile::harmonics`): an oblique
///   beam's light is peaked ahead of it and flat behind it, where the first harmonic alone left
///   0.68–0.90 of the walk's behind and 1.09–1.30 to the sides (tests/curvature_profile.rs).
///   Skin1 sphere front-lit 0.981 0.980 0.986 → 1.002 0.998 0.997, back-lit 1.055 0.969 0.933 →
///   1.057 0.982 0.953; the torus 0.992 0.988 0.999 → 1.004 1.000 1.008 and 1.070 1.017 0.981 →
///   1.072 1.025 0.993; the box 1.150 1.045 0.967 → 1.157 1.055 0.977; Potato front-lit 0.995
///   0.998 0.973 → 1.014 1.018 1.001, back-lit 1.035 1.049 1.049 → 1.037 1.050 1.052; Marble
///   +0.3–0.4%; the bunnies within 0.2%; every slab unchanged (the harmonics sum to nothing on a
///   flat surface lit evenly).
/// - **The beam focuses by the entry's curvature** (2026-12-07, the shadow pass's curvature
///   layer, shade.frag `lens_gain`): the Skin1 bunny 1.050 0.922 0.872 → 1.055 0.928 0.880 (its
///   single scattering 0.802 0.819 0.816 → 0.837 0.847 0.838), the back-lit torus 1.072 1.019
///   0.982 → 1.070 1.017 0.981; the spheres (1/R at the pixel and at the entry alike), the box
///   and Marble's bunny within 0.1%.
/// - **Single scattering's entry at the mesh's normals** (2026-12-06, the shadow pass's normal
///   layer, shade.frag `entry_surface`): the numbers in the test (the Potato and Marble spheres
///   by brute force, within 0.4% of the tree), from the exit's tilt's (below) Skin1 sphere
///   front-lit 0.980 0.979 0.985 and back-lit 1.052 0.964 0.923, the box 1.150 1.045 0.967, the
///   torus 0.992 0.988 0.999 and 1.075 1.023 0.988, the bunnies 1.037 0.901 0.846 and 1.035 1.013
///   0.967, Potato 0.994 0.998 0.973 and 1.032 1.046 1.041, Marble 1.007 1.003 1.001 and 1.002
///   1.020 1.014: what moved is single scattering on the back-lit objects, most on the Skin1
///   bunny (its single scattering 0.693 0.730 0.747 → 0.802 0.819 0.816 of the path tracer's).
/// - **The exit's tilt** (2026-12-06, `McProfile::exit_tilt`, tests/exit_tilt.rs): light leaves
///   leaning away from where it entered, which took every curved case to the numbers in the
///   test (the Skin1 sphere front-lit 1.042 1.030 1.017 → 0.980 0.979 0.985, back-lit 0.960
///   0.833 0.804 → 1.052 0.964 0.923; the box 1.179 1.064 0.971 → 1.150 1.045 0.967; the torus
///   1.045 1.040 1.035 → 0.992 0.988 0.999 and 1.038 0.964 0.926 → 1.075 1.023 0.988; the
///   bunnies 0.969 0.823 0.781 → 1.037 0.901 0.846 and 0.999 0.977 0.930 → 1.035 1.013 0.967;
///   Potato 1.056 1.059 1.039 → 0.994 0.998 0.973 and 0.959 0.964 0.929 → 1.032 1.046 1.041,
///   Marble 1.032 1.026 1.020 → 1.007 1.003 1.001 and 0.943 0.959 0.951 → 1.002 1.020 1.014,
///   brute force). The history below is of the numbers before it.
/// - The 10 mm Skin1 sphere: the curvature ratios and the oblique entry's harmonic
///   (src/physics/curvature_profile.rs, mc_profile.rs) take the front-lit one to 1.042 1.030
///   1.017, where the flat half-space's profile gave 0.88 0.90 0.93 (1.070 1.052 1.029 when the
///   ratio was read between curvature nodes at one chord, not each node at the same place on its
///   ball: `CurvatureChannel::ratio`). Its single scattering is
///   within 1–2% of the path tracer's (`single_scattering_against_the_path_tracer`); the
///   multiple scattering is 1.083 1.067 1.034 of the path tracer's light scattered twice or
///   more (its image less the one-scattering reference): too bright toward the terminator
///   (tests/curvature_profile.rs, the ring by ring walk). (1.051 1.034 1.010 before single
///   scattering took in the beam's focusing by the curved entry, which hid that much of it.)
///   Back-lit 0.960 0.833 0.804: the read between nodes had lifted green and blue by 5 and 3%,
///   hiding a deficit that a first azimuthal harmonic of an oblique entry's light on a ball
///   leaves (tests/curvature_profile.rs, `the_ball_s_own_oblique_beams_sum_to_the_walk`).
///   0.937 0.878 0.831 before that (0.937 0.877 0.818 before the curvature rows read the ball
///   against the Monte Carlo table's profile past the half-space walk's reach), of which single
///   scattering 0.931 0.930 0.918 and multiple 0.936 0.869 0.766 (split before the tail; 0.920 0.858
///   0.803 before the focusing; 0.917 0.853 0.789 before the
///   entry's normal was taken by central differences of the shadow map, shade.frag
///   `entry_surface`; the half-space's 0.51 0.53 0.80; 0.898 0.847 0.788 before the curvature
///   rows held their antipode's ratio past a ball's diameter): single scattering, entering
///   where refracted light really enters (shade.frag, light_entry), no longer lights the inside
///   beyond the terminator, which had added 5 / 12 / 23% and hidden that much of a deficit of
///   the multiple scattering (README, "Curved objects in the Monte Carlo table").
/// - A thin convex lens of Skin1 behind the default light (tests/data/thin-lens.obj.gz: a
///   flattened ellipsoid 16 × 8 × 2.4 mm, as a bunny's ear; path traced with `--routes`, convex
///   so all its light takes the one route the models draw): 1.039 1.034 1.027 since a pair
///   across a sheet thinner than half its radius of curvature is read across a slab
///   (sources.glsl `across`); 1.178 1.110 1.055 before, when the blend toward the ball began at
///   κt = 0 (its multiple scattering 1.29 1.22 1.19, single 0.834 0.845 0.844; the excess at the
///   rim, the outer 6 pixels 1.29 1.18 1.08 against the interior's 1.06 1.02 1.01). The same
///   change took the Skin1 bunny 1.008 0.909 0.874 → 0.982 0.878 0.845, Marble's 1.023 0.994
///   0.954 → 1.008 0.982 0.945, the back-lit torus 1.042 1.014 1.005 → 1.037 1.012 1.005, and
///   left every sphere, the box and the front-lit torus within 0.3%.
/// - A 16 mm Skin1 box behind the default light, where light turns the edges from the lit top,
///   back and left faces to the three the camera sees: 1.179 1.064 0.971 (1.181 1.071 0.991
///   before a pair past the last curvature node was read at that node's r·κ, 1.219 1.116 1.025
///   before each node was read at the same place on its ball, 1.218 1.114 1.019
///   before the rows' tail), each pair read at its
///   own curvature along the way (`pair_curvature`); read at the pixel's mean curvature (0 on
///   the faces) it was 0.68 0.53 0.54.
/// - A Skin1 torus (22 mm across, its tube 5.6 mm thick), whose inside is a saddle (concave
///   around the ring): front-lit 1.045 1.040 1.035, back-lit 1.038 0.964 0.926 (1.063 1.057
///   1.046 and 1.027 0.973 0.947 before each node was read at the same place on its ball;
///   0.943 in blue before the rows' tail; 1.046 1.039
///   1.027 and 1.013 0.960 0.933 before the focusing; at the pixel's mean curvature 1.083 1.029
///   1.009 and 0.965 0.841 0.837).
/// - Pairs joined only through the air dropped (sources.glsl `joined_inside`, the object's inside
///   on a 64³ grid): the bunnies 0.981 0.881 0.848 → 0.964 0.877 0.848 (Skin1) and 1.007 0.981
///   0.943 → 0.976 0.956 0.925 (Marble), the torus 0.999 → 0.997 front-lit and 1.036 → 1.034
///   back-lit in red; every convex case to the last digit.
/// - A thin sheet's lit face (sources.glsl `begin_thickness`, slab_profile's `reflected`: each
///   pair times what a flat slab of the sheet's thickness under the pixel gives back over the
///   half-space's): the bunnies 0.964 0.877 0.848 → 0.932 0.855 0.839 (Skin1) and 0.976 0.956
///   0.925 → 0.929 0.913 0.884 (Marble; their ears, 1.18 1.15 1.13 of Marble's route, → 1.06
///   1.04 1.03), the 2.4 mm lens back-lit 1.073 1.048 1.011 → 1.001 1.019 1.007, the box 1.120
///   → 1.114 and the back-lit torus 1.034 → 1.029 in red; every sphere (κt ≥ 1) unchanged.
/// - The default bunny (128 × 96, the default tree and samples), Skin1 and Marble: 0.969 0.823
///   0.781 and 0.999 0.977 0.930 (0.972 0.826 0.783 and 1.000 0.978 0.932 before a node's sigma
///   points turned their normals with the pixel's curvature, sources.glsl
///   `sigma_point_curvature`; 0.973 0.828 0.787 and 1.009 0.989 0.943 before a pair past the
///   last curvature node was read at that node's r·κ; 0.951 0.833 0.789 and 0.971 0.943 0.901 before each node was
///   read at the same place on its ball; 0.951 0.831 0.784 and 0.971 0.943 0.900 before the rows'
///   tail; 0.951 0.826 0.773 and 0.970 0.942 0.899 before the focusing;
///   0.938 0.814 0.761 and 0.967 0.936 0.898 before the far light's exit rows and the entry's
///   central differences; at the pixel's mean curvature 0.914 0.725 0.644 and 0.940 0.908
///   0.866; the flat half-space's 0.62 0.54 0.60 and 0.84 0.80 0.76).
/// - The 10 mm Potato and Marble spheres (references 1024 × 4 of 2026-12-06; the tree at the
///   default ε, which is within 0.4% of brute force here): Potato front-lit 1.056 1.059 1.039
///   (over the 5% in red and green), Marble front-lit 1.032 1.026 1.020, Potato
///   back-lit 0.959 0.964 0.929, Marble back-lit 0.943 0.959 0.951. (The ratios recorded before
///   against 256 × 2 references and carried from commit to commit by the render's change, 1.051
///   1.055 1.034 front-lit and 0.917 0.921 0.851 back-lit for Potato, were off by up to 9%; those
///   references' noise was up to 5%.)
#[test]
fn curved_objects_against_the_path_tracer() {
    let brute = ["--brute-force", "--samples", "100000"];
    let cases: [(&str, &[&str], [f64; 3]); 12] = [
        ("skin1/sphere-front", &brute, [0.997, 0.996, 0.997]),
        ("skin1/sphere-back", &brute, [1.006, 0.999, 0.993]),
        ("skin1/box-back", &brute, [1.114, 1.035, 0.975]),
        ("skin1/lens-back", &brute, [1.001, 1.019, 1.007]),
        ("skin1/torus-front", &brute, [0.995, 0.994, 1.005]),
        ("skin1/torus-back", &brute, [1.029, 1.011, 1.004]),
        ("skin1/bunny", &[], [0.932, 0.855, 0.839]),
        ("marble/bunny", &[], [0.929, 0.913, 0.884]),
        ("potato/sphere-front", &[], [1.017, 1.016, 0.996]),
        ("marble/sphere-front", &[], [1.013, 1.007, 1.003]),
        ("potato/sphere-back", &[], [0.995, 1.004, 1.021]),
        ("marble/sphere-back", &[], [0.990, 0.999, 0.996]),
    ];
    for (name, sampling, expected) in cases {
        for (ch, ratio) in mc_against_its_reference(name, sampling).into_iter().enumerate() {
            println!("{name} mc channel {ch}: translucent / path traced = {ratio:.4}");
            assert!((ratio / expected[ch] - 1.0).abs() < 0.04, "{name} channel {ch}: {ratio} against {}", expected[ch]);
        }
    }
}

/// Single scattering finds where light enters through the shadow map (shade.frag, light_entry):
/// its answer must not hang on the map's resolution. The back-lit Skin1 sphere, where light
/// grazes the terminator, at 1024² (the default) and 4096² maps: measured −0.33 / −0.79 / −1.8%
/// (R / G / B) with the beam's focusing (cacae17; −0.2 / −0.5 / −1.5% before it); the forward
/// differences the entry's normal was taken from before gave 2.7% in blue.
#[test]
fn single_scattering_converges_with_the_shadow_map() {
    let options = case("skin1/sphere-back")["render_options"].as_str().expect("render options").to_string();
    let means: Vec<[f64; 3]> = ["1024", "4096"]
        .iter()
        .map(|resolution| {
            let out = output_dir().join(format!("ground-truth-shadow-{resolution}.exr"));
            let mut args: Vec<&str> = vec!["render", "--validation"];
            args.extend(options.split_whitespace());
            let out_s = out.to_str().unwrap().to_string();
            args.extend(["--model", "mc", "--shadow-resolution", resolution, "--out", &out_s]);
            let run = translucent(&args);
            assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
            let img = translucent::compare::read_exr(&out).expect("EXR");
            let covered: Vec<_> = img.pixels.iter().filter(|p| p[3] > 0.0).collect();
            std::array::from_fn(|c| covered.iter().map(|p| p[c] as f64).sum::<f64>() / covered.len() as f64)
        })
        .collect();
    for (c, (coarse, fine)) in means[0].iter().zip(&means[1]).enumerate() {
        let change = coarse / fine - 1.0;
        println!("channel {c}: 1024² / 4096² - 1 = {:.4}", change);
        assert!(change.abs() < 0.02, "channel {c}: {change}");
    }
}

/// Single scattering alone (`--scattering single`) on 10 mm spheres against the path tracer
/// limited to light scattered once (`scripts/reference --max-depth 4`; tests/data/mitsuba-images
/// `*-single.exr`): within 10% of it in every case and channel, and held to its measured ratio
/// within 3% (the references' noise of the mean 0.04–2.4%). Measured 0.963 0.958 0.944 (Skin1
/// back-lit), 0.966 0.965 0.941 (Ketchup back-lit), 1.014 1.018 1.023 (Skin1 front-lit), 1.015
/// 1.015 1.014 (Potato front-lit); before the entry refracted at the mesh's normals (the
/// shadow pass's normal layer; it took the facets' from the depths) 0.931 0.930 0.918, 0.931
/// 0.937 0.916, 1.013 1.017 1.022, 1.013 1.014 1.013. Before the beam's focusing by the curved entry (shade.frag
/// `lens_gain`, the pixel's curvature in Coddington's equations), the stricter test of whether refracted light reaches a point and the interval's
/// mean beam: 0.767 0.835 0.882, 0.595 0.895 0.939, 0.928 0.956 0.979, 0.916 0.921 0.914. What
/// the back-lit spheres still miss (an exact sum over the ball's refracted rays, README): near
/// the fold of the refracted light past the terminator two entries reach a point and the steps
/// find one, and the ball focuses light onto its far pole, where the gain is held.
#[test]
fn single_scattering_against_the_path_tracer() {
    for name in [
        "skin1/sphere-back-single",
        "ketchup/sphere-back-single",
        "skin1/sphere-front-single",
        "potato/sphere-front-single",
    ] {
        let measured = recorded_mc_ratio(name);
        let sampling = ["--scattering", "single", "--brute-force", "--samples", "100000"];
        for (ch, ratio) in mc_against_its_reference(name, &sampling).into_iter().enumerate() {
            println!(
                "{name} channel {ch}: single scattering / path traced = {ratio:.4} (recorded {:.4})",
                measured[ch]
            );
            assert!((ratio - 1.0).abs() < 0.1, "{name} channel {ch}: {ratio} of the path tracer");
            assert!((ratio / measured[ch] - 1.0).abs() < 0.03, "{name} channel {ch}: {ratio} against {}", measured[ch]);
        }
    }
}

/// Single scattering on the default Skin1 bunny (back-lit, 128 × 96, the default tree) against
/// the path tracer limited to light scattered once (`skin1/bunny-single`, 8 × 4096 spp, noise of
/// the mean 0.8 / 0.9 / 1.2%): measured 0.837 0.847 0.838, held there within 4%. A known deficit,
/// not a goal met: it was 0.802 0.819 0.816 while the beam focused by the pixel's mean curvature
/// (shade.frag `lens_gain`) instead of the entry's (the shadow pass's curvature layer; at the base
/// of the right ear the pixel is concave where the entry, on the ear's back, is convex), and
/// 0.693 0.730 0.747 while the entry refracted the light at the facets'
/// normals (the shadow map's depth differences) where the path tracer refracts at the mesh's
/// interpolated ones (now the shadow pass's normal layer), and it is most of what the whole
/// bunny misses in green and blue (single scattering is 12 / 23 / 37% of the path tracer's light
/// there; multiple scattering alone, the full reference less this one, is 1.084 0.952 0.904).
/// What is still missing: focusing finer than the curvature's smoothing (a diffusion length).
/// Measuring it on the light's own rays (the Jacobian of neighbouring entries' refracted rays)
/// gave 0.903 0.909 0.895, the unsmoothed shape operator 0.871 0.883 0.875, both speckled
/// (README, "The default bunny").
#[test]
fn single_scattering_on_the_bunny_against_the_path_tracer() {
    let name = "skin1/bunny-single";
    let measured = recorded_mc_ratio(name);
    for (ch, ratio) in mc_against_its_reference(name, &["--scattering", "single"]).into_iter().enumerate() {
        println!("{name} channel {ch}: single scattering / path traced = {ratio:.4} (recorded {:.4})", measured[ch]);
        assert!((ratio / measured[ch] - 1.0).abs() < 0.04, "{name} channel {ch}: {ratio} against {}", measured[ch]);
    }
}

/// A point light 50 units from the default Skin1 bunny (`--light point:0,30,40:2500`: irradiance
/// 1 there, from above and in front), its light scattered once and all of it, against the path
/// tracer (`export mitsuba` writes a point light as a small sphere emitting I/(πρ²): a delta
/// point light behind a smooth dielectric renders black in Mitsuba). Single scattering measured
/// 0.954 0.963 0.969, the whole image 1.011 0.971 0.968 (1.022 0.973 0.968 before pairs joined
/// only through the air were dropped; 1.021 0.972 0.966 with the lean's first harmonic alone);
/// each held to its recorded ratio within 4%,
/// single scattering within 10% of the path tracer. With six cube faces for a far point light
/// (before 2026-12-07), where the bunny covered 20 × 35 texels of one, single scattering was
/// 0.051 0.046 0.043 of the path tracer's (0.833 0.682 0.550 the whole).
#[test]
fn a_far_point_light_against_the_path_tracer() {
    let single: &[&str] = &["--scattering", "single"];
    for (name, extra) in [("skin1/bunny-point-single", single), ("skin1/bunny-point", &[])] {
        let measured = recorded_mc_ratio(name);
        for (ch, ratio) in mc_against_its_reference(name, extra).into_iter().enumerate() {
            println!("{name} channel {ch}: translucent / path traced = {ratio:.4} (recorded {:.4})", measured[ch]);
            if name.ends_with("-single") {
                assert!((ratio - 1.0).abs() < 0.1, "{name} channel {ch}: {ratio} of the path tracer");
            }
            assert!((ratio / measured[ch] - 1.0).abs() < 0.04, "{name} channel {ch}: {ratio} against {}", measured[ch]);
        }
    }
}

/// Objects that are not convex against the path tracer's light along the one route every model
/// here draws: in at the pixel's point, through the medium, out once and straight to the light
/// (`scripts/reference --routes`, scripts/mitsuba_routes.py; recorded as `*-one-exit`). The rest
/// of the path tracer's light left the object and entered it again, or is the object's light
/// seen in the boundary's reflection at the pixel: 14 / 13 / 12% of the default Skin1 bunny's
/// (R / G / B), 15 / 16 / 15% of Marble's, 5 / 3 / 2% of the back-lit torus's, none of a
/// sphere's. Against all the light mc reads 0.932 0.855 0.839 on the Skin1 bunny; against its
/// own route it is 1.098 0.998 0.956, Marble's 1.093 1.078 1.038, the torus 1.097 1.055 1.041
/// (1.135 1.023 0.966, 1.148 1.130 1.086 and 1.101 1.055 1.041 before a thin sheet's lit face
/// gave back less than the half-space's, sources.glsl `begin_thickness`: the ears; 1.156 1.025
/// 0.964, 1.185 1.161 1.110 and 1.105 1.056 1.041 before pairs joined only
/// through the air were dropped; 1.187 1.061 0.996, 1.203 1.175 1.121 and 1.110 1.058 1.042
/// before a sheet's across pairs were read across a slab): too bright, where the whole
/// reference had called the bunny too
/// dark (README, "Routes no BSSRDF
/// draws"). Each held to its recorded ratio within 4%, as the other curved objects are; and the
/// split's total must agree with `volpathmis`' reference of the same scene (the split is the
/// same light, counted by route) within three of their combined standard errors.
#[test]
fn the_models_route_against_the_path_tracer() {
    let cases: [(&str, &str, &[&str]); 3] = [
        ("skin1/bunny-one-exit", "skin1/bunny", &[]),
        ("marble/bunny-one-exit", "marble/bunny", &[]),
        ("skin1/torus-back-one-exit", "skin1/torus-back", &["--brute-force", "--samples", "100000"]),
    ];
    for (name, whole, sampling) in cases {
        let c = case(name);
        let all = numbers(&c["routes"]["all"]["object_mean"]);
        let all_noise = numbers(&c["routes"]["all"]["relative_noise_of_mean"]);
        let reference = case(whole);
        let volpath = numbers(&reference["path_traced_mean"]);
        let volpath_noise = numbers(&reference["relative_noise_of_mean"]);
        for ch in 0..3 {
            let off = all[ch] / volpath[ch] - 1.0;
            let sigma = (all_noise[ch].powi(2) + volpath_noise[ch].powi(2)).sqrt();
            println!(
                "{name} channel {ch}: the routes' total / volpathmis = {:.4} (combined noise {:.2}%)",
                1.0 + off,
                100.0 * sigma
            );
            assert!(off.abs() < 3.0 * sigma, "{name} channel {ch}: the split's total is {off:+.4} off volpathmis'");
        }
        let measured = recorded_mc_ratio(name);
        for (ch, ratio) in mc_against_its_reference(name, sampling).into_iter().enumerate() {
            println!(
                "{name} mc channel {ch}: translucent / the route it draws = {ratio:.4} (recorded {:.4})",
                measured[ch]
            );
            assert!((ratio / measured[ch] - 1.0).abs() < 0.04, "{name} channel {ch}: {ratio} against {}", measured[ch]);
        }
    }
}

/// Light that leaves the object and enters it again (`--reentry`, passes::reentry) against the
/// path tracer's route of it (`reenters`, scripts/mitsuba_routes.py: the path left the object
/// and met it again): what `--reentry` adds to the image, over that route's mean, and the whole
/// against all the light. Measured (the tree, the default samples): the Skin1 bunny adds 36 / 20
/// / 13% (R / G / B) of its route and reads 0.977 0.876 0.849 of all the light (0.932 0.855
/// 0.839 without); Marble's adds 73 / 72 / 72% and reads 1.029 1.013 0.983 (0.929 0.913 0.884);
/// the back-lit torus (the tree: brute force draws no re-entry) adds 69 / 49 / 34% and reads
/// 1.039 1.007 1.004 (1.011 0.997 1.001). Before a thin sheet's lit face gave back less than the
/// half-space's (sources.glsl `begin_thickness`): 39 / 22 / 13% and 1.012 0.899 0.858 (Skin1),
/// 78 / 78 / 78% and 1.084 1.065 1.032 (Marble: its own route's excess, 1.148 1.130 1.086 then,
/// showed once the light that enters again was there), 69 / 49 / 34% and 1.044 1.007 1.004. With the air tested on the grid grown by a cell (which
/// calls the air within a cell of the surface inside) it was 24 / 16 / 11%, 52 / 53 / 54% and
/// 63 / 46 / 33%. Each held to its recorded value within 4% (the whole)
/// and within 0.05 of the route (the part added); what it leaves out: README, "Light that enters
/// again".
#[test]
fn light_that_enters_again_against_the_path_tracer() {
    let cases: [(&str, &str, [f64; 3], [f64; 3]); 3] = [
        ("skin1/bunny", "skin1/bunny-one-exit", [0.364, 0.201, 0.129], [0.977, 0.876, 0.849]),
        ("marble/bunny", "marble/bunny-one-exit", [0.726, 0.720, 0.719], [1.029, 1.013, 0.983]),
        ("skin1/torus-back", "skin1/torus-back-one-exit", [0.685, 0.494, 0.342], [1.039, 1.007, 1.004]),
    ];
    for (name, routes, added_expected, whole_expected) in cases {
        let all = numbers(&case(name)["path_traced_mean"]);
        let reenters = numbers(&case(routes)["routes"]["reenters"]["object_mean"]);
        let without = mc_against_its_reference(name, &[]);
        let with = mc_against_its_reference(name, &["--reentry"]);
        for ch in 0..3 {
            let added = (with[ch] - without[ch]) * all[ch] / reenters[ch];
            println!(
                "{name} channel {ch}: with the re-entry {:.4} of all the light (without {:.4}); it adds {added:.3} \
                 of the path tracer's light that entered again",
                with[ch], without[ch]
            );
            assert!((added - added_expected[ch]).abs() < 0.05, "{name} channel {ch}: adds {added}");
            assert!((with[ch] / whole_expected[ch] - 1.0).abs() < 0.04, "{name} channel {ch}: {}", with[ch]);
        }
    }
}

/// Single scattering (`--scattering single`) against the path tracer's light scattered once with
/// no internal reflection (`scripts/reference --routes`, route `one_exit_single_direct`): straight
/// in along the refracted view ray, once scattered, straight out toward the light, the one path a
/// single-scattering term draws. Of the light the path tracer scatters once along the models'
/// route, 12 / 10 / 8% (R / G / B) on the thin back-lit Skin1 lens and 12 / 10 / 7% on the
/// default Skin1 bunny reflected inside the object first (mostly light entering the lens's rim,
/// guided along the sheet by total internal reflection), which no model here carries. Against
/// all of it mc read 0.834 0.845 0.844 (lens) and 0.837 0.847 0.838 (bunny, `skin1/bunny-single`);
/// against the direct route 0.950 0.937 0.914 and 0.927 0.931 0.922, the lens's interior 0.97–1.03
/// and its outer 3 pixels 0.84–0.90 (README, "Routes no BSSRDF draws"). Each held to its
/// recorded ratio within 4% and to the path tracer within 10%; and the direct route must be a
/// part of the route's single scattering.
#[test]
fn single_scattering_against_its_direct_route() {
    let cases =
        [("skin1/lens-back-single-direct", "skin1/lens-back"), ("skin1/bunny-single-direct", "skin1/bunny-one-exit")];
    for (name, whole) in cases {
        let direct = numbers(&case(name)["path_traced_mean"]);
        let single = numbers(&case(whole)["routes"]["one_exit_single"]["object_mean"]);
        let measured = recorded_mc_ratio(name);
        for (ch, ratio) in mc_against_its_reference(name, &["--scattering", "single"]).into_iter().enumerate() {
            println!(
                "{name} mc channel {ch}: translucent / the direct single scattering = {ratio:.4} (recorded {:.4}; \
                 internally reflected: {:.1}% of the route's single scattering)",
                measured[ch],
                100.0 * (1.0 - direct[ch] / single[ch])
            );
            assert!(
                direct[ch] > 0.0 && direct[ch] < single[ch],
                "{name} channel {ch}: {} of {}",
                direct[ch],
                single[ch]
            );
            assert!((ratio - 1.0).abs() < 0.1, "{name} channel {ch}: {ratio} of the path tracer");
            assert!((ratio / measured[ch] - 1.0).abs() < 0.04, "{name} channel {ch}: {ratio} against {}", measured[ch]);
        }
    }
}

/// A JSON array of numbers.
fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(|x| x.as_f64().expect("a number")).collect()
}

/// The Monte Carlo table's ratio to the path tracer recorded for case `name`, per channel.
fn recorded_mc_ratio(name: &str) -> Vec<f64> {
    numbers(&case(name)["ratio_translucent_over_path_traced"]["mc"])
}

/// Case `name` rendered with `--model mc` and `extra` flags, against its path-traced image
/// (tests/data/mitsuba-images, named after the case): the ratio of means per channel over the
/// pixels both cover.
fn mc_against_its_reference(name: &str, extra: &[&str]) -> Vec<f64> {
    let options = case(name)["render_options"].as_str().expect("render options").to_string();
    let tag = name.replace('/', "-");
    // One file per case and flags (tests run side by side).
    let flags: String = extra.iter().map(|f| f.trim_start_matches('-')).collect::<Vec<_>>().join("-");
    let out = output_dir().join(format!("ground-truth-{tag}-mc{}{flags}.exr", if flags.is_empty() { "" } else { "-" }));
    let out_s = out.to_str().unwrap().to_string();
    let mut args: Vec<&str> = vec!["render", "--validation"];
    args.extend(options.split_whitespace());
    args.extend(["--model", "mc"]);
    args.extend(extra);
    args.extend(["--out", &out_s]);
    let run = translucent(&args);
    assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    let reference = repo_path(&format!("tests/data/mitsuba-images/{tag}.exr"));
    let (cmp, _) = translucent::compare::compare(&out, &reference, &Default::default()).expect("compare");
    cmp.channels.iter().map(|stats| stats.ratio.expect("a lit reference")).collect()
}

/// Renders case `name` with each of `models` and holds each to its recorded ratio, and the Monte
/// Carlo table to the path tracer within `mc_tolerance`.
fn against_the_path_tracer(name: &str, label: &str, models: &[&str], mc_tolerance: f64) {
    let c = case(name);
    let options = c["render_options"].as_str().expect("render options");
    let reference = numbers(&c["path_traced_mean"]);
    let noise = numbers(&c["relative_noise_of_mean"]);
    for &model in models {
        let measured = numbers(&c["ratio_translucent_over_path_traced"][model]);
        let mean = rendered_mean(options, model, label);
        for ch in 0..3 {
            let ratio = mean[ch] / reference[ch];
            println!("{name} {model} channel {ch}: translucent / path traced = {ratio:.4} (recorded {:.4}, path tracer's noise {:.2}%)", measured[ch], 100.0 * noise[ch]);
            // The recorded ratio, within the render's own variation (brute force is deterministic
            // for a given sample count; lavapipe vs a GPU differ in f32 rounding) of 0.5%.
            assert!(
                (ratio / measured[ch] - 1.0).abs() < 0.005,
                "{model} channel {ch}: {ratio} vs recorded {}",
                measured[ch]
            );
            if model == "mc" {
                assert!((ratio - 1.0).abs() < mc_tolerance, "mc channel {ch}: {ratio} of the path tracer");
            }
        }
    }
}

/// The mean per channel of `image`'s pixels whose centres lie at x within `xs` (mm) and |z| <
/// 45 mm on the textured slab's top face, seen from straight above (tests/data/textured-slab:
/// 64² pixels over 2·2000·tan 1.6° mm).
fn textured_region(image: &translucent::output::HdrImage, xs: (f64, f64)) -> [f64; 3] {
    let n = image.width as usize;
    let mm_per_pixel = 2.0 * 2000.0 * 1.6f64.to_radians().tan() / n as f64;
    let at = |i: usize| (i as f64 + 0.5 - n as f64 / 2.0) * mm_per_pixel;
    let (mut sum, mut count) = ([0.0; 3], 0.0);
    for y in (0..n).filter(|&y| at(y).abs() < 45.0) {
        for x in (0..n).filter(|&x| at(x) > xs.0 && at(x) < xs.1) {
            let p = image.pixels[y * n + x];
            (0..3).for_each(|c| sum[c] += p[c] as f64);
            count += 1.0;
        }
    }
    sum.map(|s| s / count)
}

/// A textured slab (tests/data/textured-slab: 100 × 20 × 100 mm, Skin1's mean free path, its
/// halves two colours through an OBJ's map_Kd) against the path tracer's heterogeneous medium of
/// the same colours (`export mitsuba`, recorded in reference.json there): each half's mean, 15–45
/// mm from the seam. Every model is held to its recorded ratio; the Monte Carlo table, the
/// half-space's exact transport, within 5% of the path tracer in green and blue (measured 0.956–
/// 1.015). Red is not compared with the path tracer: its heterogeneous medium's red (albedo up to
/// 0.99 under a majorant set by blue's σt) has fireflies of 100-500x the pixel's mean in 6 seeds
/// x 2048 spp, so its mean is not converged (the relative noise of the object's red mean 13.6%).
#[test]
fn textured_slab_against_the_path_tracer() {
    const MC_BOUND: f64 = 0.05;
    let text = std::fs::read_to_string(repo_path("tests/data/textured-slab/reference.json")).expect("reference data");
    let data: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    let options = data["render_options"]
        .as_str()
        .expect("render options")
        .replace("DATA", repo_path("tests/data/textured-slab").to_str().unwrap());
    let triple = |v: &serde_json::Value| -> [f64; 3] { std::array::from_fn(|c| v[c].as_f64().unwrap()) };
    for model in ["directional", "dipole", "pbd", "mc"] {
        let out = output_dir().join(format!("ground-truth-textured-slab-{model}.exr"));
        let mut args: Vec<&str> = vec!["render", "--validation"];
        args.extend(options.split_whitespace());
        args.extend(["--model", model, "--out", out.to_str().unwrap()]);
        let run = translucent(&args);
        assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
        let image = translucent::compare::read_exr(&out).expect("EXR");
        for (half, xs) in [("bright", (-45.0, -15.0)), ("dark", (15.0, 45.0))] {
            let mean = textured_region(&image, xs);
            let path_traced = triple(&data["path_traced"][half]);
            let recorded = triple(&data["ratios"][model][half]);
            for c in 0..3 {
                let ratio = mean[c] / path_traced[c];
                println!(
                    "textured slab {model} {half} channel {c}: {ratio:.4} of the path tracer (recorded {:.4})",
                    recorded[c]
                );
                assert!(
                    (ratio / recorded[c] - 1.0).abs() < 0.005,
                    "{model} {half} channel {c}: {ratio} vs recorded {}",
                    recorded[c]
                );
                if model == "mc" && c > 0 {
                    assert!((ratio - 1.0).abs() < MC_BOUND, "mc {half} channel {c}: {ratio} of the path tracer");
                }
            }
        }
    }
}

/// Single scattering through a flat slab lit from behind at an angle has a closed form: along
/// the refracted view ray (cos θv inside) light that entered the far face at cos θl, refracted to
/// cos θt, has come (T − s cos θv)/cos θt, so per pixel
///   L = Ft(θo)/η² · σs'/(4π) · E cos θl Ft(θl)/cos θt · ∫0^{T/cos θv} e^{−σt'(s + (T − s cos θv)/cos θt)} ds.
/// The 2 mm Skin1 slab lit at 60° must match it per channel within 0.5% over the image. (It was
/// 0.957 / 0.954 / 0.949 of it: the shadow pass's depth bias had put the lit face a band deeper,
/// and the ray's brightest stretch, next to that face, counted as outside.) Its path-traced
/// single scattering (`skin1/thin-slab-60-single`, 4 × 1024 spp) is 1.015 of the same sum.
#[test]
fn single_scattering_through_an_oblique_slab_is_its_closed_form() {
    let options = case("skin1/thin-slab-60")["render_options"].as_str().unwrap().to_string();
    let out = output_dir().join("ground-truth-thin-slab-60-single.exr");
    let out_s = out.to_str().unwrap().to_string();
    let mut args: Vec<&str> = vec!["render", "--validation"];
    args.extend(options.split_whitespace());
    args.extend(["--model", "mc", "--scattering", "single", "--out", &out_s]);
    let run = translucent(&args);
    assert_eq!(run.status.code(), Some(0), "{}", String::from_utf8_lossy(&run.stderr));
    let img = translucent::compare::read_exr(&out).expect("EXR");
    // Skin1 (Jensen et al. 2001), η 1.3; the slab 2 mm thick; light toward (0, −0.5, −0.866).
    let (eta, thickness, cos_l) = (1.3f64, 2.0f64, 0.5f64);
    let sigma_s = [0.74, 0.88, 1.01];
    let sigma_t = [0.74 + 0.032, 0.88 + 0.17, 1.01 + 0.48];
    let refracted = |c: f64| (1.0 - (1.0 - c * c) / (eta * eta)).sqrt();
    let ft = |c: f64| translucent::physics::fresnel::transmittance(eta, c);
    let cos_t = refracted(cos_l);
    let radiance = |cos_o: f64, ch: usize| {
        let cos_v = refracted(cos_o);
        let a = sigma_t[ch] * (1.0 - cos_v / cos_t);
        let length = thickness / cos_v;
        let integral = (-sigma_t[ch] * thickness / cos_t).exp() * (1.0 - (-a * length).exp()) / a;
        ft(cos_o) / (eta * eta) * sigma_s[ch] / (4.0 * std::f64::consts::PI) * cos_l * ft(cos_l) / cos_t * integral
    };
    // The camera of the case (--eye 0,2.232,1 --target 0,0.5,0 --fov 20, square): each pixel's
    // cosine to the slab's normal.
    let (w, h) = (img.width as usize, img.height as usize);
    let eye = glam::DVec3::new(0.0, 2.232, 1.0);
    let forward = (glam::DVec3::new(0.0, 0.5, 0.0) - eye).normalize();
    let right = forward.cross(glam::DVec3::Y).normalize();
    let up = right.cross(forward);
    let tan_half = 10f64.to_radians().tan();
    let (mut model, mut expected) = ([0.0f64; 3], [0.0f64; 3]);
    for y in 0..h {
        for x in 0..w {
            let px = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
            let py = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
            let d = (forward + px * tan_half * right + py * tan_half * up).normalize();
            let p = img.pixels[y * w + x];
            for ch in 0..3 {
                model[ch] += p[ch] as f64;
                expected[ch] += radiance(-d.y, ch);
            }
        }
    }
    for ch in 0..3 {
        let ratio = model[ch] / expected[ch];
        println!("channel {ch}: single scattering / closed form = {ratio:.4}");
        assert!((ratio - 1.0).abs() < 0.005, "channel {ch}: {ratio} of the closed form");
    }
}
