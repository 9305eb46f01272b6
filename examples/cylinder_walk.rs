//! Which ball stands for a surface that is no ball? The shade pass reads the Monte Carlo table's
//! curvature ratios (physics::curvature_profile, measured on balls) per source at the pair's
//! curvature along the way between them, κ = (no − ni)·d/|d|² (`pair_curvature`). Two exact
//! walks (f64 Monte Carlo as physics::sphere's, a normal beam, two or more scatterings) say why:
//!
//! - `cargo run --release --example cylinder_walk [MATERIAL [R_MM [PHOTONS]]]`: a cylinder of
//!   radius R; its exits around the bend and along the axis (within 22.5° of each), per unit
//!   area, over the half-space's at the same chord, beside balls of radius R, 2R, 4R. Skin1,
//!   R = 5 mm, red at chords 1.1 / 2.2 / 4.4 mm: around 1.19 / 1.45 / 1.87, the ball of radius R
//!   1.19 / 1.45 / 1.99; along 1.02 / 1.01 / 1.00 (flat). Around a bend the light does what it
//!   does in the ball of that bend's radius, along a straight line what it does on a plane: the
//!   pair's curvature is that of its way (1/R around, 0 along), not the surface's mean (1/2R).
//! - `cargo run --release --example cylinder_walk wedge [MATERIAL [A_MM]]`: a right-angled
//!   edge A mm from the beam; the front face's exits by depth below the edge over the
//!   half-space's at the same chord (2 to 12x: the light that turns an edge is far from the
//!   boundary it entered), beside the table read at the pair's curvature. Skin1, A = 1 mm, red:
//!   edge 2.1 / 2.9 / 3.7 / 3.8 at h = 0.4 / 1.1 / 2.2 / 4.4 mm, table 2.4 / 3.2 / 2.9 / 2.6.
//!   (Read at the pixel's mean curvature, 0 on a box's faces, the table gave 1 there: the Skin1
//!   box behind the default light was 0.68 0.53 0.54 of the path tracer, 1.22 1.12 1.02 now.)
use glam::DVec3;
use std::f64::consts::PI;
use translucent::materials::Material;
use translucent::physics::fresnel;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 + 0.5 / (1u64 << 53) as f64
    }
}

#[derive(Clone, Copy)]
enum Shape {
    Plane,
    Ball(f64),
    Cylinder(f64), // axis along y through (0, 0, −R)
    Wedge(f64),    // z < 0 and x < a: a right-angled edge at distance a from the entry
}

impl Shape {
    /// Distance from p (inside) along d to the surface, and the outward normal there.
    fn out(self, p: DVec3, d: DVec3) -> (f64, DVec3) {
        match self {
            Shape::Plane => {
                if d.z > 0.0 {
                    (-p.z / d.z, DVec3::Z)
                } else {
                    (f64::INFINITY, DVec3::Z)
                }
            }
            Shape::Wedge(a) => {
                let tz = if d.z > 0.0 { -p.z / d.z } else { f64::INFINITY };
                let tx = if d.x > 0.0 { (a - p.x) / d.x } else { f64::INFINITY };
                if tz < tx {
                    (tz.max(0.0), DVec3::Z)
                } else {
                    (tx.max(0.0), DVec3::X)
                }
            }
            Shape::Ball(r) | Shape::Cylinder(r) => {
                let mask = if matches!(self, Shape::Cylinder(_)) { DVec3::new(1.0, 0.0, 1.0) } else { DVec3::ONE };
                let c = DVec3::new(0.0, 0.0, -r);
                let (q, e) = ((p - c) * mask, d * mask);
                let a = e.length_squared();
                if a < 1e-300 {
                    return (f64::INFINITY, DVec3::Z);
                }
                let b = q.dot(e);
                let cc = q.length_squared() - r * r;
                let disc = (b * b - a * cc).max(0.0).sqrt();
                let t = if b > 0.0 { -cc / (b + disc) } else { (disc - b) / a };
                let t = t.max(0.0);
                let hit = p + t * d;
                (t, (((hit - c) * mask).normalize()))
            }
        }
    }
}

/// Exits of ≥ 2 scatterings: (exit point) per photon.
fn walk(shape: Shape, albedo: f64, eta: f64, photons: u64, seed: u64, mut tally: impl FnMut(DVec3, f64)) {
    let mut rng = Rng(seed);
    for _ in 0..photons {
        let (mut p, mut d) = (DVec3::ZERO, DVec3::NEG_Z);
        let mut scatterings = 0u32;
        loop {
            let s = -rng.next().ln();
            let (t, n) = shape.out(p, d);
            if s >= t {
                p += t * d;
                let cos = d.dot(n).clamp(0.0, 1.0);
                if rng.next() < fresnel::reflectance(1.0 / eta, cos) {
                    d = (d - 2.0 * d.dot(n) * n).normalize();
                    continue;
                }
                if scatterings >= 2 {
                    tally(p, (1.0 - eta * eta * (1.0 - cos * cos)).max(0.0));
                }
                break;
            }
            p += s * d;
            if rng.next() >= albedo || scatterings > 100_000 {
                break;
            }
            scatterings += 1;
            let mu = 2.0 * rng.next() - 1.0;
            let phi = 2.0 * PI * rng.next();
            let st = (1.0 - mu * mu).max(0.0).sqrt();
            d = DVec3::new(st * phi.cos(), st * phi.sin(), mu);
        }
    }
}

/// A right-angled edge `a_mm` from where a normal beam enters the top face: the front face's
/// multiple-scattering exitance by depth h below the edge (a strip through the beam) against the
/// half-space's at the same chord, and the ratio the table gives at the pair's curvature.
fn wedge(material: &str, a_mm: f64, photons: u64) {
    let m3 = Material::find(material).expect("preset");
    let media = [0, 1, 2].map(|c| m3.channel(c));
    let ratios = translucent::physics::curvature_profile::of_channels(&media);
    for (c, m) in media.iter().enumerate() {
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let albedo = m.sigma_s * (1.0 - m.g) / sigma_t;
        let a = a_mm * sigma_t;
        // Exits on the front face x = a within |y| < w, by depth h = −z (mean free paths).
        let w = 0.25;
        let hs: Vec<f64> = (0..12).map(|k| 0.25 * 2f64.powf(k as f64 / 2.0)).collect();
        let mut front = vec![0.0f64; hs.len() - 1];
        walk(Shape::Wedge(a), albedo, m.eta, photons, 7, |p, _| {
            if p.y.abs() < w && (p.x - a).abs() < 1e-9 {
                if let Some(k) = hs.iter().rposition(|&e| e <= -p.z).filter(|&k| k < hs.len() - 1) {
                    front[k] += 1.0;
                }
            }
        });
        let pe: Vec<f64> = (0..64).map(|k| 0.05 * 2f64.powf(k as f64 / 6.0)).collect();
        let mut plane = vec![0.0f64; pe.len()];
        walk(Shape::Plane, albedo, m.eta, photons * 4, 7, |p, _| {
            let r = (p.x * p.x + p.y * p.y).sqrt();
            if let Some(k) = pe.iter().rposition(|&e| e <= r).filter(|&k| k < pe.len() - 1) {
                plane[k] += 1.0;
            }
        });
        let plane_at = |r: f64| -> f64 {
            let k = pe.iter().rposition(|&e| e <= r).unwrap_or(0).min(pe.len() - 2);
            plane[k] / (4.0 * photons as f64 * PI * (pe[k + 1].powi(2) - pe[k].powi(2)))
        };
        println!("{material} channel {c}: an edge {a_mm} mm from a normal beam, its front face by depth h");
        println!("  h (mm)  chord (mm)  edge/half-space  table at κ_pair  κ_pair (1/mm)");
        for k in 0..hs.len() - 1 {
            let h = (hs[k] * hs[k + 1]).sqrt();
            let chord = (a * a + h * h).sqrt();
            let exitance = front[k] / (photons as f64 * (hs[k + 1] - hs[k]) * 2.0 * w);
            // d = (a, 0, −h) from the entry, ni = z, no = x: κ = (a + h)/|d|².
            let kappa = (a + h) / (chord * chord) * sigma_t;
            println!(
                "  {:6.3} {:9.3}   {:12.3}   {:13.3}   {:10.3}   (n = {})",
                h / sigma_t,
                chord / sigma_t,
                exitance / plane_at(chord),
                ratios[c].ratio(chord / sigma_t, kappa, 0.0),
                kappa,
                front[k]
            );
        }
    }
}

/// The exit's distribution over cos²θo (outside) of a ball's multiple-scattering escapes, near
/// the entry (chord < R√2) and on the far side, against the half-space's.
fn exits(material: &str, r_mm: f64, photons: u64) {
    let m3 = Material::find(material).expect("preset");
    for c in 0..3 {
        let m = m3.channel(c);
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let albedo = m.sigma_s * (1.0 - m.g) / sigma_t;
        let r = r_mm * sigma_t;
        let mut bins = [[0.0f64; 10]; 5];
        walk(Shape::Ball(r), albedo, m.eta, photons, 3, |p, mu2| {
            let b = ((mu2 * 10.0) as usize).min(9);
            let angle = (p.z + r).atan2((p.x * p.x + p.y * p.y).sqrt());
            let polar = std::f64::consts::FRAC_PI_2 - angle; // from the entry's axis
            let group = if p.length() < r * std::f64::consts::SQRT_2 {
                0
            } else if polar < 2.0 * PI / 3.0 {
                1
            } else if polar < 5.0 * PI / 6.0 {
                2
            } else {
                3
            };
            bins[group][b] += 1.0;
        });
        walk(Shape::Plane, albedo, m.eta, photons, 3, |_, mu2| bins[4][((mu2 * 10.0) as usize).min(9)] += 1.0);
        println!("{material} channel {c}, R = {r_mm} mm: the exit's distribution over cos²θo bins, each normalised (per bin / the half-space's)");
        let names = ["near (chord < R√2)", "90-120°", "120-150°", "150-180°"];
        for g in 0..4 {
            let n: f64 = bins[g].iter().sum();
            let n4: f64 = bins[4].iter().sum();
            let v: Vec<String> = (0..10).map(|b| format!("{:.2}", (bins[g][b] / n) / (bins[4][b] / n4))).collect();
            println!("  {:20} (n = {n:8.0}) {}", names[g], v.join(" "));
        }
    }
}

fn main() {
    if std::env::args().nth(1).as_deref() == Some("exits") {
        let r: f64 = std::env::args().nth(3).and_then(|v| v.parse().ok()).unwrap_or(5.0);
        exits(&std::env::args().nth(2).unwrap_or_else(|| "skin1".into()), r, 1_000_000);
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("wedge") {
        let a: f64 = std::env::args().nth(3).and_then(|v| v.parse().ok()).unwrap_or(1.0);
        wedge(&std::env::args().nth(2).unwrap_or_else(|| "skin1".into()), a, 2_000_000);
        return;
    }
    let args: Vec<String> = std::env::args().collect();
    let material = args.get(1).cloned().unwrap_or_else(|| "skin1".into());
    let r_mm: f64 = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(5.0);
    let photons: u64 = args.get(3).and_then(|v| v.parse().ok()).unwrap_or(400_000);
    let m3 = Material::find(&material).expect("preset");
    for c in 0..3 {
        let m = m3.channel(c);
        let sigma_t = m.sigma_a + m.sigma_s * (1.0 - m.g);
        let albedo = m.sigma_s * (1.0 - m.g) / sigma_t;
        let r = r_mm * sigma_t;
        // Chord bins (mfp): 8 per doubling from 0.25 to the diameter.
        let edges: Vec<f64> = (0..).map(|k| 0.25 * 2f64.powf(k as f64 / 2.0)).take_while(|&e| e < 2.0 * r).collect();
        let nb = edges.len() - 1;
        let bin = |chord: f64| edges.iter().rposition(|&e| e <= chord).filter(|&k| k < nb);
        // Sector of an exit point on the cylinder: around the bend (|y| small) or along the axis.
        let sector = |p: DVec3| -> Option<usize> {
            let arc = r * (p.x.atan2(p.z + r)).abs();
            let ang = p.y.abs().atan2(arc);
            if ang < PI / 8.0 {
                Some(0)
            } else if ang > 3.0 * PI / 8.0 {
                Some(1)
            } else {
                None
            }
        };
        // Area of each (bin, sector) on the cylinder by a fine quadrature over (φ, y).
        let mut cyl_area = vec![[0.0f64; 2]; nb];
        let (nphi, ny) = (2000, 2000);
        let ymax = 2.0 * r;
        for i in 0..nphi {
            let phi = (i as f64 + 0.5) / nphi as f64 * PI - PI / 2.0 + 0.0;
            let phi = phi * 2.0; // −π..π
            for j in 0..ny {
                let y = ((j as f64 + 0.5) / ny as f64 * 2.0 - 1.0) * ymax;
                let p = DVec3::new(r * phi.sin(), y, r * phi.cos() - r);
                if let (Some(b), Some(s)) = (bin(p.length()), sector(p)) {
                    cyl_area[b][s] += r * (2.0 * PI / nphi as f64) * (2.0 * ymax / ny as f64);
                }
            }
        }
        let mut cyl = vec![[0.0f64; 2]; nb];
        walk(Shape::Cylinder(r), albedo, m.eta, photons, 1, |p, _| {
            if let (Some(b), Some(s)) = (bin(p.length()), sector(p)) {
                cyl[b][s] += 1.0;
            }
        });
        // Balls and the plane: per unit area by chord (area of a ball between chords a, b: π(b² − a²), exactly).
        let per_area = |shape: Shape| -> Vec<f64> {
            let mut n = vec![0.0f64; nb];
            walk(shape, albedo, m.eta, photons, 1, |p, _| {
                if let Some(b) = bin(p.length()) {
                    n[b] += 1.0;
                }
            });
            (0..nb).map(|b| n[b] / (PI * (edges[b + 1].powi(2) - edges[b].powi(2)))).collect()
        };
        let plane = per_area(Shape::Plane);
        let balls: Vec<Vec<f64>> = [1.0, 2.0, 4.0].iter().map(|k| per_area(Shape::Ball(k * r))).collect();
        println!("{material} channel {c}: R = {r_mm} mm = {r:.2} mfp; ratios to the half-space at each chord");
        println!("  chord(mm)  cyl-around cyl-along   ball(R)  ball(2R)  ball(4R)");
        for b in 0..nb {
            let mid = (edges[b] * edges[b + 1]).sqrt() / sigma_t;
            let around = cyl[b][0] / cyl_area[b][0].max(1e-300) / plane[b];
            let along = cyl[b][1] / cyl_area[b][1].max(1e-300) / plane[b];
            println!(
                "  {mid:8.3}  {around:9.3} {along:9.3}  {:8.3} {:8.3} {:8.3}   (n={:.0})",
                balls[0][b] / plane[b],
                balls[1][b] / plane[b],
                balls[2][b] / plane[b],
                cyl[b][0]
            );
        }
    }
}
