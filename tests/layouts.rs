//! Structs shared between Rust and GLSL (src/gpu/): the Rust mirror must have the offsets the SPIR-V
//! declares.

use std::mem::{offset_of, size_of};

use translucent::gpu::ShadeConstants;
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
fn shading_params_and_tree_match_glsl() {
    use translucent::gpu::{FrameParams, ObjectParams, SurfacePoint, TreeNode};
    // The object's and the frame's parameters, in both shaders that read them.
    for shader in ["shade.frag", "tile_cut.comp"] {
        let object = member_offsets(shader, "ObjectParams").expect("ObjectParams");
        let rust: Vec<u32> = [
            offset_of!(ObjectParams, channels),
            offset_of!(ObjectParams, mm_per_unit),
            offset_of!(ObjectParams, point_count),
            offset_of!(ObjectParams, node_count),
            offset_of!(ObjectParams, spacing_mm),
            offset_of!(ObjectParams, near_start_mm),
            offset_of!(ObjectParams, near_end_mm),
            offset_of!(ObjectParams, near_scale_mm),
        ]
        .iter()
        .map(|&o| o as u32)
        .collect();
        assert_eq!(object[..rust.len()], rust[..], "{shader}");
        let frame = member_offsets(shader, "FrameParams").expect("FrameParams");
        let rust: Vec<u32> = [
            offset_of!(FrameParams, epsilon),
            offset_of!(FrameParams, brute_force),
            offset_of!(FrameParams, count_work),
            offset_of!(FrameParams, specular),
            offset_of!(FrameParams, roughness),
            offset_of!(FrameParams, near_field),
            offset_of!(FrameParams, far_field),
            offset_of!(FrameParams, scattering),
        ]
        .iter()
        .map(|&o| o as u32)
        .collect();
        assert_eq!(frame[..rust.len()], rust[..], "{shader}");
    }
    assert_eq!(size_of::<ObjectParams>(), 224);
    assert_eq!(size_of::<FrameParams>(), 32);
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
        offset_of!(SurfacePoint, scatter_weight_rg),
        offset_of!(SurfacePoint, light_dir),
        offset_of!(SurfacePoint, scatter_weight_b),
    ]
    .iter()
    .map(|&o| o as u32)
    .collect();
    assert_eq!(point, rust);
    assert_eq!(size_of::<SurfacePoint>(), 64);
}

#[test]
fn light_records_match_glsl() {
    use translucent::gpu::{NodeFlux, PointFlux, PointLight};
    let point = member_offsets("hierarchy/gather_points.comp", "PointLight").expect("PointLight");
    assert_eq!(point, [offset_of!(PointLight, irradiance), offset_of!(PointLight, toward_oct)].map(|o| o as u32));
    assert_eq!(size_of::<PointLight>(), 16);
    let flux = member_offsets("hierarchy/tree_aggregate.comp", "PointFlux").expect("PointFlux");
    assert_eq!(flux, [offset_of!(PointFlux, incident) as u32]);
    assert_eq!(size_of::<PointFlux>(), 48);
    let node = member_offsets("hierarchy/tree_aggregate.comp", "NodeFlux").expect("NodeFlux");
    let rust = [offset_of!(NodeFlux, incident), offset_of!(NodeFlux, power_center), offset_of!(NodeFlux, spread2)];
    assert_eq!(node, rust.map(|o| o as u32));
    assert_eq!(size_of::<NodeFlux>(), 64);
}

#[test]
fn bssrdf_structs_match_glsl() {
    use translucent::gpu::{BssrdfQueryGpu, GpuChannel};
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
        offset_of!(BssrdfQueryGpu, table) as u32,
    ];
    assert_eq!(query, rust);
}

#[test]
fn tonemap_structs_match_glsl() {
    use translucent::gpu::{HistogramTables, TonemapConstants, HISTOGRAM_HEADER_BYTES};
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

#[test]
fn push_constants_match_glsl() {
    use translucent::gpu::{
        DebugConstants, EvalConstants, MortonConstants, RadixConstants, SampleConstants, TileCutConstants,
    };
    let offsets =
        |shader: &str, block: &str| member_offsets(shader, block).unwrap_or_else(|| panic!("{block} in {shader}"));
    assert_eq!(
        offsets("bssrdf_eval.comp", "EvalConstants"),
        [offset_of!(EvalConstants, count), offset_of!(EvalConstants, model)].map(|o| o as u32)
    );
    let sample = [
        offset_of!(SampleConstants, point_count),
        offset_of!(SampleConstants, triangle_count),
        offset_of!(SampleConstants, seed),
        offset_of!(SampleConstants, texture_kind),
        offset_of!(SampleConstants, tex1),
        offset_of!(SampleConstants, tex2),
    ];
    assert_eq!(offsets("hierarchy/sample_points.comp", "SampleConstants"), sample.map(|o| o as u32));
    let morton = [
        offset_of!(MortonConstants, bounds_min),
        offset_of!(MortonConstants, bounds_extent),
        offset_of!(MortonConstants, point_count),
    ];
    assert_eq!(offsets("hierarchy/morton.comp", "MortonConstants"), morton.map(|o| o as u32));
    let radix =
        [offset_of!(RadixConstants, count), offset_of!(RadixConstants, tile_count), offset_of!(RadixConstants, shift)];
    for shader in ["hierarchy/radix_histogram.comp", "hierarchy/radix_scan.comp", "hierarchy/radix_scatter.comp"] {
        let glsl = offsets(shader, "RadixConstants");
        assert_eq!(glsl, radix.map(|o| o as u32), "{shader}");
    }
    let cut = [
        offset_of!(TileCutConstants, tiles),
        offset_of!(TileCutConstants, pixels),
        offset_of!(TileCutConstants, capacity),
        offset_of!(TileCutConstants, object),
        offset_of!(TileCutConstants, list_tile),
        offset_of!(TileCutConstants, model),
    ];
    assert_eq!(offsets("tile_cut.comp", "TileCutConstants"), cut.map(|o| o as u32));
    use translucent::gpu::FarFieldConstants;
    let far = [
        offset_of!(FarFieldConstants, tiles),
        offset_of!(FarFieldConstants, object),
        offset_of!(FarFieldConstants, pad),
        offset_of!(FarFieldConstants, eye),
    ];
    assert_eq!(offsets("far_field.comp", "FarFieldConstants"), far.map(|o| o as u32));
    // The re-entry's three stages share one block (include/reentry.glsl).
    use translucent::gpu::ReentryConstants;
    let reentry = [
        offset_of!(ReentryConstants, patch_count),
        offset_of!(ReentryConstants, stride),
        offset_of!(ReentryConstants, point_count),
        offset_of!(ReentryConstants, epsilon),
        offset_of!(ReentryConstants, near),
        offset_of!(ReentryConstants, exit_integral),
        offset_of!(ReentryConstants, patch_area),
        offset_of!(ReentryConstants, eta),
        offset_of!(ReentryConstants, patch_spacing),
    ];
    for stage in ["reentry/exitance.comp", "reentry/gather.comp", "reentry/spread.comp"] {
        assert_eq!(offsets(stage, "ReentryConstants"), reentry.map(|o| o as u32), "{stage}");
    }
    // The surface pass, and the opaque objects' shading.
    use translucent::gpu::{DiffuseConstants, SurfaceConstants};
    let surface = [
        offset_of!(SurfaceConstants, view_projection),
        offset_of!(SurfaceConstants, tex1),
        offset_of!(SurfaceConstants, tex2),
        offset_of!(SurfaceConstants, object),
        offset_of!(SurfaceConstants, texture_kind),
    ];
    for shader in ["surface.vert", "surface.frag"] {
        let glsl = offsets(shader, "SurfaceConstants");
        assert_eq!(glsl[..surface.len()], surface.map(|o| o as u32), "{shader}");
    }
    assert_eq!(size_of::<SurfaceConstants>(), 112);
    assert_eq!(offsets("diffuse.frag", "DiffuseConstants")[0], offset_of!(DiffuseConstants, first_opaque) as u32);
    assert_eq!(size_of::<DiffuseConstants>(), 16);
    let debug = [offset_of!(DebugConstants, view_projection), offset_of!(DebugConstants, color_scale)];
    for shader in ["debug/points.vert", "debug/lines.vert"] {
        assert_eq!(offsets(shader, "DebugConstants"), debug.map(|o| o as u32), "{shader}");
    }
}

/// The constants build.rs writes into gpu_constants.glsl are the Rust ones, and the models' GPU
/// codes are those constants.
#[test]
fn shared_constants_are_the_rust_ones() {
    use translucent::gpu::{self, GLSL_CONSTANTS};
    use translucent::physics::Model;
    let value = |name: &str| GLSL_CONSTANTS.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    assert_eq!(value("MODEL_DIRECTIONAL"), Some(Model::Directional.gpu_code()));
    assert_eq!(value("MODEL_DIPOLE"), Some(Model::Dipole.gpu_code()));
    assert_eq!(value("MODEL_PBD"), Some(Model::Pbd.gpu_code()));
    assert_eq!(value("MODEL_MC"), Some(Model::Mc.gpu_code()));
    assert_ne!(Model::Directional.gpu_code(), Model::Dipole.gpu_code());
    assert_eq!(value("LEAF_BIT"), Some(gpu::LEAF_BIT));
    assert_eq!(value("RADIX_TILE"), Some(gpu::RADIX_TILE));
}

#[test]
fn lights_match_glsl() {
    use translucent::gpu::{GpuLight, LightSetHeader};
    // lights.glsl's `light_of` reads a GpuLight as 4 vec4 words in this order: position,
    // intensity, axis, then first_layer, cube, cos_falloff_start, spot as bits.
    let rust: Vec<usize> = vec![
        offset_of!(GpuLight, position),
        offset_of!(GpuLight, intensity),
        offset_of!(GpuLight, axis),
        offset_of!(GpuLight, first_layer),
        offset_of!(GpuLight, cube),
        offset_of!(GpuLight, cos_falloff_start),
        offset_of!(GpuLight, spot),
    ];
    assert_eq!(rust, [0, 16, 32, 48, 52, 56, 60]);
    assert_eq!(size_of::<GpuLight>(), 64);
    // Every shader that reads the lights (through light_at).
    for shader in ["hierarchy/irradiance.comp", "shade.frag", "diffuse.frag"] {
        let set = member_offsets(shader, "Lights").expect("Lights");
        let rust: Vec<u32> = [
            offset_of!(LightSetHeader, light_count),
            offset_of!(LightSetHeader, eta),
            offset_of!(LightSetHeader, normal_offset),
            offset_of!(LightSetHeader, matrix_base),
            size_of::<LightSetHeader>(),
        ]
        .iter()
        .map(|&o| o as u32)
        .collect();
        assert_eq!(set, rust, "{shader}");
    }
    assert_eq!(size_of::<LightSetHeader>(), 16);
}
