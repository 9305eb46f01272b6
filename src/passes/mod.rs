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

use crate::vk::{Bind, Buffer};

/// What shaders/include/sources.glsl reads of one object: its parameters, its tree, its sorted
/// points' light records and its Sd table (the far field and the re-entry's exitance bind them
/// alike, at bindings 0 to 6).
pub struct Sources<'a> {
    pub object_params: &'a Buffer,
    pub nodes: &'a Buffer,
    pub points: &'a Buffer,
    pub node_flux: &'a Buffer,
    pub point_flux: &'a Buffer,
    pub point_spread: &'a Buffer,
    pub sd_table: &'a Buffer,
}

impl<'a> Sources<'a> {
    /// Bindings 0 to 6, in sources.glsl's order.
    pub fn binds(&self) -> [Bind<'a>; 7] {
        [
            Bind::Uniform(self.object_params),
            Bind::Texels(self.nodes),
            Bind::Texels(self.points),
            Bind::Texels(self.node_flux),
            Bind::Texels(self.point_flux),
            Bind::Texels(self.point_spread),
            Bind::Texels(self.sd_table),
        ]
    }
}
