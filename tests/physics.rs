//! The f64 physics against closed forms and the authors' reference values.

use glam::DVec3;
use translucent::physics::{dipole, dirpole, fresnel, Diffusion, Medium};

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

#[test]
fn fresnel_r_plus_t_is_one_and_normal_incidence_closed_form() {
    for eta in [0.6, 1.0, 1.3, 1.5, 2.0] {
        for i in 0..=90 {
            let c = (i as f64).to_radians().cos();
            let (r, t) = (fresnel::reflectance(eta, c), fresnel::transmittance(eta, c));
            assert!((r + t - 1.0).abs() < 1e-15 && (0.0..=1.0).contains(&r), "eta {eta} angle {i}");
        }
    }
    let expected = 1.0 - (0.3f64 / 2.3).powi(2);
    assert!((fresnel::transmittance(1.3, 1.0) - expected).abs() < 1e-15);
    // Grazing incidence reflects everything.
    assert!((fresnel::reflectance(1.3, 0.0) - 1.0).abs() < 1e-12);
}

#[test]
fn total_internal_reflection_beyond_the_critical_angle() {
    let eta: f64 = 1.0 / 1.5; // leaving glass
    let critical = eta.asin();
    assert_eq!(fresnel::reflectance(eta, (critical + 1e-3).cos()), 1.0);
    assert!(fresnel::reflectance(eta, (critical - 1e-2).cos()) < 1.0);
}

#[test]
fn fresnel_moments_at_eta_1_3() {
    let eta = 1.3;
    let a = (1.0 - fresnel::c_e(eta)) / (2.0 * fresnel::c_phi(eta));
    let n = 1.0 / (4.0 * fresnel::c_phi(1.0 / eta));
    for (name, got, want) in [
        ("Cphi", fresnel::c_phi(eta), 0.138676),
        ("CE", fresnel::c_e(eta), 0.351276),
        ("A", a, 2.338986),
        ("N", n, 1.065094),
    ] {
        assert!((got - want).abs() < 5e-7, "{name}: {got} vs {want}");
    }
}

struct RefRow {
    medium: Medium,
    xi: DVec3,
    ni: DVec3,
    wi: DVec3,
    xo: DVec3,
    no: DVec3,
    sd: f64,
    sd_dipole: f64,
}

fn reference_rows() -> Vec<RefRow> {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/dirpole-check.csv")).unwrap();
    let mut lines = text.lines();
    assert!(lines.next().unwrap().starts_with("sigma_a,sigma_s,g,eta,xi_x"));
    lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|s| s.parse().unwrap()).collect();
            let v3 = |i: usize| DVec3::new(v[i], v[i + 1], v[i + 2]);
            RefRow {
                medium: Medium { sigma_a: v[0], sigma_s: v[1], g: v[2], eta: v[3] },
                xi: v3(4),
                ni: v3(7),
                wi: v3(10),
                xo: v3(13),
                no: v3(16),
                sd: v[19],
                sd_dipole: v[20],
            }
        })
        .collect()
}

#[test]
fn directional_dipole_matches_the_authors_program() {
    let rows = reference_rows();
    assert_eq!(rows.len(), 400);
    let (mut worst, mut worst_row, mut checked) = (0.0f64, 0, 0);
    for (i, row) in rows.iter().enumerate() {
        let c = row.medium.constants(Diffusion::Classical);
        let got = dirpole::sd(&c, row.xi, row.ni, row.wi, row.xo, row.no);
        if row.sd > 1e-12 {
            let rel = (got - row.sd).abs() / row.sd;
            if rel > worst {
                (worst, worst_row) = (rel, i + 2);
            }
            checked += 1;
        } else {
            assert!(got <= 1e-12, "row {}: reference {} but got {got}", i + 2, row.sd);
        }
    }
    println!("directional dipole: worst relative error {worst:.3e} (line {worst_row}) over {checked} rows");
    assert!(worst <= 1e-6, "worst relative error {worst:e} at line {worst_row}");
}

#[test]
fn classical_dipole_matches_the_reference_column() {
    let mut worst = 0.0f64;
    for (i, row) in reference_rows().iter().enumerate() {
        let c = row.medium.constants(Diffusion::Classical);
        let got = dipole::sd(&c, (row.xo - row.xi).length());
        if row.sd_dipole > 1e-12 {
            let rel = (got - row.sd_dipole).abs() / row.sd_dipole;
            assert!(rel <= 1e-6, "line {}: {got} vs {}", i + 2, row.sd_dipole);
            worst = worst.max(rel);
        }
    }
    println!("classical dipole: worst relative error {worst:.3e}");
}

/// 2π∫Rd(r) r dr with r = e^u and composite Simpson in u: the integrand spans many decades.
fn plane_integral(f: impl Fn(f64) -> f64, r_min: f64, r_max: f64) -> f64 {
    let (a, b) = (r_min.ln(), r_max.ln());
    let n = 20_000;
    let h = (b - a) / n as f64;
    let g = |u: f64| {
        let r = u.exp();
        f(r) * r * r
    };
    let mut sum = g(a) + g(b);
    for k in 1..n {
        sum += g(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    2.0 * std::f64::consts::PI * sum * h / 3.0
}

#[test]
fn classical_dipole_integral_equals_the_closed_form_for_every_preset() {
    use translucent::materials::Material;
    let mut checked = 0;
    for m in Material::presets() {
        for ch in 0..3 {
            let medium = m.channel(ch);
            let c = medium.constants(Diffusion::Classical);
            if !c.transports {
                continue;
            }
            // Far enough that the exponential tail is gone (or 1e5 mean free paths without absorption).
            let reach = if c.dipole_sigma_tr > 0.0 { 60.0 / c.dipole_sigma_tr } else { 1e7 * c.zr };
            let numeric = plane_integral(|r| dipole::rd(&c, r), c.zr * 1e-6, reach.max(c.zv * 100.0));
            let closed = dipole::total_rd(c.alpha_reduced, c.a_dipole);
            // Spectralon (σa = 0) has a 1/r³ tail: the integral beyond `reach` is ≈ α'zv/(2·reach)·…
            let tol = if c.sigma_a == 0.0 { 2e-4 } else { 1e-4 };
            assert!(close(numeric, closed, tol), "{} channel {ch}: numeric {numeric} vs closed form {closed}", m.name);
            checked += 1;
        }
    }
    assert!(checked > 100);
}

#[test]
fn jensen_table_rd_is_reproduced() {
    use translucent::materials::Material;
    let table = [
        ("apple", [0.846, 0.841, 0.528]),
        ("chicken1", [0.314, 0.156, 0.126]),
        ("chicken2", [0.321, 0.160, 0.108]),
        ("cream", [0.976, 0.900, 0.725]),
        ("ketchup", [0.164, 0.006, 0.002]),
        ("marble", [0.830, 0.791, 0.753]),
        ("potato", [0.764, 0.612, 0.213]),
        ("skimmilk", [0.815, 0.813, 0.682]),
        ("skin1", [0.436, 0.227, 0.131]),
        ("skin2", [0.623, 0.433, 0.343]),
        ("spectralon", [1.000, 1.000, 1.000]),
        ("wholemilk", [0.908, 0.881, 0.759]),
    ];
    for (name, rd) in table {
        let m = Material::find(name).unwrap();
        for (ch, &expected) in rd.iter().enumerate() {
            let c = m.channel(ch).constants(Diffusion::Classical);
            let got = dipole::total_rd(c.alpha_reduced, c.a_dipole);
            // "To 3 decimals": within half a unit of the third decimal. The table was computed with
            // the 4-digit Fdr fit (−1.4399, 0.7099, 0.6681), which moves Rd by at most 3e-5 from
            // the paper's coefficients used here (they match the authors' program to 1e-15); that
            // puts potato green at 0.6125005 vs 0.612 in the table, on the rounding boundary.
            assert!((got - expected).abs() <= 5e-4 + 3e-5, "{name} channel {ch}: {got:.5} vs {expected}");
        }
    }
}

/// π∫Sd dA over a plane at normal incidence (coplanar; the integrand is radially symmetric there).
fn dirpole_plane_albedo(medium: Medium) -> f64 {
    let c = medium.constants(Diffusion::Classical);
    let n = DVec3::Z;
    std::f64::consts::PI
        * plane_integral(|r| dirpole::sd(&c, DVec3::ZERO, n, n, DVec3::new(r, 0.0, 0.0), n), 1e-7, 60.0 / c.sigma_tr)
}

#[test]
fn directional_dipole_plane_integral_exceeds_one_for_marble_red() {
    // The published model is not energy-conserving at high albedo. The equations file quotes
    // "about 1.18" for marble red: that is the value at η = 1.3 (the authors' program's default);
    // the marble preset uses η = 1.5 (which reproduces Jensen's Rd column) and gives 1.12.
    let marble = translucent::materials::Material::find("marble").unwrap().channel(0);
    let at_1_3 = dirpole_plane_albedo(Medium { eta: 1.3, ..marble });
    let preset = dirpole_plane_albedo(marble);
    println!("marble red: pi * plane integral of Sd = {at_1_3:.4} at eta 1.3, {preset:.4} at eta 1.5");
    assert!((at_1_3 - 1.18).abs() < 0.005, "{at_1_3}");
    assert!(preset > 1.0 && preset < at_1_3, "{preset}");
}

#[test]
fn directional_dipole_keeps_light_at_low_albedo() {
    // The published form has no α' factor: at low albedo it still returns light near the entry
    // point, far more than the classical dipole's Rd (which carries α'). Ketchup's green and blue
    // (α' = 0.067, 0.020) show it as a cyan glow where thin parts are lit from behind. Recorded
    // here, not "fixed" (see shared/reference/bssrdf.md).
    use translucent::physics::dipole;
    let ketchup = translucent::materials::Material::find("ketchup").unwrap();
    for ch in 0..3 {
        let m = ketchup.channel(ch);
        let c = m.constants(Diffusion::Classical);
        let directional = dirpole_plane_albedo(m);
        let classical = dipole::total_rd(c.alpha_reduced, c.a_dipole);
        println!(
            "ketchup channel {ch}: α' {:.3}, π∫Sd dA directional {directional:.4}, classical Rd {classical:.4}",
            c.alpha_reduced
        );
        if ch > 0 {
            assert!(directional > 3.0 * classical, "channel {ch}: {directional} vs {classical}");
        }
    }
}

#[test]
fn edge_cases_stay_finite() {
    let n = DVec3::Z;
    let media = [
        Medium { sigma_a: 0.0, sigma_s: 11.6, g: 0.0, eta: 1.3 }, // spectralon: σtr = 0
        Medium { sigma_a: 0.7, sigma_s: 0.0, g: 0.0, eta: 1.3 },  // pure absorber
        Medium { sigma_a: 0.01, sigma_s: 1.0, g: 0.9, eta: 1.0 }, // index matched
        Medium { sigma_a: 0.01, sigma_s: 1.0, g: -0.3, eta: 1.6 }, // backward scattering
    ];
    let grazing = DVec3::new(1.0, 0.0, 1e-9).normalize();
    let geometries = [
        (DVec3::ZERO, n, n, DVec3::ZERO, n),                      // r = 0
        (DVec3::ZERO, n, grazing, DVec3::new(1e-9, 0.0, 0.0), n), // grazing, r → 0
        (DVec3::ZERO, n, n, DVec3::new(0.0, 0.0, 2.0), -n),       // x parallel to ni (back-lit)
        (DVec3::ZERO, n, -grazing, DVec3::new(0.5, 0.0, 0.0), n), // light from below the horizon
        (DVec3::ZERO, n, n, DVec3::new(1e3, 0.0, 0.0), n),        // far
    ];
    for m in media {
        for diffusion in [Diffusion::Classical, Diffusion::Alternative] {
            let c = m.constants(diffusion);
            for (xi, ni, wi, xo, no) in geometries {
                let v = dirpole::sd(&c, xi, ni, wi, xo, no);
                assert!(v.is_finite() && v >= 0.0, "{m:?} {diffusion:?}: {v}");
                assert!(dipole::sd(&c, (xo - xi).length()).is_finite());
            }
        }
    }
    let absorber = media[1].constants(Diffusion::Classical);
    assert!(!absorber.transports);
    assert_eq!(dirpole::sd(&absorber, DVec3::ZERO, n, n, DVec3::X, n), 0.0);
}

mod microfacet {
    use glam::DVec3;
    use translucent::physics::{fresnel, microfacet};

    #[test]
    fn normal_incidence_equals_the_closed_form() {
        // h = n: D = 1/(πα²), G2 = 1, so f = F(η, 1)/(4πα²).
        for (roughness, eta) in [(0.35, 1.3), (0.1, 1.5), (0.8, 1.33)] {
            let alpha2 = f64::powi(roughness, 4);
            let expected = fresnel::reflectance(eta, 1.0) / (4.0 * std::f64::consts::PI * alpha2);
            let got = microfacet::brdf(DVec3::Z, DVec3::Z, DVec3::Z, roughness, eta);
            assert!((got - expected).abs() <= 1e-12 * expected, "{got} vs {expected}");
        }
    }

    #[test]
    fn is_reciprocal_and_zero_below_the_surface() {
        let n = DVec3::Z;
        let a = DVec3::new(0.3, -0.2, 0.9).normalize();
        let b = DVec3::new(-0.7, 0.1, 0.4).normalize();
        let (f_ab, f_ba) = (microfacet::brdf(n, a, b, 0.4, 1.4), microfacet::brdf(n, b, a, 0.4, 1.4));
        assert!((f_ab - f_ba).abs() <= 1e-14 * f_ab);
        assert_eq!(microfacet::brdf(n, -a, b, 0.4, 1.4), 0.0);
        assert_eq!(microfacet::brdf(n, a, -b, 0.4, 1.4), 0.0);
    }

    #[test]
    fn albedo_is_the_fresnel_reflectance_less_shadowing() {
        // Seen along the normal, a smooth lobe reflects F(η, 1); rougher ones lose a little to
        // shadowing-masking (single scattering), never gain.
        let f0 = fresnel::reflectance(1.5, 1.0);
        let smooth = microfacet::albedo(DVec3::Z, 0.2, 1.5, 2000);
        assert!((smooth - f0).abs() <= 0.02 * f0, "{smooth} vs {f0}");
        let wo = DVec3::new(0.8, 0.0, 0.6);
        for roughness in [0.3, 0.6, 1.0] {
            let a = microfacet::albedo(wo, roughness, 1.5, 300);
            assert!(a > 0.0 && a <= 1.0, "{roughness}: {a}");
        }
    }
}
