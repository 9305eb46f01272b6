//! lights.glsl: the lights as the GPU reads them.

use bytemuck::{Pod, Zeroable};
use glam::Vec4;

use super::MAX_LIGHTS;

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
