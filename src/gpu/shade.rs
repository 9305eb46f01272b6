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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct WorkCounters {
    pub pixels: u32,
    pub node_sum: u32,
    pub node_max: u32,
    pub point_sum: u32,
    pub point_max: u32,
    /// Sd evaluations (three channels each): a point is one per light, a node used whole two.
    pub evaluation_sum: u32,
}

impl WorkCounters {
    /// The work of several objects' pixels together: sums added, maxima the largest.
    pub fn combined(all: &[WorkCounters]) -> WorkCounters {
        all.iter().fold(WorkCounters::default(), |a, w| WorkCounters {
            pixels: a.pixels + w.pixels,
            node_sum: a.node_sum + w.node_sum,
            node_max: a.node_max.max(w.node_max),
            point_sum: a.point_sum + w.point_sum,
            point_max: a.point_max.max(w.point_max),
            evaluation_sum: a.evaluation_sum + w.evaluation_sum,
        })
    }
}

/// Mirrors `SurfaceConstants` in shaders/include/surface_constants.glsl: an object's draw into
/// the G-buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SurfaceConstants {
    pub view_projection: Mat4,
    /// rgb: the texture's value (a checkerboard's first); w: the checkerboard's u scale.
    pub tex1: Vec4,
    /// rgb: a checkerboard's second value; w: its v scale.
    pub tex2: Vec4,
    /// The object's G-buffer id (position w = object + 1).
    pub object: u32,
    /// surface_texture.glsl's kinds: 0 `tex1` everywhere, 1 a checkerboard over the mesh's uv,
    /// 2 its image.
    pub texture_kind: u32,
    pub pad: [u32; 2],
}

/// Mirrors `DiffuseConstants` in shaders/include/diffuse_constants.glsl: the diffuse pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct DiffuseConstants {
    /// G-buffer ids from here on are opaque objects.
    pub first_opaque: u32,
    pub pad: [u32; 3],
}

/// Mirrors `BackgroundConstants` in shaders/include/background_constants.glsl: the background pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BackgroundConstants {
    /// Pixel → direction in the map's frame, as columns (w unused).
    pub ray_x: glam::Vec4,
    pub ray_y: glam::Vec4,
    pub ray_z: glam::Vec4,
    /// rgb: a constant map's radiance; w: the scale.
    pub constant: glam::Vec4,
    /// 0 none, 1 constant, 2 latitude-longitude, 3 equal-area octahedral.
    pub kind: u32,
    pub width: u32,
    pub height: u32,
    pub pad: u32,
}
