//! The Karras binary radix tree over the sorted keys, then its bottom-up summaries.
//! Reads: sorted keys, sorted points and their light records. Writes: nodes and their light
//! records, parent links, arrival counters.

use crate::error::Result;
use crate::vk::{Bind, Buffer, Context, Pipeline, Recorder};

pub struct TreeBuffers<'a> {
    pub keys: &'a Buffer,
    pub sorted_points: &'a Buffer,
    pub nodes: &'a Buffer,
    pub node_parent: &'a Buffer,
    pub point_parent: &'a Buffer,
    pub arrivals: &'a Buffer,
    pub sorted_point_flux: &'a Buffer,
    pub node_flux: &'a Buffer,
}

pub struct TreePass {
    build: Pipeline,
    aggregate: Pipeline,
}

impl TreePass {
    pub fn new(ctx: &Context) -> Result<TreePass> {
        Ok(TreePass {
            build: Pipeline::compute(ctx, "hierarchy/tree_build.comp")?,
            aggregate: Pipeline::compute(ctx, "hierarchy/tree_aggregate.comp")?,
        })
    }

    pub fn record_build(&self, rec: &mut Recorder, b: &TreeBuffers, n: u32) -> Result<()> {
        rec.dispatch(
            &self.build,
            &[
                Bind::Read(b.keys),
                Bind::Write(b.nodes),
                Bind::Write(b.node_parent),
                Bind::Write(b.point_parent),
                Bind::Write(b.arrivals),
            ],
            &n.to_le_bytes(),
            [(n - 1).div_ceil(64), 1, 1],
        )
    }

    pub fn record_aggregate(&self, rec: &mut Recorder, b: &TreeBuffers, n: u32) -> Result<()> {
        rec.dispatch(
            &self.aggregate,
            &[
                Bind::Read(b.sorted_points),
                Bind::Write(b.nodes),
                Bind::Read(b.node_parent),
                Bind::Read(b.point_parent),
                Bind::Write(b.arrivals),
                Bind::Read(b.sorted_point_flux),
                Bind::Write(b.node_flux),
            ],
            bytemuck::bytes_of(&n),
            [n.div_ceil(64), 1, 1],
        )
    }
}
