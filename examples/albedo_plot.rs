//! docs/images/albedo.png: the thick slab's total diffuse reflectance (light at normal
//! incidence, η = 1.3, the boundary's own reflection excluded) against the reduced albedo for
//! every model, with the exact radiative transfer answer (the half-space Monte Carlo of
//! src/physics/halfspace.rs, which reproduces Mitsuba 3's recorded Skin1 slab within 0.5%,
//! tests/halfspace.rs). Also prints the numbers as CSV.
//! `nice -n 19 cargo run --release --example albedo_plot` (about a minute).

use plotters::style::RGBColor;
use translucent::physics::beam_diffusion::{self, BeamMedium};
use translucent::physics::{halfspace, Diffusion, Medium};
use translucent::plot::{write_albedo_plot, AlbedoSeries};

fn main() {
    let eta = 1.3;
    // A medium of σ't = 1/mm with reduced albedo a: the half-space's answers depend on a and η only.
    let constants = |a: f64| Medium { sigma_a: 1.0 - a, sigma_s: a, g: 0.0, eta }.constants(Diffusion::Classical);
    let curve: Vec<f64> = (0..=70).map(|i| 0.3 + 0.699 * (i as f64 / 70.0).powf(0.5)).collect();
    let classical: Vec<(f64, f64)> = curve.iter().map(|&a| (a, halfspace::dipole_total(&constants(a), 1.0))).collect();
    let directional: Vec<(f64, f64)> = curve
        .iter()
        .map(|&a| (a, halfspace::model_total(halfspace::dirpole_plane(&constants(a), 1.0), eta, 1.0)))
        .collect();
    let times_alpha: Vec<(f64, f64)> = directional.iter().map(|&(a, r)| (a, a * r)).collect();
    let integrated: Vec<(f64, f64)> = curve
        .iter()
        .map(|&a| {
            let c = constants(a);
            (a, halfspace::exitance_total(&c, halfspace::ray_source_plane(&c, 1.0), 1.0))
        })
        .collect();
    // Photon beam diffusion: its f64 profile's plane integral, multiple and single scattering.
    let pbd_total = |a: f64| {
        let b = BeamMedium::new(&Medium { sigma_a: 1.0 - a, sigma_s: a, g: 0.0, eta });
        let plane = halfspace::plane_integral(|x| beam_diffusion::sd(&b, x.length()), 1e-7, 60.0 / b.sigma_tr, 1);
        halfspace::model_total(plane, eta, 1.0)
    };
    let pbd: Vec<(f64, f64)> = curve.iter().map(|&a| (a, pbd_total(a))).collect();
    let albedos = [0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 0.97, 0.98, 0.99, 0.995, 0.999];
    let traced: Vec<(f64, f64)> = albedos
        .iter()
        .enumerate()
        .map(|(i, &a)| (a, halfspace::rte_reflectance(a, eta, 1.0, 200_000, 100 + i as u64).total))
        .collect();
    println!("albedo,path_traced,classical,directional,directional_times_alpha,ray_source_integrated,beam_diffusion");
    for &(a, pt) in &traced {
        let c = constants(a);
        let dir = halfspace::model_total(halfspace::dirpole_plane(&c, 1.0), eta, 1.0);
        println!(
            "{a},{pt:.4},{:.4},{dir:.4},{:.4},{:.4},{:.4}",
            halfspace::dipole_total(&c, 1.0),
            a * dir,
            halfspace::exitance_total(&c, halfspace::ray_source_plane(&c, 1.0), 1.0),
            pbd_total(a)
        );
    }
    let series = [
        AlbedoSeries {
            label: "directional dipole (published)".into(),
            colour: RGBColor(200, 30, 30),
            points_only: false,
            points: directional,
        },
        AlbedoSeries {
            label: "directional dipole × α' (source strength)".into(),
            colour: RGBColor(230, 140, 40),
            points_only: false,
            points: times_alpha,
        },
        AlbedoSeries {
            label: "its ray source integrated along the beam (not a model here)".into(),
            colour: RGBColor(150, 60, 180),
            points_only: false,
            points: integrated,
        },
        AlbedoSeries {
            label: "classical dipole".into(),
            colour: RGBColor(40, 60, 210),
            points_only: false,
            points: classical,
        },
        AlbedoSeries {
            label: "photon beam diffusion (multiple + single scattering)".into(),
            colour: RGBColor(30, 150, 70),
            points_only: false,
            points: pbd,
        },
        AlbedoSeries {
            label: "path tracer (exact RTE, half-space Monte Carlo)".into(),
            colour: RGBColor(0, 0, 0),
            points_only: true,
            points: traced,
        },
    ];
    let out = std::path::Path::new("docs/images/albedo.png");
    write_albedo_plot("Thick slab, light at normal incidence, η = 1.3: total diffuse reflectance", &series, out)
        .expect("plot");
    eprintln!("wrote {}", out.display());
}
