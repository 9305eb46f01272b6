//! lights.glsl: the lights as the GPU reads them.

use bytemuck::{Pod, Zeroable};
use glam::Vec4;

/// Mirrors `GpuLight` in shaders/include/lights.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuLight {
    pub position: Vec4,
    pub intensity: Vec4,
    /// Spot lights: the cone's axis from the light (xyz), cos of the cone angle (w).
    pub axis: Vec4,
    pub first_layer: u32,
    /// 1: six cube-face layers (a point light or spot near or inside the receiver, a spot wider
    /// than 60°: `shadow::light_matrices`); 0: one layer.
    pub cube: u32,
    /// Spot lights: cos(cone angle − delta), where the falloff begins.
    pub cos_falloff_start: f32,
    /// 1: a spot light.
    pub spot: u32,
}

/// Mirrors the header of the `Lights` block in shaders/include/lights.glsl; `light_count`
/// [`GpuLight`]s follow it in the buffer, then from `matrix_base` (in 16-byte words after the
/// header) one matrix per shadow-map layer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct LightSetHeader {
    pub light_count: u32,
    pub eta: f32,
    pub normal_offset: f32,
    pub matrix_base: u32,
}
