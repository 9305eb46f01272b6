//! Which cells of a grid over a closed mesh lie inside it: the medium's extent, so that the shade
//! pass can tell a pair of surface points joined through the object from one joined only through
//! the air (an ear beside the other, across a torus's hole, a paw and the chest above it). A
//! BSSRDF carries light from entry to exit as through a half-space; where no short way between
//! them stays inside, light that stays in the medium goes the long way round, and the path
//! tracer's light that exits once has none of it, so the Monte Carlo table's pair is not summed
//! ([`joined_inside`], mirrored by sources.glsl `joined_inside`).
//!
//! The grid is OCCUPANCY_CELLS per axis over the mesh's bounds padded by one cell, one bit per
//! cell: set where the cell's centre is inside, by the parity of the mesh's crossings along a
//! line through the centres of a column of cells (the columns run along z), then grown by one
//! cell.

use glam::{DVec2, Vec3};

use super::Mesh;

/// Cells per axis (gpu::constants' OCCUPANCY_CELLS).
pub const CELLS: usize = crate::gpu::OCCUPANCY_CELLS as usize;

#[derive(Clone, Debug, PartialEq)]
pub struct Occupancy {
    /// The grid's corner and cell size per axis, in scene units.
    pub min: Vec3,
    pub cell: Vec3,
    /// Bit (x + CELLS (y + CELLS z)) set where that cell's centre is inside the mesh, grown by
    /// one cell ([`dilated`]): where a pair's way through the medium is tested.
    pub bits: Vec<u32>,
    /// The same before it was grown: where light crosses the air (passes::reentry) is tested,
    /// which the grown grid would call inside within a cell of the surface.
    pub centres: Vec<u32>,
}

impl Occupancy {
    /// The grid over `mesh`, or None where inside is not defined (a mesh that is not closed) or
    /// the mesh is flat along an axis.
    pub fn of(mesh: &Mesh) -> Option<Occupancy> {
        if mesh.indices.is_empty() || !mesh.is_closed() {
            return None;
        }
        let (lo, hi) = mesh.bounds();
        let n = CELLS as f32;
        // One cell of padding on each side: a sample just outside the surface reads a cell outside.
        let cell = (hi - lo) / (n - 2.0);
        if !cell.is_finite() || cell.min_element() <= 0.0 {
            return None;
        }
        let min = lo - cell;
        // The columns' lines stand off the cell centres by an odd fraction of a cell, so that they
        // miss the edges and vertices of regular meshes (the built-in sphere, torus and slab).
        let offset = DVec2::new(0.5 + 0.0123, 0.5 + 0.0371);
        let column = |i: usize, j: usize| {
            DVec2::new(
                min.x as f64 + (i as f64 + offset.x) * cell.x as f64,
                min.y as f64 + (j as f64 + offset.y) * cell.y as f64,
            )
        };
        // Each triangle's crossings with the columns its xy bounds cover.
        let mut crossings: Vec<Vec<f64>> = vec![Vec::new(); CELLS * CELLS];
        for t in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize].as_dvec3());
            let (tmin, tmax) = (a.min(b).min(c), a.max(b).max(c));
            // The columns whose lines lie within the triangle's bounds.
            let index_range = |lo: f64, hi: f64, start: f32, size: f32, off: f64| {
                let first = ((lo - start as f64) / size as f64 - off).ceil().max(0.0) as usize;
                let last = ((hi - start as f64) / size as f64 - off).floor().min(CELLS as f64 - 1.0);
                first..(last + 1.0).max(0.0) as usize
            };
            let columns_x = index_range(tmin.x, tmax.x, min.x, cell.x, offset.x);
            let columns_y = index_range(tmin.y, tmax.y, min.y, cell.y, offset.y);
            let (ab, ac) = (b - a, c - a);
            let det = ab.x * ac.y - ab.y * ac.x;
            if det == 0.0 {
                continue; // parallel to the columns
            }
            for j in columns_y {
                for i in columns_x.clone() {
                    let p = column(i, j);
                    let (px, py) = (p.x - a.x, p.y - a.y);
                    let u = (px * ac.y - py * ac.x) / det;
                    let v = (ab.x * py - ab.y * px) / det;
                    if u >= 0.0 && v >= 0.0 && u + v <= 1.0 {
                        crossings[i + CELLS * j].push(a.z + u * ab.z + v * ac.z);
                    }
                }
            }
        }
        let mut bits = vec![0u32; CELLS * CELLS * CELLS / 32];
        for j in 0..CELLS {
            for i in 0..CELLS {
                let zs = &mut crossings[i + CELLS * j];
                zs.sort_by(f64::total_cmp);
                // Inside between the 1st and 2nd crossing, the 3rd and 4th, …
                let mut next = 0;
                for k in 0..CELLS {
                    let z = min.z as f64 + (k as f64 + 0.5) * cell.z as f64;
                    while next < zs.len() && zs[next] < z {
                        next += 1;
                    }
                    if next % 2 == 1 {
                        let bit = i + CELLS * (j + CELLS * k);
                        bits[bit / 32] |= 1 << (bit % 32);
                    }
                }
            }
        }
        Some(Occupancy { min, cell, bits: dilated(&bits), centres: bits })
    }

    /// Whether the cell holding `p` is inside (outside the grid: no).
    pub fn inside(&self, p: Vec3) -> bool {
        self.occupied((p - self.min) / self.cell)
    }

    /// Whether the cell holding `p` has its centre inside (the grid before it was grown; outside
    /// the grid: no): reentry/gather.comp's test of the air.
    pub fn centre_inside(&self, p: Vec3) -> bool {
        bit_at(&self.centres, (p - self.min) / self.cell)
    }

    /// Whether cell `at` (in cells from the corner, floored) is inside (bssrdf.glsl `occupied`).
    fn occupied(&self, at: Vec3) -> bool {
        bit_at(&self.bits, at)
    }

    /// Whether light can go from `a` (normal `na`) to `b` (normal `nb`) inside the object, as
    /// the shade pass tests it (bssrdf.glsl `through_medium`, in the same arithmetic): along an
    /// arc that sags into the object by a quarter of the chord at its middle, toward
    /// −(na + nb)/2, at 1/4, 1/2 and 3/4 of the way. Not tested for a chord shorter than two
    /// cells (the grid cannot tell there; a surface that close is one surface).
    pub fn through_medium(&self, a: Vec3, na: Vec3, b: Vec3, nb: Vec3) -> bool {
        let (start, d) = ((a - self.min) / self.cell, (b - a) / self.cell);
        if d.length_squared() < 4.0 {
            return true;
        }
        let sag = (-0.25 * 0.5 * (b - a).length()) * (na + nb) / self.cell;
        self.occupied(start + d * 0.5 + sag)
            && self.occupied(start + d * 0.25 + 0.75 * sag)
            && self.occupied(start + d * 0.75 + 0.75 * sag)
    }

    /// The GPU's texels (after the Sd table's curvature rows; `OCCUPANCY_BASE` in bssrdf.glsl):
    /// min.xyz and 1 (0: no grid, every chord inside), then cell.xyz, then the grown bits, four
    /// words a texel, then the centres' bits the same way.
    pub fn texels(grid: Option<&Occupancy>) -> Vec<[u32; 4]> {
        let mut texels = vec![[0u32; 4]; TEXELS];
        if let Some(g) = grid {
            texels[0] = [g.min.x.to_bits(), g.min.y.to_bits(), g.min.z.to_bits(), 1.0f32.to_bits()];
            texels[1] = [g.cell.x.to_bits(), g.cell.y.to_bits(), g.cell.z.to_bits(), 0];
            for (t, words) in texels[2..].iter_mut().zip(g.bits.chunks_exact(4).chain(g.centres.chunks_exact(4))) {
                t.copy_from_slice(words);
            }
        }
        texels
    }
}

/// Whether light goes from `xi` (normal `ni`) to `xo` (normal `no`) inside the object, as the
/// shade pass decides it (sources.glsl `joined_inside`): a chord that leaves neither end's
/// surface by more than ~3° (every pair of a convex object) is inside; another is tested by
/// [`Occupancy::through_medium`]. No grid (an open mesh): always.
pub fn joined_inside(grid: Option<&Occupancy>, xi: Vec3, ni: Vec3, xo: Vec3, no: Vec3) -> bool {
    let d = xo - xi;
    let lean = 0.05 * d.length();
    if d.dot(ni) <= lean && d.dot(no) >= -lean {
        return true;
    }
    grid.is_none_or(|g| g.through_medium(xi, ni, xo, no))
}

/// Bit `at` (in cells from the corner, floored) of a grid's words; outside the grid: no.
fn bit_at(words: &[u32], at: Vec3) -> bool {
    let c = at.floor();
    if !c.is_finite() || c.min_element() < 0.0 || c.max_element() >= CELLS as f32 {
        return false;
    }
    let bit = c.x as usize + CELLS * (c.y as usize + CELLS * c.z as usize);
    words[bit / 32] & (1 << (bit % 32)) != 0
}

/// `bits` grown by one cell toward each of its six neighbours. A chord between two points of a
/// gently concave surface runs a little outside it (its sagitta r²/8R), and a cell whose centre
/// is outside may hold surface: neither is air that light must go round (without it the
/// front-lit Skin1 bunny lost 18% of its red).
fn dilated(bits: &[u32]) -> Vec<u32> {
    let get = |x: usize, y: usize, z: usize| {
        let bit = x + CELLS * (y + CELLS * z);
        bits[bit / 32] & (1 << (bit % 32)) != 0
    };
    let mut out = bits.to_vec();
    for z in 0..CELLS {
        for y in 0..CELLS {
            for x in 0..CELLS {
                let near = get(x, y, z)
                    || (x > 0 && get(x - 1, y, z))
                    || (x + 1 < CELLS && get(x + 1, y, z))
                    || (y > 0 && get(x, y - 1, z))
                    || (y + 1 < CELLS && get(x, y + 1, z))
                    || (z > 0 && get(x, y, z - 1))
                    || (z + 1 < CELLS && get(x, y, z + 1));
                if near {
                    let bit = x + CELLS * (y + CELLS * z);
                    out[bit / 32] |= 1 << (bit % 32);
                }
            }
        }
    }
    out
}

/// Texels of the grid on the GPU.
pub const TEXELS: usize = 2 + 2 * GRID_TEXELS;
/// Texels of one grid's bits (bssrdf.glsl's OCCUPANCY_GRID_TEXELS).
pub const GRID_TEXELS: usize = CELLS * CELLS * CELLS / 128;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_holds_its_centre_not_its_corners() {
        let g = Occupancy::of(&Mesh::sphere(1.0, 48)).expect("closed");
        assert!(g.inside(Vec3::ZERO));
        assert!(g.inside(Vec3::new(0.9, 0.0, 0.0)));
        assert!(!g.inside(Vec3::new(0.8, 0.8, 0.0)));
        assert!(!g.inside(Vec3::splat(0.8)));
        // The cells inside fill the ball grown by the one cell of dilation, to within the cells
        // along its surface.
        let count: u32 = g.bits.iter().map(|w| w.count_ones()).sum();
        let volume = count as f32 * g.cell.x * g.cell.y * g.cell.z;
        let grown = 4.0 / 3.0 * std::f32::consts::PI * (1.0 + g.cell.x).powi(3);
        assert!((volume / grown - 1.0).abs() < 0.03, "{volume} against {grown}");
        // Before it was grown, the cells whose centres are inside fill the ball itself, and are
        // among the grown grid's.
        let centres: u32 = g.centres.iter().map(|w| w.count_ones()).sum();
        let volume = centres as f32 * g.cell.x * g.cell.y * g.cell.z;
        let ball = 4.0 / 3.0 * std::f32::consts::PI;
        assert!((volume / ball - 1.0).abs() < 0.03, "{volume} against {ball}");
        assert!(g.centres.iter().zip(&g.bits).all(|(c, b)| c & !b == 0));
        assert!(
            g.centre_inside(Vec3::new(0.9, 0.0, 0.0)) && !g.centre_inside(Vec3::new(1.0 + 0.6 * g.cell.x, 0.0, 0.0))
        );
        // Every chord of a convex body stays inside; one across the torus's hole does not.
        assert!(g.through_medium(Vec3::new(-0.99, 0.0, 0.0), Vec3::NEG_X, Vec3::new(0.0, 0.99, 0.0), Vec3::Y));
        let torus = Occupancy::of(&Mesh::torus(1.0, 0.3, 64, 32)).expect("closed");
        assert!(torus.inside(Vec3::new(1.0, 0.0, 0.0)));
        assert!(!torus.inside(Vec3::ZERO));
        // Across the hole the inner faces face each other: no way round.
        assert!(!torus.through_medium(Vec3::new(-0.7, 0.0, 0.0), Vec3::X, Vec3::new(0.7, 0.0, 0.0), Vec3::NEG_X));
        // Over the top of the tube, between points whose chord crosses the hole's rim: the arc
        // sags into the tube.
        let (p, q) = (Vec3::new(0.75, 0.0, 0.22), Vec3::new(1.25, 0.0, 0.22));
        let n = |c: Vec3| (c - Vec3::new(1.0, 0.0, 0.0)).normalize();
        assert!(torus.through_medium(p, n(p), q, n(q)));
    }

    #[test]
    fn pairs_of_a_convex_object_are_never_tested() {
        // A ball's pairs: the chord below both tangent planes, whatever the grid says.
        let empty = Occupancy {
            min: Vec3::splat(-2.0),
            cell: Vec3::splat(4.0 / CELLS as f32),
            bits: vec![0; CELLS * CELLS * CELLS / 32],
            centres: vec![0; CELLS * CELLS * CELLS / 32],
        };
        for (a, b) in [(0.1f32, 2.0f32), (0.5, 1.0), (1.5, 3.0)] {
            let (pa, pb) = (Vec3::new(a.cos(), a.sin(), 0.0), Vec3::new(b.cos(), b.sin(), 0.0));
            assert!(joined_inside(Some(&empty), pa, pa, pb, pb));
        }
        // Two points of a plane, their normals tilted by a facet's 2°: still not tested.
        let tilt = Vec3::new(0.035, 0.0, 1.0).normalize();
        assert!(joined_inside(Some(&empty), Vec3::ZERO, tilt, Vec3::X, Vec3::Z));
        // Two faces facing each other across air: tested, and the empty grid says no.
        assert!(!joined_inside(Some(&empty), Vec3::ZERO, Vec3::X, Vec3::X, Vec3::NEG_X));
        assert!(joined_inside(None, Vec3::ZERO, Vec3::X, Vec3::X, Vec3::NEG_X));
    }

    #[test]
    fn an_open_mesh_has_no_inside() {
        let mut m = Mesh::sphere(1.0, 16);
        m.indices.truncate(m.indices.len() - 3);
        assert_eq!(Occupancy::of(&m), None);
    }
}
