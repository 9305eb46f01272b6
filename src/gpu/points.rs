//! points.glsl: the surface samples, what each light brings to each, and the tree's nodes.

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};

/// Mirrors `SurfacePoint` in shaders/include/points.glsl (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SurfacePoint {
    pub position: Vec3,
    pub area: f32,
    pub normal: Vec3,
    pub triangle: u32,
    /// Times the scatter weight.
    pub irradiance: Vec3,
    /// The object's texture at the point (1 without one), r and g as two f16.
    pub scatter_weight_rg: u32,
    pub light_dir: Vec3,
    pub scatter_weight_b: f32,
}

/// Mirrors `PointLight` in shaders/include/points.glsl (16 bytes): one light at one point (kept
/// for brute force only).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PointLight {
    pub irradiance: Vec3,
    pub toward_oct: u32,
}

/// Mirrors `PointFlux` in shaders/include/points.glsl (48 bytes): every light at one point, per
/// channel c `incident[c]` = (Σ_k E_k,c ωi,k, Σ_k E_k,c cos θt,k).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PointFlux {
    pub incident: [Vec4; 3],
}

/// Mirrors `NodeFlux` in shaders/include/points.glsl (64 bytes): every light over one node, per
/// channel PointFlux's sums times the points' areas, and the power centre and spread.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct NodeFlux {
    pub incident: [Vec4; 3],
    pub power_center: Vec3,
    pub spread2: f32,
}

/// Mirrors `TreeNode` in shaders/include/points.glsl (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct TreeNode {
    pub power: Vec3,
    pub area: f32,
    pub center: Vec3,
    pub left: u32,
    pub box_half: [u32; 3],
    pub right: u32,
    pub normal_oct: u32,
    pub light_oct: u32,
    pub first_point: u32,
    pub point_count: u32,
}
