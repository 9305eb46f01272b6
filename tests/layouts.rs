//! Structs shared between Rust and GLSL: the Rust mirror must have the offsets the SPIR-V declares.

use std::mem::{offset_of, size_of};

use translucent::passes::shade::ShadeConstants;
use translucent::shaders::member_offsets;

#[test]
fn shade_constants_match_glsl() {
    let glsl = member_offsets("shade.frag", "ShadeConstants").expect("ShadeConstants in shade.frag");
    let rust = vec![
        offset_of!(ShadeConstants, view_projection) as u32,
        offset_of!(ShadeConstants, eye) as u32,
        offset_of!(ShadeConstants, point_range) as u32,
    ];
    assert_eq!(glsl, rust);
    assert_eq!(size_of::<ShadeConstants>(), 96);
}

#[test]
fn subsurface_params_and_tree_match_glsl() {
    use translucent::hierarchy::{SurfacePoint, TreeNode};
    use translucent::passes::shade::SubsurfaceParams;
    let params = member_offsets("shade.frag", "SubsurfaceParams").expect("SubsurfaceParams");
    let rust: Vec<u32> = [
        offset_of!(SubsurfaceParams, channels),
        offset_of!(SubsurfaceParams, mm_per_unit),
        offset_of!(SubsurfaceParams, epsilon),
        offset_of!(SubsurfaceParams, model),
        offset_of!(SubsurfaceParams, brute_force),
        offset_of!(SubsurfaceParams, point_count),
        offset_of!(SubsurfaceParams, node_count),
        offset_of!(SubsurfaceParams, count_work),
        offset_of!(SubsurfaceParams, specular),
        offset_of!(SubsurfaceParams, roughness),
        offset_of!(SubsurfaceParams, dipole_reach),
    ]
    .iter()
    .map(|&o| o as u32)
    .collect();
    assert_eq!(params[..rust.len()], rust[..]);
    assert_eq!(size_of::<SubsurfaceParams>(), 240);
    let node = member_offsets("hierarchy/tree_aggregate.comp", "TreeNode").expect("TreeNode");
    let rust: Vec<u32> = [
        offset_of!(TreeNode, power),
        offset_of!(TreeNode, area),
        offset_of!(TreeNode, center),
        offset_of!(TreeNode, left),
        offset_of!(TreeNode, box_half),
        offset_of!(TreeNode, right),
        offset_of!(TreeNode, normal_oct),
        offset_of!(TreeNode, light_oct),
        offset_of!(TreeNode, first_point),
        offset_of!(TreeNode, point_count),
    ]
    .iter()
    .map(|&o| o as u32)
    .collect();
    assert_eq!(node, rust);
    assert_eq!(size_of::<TreeNode>(), 64);
    let point = member_offsets("hierarchy/tree_aggregate.comp", "SurfacePoint").expect("SurfacePoint");
    let rust: Vec<u32> = [
        offset_of!(SurfacePoint, position),
        offset_of!(SurfacePoint, area),
        offset_of!(SurfacePoint, normal),
        offset_of!(SurfacePoint, triangle),
        offset_of!(SurfacePoint, irradiance),
        offset_of!(SurfacePoint, pad0),
        offset_of!(SurfacePoint, light_dir),
        offset_of!(SurfacePoint, pad1),
    ]
    .iter()
    .map(|&o| o as u32)
    .collect();
    assert_eq!(point, rust);
    assert_eq!(size_of::<SurfacePoint>(), 64);
}

#[test]
fn light_records_match_glsl() {
    use translucent::hierarchy::{NodeLight, PointLight};
    let point = member_offsets("hierarchy/tree_aggregate.comp", "PointLight").expect("PointLight");
    assert_eq!(point, [offset_of!(PointLight, irradiance), offset_of!(PointLight, toward_oct)].map(|o| o as u32));
    assert_eq!(size_of::<PointLight>(), 16);
    let node = member_offsets("hierarchy/tree_aggregate.comp", "NodeLight").expect("NodeLight");
    let rust = [
        offset_of!(NodeLight, power),
        offset_of!(NodeLight, toward_oct),
        offset_of!(NodeLight, power_center),
        offset_of!(NodeLight, spread2),
    ];
    assert_eq!(node, rust.map(|o| o as u32));
    assert_eq!(size_of::<NodeLight>(), 32);
}

#[test]
fn bssrdf_structs_match_glsl() {
    use translucent::passes::bssrdf_eval::BssrdfQueryGpu;
    use translucent::physics::GpuChannel;
    let channel = member_offsets("bssrdf_eval.comp", "BssrdfChannel").expect("BssrdfChannel");
    assert_eq!(channel, (0..16).map(|i| i * 4).collect::<Vec<u32>>());
    assert_eq!(size_of::<GpuChannel>(), 64);
    let query = member_offsets("bssrdf_eval.comp", "BssrdfQuery").expect("BssrdfQuery");
    let rust = vec![
        offset_of!(BssrdfQueryGpu, channel) as u32,
        offset_of!(BssrdfQueryGpu, xi) as u32,
        offset_of!(BssrdfQueryGpu, ni) as u32,
        offset_of!(BssrdfQueryGpu, wi) as u32,
        offset_of!(BssrdfQueryGpu, xo) as u32,
        offset_of!(BssrdfQueryGpu, no) as u32,
    ];
    assert_eq!(query, rust);
}

#[test]
fn tonemap_structs_match_glsl() {
    use translucent::passes::tonemap::{HistogramTables, TonemapConstants, HISTOGRAM_HEADER_BYTES};
    let tables = member_offsets("tonemap.comp", "HistogramTables").expect("HistogramTables");
    let rust: Vec<u32> = [
        offset_of!(HistogramTables, thresholds),
        offset_of!(HistogramTables, inv_centres),
        offset_of!(HistogramTables, log2_min),
        offset_of!(HistogramTables, bin_count),
    ]
    .iter()
    .map(|&o| o as u32)
    .collect();
    // The offsets also pin the GLSL array lengths to HIST_BINS_PER_STOP.
    assert_eq!(tables, rust);
    let constants = member_offsets("tonemap.comp", "TonemapConstants").expect("TonemapConstants");
    let rust: Vec<u32> = [
        offset_of!(TonemapConstants, stage),
        offset_of!(TonemapConstants, width),
        offset_of!(TonemapConstants, height),
        offset_of!(TonemapConstants, fixed_exposure),
        offset_of!(TonemapConstants, fixed_scale),
    ]
    .iter()
    .map(|&o| o as u32)
    .collect();
    assert_eq!(constants, rust);
    let histogram = member_offsets("tonemap.comp", "Histogram").expect("Histogram");
    assert_eq!(histogram.last().copied(), Some(HISTOGRAM_HEADER_BYTES as u32), "bins follow the header");
}

/// Constants the shaders and Rust share, written in both: the tile lists' and the dipole table's.
#[test]
fn shared_constants_match_glsl() {
    let read = |path: &str| std::fs::read_to_string(format!("{}/shaders/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let tiles = read("include/tile_lists.glsl");
    let tile_size = translucent::passes::tile_cut::TILE_SIZE;
    assert!(tiles.contains(&format!("const uint TILE_SIZE = {tile_size}u;")), "TILE_SIZE");
    assert_eq!(translucent::passes::tile_cut::WALK_FROM_ROOT, u32::MAX);
    assert!(tiles.contains("const uint WALK_FROM_ROOT = 0xffffffffu;"), "WALK_FROM_ROOT");
    let table_size = translucent::physics::dipole::TABLE_SIZE;
    assert!(read("include/bssrdf.glsl").contains(&format!("const uint DIPOLE_TABLE_SIZE = {table_size}u;")));
}
