//! shade_constants.glsl (the shading draw's push constants) and shade.frag's work counters.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

/// Mirrors `ShadeConstants` in shaders/include/shade_constants.glsl (std430 push constants).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadeConstants {
    pub view_projection: Mat4,
    pub eye: Vec4,
    /// Brute force: first point and count of one draw; draws are added by blending.
    pub point_range: glam::UVec4,
}

/// Mirrors `WorkCounters` in shaders/shade.frag.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WorkCounters {
    pub pixels: u32,
    pub node_sum: u32,
    pub node_max: u32,
    pub point_sum: u32,
    pub point_max: u32,
    /// Sd evaluations (three channels each): a point is one per light, a node used whole two.
    pub evaluation_sum: u32,
}
