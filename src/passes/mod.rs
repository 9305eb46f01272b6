//! GPU passes: each is one shader (or a few stages of one) plus one file here.

pub mod background;
pub mod bssrdf_eval;
pub mod debug_view;
pub mod diffuse;
pub mod far_field;
pub mod irradiance;
pub mod reentry;
pub mod sampling;
pub mod shade;
pub mod shadow;
pub mod sort;
pub mod tile_cut;
pub mod tonemap;
pub mod tree;
