//! Meshes: procedural shapes are closed and consistently wound; OBJ files load, merge and get
//! normals; malformed files are refused with the reason.

mod common;

use glam::Vec3;
use translucent::mesh::Mesh;

/// Every triangle's winding normal agrees with its vertex normals (counter-clockwise outside).
fn assert_winding_matches_normals(mesh: &Mesh, what: &str) {
    for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| mesh.positions[i as usize]);
        let geometric = (b - a).cross(c - a);
        if geometric.length() < 1e-9 {
            continue;
        }
        let shading: Vec3 = tri.iter().map(|&i| mesh.normals[i as usize]).sum();
        assert!(geometric.dot(shading) > 0.0, "{what}: triangle {t} is wound against its normals");
    }
}

/// A closed mesh crosses each edge once each way, welded by position (the built-in shapes' seams
/// and a slab's faces duplicate vertices); a hole, a flipped triangle or a mesh without
/// triangles is not closed. At two million triangles too (the inside grid and every mesh load
/// ask; it answers from sorted edge lists).
#[test]
fn closed_meshes_are_told_from_open_and_misturned_ones() {
    for (name, mesh) in [
        ("sphere", Mesh::sphere(1.0, 48)),
        ("slab", Mesh::slab(4.0, 4.0, 1.0)),
        ("torus", Mesh::torus(1.0, 0.35, 64, 32)),
        ("large sphere", Mesh::sphere(1.0, 724)),
    ] {
        assert!(mesh.is_closed(), "{name}");
        let mut holed = mesh.clone();
        holed.indices.truncate(holed.indices.len() - 3);
        assert!(!holed.is_closed(), "{name} less its last triangle");
        let mut flipped = mesh.clone();
        flipped.indices.swap(0, 1);
        assert!(!flipped.is_closed(), "{name} with a triangle wound the other way");
        // Two triangles back to back over the last one's edges: every edge crossed once each
        // way more, still closed (a zero-volume fin).
        let mut finned = mesh.clone();
        let last: Vec<u32> = mesh.indices[mesh.indices.len() - 3..].to_vec();
        finned.indices.extend([last[0], last[2], last[1], last[0], last[1], last[2]]);
        assert!(finned.is_closed(), "{name} with a fin");
    }
    let mut empty = Mesh::sphere(1.0, 8);
    empty.indices.clear();
    assert!(!empty.is_closed(), "no triangles");
}

#[test]
fn procedural_shapes_are_valid_and_wound_outward() {
    for (name, mesh, area) in [
        ("sphere", Mesh::sphere(1.0, 48), 4.0 * std::f32::consts::PI),
        ("slab", Mesh::slab(4.0, 4.0, 1.0), 2.0 * 16.0 + 4.0 * 4.0),
        ("torus", Mesh::torus(1.0, 0.35, 64, 32), 4.0 * std::f32::consts::PI.powi(2) * 0.35),
    ] {
        mesh.validate().unwrap();
        assert_winding_matches_normals(&mesh, name);
        let rel = (mesh.surface_area() - area).abs() / area;
        assert!(rel < 0.01, "{name}: area {} vs {area}", mesh.surface_area());
        for n in &mesh.normals {
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
    }
}

#[test]
fn obj_objects_are_merged_and_normals_computed() {
    let mesh = Mesh::load_obj(&common::repo_path("tests/data/tetra_two_objects.obj")).unwrap();
    assert_eq!(mesh.triangle_count(), 4);
    assert_winding_matches_normals(&mesh, "tetrahedron");
    // The vertex at the origin is shared by three faces whose normals are -x, -y, -z.
    let origin = mesh.positions.iter().position(|p| *p == Vec3::ZERO).unwrap();
    let n = mesh.normals[origin];
    assert!((n - Vec3::splat(-1.0).normalize()).length() < 1e-5, "{n}");
}

#[test]
fn malformed_obj_files_are_refused_with_the_reason() {
    for (file, reason) in [
        ("garbage.obj", "not an OBJ statement"),
        ("truncated_face.obj", "at least 3 vertices"),
        ("index_out_of_range.obj", "out of range"),
        ("empty.obj", "no faces"),
        ("nan_vertex.obj", "not finite"),
        ("zero_area.obj", "zero surface area"),
        // Cases found by reading tobj 4.0.5: it drops or misreads these without an error.
        ("normal_index_out_of_range.obj", "normal index"),
        ("normal_index_negative.obj", "normal index -3"),
        ("texcoord_index_out_of_range.obj", "texture coordinate index"),
        ("forward_reference.obj", "out of range"),
        ("index_zero.obj", "vertex index 0"),
        ("inf_vertex.obj", "not finite"),
        ("index_out_of_range_negative.obj", "out of range"),
    ] {
        let err = Mesh::load_obj(&common::repo_path(&format!("tests/data/{file}"))).unwrap_err();
        assert_eq!(err.exit_code(), 2, "{file}");
        let msg = err.to_string();
        assert!(msg.contains(file) && msg.contains(reason), "{file}: {msg}");
    }
    let missing = Mesh::load_obj(std::path::Path::new("/nonexistent.obj")).unwrap_err();
    assert!(missing.to_string().contains("/nonexistent.obj"));
}

#[test]
fn stanford_bunny_loads_when_installed() {
    let path = std::path::Path::new(translucent::settings::BUNNY);
    if !path.exists() {
        eprintln!("skipped: {} is not installed (Debian package glmark2-data)", path.display());
        return;
    }
    let mesh = Mesh::load_obj(path).unwrap();
    assert_eq!(mesh.positions.len(), 34_835);
    assert_eq!(mesh.triangle_count(), 69_666);
    assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
}
