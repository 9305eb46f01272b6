//! Irradiance at each point from every light, with shadow-map visibility and Fresnel transmittance.
//! Reads: lights, shadow map. Writes: points (irradiance, mean light direction), each light's
//! record of each point.

use crate::error::Result;
use crate::vk::{Bind, Buffer, Context, Image, Pipeline, Recorder, Sampler};

pub struct IrradiancePass {
    pipeline: Pipeline,
}

impl IrradiancePass {
    pub fn new(ctx: &Context) -> Result<IrradiancePass> {
        Ok(IrradiancePass { pipeline: Pipeline::compute(ctx, "hierarchy/irradiance.comp")? })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        points: &Buffer,
        point_lights: &Buffer,
        point_count: u32,
        lights: &Buffer,
        shadow_map: &Image,
        sampler: &Sampler,
    ) -> Result<()> {
        rec.dispatch(
            &self.pipeline,
            &[Bind::Write(points), Bind::Read(lights), Bind::Sampled(shadow_map, sampler), Bind::Write(point_lights)],
            &point_count.to_le_bytes(),
            [point_count.div_ceil(64), 1, 1],
        )
    }
}
