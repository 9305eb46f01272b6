//! The GPU point cloud and tree against CPU references and physical expectations, under validation.

mod common;

use common::{assert_clean, validated_context};
use glam::{Vec3, Vec3Swizzles};
use translucent::frame::HierarchyPasses;
use translucent::gpu::{SurfacePoint, LEAF_BIT};
use translucent::hierarchy::{reference_tree, Hierarchy, HierarchyOptions, Snapshot};
use translucent::mesh::Mesh;
use translucent::scene::Light;
use translucent::vk::BufferUsageFlags;

const ETA: f32 = 1.3;

/// Builds the hierarchy once and downloads it.
fn build(mesh: &Mesh, lights: &[Light], n: u32) -> Snapshot {
    let (ctx, counts) = validated_context();
    let vertices = translucent::vk::upload_buffer(
        &ctx,
        "vertices",
        &mesh.vertex_data(),
        BufferUsageFlags::VERTEX_BUFFER | BufferUsageFlags::STORAGE_BUFFER,
    )
    .unwrap();
    let indices = translucent::vk::upload_buffer(
        &ctx,
        "indices",
        &mesh.indices,
        BufferUsageFlags::INDEX_BUFFER | BufferUsageFlags::STORAGE_BUFFER,
    )
    .unwrap();
    let hierarchy = Hierarchy::new(
        &ctx,
        mesh,
        lights,
        &HierarchyOptions { point_count: n, shadow_resolution: 1024, eta: ETA, per_light_records: true },
    )
    .unwrap();
    let passes = HierarchyPasses::new(&ctx).unwrap();
    ctx.submit(None, |rec| passes.record(rec, &hierarchy, &vertices, &indices)).unwrap();
    let snapshot = hierarchy.download(&ctx).unwrap();
    drop((passes, hierarchy, vertices, indices));
    drop(ctx);
    assert_clean(&counts);
    snapshot
}

fn sun(toward: Vec3, e: f32) -> Light {
    Light::Directional { toward, irradiance: Vec3::splat(e) }
}

fn ft(cos: f32) -> f32 {
    translucent::physics::fresnel::transmittance(ETA as f64, cos as f64) as f32
}

#[test]
fn gpu_sort_equals_cpu_sort_and_gather_follows_it() {
    let s = build(&Mesh::from_spec("tests/data/irregular.obj").unwrap(), &[sun(Vec3::Y, 1.0)], 5000);
    let n = s.keys.len();
    // Recover the unsorted keys through the permutation, then sort (key, index) on the CPU.
    let mut unsorted = vec![[0u32; 2]; n];
    let mut seen = vec![false; n];
    for (i, &o) in s.order.iter().enumerate() {
        assert!(!seen[o as usize], "order is not a permutation");
        seen[o as usize] = true;
        unsorted[o as usize] = s.keys[i];
    }
    let key = |k: [u32; 2]| ((k[1] as u64) << 32) | k[0] as u64;
    let mut cpu: Vec<(u64, u32)> = unsorted.iter().enumerate().map(|(i, k)| (key(*k), i as u32)).collect();
    cpu.sort();
    let gpu: Vec<(u64, u32)> = s.keys.iter().zip(&s.order).map(|(k, &o)| (key(*k), o)).collect();
    assert_eq!(gpu, cpu, "GPU radix sort differs from the CPU sort");
    assert!(key(s.keys[n - 1]) < (1 << 63), "keys are 63-bit");
    for (i, &o) in s.order.iter().enumerate() {
        assert_eq!(s.sorted_points[i].position, s.points[o as usize].position);
    }
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-12)
}

fn check_tree(s: &Snapshot) {
    let n = s.sorted_points.len();
    let reference = reference_tree(&s.keys, &s.sorted_points);
    assert_eq!(reference.len(), s.nodes.len());
    let mut in_leaf = vec![0u32; n];
    let mut worst = 0.0f64;
    for (k, (g, r)) in s.nodes.iter().zip(&reference).enumerate() {
        assert_eq!(
            (g.left, g.right, g.first_point, g.point_count),
            (r.left, r.right, r.first_point, r.point_count),
            "node {k} topology"
        );
        assert!(g.point_count >= 2, "node {k} is empty or degenerate");
        for (a, b) in [(g.power.x, r.power.x), (g.power.y, r.power.y), (g.power.z, r.power.z), (g.area, r.area)] {
            let scale = r.power.max_element().max(r.area);
            worst = worst.max((a as f64 - b).abs() / scale.max(1e-30));
        }
        for c in 0..3 {
            let extent = (r.hi - r.lo).max_element().max(1e-9);
            assert!(
                ((g.center[c] as f64) - r.center[c]).abs() <= 1e-4 * extent.max(1.0),
                "node {k} centre {} vs {} (power {} vs {})",
                g.center,
                r.center,
                g.power,
                r.power
            );
        }
        // Directions: 16-bit octahedral, so ~1e-4 rad; where the children's directions cancel the
        // mean direction is noise (the root of a sphere), so only coherent nodes are compared.
        if r.normal_coherence > 0.05 {
            assert!(g.normal().as_dvec3().dot(r.normal) > 0.9999, "node {k} normal");
        }
        if r.light_coherence > 0.05 {
            assert!(g.light_dir().as_dvec3().dot(r.light_dir) > 0.9999, "node {k} light direction");
        }
        let (lo, hi) = g.bounds();
        assert!(
            lo.as_dvec3().cmple(r.lo).all() && hi.as_dvec3().cmpge(r.hi).all(),
            "node {k}: box does not contain its points"
        );
        for child in [g.left, g.right] {
            if child & LEAF_BIT != 0 {
                in_leaf[(child & !LEAF_BIT) as usize] += 1;
            } else {
                let (clo, chi) = s.nodes[child as usize].bounds();
                assert!(clo.cmpge(lo).all() && chi.cmple(hi).all(), "node {child} box outside its parent {k}");
            }
        }
    }
    assert!(worst <= 1e-4, "power/area differ from the CPU build by {worst:e}");
    // Each point's lights add up to its irradiance and to its merged record (brute force's
    // per-light records against the merged ones); the root's merged record is the points' sum.
    let lights = s.sorted_point_lights.len() / s.sorted_points.len();
    assert!(lights >= 1);
    for (i, p) in s.sorted_points.iter().enumerate() {
        let own = &s.sorted_point_lights[i * lights..(i + 1) * lights];
        let e: Vec3 = own.iter().map(|l| l.irradiance).sum();
        assert!((e - p.irradiance).abs().max_element() <= 1e-5 * p.irradiance.max_element().max(1e-30), "point {i}");
        let toward: Vec3 = own.iter().map(|l| l.irradiance.x * translucent::hierarchy::decode_oct(l.toward_oct)).sum();
        let merged = s.sorted_point_flux[i].incident[0].truncate();
        assert!((toward - merged).abs().max_element() <= 1e-5 * e.x.max(1e-30), "point {i}: {toward} vs {merged}");
    }
    let root: f64 =
        s.sorted_points.iter().zip(&s.sorted_point_flux).map(|(p, f)| (f.incident[0].w * p.area) as f64).sum();
    assert!(
        rel(s.node_flux[0].incident[0].w as f64, root) < 1e-4,
        "root flux {} vs {root}",
        s.node_flux[0].incident[0].w
    );
    assert!(in_leaf.iter().all(|&c| c == 1), "every point must sit in exactly one leaf (of one point)");
    let total: f64 = s.sorted_points.iter().map(|p| (p.irradiance.x * p.area) as f64).sum();
    assert!(rel(s.nodes[0].power.x as f64, total) < 1e-4, "root power {} vs sum {total}", s.nodes[0].power.x);
    assert_eq!(s.nodes[0].point_count as usize, n);
}

#[test]
fn gpu_tree_equals_cpu_build_and_keeps_its_invariants() {
    check_tree(&build(&Mesh::sphere(1.0, 32), &[sun(Vec3::new(1.0, 1.0, 0.3), 2.0)], 8192));
    check_tree(&build(&Mesh::from_spec("tests/data/irregular.obj").unwrap(), &[sun(Vec3::Y, 1.0)], 3001));
}

/// A jittered grid in the xz plane: triangles of many sizes.
fn irregular_grid(cells: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut state = 12345u32;
    let mut rand = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state as f32 / u32::MAX as f32) - 0.5
    };
    for i in 0..=cells {
        for j in 0..=cells {
            let interior = i > 0 && j > 0 && i < cells && j < cells;
            let jitter = if interior { Vec3::new(rand(), 0.0, rand()) * 0.8 } else { Vec3::ZERO };
            positions.push(Vec3::new(i as f32, 0.0, j as f32) + jitter);
        }
    }
    let mut indices = Vec::new();
    for i in 0..cells {
        for j in 0..cells {
            let a = i * (cells + 1) + j;
            let b = a + cells + 1;
            indices.extend_from_slice(&[a, a + 1, b, b, a + 1, b + 1]);
        }
    }
    let normals = vec![Vec3::Y; positions.len()];
    Mesh { positions, normals, indices }
}

/// Each triangle's area, the total area (f64) and how many points fell on each triangle.
fn points_per_triangle(mesh: &Mesh, s: &Snapshot) -> (Vec<f32>, f64, Vec<u32>) {
    let areas = mesh.triangle_areas();
    let total: f64 = areas.iter().map(|&a| a as f64).sum();
    let mut counts = vec![0u32; areas.len()];
    for p in &s.points {
        counts[p.triangle as usize] += 1;
    }
    (areas, total, counts)
}

#[test]
fn samples_are_uniform_by_area() {
    let mesh = irregular_grid(20);
    let n = 24_000u32;
    let s = build(&mesh, &[sun(Vec3::Y, 1.0)], n);
    let (areas, total, counts) = points_per_triangle(&mesh, &s);
    let chi2: f64 = counts
        .iter()
        .zip(&areas)
        .map(|(&o, &a)| {
            let e = n as f64 * a as f64 / total;
            (o as f64 - e).powi(2) / e
        })
        .sum();
    let dof = (areas.len() - 1) as f64;
    // Upper 0.1% point of chi-square, normal approximation.
    let critical = dof + 3.09 * (2.0 * dof).sqrt();
    println!("chi-square {chi2:.1} with {dof} degrees of freedom (critical {critical:.1})");
    assert!(chi2 < critical);
    // And the points lie on their triangles.
    for p in s.points.iter().take(500) {
        assert!(p.position.y.abs() < 1e-5 && (p.normal - Vec3::Y).length() < 1e-5);
    }
}

#[test]
fn flat_lit_plane_has_no_self_shadowing() {
    let slab = Mesh::slab(4.0, 4.0, 1.0);
    let s = build(&slab, &[sun(Vec3::Y, 3.0)], 8192);
    let expected = 3.0 * ft(1.0);
    let top: Vec<&SurfacePoint> = s.points.iter().filter(|p| p.normal.y > 0.99).collect();
    assert!(top.len() > 1000);
    for p in top {
        assert!((p.irradiance.x - expected).abs() < 1e-4 * expected, "{p:?}");
        assert!((p.light_dir - Vec3::Y).length() < 1e-5);
    }
}

fn merge(a: &Mesh, b: &Mesh) -> Mesh {
    let base = a.positions.len() as u32;
    Mesh {
        positions: a.positions.iter().chain(&b.positions).copied().collect(),
        normals: a.normals.iter().chain(&b.normals).copied().collect(),
        indices: a.indices.iter().copied().chain(b.indices.iter().map(|i| i + base)).collect(),
    }
}

#[test]
fn occluded_points_get_no_irradiance() {
    let floor = Mesh::slab(6.0, 6.0, 0.2);
    let blocker = Mesh::slab(2.0, 2.0, 0.2).scaled(1.0);
    let blocker =
        Mesh { positions: blocker.positions.iter().map(|p| *p + Vec3::new(0.0, 1.5, 0.0)).collect(), ..blocker };
    let s = build(&merge(&floor, &blocker), &[sun(Vec3::Y, 1.0)], 16_384);
    let shadowed: Vec<&SurfacePoint> = s
        .points
        .iter()
        .filter(|p| p.normal.y > 0.99 && p.position.y < 0.2 && p.position.xz().abs().max_element() < 0.8)
        .collect();
    let lit: Vec<&SurfacePoint> = s
        .points
        .iter()
        .filter(|p| p.normal.y > 0.99 && p.position.y < 0.2 && p.position.xz().abs().min_element() > 1.5)
        .collect();
    assert!(shadowed.len() > 50 && lit.len() > 50);
    assert!(shadowed.iter().all(|p| p.irradiance == Vec3::ZERO), "points under the blocker are lit");
    assert!(lit.iter().all(|p| p.irradiance.x > 0.9 * ft(1.0)), "open floor points are dark");
}

#[test]
fn sphere_lit_from_one_side_splits_at_the_terminator() {
    let light = Vec3::X;
    let s = build(&Mesh::sphere(1.0, 48), &[sun(light, 1.0)], 8192);
    for p in &s.points {
        let cos = p.normal.dot(light);
        if cos < 0.0 {
            assert_eq!(p.irradiance, Vec3::ZERO, "unlit half: {p:?}");
        } else if cos > 0.1 {
            let expected = cos * ft(cos);
            assert!((p.irradiance.x - expected).abs() < 1e-3 + 1e-3 * expected, "lit half: {p:?} expected {expected}");
        }
    }
}

#[test]
fn irradiance_of_two_lights_is_the_sum_of_each() {
    let mesh = Mesh::torus(1.0, 0.35, 48, 24);
    let a = sun(Vec3::new(0.3, 1.0, 0.2), 1.0);
    let b = Light::Point { position: Vec3::new(-2.0, 1.5, 1.0), intensity: Vec3::new(4.0, 2.0, 1.0) };
    let both = build(&mesh, &[a, b], 4096);
    let only_a = build(&mesh, &[a], 4096);
    let only_b = build(&mesh, &[b], 4096);
    let mut lit_by_b = 0;
    for ((ab, pa), pb) in both.points.iter().zip(&only_a.points).zip(&only_b.points) {
        assert_eq!(ab.position, pa.position);
        let sum = pa.irradiance + pb.irradiance;
        assert!((ab.irradiance - sum).abs().max_element() <= 1e-5 * sum.max_element().max(1.0), "{ab:?} vs {sum}");
        lit_by_b += (pb.irradiance.x > 0.0) as u32;
    }
    assert!(lit_by_b > 100, "the point light must light part of the torus");
    // Each light's own records are those of that light alone, and the merged records of both
    // are the sums of each alone (points and nodes).
    for (k, single) in [&only_a, &only_b].into_iter().enumerate() {
        for (i, record) in single.sorted_point_lights.iter().enumerate() {
            assert_eq!(both.sorted_point_lights[2 * i + k].irradiance, record.irradiance, "point {i}, light {k}");
        }
    }
    let close = |x: glam::Vec4, y: glam::Vec4| (x - y).abs().max_element() <= 1e-5 * y.abs().max_element().max(1e-3);
    for (i, ab) in both.sorted_point_flux.iter().enumerate() {
        for c in 0..3 {
            let sum = only_a.sorted_point_flux[i].incident[c] + only_b.sorted_point_flux[i].incident[c];
            assert!(close(ab.incident[c], sum), "point {i} channel {c}: {:?} vs {sum:?}", ab.incident[c]);
        }
    }
    for (n, ab) in both.node_flux.iter().enumerate() {
        for c in 0..3 {
            let sum = only_a.node_flux[n].incident[c] + only_b.node_flux[n].incident[c];
            assert!(close(ab.incident[c], sum), "node {n} channel {c}: {:?} vs {sum:?}", ab.incident[c]);
        }
    }
}

/// Two triangles making the unit square in the xz plane.
fn unit_square() -> Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 0.0, 1.0), Vec3::Z];
    Mesh { positions, normals: vec![Vec3::Y; 4], indices: vec![0, 2, 1, 0, 3, 2] }
}

/// Variance over mean of the point counts in `cells` × `cells` squares of the unit square: 1 for
/// independent uniform points (Poisson), below for stratified ones, far above for clumps.
fn cell_count_dispersion(points: &[SurfacePoint], cells: usize) -> (f64, u32, u32) {
    let mut counts = vec![0u32; cells * cells];
    for p in points {
        let (x, z) = (p.position.x.clamp(0.0, 0.999_999), p.position.z.clamp(0.0, 0.999_999));
        counts[(z * cells as f32) as usize * cells + (x * cells as f32) as usize] += 1;
    }
    let mean = points.len() as f64 / counts.len() as f64;
    let variance = counts.iter().map(|&c| (c as f64 - mean).powi(2)).sum::<f64>() / counts.len() as f64;
    (variance / mean, *counts.iter().min().unwrap(), *counts.iter().max().unwrap())
}

/// At the sizes a user may ask for, the barycentrics must not fall onto a lattice: an R2
/// sequence computed as `fract(float(i) · α)` in f32 has only a few distinct values past a
/// million points (at i = 1.6M the product's spacing is 1/8), so points clump.
#[test]
fn samples_stay_uniform_at_one_and_a_half_million_points() {
    let n = 1_500_000u32;
    let s = build(&unit_square(), &[sun(Vec3::Y, 1.0)], n);
    let cells = 300;
    let (dispersion, min, max) = cell_count_dispersion(&s.points, cells);
    println!(
        "{n} points in {cells}² cells, {:.1} per cell: variance/mean {dispersion:.4}, min {min}, max {max}",
        n as f64 / (cells * cells) as f64
    );
    // Independent uniform points give 1; stratified low-discrepancy points far less.
    assert!(dispersion < 0.25, "points clump (variance/mean of cell counts {dispersion})");
}

/// The points that fall in any run of consecutive triangles are, by the stratification along the
/// area prefix sum, N × (their area / total area) within ±1 — for a mesh of two million triangles
/// too, where an f32 running sum of areas has lost the small triangles' areas to rounding.
#[test]
fn stratification_holds_over_two_million_triangles() {
    let mesh = irregular_grid(1000);
    let n = 1_000_003u32;
    let s = build(&mesh, &[sun(Vec3::Y, 1.0)], n);
    let (areas, total, counts) = points_per_triangle(&mesh, &s);
    let group = 2000;
    let mut worst = 0.0f64;
    let (mut cumulative_area, mut cumulative_count) = (0.0f64, 0u64);
    for (g, (a, c)) in areas.chunks(group).zip(counts.chunks(group)).enumerate() {
        cumulative_area += a.iter().map(|&x| x as f64).sum::<f64>();
        cumulative_count += c.iter().map(|&x| x as u64).sum::<u64>();
        // Points before the end of group g: stratum i covers [i, i + 1) · total / N.
        let expected = n as f64 * cumulative_area / total;
        let off = cumulative_count as f64 - expected;
        if off.abs() > worst {
            worst = off.abs();
            println!("group {g}: {cumulative_count} points before its end, expected {expected:.2}");
        }
    }
    println!("{} triangles, {n} points: worst cumulative count off by {worst:.2} points", areas.len());
    assert!(worst <= 1.5, "the stratification drifts by {worst:.2} points");
}

/// The sampling pass checks the bytes its shaders will touch against the buffers bound (the
/// validation layer's GPU-assisted mode, which would catch a shader writing past a buffer's end,
/// does not run on lavapipe): a prefix sum sized as `Hierarchy::set_mesh` once re-allocated it,
/// a quarter of what the triangles need, is refused by name before anything is submitted.
#[test]
fn sampling_refuses_buffers_smaller_than_its_counts_need() {
    use translucent::passes::sampling::{prefix_bytes, SamplingPass};
    use translucent::vk::{Buffer, MemoryLocation};
    let (ctx, counts) = validated_context();
    let mesh = Mesh::sphere(1.0, 16);
    let storage = BufferUsageFlags::STORAGE_BUFFER;
    let vertices = translucent::vk::upload_buffer(&ctx, "vertices", &mesh.vertex_data(), storage).unwrap();
    let indices = translucent::vk::upload_buffer(&ctx, "indices", &mesh.indices, storage).unwrap();
    let t = mesh.triangle_count() as u32;
    let buffer = |name: &str, bytes: u64| Buffer::new(&ctx, name, bytes, storage, MemoryLocation::GpuOnly).unwrap();
    let points = buffer("points", 1000 * 64);
    let pass = SamplingPass::new(&ctx).unwrap();
    let white = translucent::world::Reflectance::Constant(glam::Vec3::ONE);
    let none = translucent::gpu_world::SurfaceTexture::new(&ctx, &white, None, 1).unwrap();
    let old_size = buffer("triangle area prefix sum", (t as u64 + 1) * 4);
    let e = ctx
        .submit(None, |rec| pass.record(rec, &vertices, &indices, &none, t, &old_size, &points, 1000, 1))
        .unwrap_err();
    assert!(e.to_string().contains("triangle area prefix sum"), "{e}");
    assert_eq!(prefix_bytes(t), 8 + (t as u64 + 1) * 8);
    let right = buffer("triangle area prefix sum", prefix_bytes(t));
    ctx.submit(None, |rec| pass.record(rec, &vertices, &indices, &none, t, &right, &points, 1000, 1)).unwrap();
    let e =
        ctx.submit(None, |rec| pass.record(rec, &vertices, &indices, &none, t, &right, &points, 1001, 1)).unwrap_err();
    assert!(e.to_string().contains("points"), "{e}");
    drop((pass, old_size, right, points, vertices, indices, none));
    drop(ctx);
    assert_clean(&counts);
}

/// A narrow spot above a sphere lights only the cap inside its cone: there each point's
/// irradiance is I cos θi Ft / d² (the falloff is 1 well inside), beyond the cone nothing.
#[test]
fn a_spot_lights_only_the_points_inside_its_cone() {
    let (position, cone, delta) = (Vec3::new(0.0, 3.0, 0.5), 12.0f32, 2.0f32);
    // Aimed off the centre, so that the cap is on one side.
    let target = Vec3::new(0.3, 0.0, 0.0);
    let spot = Light::spot(position, target, cone, delta, Vec3::splat(9.0)).unwrap();
    let s = build(&Mesh::sphere(1.0, 48), &[spot], 16_384);
    let axis = (target - position).normalize();
    let (mut inside, mut outside) = (0, 0);
    for p in &s.points {
        let d = p.position - position;
        let angle = d.normalize().dot(axis).clamp(-1.0, 1.0).acos().to_degrees();
        let cos_i = p.normal.dot(-d.normalize());
        if angle > cone + 0.2 {
            assert_eq!(p.irradiance, Vec3::ZERO, "outside the cone ({angle}°): {p:?}");
            outside += 1;
        } else if angle < cone - delta - 0.2 && cos_i > 0.1 {
            let expected = 9.0 * cos_i * ft(cos_i) / d.length_squared();
            assert!(
                (p.irradiance.x - expected).abs() < 1e-3 * expected,
                "inside ({angle}°): {p:?} expected {expected}"
            );
            inside += 1;
        }
    }
    assert!(inside > 200 && outside > 10_000, "{inside} points lit inside the cone, {outside} outside");
}

/// The shadow pass writes, at each texel the mesh covers, the mesh's interpolated normal and its
/// mean curvature there (shade.frag refracts single scattering's light and focuses its beam by
/// them): on a ball of radius 2 lit from an oblique direction, every covered texel holds
/// curvature 1/2 (the vertices' exactly, interpolated) and the ball's normal where the light's
/// ray through the texel meets it, within 1°; no texel off the ball is written.
#[test]
fn shadow_pass_writes_the_mesh_normal_and_curvature_at_each_texel() {
    use translucent::hierarchy::decode_oct;
    use translucent::passes::shadow::Caster;
    use translucent::shadows::Shadows;
    use translucent::vk::{upload_buffer, Buffer, MemoryLocation};
    let radius = 2.0f32;
    let mesh = Mesh::sphere(radius, 64);
    let curvature = translucent::mesh::curvature::mean_curvature(&mesh);
    let toward = Vec3::new(0.3, 0.8, 0.5).normalize();
    let light = [sun(toward, 1.0)];
    let resolution = 128u32;
    let (ctx, counts) = validated_context();
    let (texels, matrix) = {
        let storage = BufferUsageFlags::STORAGE_BUFFER;
        let vertices =
            upload_buffer(&ctx, "vertices", &mesh.vertex_data(), BufferUsageFlags::VERTEX_BUFFER | storage).unwrap();
        let indices = upload_buffer(&ctx, "indices", &mesh.indices, BufferUsageFlags::INDEX_BUFFER | storage).unwrap();
        let curvature = upload_buffer(&ctx, "curvature", &curvature, storage).unwrap();
        let mut shadows = Shadows::new(&ctx, &light, resolution, ETA).unwrap();
        shadows.set_lights(Vec3::ZERO, radius, &light).unwrap();
        let count = (resolution * resolution) as usize;
        let readback = Buffer::new(
            &ctx,
            "normals read back",
            8 * count as u64,
            BufferUsageFlags::TRANSFER_DST | BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )
        .unwrap();
        let passes = HierarchyPasses::new(&ctx).unwrap();
        let casters: [Caster; 1] = [(&vertices, &indices, mesh.indices.len() as u32, &curvature)];
        ctx.submit(None, |rec| {
            passes.record_shadows(rec, &casters, &shadows)?;
            rec.copy_image_to_buffer(&shadows.shadow_normals, &readback)
        })
        .unwrap();
        let texels: Vec<[u32; 2]> = translucent::vk::download_buffer(&ctx, &readback, count).unwrap();
        (texels, shadows.layer_matrices()[0])
    };
    drop(ctx);
    assert_clean(&counts);
    let unproject = matrix.inverse();
    let (mut covered, mut worst_angle, mut worst_curvature) = (0, 0.0f32, 0.0f32);
    for (i, &[normal, curvature]) in texels.iter().enumerate() {
        let (x, y) = (i as u32 % resolution, i as u32 / resolution);
        let ndc = |z: f32| {
            let v = [x, y].map(|c| (c as f32 + 0.5) / resolution as f32 * 2.0 - 1.0);
            unproject.project_point3(Vec3::new(v[0], v[1], z))
        };
        // The light's ray through the texel's centre, from the near plane: where it meets the ball.
        let (p0, p1) = (ndc(0.0), ndc(1.0));
        let d = (p1 - p0).normalize();
        let b = p0.dot(d);
        let disc = b * b - (p0.length_squared() - radius * radius);
        if normal == 0 && curvature == 0 {
            // Unwritten: only off the ball (or within a texel of its rim, the mesh's polygon).
            assert!(disc < 0.05 * radius * radius, "texel {x},{y} meets the ball but holds nothing");
            continue;
        }
        assert!(disc > -0.05 * radius * radius, "texel {x},{y} off the ball holds {normal:#x}, {curvature}");
        let k = f32::from_bits(curvature);
        worst_curvature = worst_curvature.max((k * radius - 1.0).abs());
        // Away from the rim, where the polygon and the ball part.
        if disc > 0.1 * radius * radius {
            let hit = p0 + d * (-b - disc.sqrt());
            let angle = decode_oct(normal).dot(hit / radius).clamp(-1.0, 1.0).acos().to_degrees();
            worst_angle = worst_angle.max(angle);
            covered += 1;
        }
    }
    println!("{covered} texels: normal within {worst_angle:.3}°, curvature × R within {worst_curvature:.2e} of 1");
    assert!(covered > 5000, "{covered} texels covered");
    assert!(worst_angle < 1.0, "normal {worst_angle}° from the ball's");
    assert!(worst_curvature < 1e-3, "curvature {worst_curvature} off 1/R");
}
