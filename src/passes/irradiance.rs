//! Irradiance at each point from every light, with shadow-map visibility and Fresnel transmittance.
//! Reads: lights, shadow map, the object's Sd table (its incidence factors). Writes: points (irradiance, mean light direction), every light's
//! merged record of each point, and (for brute force) each light's own.

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
        (point_lights, per_light_records): (&Buffer, bool),
        (point_flux, point_spread): (&Buffer, &Buffer),
        point_count: u32,
        lights: &Buffer,
        shadow_map: &Image,
        sampler: &Sampler,
        sd_table: &Buffer,
    ) -> Result<()> {
        rec.dispatch(
            &self.pipeline,
            &[
                Bind::Write(points),
                Bind::Read(lights),
                Bind::Sampled(shadow_map, sampler),
                Bind::Write(point_lights),
                Bind::Write(point_flux),
                Bind::Write(point_spread),
                Bind::Texels(sd_table),
            ],
            bytemuck::bytes_of(&[point_count, per_light_records as u32]),
            [point_count.div_ceil(64), 1, 1],
        )
    }
}
