// Constants the GPU code and the Rust code share, defined here only. build.rs includes this file
// and writes every entry of `GLSL_CONSTANTS` into the generated header `gpu_constants.glsl`
// (`const uint NAME = VALUEu;`), which the shaders include; so this file must stand alone (no
// `crate::` paths, no `use`).

/// The shade pipeline's specialisation constant and the BSSRDF evaluation's push constant: the
/// directional dipole (registered in src/models.rs).
pub const MODEL_DIRECTIONAL: u32 = 0;
/// The same for the classical dipole.
pub const MODEL_DIPOLE: u32 = 1;
/// The same for photon beam diffusion (read from its Sd table like the classical dipole's).
pub const MODEL_PBD: u32 = 2;
/// The same for the half-space's Monte Carlo table (its Sd table, and the angular factors after it).
pub const MODEL_MC: u32 = 3;
/// The BSSRDF evaluation's push constant for whether a pair is joined inside its object
/// (bssrdf.glsl `joined_inside`, cross-tested against mesh::occupancy).
pub const EVAL_JOINED_INSIDE: u32 = 16;
/// Nodes of the Monte Carlo table's incidence factor and bins of its exit factor
/// (src/physics/mc_profile.rs's INCIDENCE_NODES and EXIT_BINS; checked equal in gpu::sd_table).
pub const MC_INCIDENCE_NODES: u32 = 8;
pub const MC_EXIT_BINS: u32 = 10;
/// The Monte Carlo table's light across an object (src/physics/slab_profile.rs's
/// THICKNESS_NODES, LOOKUP_NODES, ENTRIES, OBLIQUE_ROWS and FIRST_NODE_LOG2 + 8, checked equal in
/// gpu::sd_table): measured and lookup thickness nodes, radial entries per node, and the first
/// node's log2 thickness plus 8 in units of L; rows of incidence per node.
pub const SLAB_THICKNESS_NODES: u32 = 22;
pub const SLAB_LOOKUP_NODES: u32 = 43;
pub const SLAB_ENTRIES: u32 = 64;
pub const SLAB_OBLIQUE_ROWS: u32 = 6;
pub const SLAB_FIRST_NODE_LOG2_PLUS_8: u32 = 4;

/// The Monte Carlo table's curvature ratios (src/physics/curvature_profile.rs's CURVATURE_NODES
/// and FIRST_CURVATURE_LOG2 + 8, checked equal in gpu::sd_table): nodes per sign of curvature,
/// node 0's log2 curvature plus 8 in units of 1/L; and the entries per row of the shade pass's
/// table of them (gpu::sd_table::CurvatureRatios).
pub const CURVATURE_NODES: u32 = 8;
pub const CURVATURE_FIRST_LOG2_PLUS_8: u32 = 4;
pub const CURVATURE_TABLE_ENTRIES: u32 = 1024;
/// The angles of incidence of the curvature ratio rows (curvature_profile's INCIDENCE_SIN2, checked
/// equal in gpu::sd_table): their count, and sin²θi of the second and third in hundredths (the
/// first is normal incidence).
pub const CURVATURE_INCIDENCES: u32 = 3;
pub const CURVATURE_SIN2_PERCENT_1: u32 = 64;
pub const CURVATURE_SIN2_PERCENT_2: u32 = 96;
/// Entries of the Monte Carlo table's exit tilt, after the curvature rows.
pub const EXIT_TILT_ENTRIES: u32 = 256;

/// Cells per axis of the grid of an object's inside (src/mesh/occupancy.rs), after the Sd
/// table's curvature rows (a multiple of 8, so that the bits fill whole texels).
pub const OCCUPANCY_CELLS: u32 = 64;

/// Set in a tree node's child index when the child is a point (index into the sorted points).
pub const LEAF_BIT: u32 = 0x8000_0000;

/// Keys per tile of the radix sort (radix.glsl).
pub const RADIX_TILE: u32 = 256;

/// Pixels per side of the tile-cut pass's tiles, chosen per object and frame
/// (`passes::tile_cut::list_tile`): 8x8 = 64 pixels, a multiple of a GPU warp or wave, or 4x4,
/// llvmpipe's fragment block, where an 8x8 tile would span more than 1.5 point spacings.
pub const LIST_TILE_SIZES: [u32; 2] = [4, 8];
/// The list tiles that split off a far field (shaders/far_field.comp): the large ones, where a
/// tile spans less than 1.5 point spacings, so that most of its sources are far from it.
pub const FAR_FIELD_TILE: u32 = LIST_TILE_SIZES[1];
/// The pixels of such a tile at which its far field is summed (4 x 4, include/far_field.glsl).
pub const FAR_FIELD_SAMPLES: u32 = 16;
/// A tile header's frontier count meaning "no list: every pixel walks from the root" (the list
/// did not fit in the buffer this frame).
pub const WALK_FROM_ROOT: u32 = u32::MAX;
/// A tile header's last word for a list built for the near field: some pixel of the tile is
/// lit (0: none is, so the list has no points for the control variate and no pixel runs it).
pub const NEAR_FIELD_TILE: u32 = 1;
/// Steps of one tile's walk in the cut pass (it walks twice; llvmpipe ends an invocation's loops
/// after ~65k iterations in total).
pub const MAX_CUT_STEPS: u32 = 24000;
/// Evaluations in one tile's list (the shade pass loops once per evaluation), past which the cut
/// pass uses nodes whole.
pub const MAX_LIST_EVALUATIONS: u32 = 16384;
/// Entries of an Sd table (`gpu::SdTable`, bssrdf.glsl): the classical dipole's and photon beam
/// diffusion's.
pub const DIPOLE_TABLE_SIZE: u32 = 4096;

/// Every constant of the GLSL header, by its GLSL name.
pub const GLSL_CONSTANTS: &[(&str, u32)] = &[
    ("MODEL_DIRECTIONAL", MODEL_DIRECTIONAL),
    ("MODEL_DIPOLE", MODEL_DIPOLE),
    ("MODEL_PBD", MODEL_PBD),
    ("MODEL_MC", MODEL_MC),
    ("MC_INCIDENCE_NODES", MC_INCIDENCE_NODES),
    ("MC_EXIT_BINS", MC_EXIT_BINS),
    ("SLAB_THICKNESS_NODES", SLAB_THICKNESS_NODES),
    ("SLAB_LOOKUP_NODES", SLAB_LOOKUP_NODES),
    ("SLAB_ENTRIES", SLAB_ENTRIES),
    ("SLAB_OBLIQUE_ROWS", SLAB_OBLIQUE_ROWS),
    ("SLAB_FIRST_NODE_LOG2_PLUS_8", SLAB_FIRST_NODE_LOG2_PLUS_8),
    ("CURVATURE_NODES", CURVATURE_NODES),
    ("CURVATURE_TABLE_ENTRIES", CURVATURE_TABLE_ENTRIES),
    ("CURVATURE_INCIDENCES", CURVATURE_INCIDENCES),
    ("CURVATURE_SIN2_PERCENT_1", CURVATURE_SIN2_PERCENT_1),
    ("CURVATURE_SIN2_PERCENT_2", CURVATURE_SIN2_PERCENT_2),
    ("EXIT_TILT_ENTRIES", EXIT_TILT_ENTRIES),
    ("CURVATURE_FIRST_LOG2_PLUS_8", CURVATURE_FIRST_LOG2_PLUS_8),
    ("LEAF_BIT", LEAF_BIT),
    ("RADIX_TILE", RADIX_TILE),
    ("WALK_FROM_ROOT", WALK_FROM_ROOT),
    ("NEAR_FIELD_TILE", NEAR_FIELD_TILE),
    ("FAR_FIELD_TILE", FAR_FIELD_TILE),
    ("FAR_FIELD_SAMPLES", FAR_FIELD_SAMPLES),
    ("MAX_CUT_STEPS", MAX_CUT_STEPS),
    ("MAX_LIST_EVALUATIONS", MAX_LIST_EVALUATIONS),
    ("DIPOLE_TABLE_SIZE", DIPOLE_TABLE_SIZE),
    ("OCCUPANCY_CELLS", OCCUPANCY_CELLS),
    ("EVAL_JOINED_INSIDE", EVAL_JOINED_INSIDE),
];
