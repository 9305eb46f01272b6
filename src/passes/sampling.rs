//! Surface sampling: the triangle-area prefix sum (64-bit fixed point), then N points uniform by area.
//! Reads: vertices, indices. Writes: area prefix sum, points (unsorted).

use crate::error::Result;
use crate::gpu::SampleConstants;
use crate::vk::{Bind, Buffer, Context, Pipeline, Recorder};

pub struct SamplingPass {
    areas: Pipeline,
    points: Pipeline,
}

impl SamplingPass {
    pub fn new(ctx: &Context) -> Result<SamplingPass> {
        Ok(SamplingPass {
            areas: Pipeline::compute(ctx, "hierarchy/triangle_areas.comp")?,
            points: Pipeline::compute(ctx, "hierarchy/sample_points.comp")?,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        vertices: &Buffer,
        indices: &Buffer,
        triangle_count: u32,
        prefix: &Buffer,
        points: &Buffer,
        point_count: u32,
        seed: u32,
    ) -> Result<()> {
        rec.dispatch(
            &self.areas,
            &[Bind::Read(vertices), Bind::Read(indices), Bind::Write(prefix)],
            bytemuck::bytes_of(&[triangle_count, point_count]),
            [1, 1, 1],
        )?;
        let constants = SampleConstants { point_count, triangle_count, seed };
        rec.dispatch(
            &self.points,
            &[Bind::Read(vertices), Bind::Read(indices), Bind::Read(prefix), Bind::Write(points)],
            bytemuck::bytes_of(&constants),
            [point_count.div_ceil(64), 1, 1],
        )
    }
}
