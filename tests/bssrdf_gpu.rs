//! The GLSL BSSRDF (f32, GPU) against the Rust one (f64), under validation.

mod common;

use common::{assert_clean, validated_context};
use translucent::passes::bssrdf_eval::BssrdfEvalPass;
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
            Model::Dipole => false,
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
