//! The exact transport of a homogeneous sphere under a beam, in f64: the half-space Monte Carlo
//! of [`super::halfspace`] with the flat boundary replaced by a sphere of radius R, to measure
//! what curvature does to the exit profile that every model takes from the flat half-space.
//!
//! Same conventions as [`halfspace::trace_slab`]: units of the mean free path 1/σ't, isotropic
//! scattering with the reduced coefficients (the similarity relation), analogue absorption with
//! probability 1 − α' per collision, a smooth Fresnel boundary of relative index η, SplitMix64
//! seeded per call. The sphere's centre is at (0, 0, −R): its pole, the origin, is where a pencil
//! beam enters, with outward normal +z, so that for R → ∞ the walk is the half-space's.

use super::{fresnel, halfspace};
use glam::DVec3;
use std::f64::consts::PI;

use halfspace::{Photon, Split, SplitMix as Rng};

/// Where a photon left the sphere: its exit point relative to the pole (mean free paths), its
/// direction outside (refracted), cos²θo outside to the local normal, the geodesic distance
/// from the pole along the surface, and how often it scattered.
#[derive(Clone, Copy, Debug)]
pub struct SphereEscape {
    pub position: DVec3,
    pub direction: DVec3,
    pub mu_o2: f64,
    pub geodesic: f64,
    pub scatterings: u32,
    /// The photon's weight: 1, less after it split ([`Split`]).
    pub weight: f64,
}

/// Distance along `d` from `p` (in the medium) to the sphere |p − c| = |R|, c = (0, 0, −R).
/// Written with |q|² − R² = |p|² + 2Rz, which keeps its precision near the pole for large R, and
/// the cancellation-free root. A negative `radius` is a cavity (the medium outside the ball,
/// the surface concave): the ray meets it only going toward it within |R| (else ∞).
fn distance_out(radius: f64, p: DVec3, d: DVec3) -> f64 {
    let b = p.dot(d) + radius * d.z;
    let c = p.length_squared() + 2.0 * radius * p.z;
    if radius < 0.0 {
        let disc = b * b - c;
        return if b >= 0.0 || disc < 0.0 { f64::INFINITY } else { (c / (-b + disc.sqrt())).max(0.0) };
    }
    let root = (b * b - c).max(0.0).sqrt();
    let t = if b > 0.0 { -c / (b + root) } else { root - b };
    t.max(0.0)
}

/// One photon's walk inside a sphere of radius `radius` from where `photon` is (on or inside the
/// surface; its direction unit, into the medium): exponential free paths, absorption with
/// probability 1 − `albedo` at each collision (and after `max_collisions`), isotropic
/// scattering, and at the surface Fresnel reflection or escape with refraction, which
/// `on_escape` is told; where it splits (`split`), its copies' walks too. Returns the
/// scatterings.
fn walk(
    rng: &mut Rng,
    (albedo, eta, radius): (f64, f64, f64),
    mut photon: Photon,
    max_collisions: u32,
    split: Option<&Split>,
    on_escape: &mut dyn FnMut(&SphereEscape),
) -> u64 {
    let centre = DVec3::new(0.0, 0.0, -radius);
    let mut collisions = 0u64;
    // A copy split off at a collision starts there, before its own absorption and scattering.
    let mut fly = !std::mem::take(&mut photon.colliding);
    loop {
        if std::mem::replace(&mut fly, true) {
            let s = -rng.next().ln();
            let (p, d) = (&mut photon.p, &mut photon.d);
            let t = distance_out(radius, *p, *d);
            if s >= t {
                *p += t * *d;
                // Outward from the medium: away from a ball's centre, toward a cavity's.
                let n = ((*p - centre) * radius.signum()).normalize();
                let cos = d.dot(n).clamp(0.0, 1.0);
                if rng.next() < fresnel::reflectance(1.0 / eta, cos) {
                    *d = (*d - 2.0 * d.dot(n) * n).normalize();
                    continue;
                }
                let mu_o2 = (1.0 - eta * eta * (1.0 - cos * cos)).clamp(0.0, 1.0);
                // Snell from index η to 1: the tangential part scales by η.
                let direction = (eta * (*d - cos * n) + mu_o2.sqrt() * n).normalize();
                // |R| times the angle at the centre between the pole and the exit.
                let (q, pole) = (*p - centre, -centre);
                let geodesic = radius.abs() * q.cross(pole).length().atan2(q.dot(pole));
                let (position, scatterings, weight) = (*p, photon.scatterings, photon.weight);
                on_escape(&SphereEscape { position, direction, mu_o2, geodesic, scatterings, weight });
                return collisions;
            }
            *p += s * *d;
            if let Some(split) = split {
                collisions += split.at(rng, &mut photon, &mut |rng, copy| {
                    walk(rng, (albedo, eta, radius), copy, max_collisions, Some(split), on_escape)
                });
            }
        }
        if !photon.collide(rng, albedo, max_collisions) {
            return collisions;
        }
        collisions += 1;
    }
}

/// [`halfspace::trace_slab`]'s walk in a sphere of radius `radius` (mean free paths): `photons`
/// photons start at the pole going `start` (into the medium, z < 0; [`halfspace::entry_direction`]
/// gives the refracted beam of an angle of incidence), with reduced albedo `albedo` and index
/// `eta`; a negative `radius` walks the medium outside a spherical cavity of radius |R| instead
/// (a concave surface, centre (0, 0, |R|)). Returns the scatterings traced.
pub fn trace_sphere(
    albedo: f64,
    eta: f64,
    radius: f64,
    start: DVec3,
    photons: u64,
    seeds: (u64, u32),
    on_escape: impl FnMut(&SphereEscape),
) -> u64 {
    trace_sphere_split(albedo, eta, radius, start, photons, seeds, None, on_escape)
}

/// [`trace_sphere`] whose photons split as they go far from the pole ([`Split`]; None: the
/// analogue walk, bit for bit).
#[allow(clippy::too_many_arguments)]
pub fn trace_sphere_split(
    albedo: f64,
    eta: f64,
    radius: f64,
    start: DVec3,
    photons: u64,
    (seed, max_collisions): (u64, u32),
    split: Option<&Split>,
    mut on_escape: impl FnMut(&SphereEscape),
) -> u64 {
    let mut rng = Rng(seed);
    (0..photons)
        .map(|_| walk(&mut rng, (albedo, eta, radius), Photon::entering(start), max_collisions, split, &mut on_escape))
        .sum()
}

/// One photon's walk from `p` on the sphere going `d` into it (a beam entering anywhere, not
/// only at the pole), seeded `seed`, splitting by its distance from the pole where `split` says
/// (a light's far side, measured: `tests/common` `front_lit_walk`); returns the scatterings of
/// it and its copies.
pub fn trace_from(
    (albedo, eta, radius): (f64, f64, f64),
    p: DVec3,
    d: DVec3,
    (seed, max_collisions): (u64, u32),
    split: Option<&Split>,
    mut on_escape: impl FnMut(&SphereEscape),
) -> u64 {
    let photon = Photon { p, ..Photon::entering(d) };
    walk(&mut Rng(seed), (albedo, eta, radius), photon, max_collisions, split, &mut on_escape)
}

/// Rings of geodesic distance from the entry point (mean free paths): edge 0 is 0, then
/// [`RINGS_PER_DECADE`] a decade from [`RING_MIN`] up to the antipode πR (or [`RING_MAX`]).
pub const RING_MIN: f64 = 0.01;
pub const RING_MAX: f64 = 1e3;
pub const RINGS_PER_DECADE: usize = 8;

/// The ring edges for a sphere of radius `radius` (∞: the half-space).
pub fn ring_edges(radius: f64) -> Vec<f64> {
    let top = (PI * radius).min(RING_MAX);
    let mut edges = vec![0.0];
    let mut k = 0;
    loop {
        let e = RING_MIN * 10f64.powf(k as f64 / RINGS_PER_DECADE as f64);
        if e >= top * (1.0 - 1e-9) {
            break;
        }
        edges.push(e);
        k += 1;
    }
    edges.push(top);
    edges
}

/// The sphere's area between geodesic distances `a` < `b` from a point: 2πR²(cos(a/R) −
/// cos(b/R)), written as a product of sines to keep it exact for large R (∞: π(b² − a²)).
pub fn ring_area(radius: f64, a: f64, b: f64) -> f64 {
    if radius.is_infinite() {
        return PI * (b * b - a * a);
    }
    4.0 * PI * radius * radius * ((a + b) / (2.0 * radius)).sin() * ((b - a) / (2.0 * radius)).sin()
}

/// What [`sphere_profile`] measured, per channel.
#[derive(Clone, Debug)]
pub struct SphereTally {
    /// Radius in mean free paths (∞: the half-space).
    pub radius: f64,
    pub photons: u64,
    /// Diffuse reflectance of the sphere: all the power that leaves after at least one
    /// scattering (anywhere on it), per unit incident power, Ft(θi) at entry included (as
    /// [`halfspace::RteTally::total`]), and its standard error.
    pub total: f64,
    pub total_error: f64,
    /// The part of `total` that left after exactly one scattering, and its standard error.
    pub single: f64,
    pub single_error: f64,
    /// Ring edges in geodesic distance ([`ring_edges`]).
    pub edges: Vec<f64>,
    /// Exitance per unit area (mean free paths²) per unit power entering, per ring: all orders,
    /// and two or more scatterings (the part `--model mc` tabulates); photon counts of each.
    pub exitance: Vec<f64>,
    pub multiple: Vec<f64>,
    pub counts: Vec<u64>,
    pub multiple_counts: Vec<u64>,
}

impl SphereTally {
    /// Geometric centre of ring `k` (for k = 0, half its outer edge).
    pub fn ring_centre(&self, k: usize) -> f64 {
        let (a, b) = (self.edges[k], self.edges[k + 1]);
        if a > 0.0 {
            (a * b).sqrt()
        } else {
            0.5 * b
        }
    }

    /// The exitance (all orders, or orders ≥ 2) averaged over geodesic distances from `lo` to
    /// `hi` (rings whose centre lies there, weighted by area), with its relative standard error
    /// from the photon count.
    pub fn band(&self, lo: f64, hi: f64, multiple_only: bool) -> (f64, f64) {
        let (values, counts) =
            if multiple_only { (&self.multiple, &self.multiple_counts) } else { (&self.exitance, &self.counts) };
        let (mut power, mut area, mut n) = (0.0, 0.0, 0u64);
        for k in 0..values.len() {
            let c = self.ring_centre(k);
            if c >= lo && c < hi {
                let a = ring_area(self.radius, self.edges[k], self.edges[k + 1]);
                power += values[k] * a;
                area += a;
                n += counts[k];
            }
        }
        if area == 0.0 || n == 0 {
            return (0.0, f64::INFINITY);
        }
        (power / area, 1.0 / (n as f64).sqrt())
    }
}

/// The sphere of radius `radius` (mean free paths; `f64::INFINITY`: the half-space, by
/// [`halfspace::trace_half_space`]) of reduced albedo `albedo` and index `eta` under a pencil
/// beam at its pole at cos θi = `cos_i`, by analogue Monte Carlo with `photons` photons entering
/// (weighted Ft(θi)).
pub fn sphere_profile(
    albedo: f64,
    eta: f64,
    radius: f64,
    cos_i: f64,
    photons: u64,
    (seed, max_collisions): (u64, u32),
) -> SphereTally {
    let edges = ring_edges(radius);
    let bins = edges.len() - 1;
    let (mut counts, mut multiple_counts) = (vec![0u64; bins], vec![0u64; bins]);
    let (mut escaped, mut once) = (0u64, 0u64);
    let mut tally = |s: f64, scatterings: u32| {
        escaped += 1;
        once += (scatterings == 1) as u64;
        // The ring of s: the first edge above it, less one.
        let k = edges.partition_point(|&e| e <= s).saturating_sub(1).min(bins - 1);
        if s <= edges[bins] {
            counts[k] += 1;
            multiple_counts[k] += (scatterings >= 2) as u64;
        }
    };
    let start = halfspace::entry_direction(eta, cos_i);
    if radius.is_infinite() {
        halfspace::trace_half_space(albedo, eta, start, photons, (seed, max_collisions), |e| {
            tally((e.x * e.x + e.y * e.y).sqrt(), e.scatterings)
        });
    } else {
        trace_sphere(albedo, eta, radius, start, photons, (seed, max_collisions), |e| tally(e.geodesic, e.scatterings));
    }
    let entry = fresnel::transmittance(eta, cos_i);
    let n = photons as f64;
    let (p, p1) = (escaped as f64 / n, once as f64 / n);
    let density = |c: &[u64]| -> Vec<f64> {
        c.iter().enumerate().map(|(k, &c)| c as f64 / n / ring_area(radius, edges[k], edges[k + 1])).collect()
    };
    SphereTally {
        radius,
        photons,
        total: entry * p,
        total_error: entry * (p * (1.0 - p) / n).sqrt(),
        single: entry * p1,
        single_error: entry * (p1 * (1.0 - p1) / n).sqrt(),
        exitance: density(&counts),
        multiple: density(&multiple_counts),
        edges: edges.clone(),
        counts,
        multiple_counts,
    }
}

/// A beam as the path-traced reference makes it (scripts/sphere-reference): light from a far disk
/// of angular radius `cone` (radians) about +z, of uniform radiance, through a circular hole of
/// radius `hole` in a black screen at height `height` above the pole (mean free paths).
#[derive(Clone, Copy, Debug)]
pub struct Beam {
    pub hole: f64,
    pub height: f64,
    pub cone: f64,
}

/// An orthographic camera looking down −z at the pole: `pixels`² square pixels over
/// |x|, |y| < `half_extent` (mean free paths), which counts the light leaving within `cone`
/// (radians) of +z.
#[derive(Clone, Copy, Debug)]
pub struct View {
    pub pixels: usize,
    pub half_extent: f64,
    pub cone: f64,
}

/// A photon of the beam: a point uniform on the hole and a direction of the far disk weighted by
/// its cosine to the screen (power through an aperture ∝ L cos θ dω dA), to where it meets the
/// sphere; None if it misses it or is reflected there (the boundary's own reflection, which the
/// reference subtracts), else the entry point and the refracted direction.
fn launch(rng: &mut Rng, eta: f64, radius: f64, beam: &Beam) -> Option<(DVec3, DVec3)> {
    let (r, phi) = (beam.hole * rng.next().sqrt(), 2.0 * PI * rng.next());
    let p = DVec3::new(r * phi.cos(), r * phi.sin(), beam.height);
    let cos2 = 1.0 - rng.next() * beam.cone.sin().powi(2);
    let (ct, st, psi) = (cos2.sqrt(), (1.0 - cos2).max(0.0).sqrt(), 2.0 * PI * rng.next());
    let d = DVec3::new(st * psi.cos(), st * psi.sin(), -ct);
    // The near root of |p + t d − c|² = R² from outside.
    let b = p.dot(d) + radius * d.z;
    let c = p.length_squared() + 2.0 * radius * p.z;
    let disc = b * b - c;
    if disc < 0.0 || b > 0.0 {
        return None;
    }
    let x = p + c / (-b + disc.sqrt()) * d;
    let n = (x - DVec3::new(0.0, 0.0, -radius)).normalize();
    let cos_i = (-d.dot(n)).clamp(0.0, 1.0);
    if rng.next() < fresnel::reflectance(eta, cos_i) {
        return None;
    }
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (eta * eta)).max(0.0).sqrt();
    Some((x, ((d + cos_i * n) / eta - cos_t * n).normalize()))
}

/// What the camera of `view` sees of the sphere under `beam`, with the boundary's own reflection
/// left out: per pixel (row-major, pixel (i, j) centred at x = −e + (i + ½)·2e/N, y likewise),
/// the radiance per unit irradiance of the beam on the screen, from `photons` photons through the
/// hole; and the photon counts per pixel. Radiance = power leaving / (pixel area · π sin²γ), the
/// projected solid angle of the counting cone.
pub fn beam_view(
    (albedo, eta, radius): (f64, f64, f64),
    beam: &Beam,
    view: &View,
    photons: u64,
    (seed, max_collisions): (u64, u32),
) -> (Vec<f64>, Vec<u64>) {
    let n = view.pixels;
    let mut counts = vec![0u64; n * n];
    let cos_cone = view.cone.cos();
    let pixel = 2.0 * view.half_extent / n as f64;
    let mut rng = Rng(seed);
    let mut on_escape = |e: &SphereEscape| {
        if e.direction.z < cos_cone {
            return;
        }
        let (i, j) = ((e.position.x + view.half_extent) / pixel, (e.position.y + view.half_extent) / pixel);
        if i >= 0.0 && j >= 0.0 && (i as usize) < n && (j as usize) < n {
            counts[j as usize * n + i as usize] += 1;
        }
    };
    for _ in 0..photons {
        if let Some((p, d)) = launch(&mut rng, eta, radius, beam) {
            walk(
                &mut rng,
                (albedo, eta, radius),
                Photon { p, ..Photon::entering(d) },
                max_collisions,
                None,
                &mut on_escape,
            );
        }
    }
    // Each photon carries the power through the hole, πa² per unit irradiance, over `photons`.
    let power = PI * beam.hole * beam.hole / photons as f64;
    let scale = power / (pixel * pixel * PI * view.cone.sin().powi(2));
    (counts.iter().map(|&c| c as f64 * scale).collect(), counts)
}
