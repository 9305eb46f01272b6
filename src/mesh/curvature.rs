//! A mesh's mean curvature per vertex, smoothed over a length: the pixel's curvature, through the
//! surface pass, at which the Monte Carlo table's exit direction and light across read the
//! curvature ratios (physics::curvature_profile); each source's ratio is read at its pair's own
//! curvature (`curvature_profile::pair_curvature`).

use std::collections::HashMap;

use glam::{DVec3, IVec3, Vec3};

use super::Mesh;

/// Per vertex, the mean over its edges of the normal curvature along each,
/// κ_ij = (n_i − n_j)·(p_i − p_j)/|p_i − p_j|² (1/scene unit; > 0 where the surface is convex
/// with outward normals, < 0 where concave): exactly 1/R on a sphere with its true normals, and
/// the mean curvature (κ1 + κ2)/2 where the edges' directions spread evenly. A vertex on no edge
/// of length > 0 has 0.
pub fn mean_curvature(mesh: &Mesh) -> Vec<f32> {
    let mut sum = vec![0.0f64; mesh.positions.len()];
    let mut count = vec![0u32; mesh.positions.len()];
    for t in mesh.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let (a, b) = (a as usize, b as usize);
            let d = (mesh.positions[a] - mesh.positions[b]).as_dvec3();
            let len2 = d.length_squared();
            if len2.is_nan() || len2 <= 0.0 {
                continue;
            }
            let k = (mesh.normals[a] - mesh.normals[b]).as_dvec3().dot(d) / len2;
            if !k.is_finite() {
                continue;
            }
            // Each edge of a closed mesh is seen from both of its triangles: counted twice
            // for both ends alike.
            for v in [a, b] {
                sum[v] += k;
                count[v] += 1;
            }
        }
    }
    sum.iter().zip(&count).map(|(&s, &n)| if n > 0 { (s / n as f64) as f32 } else { 0.0 }).collect()
}

/// [`mean_curvature`] smoothed over `radius` (scene units): per vertex, the Gaussian-weighted
/// (σ = radius/2) mean of the vertex areas' curvature, gathered per cell of a grid of `radius`
/// and per side (the dominant axis of the normal, six buckets), over the 27 cells around the
/// vertex and only from buckets facing its side (n̄·n > 0), so that the two faces of a sheet
/// thinner than `radius` (an ear) do not mix. Its cost is bounded by the vertex count
/// (27 × 6 buckets a vertex), whatever the radius. A radius that is not a length > 0 returns
/// the raw curvature.
pub fn smoothed_mean_curvature(mesh: &Mesh, radius: f32) -> Vec<f32> {
    let raw = mean_curvature(mesh);
    if radius.is_nan() || radius <= 0.0 || !radius.is_finite() {
        return raw;
    }
    // Each vertex's area: a third of its triangles'.
    let mut area = vec![0.0f64; mesh.positions.len()];
    for (t, a) in mesh.indices.chunks_exact(3).zip(mesh.triangle_areas()) {
        for &v in t {
            area[v as usize] += a as f64 / 3.0;
        }
    }
    let cell_of = |p: Vec3| (p / radius).floor().as_ivec3();
    let side_of = |n: Vec3| {
        let a = n.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        axis * 2 + (n[axis] < 0.0) as usize
    };
    /// Area-weighted sums of one cell's bucket: curvature, position, normal, area.
    #[derive(Default, Clone, Copy)]
    struct Bucket {
        curvature: f64,
        position: DVec3,
        normal: DVec3,
        area: f64,
    }
    let mut cells: HashMap<IVec3, [Bucket; 6]> = HashMap::new();
    for (v, p) in mesh.positions.iter().enumerate() {
        let b = &mut cells.entry(cell_of(*p)).or_insert([Bucket::default(); 6])[side_of(mesh.normals[v])];
        let a = area[v];
        b.curvature += raw[v] as f64 * a;
        b.position += p.as_dvec3() * a;
        b.normal += mesh.normals[v].as_dvec3() * a;
        b.area += a;
    }
    let inv_two_sigma2 = 1.0 / (2.0 * (0.5 * radius as f64).powi(2));
    mesh.positions
        .iter()
        .zip(&mesh.normals)
        .enumerate()
        .map(|(v, (p, n))| {
            let (c, pd, nd) = (cell_of(*p), p.as_dvec3(), n.as_dvec3());
            let (mut sum, mut weight) = (0.0, 0.0);
            for dz in -1..=1 {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let Some(buckets) = cells.get(&(c + IVec3::new(dx, dy, dz))) else { continue };
                        for b in buckets.iter().filter(|b| b.area > 0.0 && b.normal.dot(nd) > 0.0) {
                            let centre = b.position / b.area;
                            let w = (-(centre - pd).length_squared() * inv_two_sigma2).exp();
                            sum += w * b.curvature;
                            weight += w * b.area;
                        }
                    }
                }
            }
            if weight > 0.0 {
                (sum / weight) as f32
            } else {
                raw[v]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_is_one_over_its_radius_and_a_slab_flat() {
        let sphere = Mesh::sphere(2.0, 48);
        // The UV sphere leaves one vertex at each pole on no triangle.
        let mut used = vec![false; sphere.positions.len()];
        sphere.indices.iter().for_each(|&i| used[i as usize] = true);
        for k in [mean_curvature(&sphere), smoothed_mean_curvature(&sphere, 1.0)] {
            let on_triangles = k.iter().zip(&used).filter(|(_, &u)| u).map(|(&x, _)| x);
            let (lo, hi) = on_triangles.fold((f32::MAX, f32::MIN), |(lo, hi), x| (lo.min(x), hi.max(x)));
            assert!(lo > 0.45 && hi < 0.55, "{lo} .. {hi}");
        }
        // Inside out (normals inward): concave, −1/R.
        let mut cavity = sphere.clone();
        cavity.normals.iter_mut().for_each(|n| *n = -*n);
        let k = smoothed_mean_curvature(&cavity, 1.0);
        assert!(k.iter().zip(&used).all(|(&x, &u)| !u || (x < -0.45 && x > -0.55)));
        let slab = Mesh::slab(4.0, 4.0, 1.0);
        let k = smoothed_mean_curvature(&slab, 0.5);
        // Face centres flat; the edges' vertices carry the fold.
        let mid = slab.positions.iter().position(|p| p.x.abs() < 1.0 && p.z.abs() < 1.0);
        if let Some(v) = mid {
            assert!(k[v].abs() < 1e-3, "{}", k[v]);
        }
    }
}
