//! Triangle meshes (interim: the full loader lands from the mesh branch).
use glam::Vec3;

use crate::error::Result;

pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub indices: Vec<u32>,
}

impl Mesh {
    pub fn sphere(radius: f32, subdivisions: u32) -> Mesh {
        let (rings, segments) = (subdivisions * 8, subdivisions * 16);
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        for i in 0..=rings {
            let theta = std::f32::consts::PI * i as f32 / rings as f32;
            for j in 0..=segments {
                let phi = 2.0 * std::f32::consts::PI * j as f32 / segments as f32;
                let n = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                positions.push(n * radius);
                normals.push(n);
            }
        }
        let mut indices = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let a = i * (segments + 1) + j;
                let b = a + segments + 1;
                indices.extend_from_slice(&[a, a + 1, b, b, a + 1, b + 1]);
            }
        }
        Mesh { positions, normals, indices }
    }
    pub fn from_spec(_spec: &str) -> Result<Mesh> {
        Ok(Mesh::sphere(1.0, 4))
    }
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.positions
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    }
    pub fn validate(&self) -> Result<()> {
        Ok(())
    }
    pub fn vertex_data(&self) -> Vec<[f32; 6]> {
        self.positions.iter().zip(&self.normals).map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z]).collect()
    }
}
