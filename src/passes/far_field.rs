//! The far-field pass (shaders/far_field.comp): per 8x8 list tile that has a far field (the tile
//! cut decides), the sum of its far sources at nine of its pixels, which the shade pass
//! interpolates at each of the 64 (include/far_field.glsl). Reads: the object's parameters, tree
//! nodes, sorted points and their light records, the Sd table, the G-buffer's positions and
//! normals, the tile cut's far headers and list entries. Writes: the nine sums per tile.

use std::collections::HashMap;

use crate::error::Result;
use crate::gpu::{FarFieldConstants, FAR_FIELD_SAMPLES, FAR_FIELD_TILE};
use crate::passes::tile_cut::TileLists;
use crate::passes::Sources;
use crate::physics::Model;
use crate::vk::{Bind, Context, Image, Pipeline, Recorder};

/// What one object's far field reads: its sources, and the G-buffer's positions and normals.
pub struct FarFieldInputs<'a> {
    pub sources: Sources<'a>,
    pub position: &'a Image,
    pub normal: &'a Image,
}

/// One pipeline per model and light count (far_field.comp's specialisation constants, as the
/// shade pass's), made when a frame first needs it.
#[derive(Default)]
pub struct FarFieldPass {
    pipelines: HashMap<(Model, bool), Pipeline>,
}

impl FarFieldPass {
    /// Makes the pipeline for `model` with one light or several, if not made yet.
    pub fn prepare(&mut self, ctx: &Context, model: Model, one_light: bool) -> Result<()> {
        if let std::collections::hash_map::Entry::Vacant(slot) = self.pipelines.entry((model, one_light)) {
            let specialization = [model.gpu_code(), one_light as u32];
            slot.insert(Pipeline::compute_specialized(ctx, "far_field.comp", &specialization)?);
        }
        Ok(())
    }

    /// The nine sums of every tile of `lists` (which must be of 8x8 tiles) for `object`, seen
    /// from `eye` (the Monte Carlo table's exit tilt leans toward it).
    pub fn record(
        &self,
        rec: &mut Recorder,
        (model, one_light): (Model, bool),
        inputs: &FarFieldInputs,
        lists: &TileLists,
        (object, eye): (u32, [f32; 4]),
    ) -> Result<()> {
        if lists.list_tile != FAR_FIELD_TILE {
            return Err(crate::runtime!(
                "far field: lists of {0}x{0} tiles, not {1}x{1}",
                lists.list_tile,
                FAR_FIELD_TILE
            ));
        }
        let pipeline = self
            .pipelines
            .get(&(model, one_light))
            .ok_or_else(|| crate::runtime!("far field: the pipeline of {model:?} was not prepared"))?;
        let constants = FarFieldConstants { tiles: lists.tiles, object, pad: 0, eye };
        let [params, nodes, points, node_flux, point_flux, point_spread, sd_table] = inputs.sources.binds();
        rec.dispatch(
            pipeline,
            &[
                params,
                nodes,
                points,
                node_flux,
                point_flux,
                point_spread,
                sd_table,
                Bind::StorageImageRead(inputs.position),
                Bind::StorageImageRead(inputs.normal),
                Bind::Texels(&lists.far_headers),
                Bind::Texels(&lists.entries),
                Bind::Write(&lists.far_field),
            ],
            bytemuck::bytes_of(&constants),
            // Eight invocations per group: a tile's nine samples side by side along x.
            [(lists.tiles[0] * FAR_FIELD_SAMPLES).div_ceil(8), lists.tiles[1], 1],
        )
    }
}
