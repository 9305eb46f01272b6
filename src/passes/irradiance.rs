//! Irradiance at each point from every light, with shadow-map visibility and Fresnel transmittance.
//! Reads: lights, shadow map. Writes: points (irradiance, mean light direction), each light's
//! record of each point.

use bytemuck::{Pod, Zeroable};
use glam::Vec4;

use crate::error::Result;
use crate::vk::{Bind, Buffer, Context, Image, Pipeline, Recorder, Sampler};

pub const MAX_LIGHTS: usize = 8;

/// Mirrors `GpuLight` in shaders/include/lights.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    pub position: Vec4,
    pub intensity: Vec4,
    pub first_layer: u32,
    pub pad: [u32; 3],
}

/// Mirrors `LightSet` in shaders/include/lights.glsl; the layer matrices follow it in the buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightSetHeader {
    pub light_count: u32,
    pub eta: f32,
    pub normal_offset: f32,
    pub pad: f32,
    pub lights: [GpuLight; MAX_LIGHTS],
}

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
