//! The GLSL BSSRDF (f32, GPU) against the Rust one (f64), under validation.

mod common;

use common::{assert_clean, validated_context};
use translucent::gpu::SdTable;
use translucent::passes::bssrdf_eval::BssrdfEvalPass;
use translucent::physics::beam_diffusion::BeamMedium;
use translucent::physics::{dirpole, Diffusion, Model, Query};

struct Report {
    worst: f64,
    worst_cancelling: f64,
    checked: usize,
}

/// Compares GPU and CPU values. Rows where the real and virtual terms cancel by more than 10× lose
/// f32 precision in proportion: they are reported, not bounded.
fn compare(queries: &[Query], gpu: &[f32], model: Model) -> Report {
    let mut r = Report { worst: 0.0, worst_cancelling: 0.0, checked: 0 };
    for (i, (q, &g)) in queries.iter().zip(gpu).enumerate() {
        assert!(g.is_finite(), "query {i}: GPU value {g} ({q:?})");
        let cpu = q.sd(model, Diffusion::Classical);
        if cpu <= 1e-30 {
            continue;
        }
        let cancelling = match model {
            Model::Directional => {
                let c = q.medium.constants(Diffusion::Classical);
                let (real, virt) = dirpole::terms(&c, q.xi, q.ni, q.wi, q.xo, q.no);
                real.abs().max(virt.abs()) > 10.0 * (real - virt).abs()
            }
            Model::Dipole | Model::Pbd | Model::Mc => false,
        };
        let rel = (g as f64 - cpu).abs() / cpu;
        if cancelling {
            r.worst_cancelling = r.worst_cancelling.max(rel);
        } else {
            assert!(rel <= 1e-3, "query {i}: GPU {g} vs CPU {cpu} (relative error {rel:e}) {q:?}");
            r.worst = r.worst.max(rel);
            r.checked += 1;
        }
    }
    r
}

#[test]
fn gpu_matches_cpu_on_random_queries() {
    let (ctx, counts) = validated_context();
    let pass = BssrdfEvalPass::new(&ctx).unwrap();
    let queries = common::random_queries(30_000, 7);
    for model in [Model::Directional, Model::Dipole] {
        let gpu = pass.evaluate(&ctx, &queries, model, Diffusion::Classical).unwrap();
        assert_eq!(gpu.len(), queries.len());
        let r = compare(&queries, &gpu, model);
        println!(
            "{model:?}: worst relative error {:.2e} over {} rows; {:.2e} where the terms cancel >10x",
            r.worst, r.checked, r.worst_cancelling
        );
        // Many random rows are clamped to 0 or cancel; at least 10,000 must be checked.
        assert!(r.checked >= 10_000, "only {} rows checked", r.checked);
    }
    drop(pass);
    drop(ctx);
    assert_clean(&counts);
}

#[test]
fn gpu_matches_the_reference_file() {
    let text = std::fs::read_to_string(common::repo_path("tests/data/dirpole-check.csv")).unwrap();
    let queries = translucent::bssrdf_csv::parse(text.as_bytes()).unwrap();
    let (ctx, counts) = validated_context();
    let pass = BssrdfEvalPass::new(&ctx).unwrap();
    let gpu = pass.evaluate(&ctx, &queries, Model::Directional, Diffusion::Classical).unwrap();
    let r = compare(&queries, &gpu, Model::Directional);
    println!(
        "reference file: worst {:.2e} over {} rows; {:.2e} where cancelling",
        r.worst, r.checked, r.worst_cancelling
    );
    drop(pass);
    drop(ctx);
    assert_clean(&counts);
}

/// The table models (photon beam diffusion, the Monte Carlo table) on the GPU read a table per
/// medium, as the shade pass does: random
/// geometry over eight preset media (rows of one medium share a table). Against the same table
/// read in f64 (`SdTable::lookup`): within 1e-4 relative plus 1e-3 of the interval's step (f32's
/// rounding of where in the interval r falls); against the f64 profile itself within 2e-3 from
/// the table's 16th entry on, down to 1e-6 of its peak (its interpolation, tests in
/// src/gpu/sd_table.rs).
#[test]
fn gpu_table_models_match_cpu() {
    use translucent::gpu::sd_table::TABLE_SIZE;
    use translucent::materials::Material;
    let media: Vec<_> = ["skin1", "marble", "ketchup", "potato"]
        .iter()
        .flat_map(|name| {
            let m = Material::find(name).unwrap();
            [0, 2].map(|c| m.channel(c))
        })
        .collect();
    let mut queries = common::random_queries(4_000, 11);
    for (i, q) in queries.iter_mut().enumerate() {
        q.medium = media[i % media.len()];
    }
    let (ctx, counts) = validated_context();
    let pass = BssrdfEvalPass::new(&ctx).unwrap();
    // Both table models: photon beam diffusion and the Monte Carlo table.
    for model in [Model::Pbd, Model::Mc] {
        let gpu = pass.evaluate(&ctx, &queries, model, Diffusion::Classical).unwrap();
        let table_of = |m: &translucent::physics::Medium| match model {
            Model::Mc => SdTable::monte_carlo_one(m),
            _ => SdTable::beam_diffusion_one(&BeamMedium::new(m)),
        };
        let tables: Vec<SdTable> = media.iter().map(table_of).collect();
        let (mut worst_table, mut worst_profile, mut checked) = (0.0f64, 0.0f64, 0);
        for (i, (q, &g)) in queries.iter().zip(&gpu).enumerate() {
            let table = &tables[i % media.len()];
            let r = (q.xo - q.xi).length();
            let cpu_table = table.lookup(r)[0];
            let x = r / (r + table.reach) * (TABLE_SIZE - 1) as f64;
            let k = (x.floor() as usize).min(TABLE_SIZE - 2);
            let step = (table.lookup_entry(k) - table.lookup_entry(k + 1)).abs();
            let err = (g as f64 - cpu_table).abs();
            assert!(err <= 1e-4 * cpu_table + 1e-3 * step + 1e-30, "row {i}: GPU {g} vs table {cpu_table} (r {r})");
            worst_table = worst_table.max(err / cpu_table.max(1e-30));
            if x >= 16.0 {
                let profile = q.sd(model, Diffusion::Classical);
                // Where f16 keeps its precision (down to 2e-9 of the peak; 1e-6 here).
                if profile > 1e-6 * table.scale[0] as f64 * 32768.0 {
                    let rel = (g as f64 / profile - 1.0).abs();
                    assert!(rel <= 2e-3, "row {i}: GPU {g} vs profile {profile} (r {r})");
                    worst_profile = worst_profile.max(rel);
                    checked += 1;
                }
            }
        }
        println!("{}: worst relative to the f64 table {worst_table:.2e}; to the profile {worst_profile:.2e} over {checked} rows", model.name());
        assert!(checked >= 2_000, "only {checked} rows checked");
    }
    drop(pass);
    drop(ctx);
    assert_clean(&counts);
}

/// The Monte Carlo table's curvature terms as the shade pass reads them (bssrdf.glsl
/// `curvature_rows` + `curvature_ratio`, `curvature_exit`, `exit_terms`; f16 texels, f32
/// arithmetic) against their Rust mirrors (`CurvatureRatios::lookup`, `lookup_exit`,
/// `exit_tilt_at`, `harmonics_at`, `radial_at`; the same f16 values in f64), for Skin1: random chords out to 30 L, curvatures
/// of both signs from L/64 to 16 L (past the last node too) and flat, exit cosines and far
/// shares. Within 1e-5 relative (the tilt, the harmonics and the radial change, which cross 0, 1e-5 absolute and relative; measured
/// 8e-7 for the ratio, 2e-7 for the exit's, the tilt exact), except where the nearest entry's
/// index lies within 1e-4 of a boundary (f32 and f64 may round apart). It found the Rust mirror
/// of f16 dropping the sign (the tilt's g is negative near the entry).
#[test]
fn gpu_curvature_terms_match_cpu() {
    use translucent::gpu::sd_table::{
        AngularFactors, CurvatureRatios, SlabTransmission, CURVATURE_TABLE_ENTRIES, EXIT_TILT_ENTRIES, TABLE_SIZE,
    };
    use translucent::materials::Material;
    use translucent::physics::curvature_profile;
    use translucent::physics::mc_profile::McProfile;
    use translucent::vk::{self, Bind, Buffer, BufferUsageFlags, MemoryLocation, Pipeline};

    let m = Material::find("skin1").unwrap();
    let media = [0, 1, 2].map(|c| m.channel(c));
    let ratios = CurvatureRatios::monte_carlo(&curvature_profile::of_channels(&media), &McProfile::of_channels(&media));
    let unit = ratios.unit_mm as f64;
    assert!(unit > 0.0);
    // The object's table as the shade pass binds it, zeros before the curvature rows.
    let mut texels = vec![[0u32; 4]; TABLE_SIZE + AngularFactors::TEXELS + SlabTransmission::TEXELS];
    texels.extend(ratios.texels());

    let mut uniform = xorshift(0x9e37_79b9_7f4a_7c15);
    let n = 4096;
    let queries: Vec<[[f32; 4]; 2]> = (0..n)
        .map(|i| {
            let r = 30.0 * unit * uniform().powi(2);
            let magnitude = 2f64.powf(-6.0 + 10.0 * uniform()) / unit;
            let kappa = match i % 8 {
                0 => 0.0,
                k if k % 2 == 1 => -magnitude,
                _ => magnitude,
            };
            // sin²θi per channel: normal, each row's own, between rows, past the last.
            let sin2 = |u: f64| match i % 5 {
                0 => 0.0,
                1 => [0.0, 0.64, 0.96][(3.0 * u) as usize % 3],
                _ => u,
            };
            [[r as f32, kappa as f32, uniform() as f32, uniform() as f32], [0, 1, 2, 3].map(|_| sin2(uniform()) as f32)]
        })
        .collect();

    let (ctx, counts) = validated_context();
    const TERMS: usize = 7;
    let results: Vec<[f32; 4]> = {
        let pipeline = Pipeline::compute(&ctx, "test/curvature_terms.comp").unwrap();
        let table = vk::upload_buffer(&ctx, "table", &texels, BufferUsageFlags::UNIFORM_TEXEL_BUFFER).unwrap();
        let input = vk::upload_buffer(&ctx, "queries", &queries, BufferUsageFlags::STORAGE_BUFFER).unwrap();
        let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC;
        let output = Buffer::new(&ctx, "results", (16 * TERMS * n) as u64, usage, MemoryLocation::GpuOnly).unwrap();
        let binds = [Bind::Read(&input), Bind::Write(&output), Bind::Texels(&table)];
        let count = n as u32;
        ctx.submit(None, |rec| rec.dispatch(&pipeline, &binds, bytemuck::bytes_of(&count), [count.div_ceil(64), 1, 1]))
            .unwrap();
        vk::download_buffer(&ctx, &output, TERMS * n).unwrap()
    };
    drop(ctx);
    assert_clean(&counts);

    // How near an entry boundary the nearest-entry read falls (f32 against f64).
    let near_boundary = |x: f64| x > 0.5 && (x - x.round()).abs() < 1e-4;
    let (mut checked, mut worst) = (0, [0.0f64; TERMS]);
    for (i, q) in queries.iter().enumerate() {
        let [r, kappa, cos_o, far] = q[0].map(|v| v as f64);
        let sin2_i = [0, 1, 2].map(|c| q[1][c] as f64);
        let held = kappa.abs().min(curvature_profile::last_curvature(unit));
        let s = r * held;
        let tilt_u = r / (r + unit) * EXIT_TILT_ENTRIES as f64;
        // The rows of incidence are picked by the channels' mean sin²θi (f32 against f64 at 0.64).
        let mean_sin2 = sin2_i.iter().sum::<f64>() / 3.0;
        if near_boundary(s / (s + 1.0) * CURVATURE_TABLE_ENTRIES as f64)
            || near_boundary(tilt_u)
            || (mean_sin2 - curvature_profile::INCIDENCE_SIN2[1]).abs() < 1e-5
        {
            continue;
        }
        let [c, g] = ratios.exit_tilt_at(r);
        let [b2, b3] = ratios.harmonics_at(r);
        let cpu = [
            ratios.lookup(r, kappa, sin2_i),
            ratios.lookup_exit(cos_o, kappa, far, q[1][3] as f64),
            c,
            g,
            b2,
            b3,
            ratios.radial_at(r),
        ];
        for (k, expected) in cpu.iter().enumerate() {
            for ch in 0..3 {
                let gpu = results[TERMS * i + k][ch] as f64;
                let e = expected[ch];
                // Relative for the ratios, absolute for the tilt.
                let err = if k >= 2 { (gpu - e).abs() } else { (gpu - e).abs() / e.abs().max(1e-6) };
                let bound = if k >= 2 { 1e-5 + 1e-5 * e.abs() } else { 1e-5 };
                assert!(
                    err <= bound,
                    "query {i} (r {r}, κ {kappa}, cos_o {cos_o}, far {far}) term {k} channel {ch}: GPU {gpu} against {e}"
                );
                worst[k] = worst[k].max(err);
            }
        }
        checked += 1;
    }
    println!(
        "{checked} queries; worst ratio {:.1e}, exit {:.1e}, c {:.1e}, g {:.1e}, b₂ {:.1e}, b₃ {:.1e}, a {:.1e}",
        worst[0], worst[1], worst[2], worst[3], worst[4], worst[5], worst[6]
    );
    assert!(checked > n * 9 / 10, "only {checked} of {n} queries checked");
}

/// The shade pass's test of whether a pair is joined inside its object (bssrdf.glsl
/// `joined_inside`) against its Rust mirror (mesh::occupancy::joined_inside), on pairs of points
/// of the torus's surface (and the default bunny's where glmark2-data is installed): the same
/// answer for all but a few pairs whose arc passes within f32 rounding of a cell's face.
#[test]
fn joined_inside_matches_its_mirror() {
    use translucent::mesh::occupancy::{joined_inside, Occupancy};
    use translucent::mesh::Mesh;
    let (ctx, counts) = validated_context();
    let pass = BssrdfEvalPass::new(&ctx).unwrap();
    let mut meshes = vec![("torus", Mesh::torus(1.0, 0.3, 64, 32))];
    let bunny = std::path::Path::new("/usr/share/glmark2/models/bunny.obj");
    if bunny.exists() {
        meshes.push(("bunny", Mesh::load(bunny).unwrap()));
    }
    for (name, mesh) in meshes {
        let grid = Occupancy::of(&mesh).expect("a closed mesh");
        // Points on the surface, with their interpolated normals (a fixed LCG).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let triangles = mesh.indices.len() / 3;
        let mut point = || {
            let t = ((next() * triangles as f32) as usize).min(triangles - 1);
            let (mut u, mut v) = (next(), next());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let [a, b, c] = [0, 1, 2].map(|k| mesh.indices[3 * t + k] as usize);
            let p = mesh.positions[a] * (1.0 - u - v) + mesh.positions[b] * u + mesh.positions[c] * v;
            let n = (mesh.normals[a] * (1.0 - u - v) + mesh.normals[b] * u + mesh.normals[c] * v).normalize();
            (p, n)
        };
        let pairs: Vec<[glam::Vec3; 4]> = (0..40_000)
            .map(|_| {
                let ((xi, ni), (xo, no)) = (point(), point());
                [xi, ni, xo, no]
            })
            .collect();
        let gpu = pass.joined_inside(&ctx, &grid, &pairs).unwrap();
        let cpu: Vec<bool> = pairs.iter().map(|&[xi, ni, xo, no]| joined_inside(Some(&grid), xi, ni, xo, no)).collect();
        let apart = gpu.iter().zip(&cpu).filter(|(g, c)| g != c).count();
        let through_air = cpu.iter().filter(|&&c| !c).count();
        println!("{name}: {through_air} of {} pairs through the air; GPU and CPU differ on {apart}", pairs.len());
        assert!(through_air > 1_000, "{name}: too few pairs through the air to test ({through_air})");
        assert!(apart * 1000 <= pairs.len(), "{name}: GPU and CPU differ on {apart} pairs");
    }
    drop(pass);
    drop(ctx);
    assert_clean(&counts);
}

/// The slab's lit face over the half-space's as the shade pass reads it (bssrdf.glsl
/// `slab_reflected_ratio`) against its Rust mirror (`SlabChannel::reflected_ratio`), for Marble:
/// random ρ out to 40 L and thicknesses from L/32 (below the first node) to past the last (where
/// no sheet is read, ratio 1). Within 1e-3 (the table holds f16: 2^-11 of values up to 1).
#[test]
fn gpu_slab_reflected_ratio_matches_cpu() {
    use translucent::gpu::sd_table::{AngularFactors, SlabTransmission, TABLE_SIZE};
    use translucent::materials::Material;
    use translucent::physics::slab_profile;
    use translucent::vk::{self, Bind, Buffer, BufferUsageFlags, MemoryLocation, Pipeline};

    let m = Material::find("marble").unwrap();
    let channels = slab_profile::of_channels(&[0, 1, 2].map(|c| m.channel(c)));
    let slab = SlabTransmission::monte_carlo(&channels);
    let unit = channels[0].unit_mm;
    let mut texels = vec![[0u32; 4]; TABLE_SIZE + AngularFactors::TEXELS];
    texels.extend(slab.texels());
    let mut uniform = xorshift(0x5eed_1234_abcd_0001);
    let n = 4096;
    let queries: Vec<[f32; 2]> = (0..n)
        .map(|_| [(40.0 * unit * uniform().powi(2)) as f32, (unit * 2f64.powf(-5.0 + 12.5 * uniform())) as f32])
        .collect();
    let (ctx, counts) = validated_context();
    let results: Vec<[f32; 4]> = {
        let pipeline = Pipeline::compute(&ctx, "test/slab_reflected.comp").unwrap();
        let table = vk::upload_buffer(&ctx, "table", &texels, BufferUsageFlags::UNIFORM_TEXEL_BUFFER).unwrap();
        let input = vk::upload_buffer(&ctx, "queries", &queries, BufferUsageFlags::STORAGE_BUFFER).unwrap();
        let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC;
        let output = Buffer::new(&ctx, "results", (16 * n) as u64, usage, MemoryLocation::GpuOnly).unwrap();
        let binds = [Bind::Read(&input), Bind::Write(&output), Bind::Texels(&table)];
        let count = n as u32;
        ctx.submit(None, |rec| rec.dispatch(&pipeline, &binds, bytemuck::bytes_of(&count), [count.div_ceil(64), 1, 1]))
            .unwrap();
        vk::download_buffer(&ctx, &output, n).unwrap()
    };
    drop(ctx);
    assert_clean(&counts);
    let (mut worst, mut sheets) = (0.0f64, 0);
    for (q, got) in queries.iter().zip(&results) {
        let (rho, t) = (q[0] as f64, q[1] as f64);
        sheets += (got[3] == 1.0) as usize;
        for c in 0..3 {
            let expected = channels[c].reflected_ratio(rho, t);
            let err = (got[c] as f64 - expected).abs();
            assert!(err < 1e-3, "ρ {rho} mm, t {t} mm, channel {c}: GPU {} against {expected}", got[c]);
            worst = worst.max(err);
        }
    }
    println!("{n} queries, {sheets} read as a sheet; worst difference {worst:.1e}");
    assert!(sheets > n / 2 && sheets < n, "{sheets} of {n} read as a sheet");
}

/// A small deterministic generator (xorshift) of uniform numbers in [0, 1).
fn xorshift(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}
