//! Meshes that change from frame to frame: a sequence of OBJ files (`--mesh 'anim/frame-{frame}.obj'`)
//! and built-in deformations of any mesh (`--deform twist:DEG`, `--deform squash:F`), animated
//! over `--deform-period` frames. Vertex normals are recomputed on the CPU for every frame (carried
//! by the deformation's Jacobian).

use std::path::Path;

use glam::{Mat3, Quat, Vec3};

use crate::bad_input;
use crate::error::Result;
use crate::mesh::Mesh;

/// A built-in deformation at full strength; the animation scales it from 0 to 1 and back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Deformation {
    /// Turn each vertex about the vertical axis through the mesh's centre by up to this many
    /// degrees, in proportion to its height (the bottom stays, the top turns the most).
    Twist(f32),
    /// Scale heights about the mesh's bottom by this factor, and widths by 1/√factor, which keeps
    /// the volume.
    Squash(f32),
}

impl Deformation {
    /// `twist:DEG` or `squash:F`.
    pub fn parse(s: &str) -> std::result::Result<Deformation, String> {
        let (kind, value) = s.split_once(':').ok_or_else(|| format!("'{s}': expected twist:DEG or squash:FACTOR"))?;
        let v: f32 = value.trim().parse().map_err(|_| format!("'{value}' is not a number"))?;
        if !v.is_finite() {
            return Err(format!("'{value}' is not finite"));
        }
        match kind {
            "twist" => Ok(Deformation::Twist(v)),
            "squash" if v > 0.0 => Ok(Deformation::Squash(v)),
            "squash" => Err(format!("squash:{v}: the factor must be positive")),
            _ => Err(format!("'{s}': the kind must be twist or squash, not '{kind}'")),
        }
    }

    /// `mesh` deformed at `amount` (0 = unchanged, 1 = full strength). The vertical axis is
    /// `up`; heights are measured from the mesh's lowest point along it. Each normal is carried by
    /// the deformation's Jacobian J at its vertex (as (J⁻¹)ᵀ n), so smooth normals stay smooth,
    /// hard edges stay hard, and strength 0 gives back the mesh exactly.
    pub fn apply(&self, mesh: &Mesh, amount: f32, up: Vec3) -> Mesh {
        if mesh.normals.len() != mesh.positions.len() {
            let mut with_normals = mesh.clone();
            with_normals.compute_normals();
            return self.apply(&with_normals, amount, up);
        }
        let up = up.normalize_or(Vec3::Y);
        let (centre, _) = crate::scene::bounding_sphere(&mesh.positions);
        let heights: Vec<f32> = mesh.positions.iter().map(|p| (*p - centre).dot(up)).collect();
        let (low, high) = heights.iter().fold((f32::MAX, f32::MIN), |(l, h), &y| (l.min(y), h.max(y)));
        let span = (high - low).max(1e-12);
        let outer = |a: Vec3, b: Vec3| Mat3::from_cols(a * b.x, a * b.y, a * b.z);
        let along_up = outer(up, up);
        let mut positions = Vec::with_capacity(mesh.positions.len());
        let mut normals = Vec::with_capacity(mesh.normals.len());
        for ((p, n), &y) in mesh.positions.iter().zip(&mesh.normals).zip(&heights) {
            let r = *p - centre;
            let (moved, jacobian) = match *self {
                Deformation::Twist(deg) => {
                    // θ(y) = k (y - low): J = R + k (up × R r) upᵀ.
                    let k = (deg * amount).to_radians() / span;
                    let turn = Mat3::from_quat(Quat::from_axis_angle(up, k * (y - low)));
                    let turned = turn * r;
                    (centre + turned, turn + outer(up.cross(turned) * k, up))
                }
                Deformation::Squash(factor) => {
                    let s = 1.0 + (factor - 1.0) * amount;
                    let across = r - up * y;
                    let moved = centre + up * (low + (y - low) * s) + across / s.sqrt();
                    (moved, along_up * s + (Mat3::IDENTITY - along_up) / s.sqrt())
                }
            };
            positions.push(moved);
            let carried = jacobian.inverse().transpose() * *n;
            normals.push(carried.try_normalize().unwrap_or(*n));
        }
        Mesh { positions, normals, indices: mesh.indices.clone() }
    }
}

/// The strength of an animated deformation at `frame`: 0 at frame 0, 1 half a period later, 0
/// again after a whole period (a smooth cosine).
pub fn strength(frame: u32, period: u32) -> f32 {
    let phase = (frame % period.max(1)) as f64 / period.max(1) as f64;
    (0.5 - 0.5 * (std::f64::consts::TAU * phase).cos()) as f32
}

/// Where the meshes of frames come from, and what is done to them.
pub struct Animation {
    /// A sequence of OBJ files, or one mesh for every frame.
    source: MeshSource,
    deformation: Option<Deformation>,
    /// Frames per period of the deformation.
    period: u32,
    up: Vec3,
}

enum MeshSource {
    Fixed(Mesh),
    /// `{frame}` in the path; the files exist for frames `first..first + count`.
    Sequence {
        pattern: String,
        first: u32,
        count: u32,
    },
}

/// The file of frame `index`: `{frame}` replaced by the number, unpadded or zero-padded to 4.
fn sequence_file(pattern: &str, index: u32) -> Option<String> {
    [index.to_string(), format!("{index:04}")]
        .into_iter()
        .map(|n| pattern.replace("{frame}", &n))
        .find(|p| Path::new(p).is_file())
}

impl Animation {
    /// None when nothing changes between frames. `base` is the mesh already loaded for frame 0.
    pub fn new(
        spec: &str,
        base: &Mesh,
        deformation: Option<Deformation>,
        period: u32,
        up: Vec3,
    ) -> Result<Option<Animation>> {
        let source = if spec.contains("{frame}") {
            let (first, count) = sequence_range(spec)?;
            MeshSource::Sequence { pattern: spec.to_string(), first, count }
        } else if deformation.is_some() {
            MeshSource::Fixed(base.clone())
        } else {
            return Ok(None);
        };
        if period == 0 {
            return Err(bad_input!("--deform-period 0: must be at least 1 frame"));
        }
        Ok(Some(Animation { source, deformation, period, up }))
    }

    /// Frames in the file sequence (1 for a single mesh).
    pub fn sequence_length(&self) -> u32 {
        match &self.source {
            MeshSource::Fixed(_) => 1,
            MeshSource::Sequence { count, .. } => *count,
        }
    }

    /// The mesh of `frame` (sequences wrap around), deformed.
    pub fn mesh(&self, frame: u32) -> Result<Mesh> {
        let mesh = match &self.source {
            MeshSource::Fixed(m) => m.clone(),
            MeshSource::Sequence { pattern, first, count } => {
                let index = first + frame % count;
                let path = sequence_file(pattern, index)
                    .ok_or_else(|| bad_input!("--mesh {pattern}: frame {index} is missing"))?;
                Mesh::load(Path::new(&path))?
            }
        };
        Ok(match self.deformation {
            Some(d) => d.apply(&mesh, strength(frame, self.period), self.up),
            None => mesh,
        })
    }
}

/// The first frame number (0 or 1) and the number of consecutive files of a `{frame}` pattern.
fn sequence_range(pattern: &str) -> Result<(u32, u32)> {
    let first = (0..=1).find(|&i| sequence_file(pattern, i).is_some()).ok_or_else(|| {
        bad_input!(
            "--mesh {pattern}: no file for frame 0 or 1 (`{{frame}}` is the number, plain or padded to 4 digits)"
        )
    })?;
    let count = (first..).take_while(|&i| sequence_file(pattern, i).is_some()).count() as u32;
    Ok((first, count))
}

/// The mesh of `--mesh`: a built-in shape, an OBJ file, or the first file of a `{frame}` sequence.
pub fn first_mesh(spec: &str) -> Result<Mesh> {
    if spec.contains("{frame}") {
        let (first, _) = sequence_range(spec)?;
        let path = sequence_file(spec, first).expect("found by sequence_range");
        return Mesh::load(Path::new(&path));
    }
    Mesh::from_spec(spec)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_deformations() {
        assert_eq!(Deformation::parse("twist:90"), Ok(Deformation::Twist(90.0)));
        assert_eq!(Deformation::parse("squash:0.5"), Ok(Deformation::Squash(0.5)));
        assert!(Deformation::parse("squash:-1").unwrap_err().contains("positive"));
        assert!(Deformation::parse("bend:3").unwrap_err().contains("twist or squash"));
        assert!(Deformation::parse("twist").is_err());
    }

    #[test]
    fn strength_rises_and_falls_over_a_period() {
        assert_eq!(strength(0, 4), 0.0);
        assert!((strength(2, 4) - 1.0).abs() < 1e-6);
        assert!((strength(1, 4) - 0.5).abs() < 1e-6);
        assert_eq!(strength(4, 4), 0.0);
    }

    #[test]
    fn twist_turns_the_normals_and_zero_strength_keeps_the_mesh() {
        let box_mesh = Mesh::slab(1.0, 1.0, 2.0);
        let same = Deformation::Twist(90.0).apply(&box_mesh, 0.0, Vec3::Y);
        assert_eq!(same.positions, box_mesh.positions);
        let twisted = Deformation::Twist(90.0).apply(&box_mesh, 1.0, Vec3::Y);
        assert!(twisted.positions.iter().zip(&box_mesh.positions).any(|(a, b)| (*a - *b).length() > 0.1));
        // Normals follow: the side faces' normals turn with them (the top keeps +Y).
        for (p, n) in twisted.positions.iter().zip(&twisted.normals) {
            assert!((n.length() - 1.0).abs() < 1e-4);
            if p.y > 0.99 && n.y > 0.99 {
                continue;
            }
            if n.y.abs() < 0.01 {
                // A side normal is horizontal and points away from the axis (a box stays convex per height).
                assert!(n.dot(Vec3::new(p.x, 0.0, p.z)) > 0.0, "{p} {n}");
            }
        }
    }

    #[test]
    fn squash_keeps_the_bottom_and_scales_the_height() {
        let sphere = Mesh::sphere(1.0, 16);
        let squashed = Deformation::Squash(0.5).apply(&sphere, 1.0, Vec3::Y);
        let (lo, hi) = squashed.bounds();
        assert!((lo.y - -1.0).abs() < 1e-5, "bottom stays: {lo}");
        assert!((hi.y - lo.y - 1.0).abs() < 1e-4, "height halved: {}", hi.y - lo.y);
        assert!((hi.x - 2f32.sqrt()).abs() < 1e-3, "width × √2: {}", hi.x);
        // The normals of the squashed sphere (an ellipsoid) are the gradient of its equation.
        for (p, n) in squashed.positions.iter().zip(&squashed.normals) {
            let c = *p - Vec3::new(0.0, -0.5, 0.0);
            let gradient = Vec3::new(c.x / 2.0, c.y / 0.25, c.z / 2.0).normalize();
            assert!(n.dot(gradient) > 0.999, "{p}: {n} vs {gradient}");
        }
    }
}
