//! shading_params.glsl, and the per-channel constants of bssrdf.glsl it holds.

use bytemuck::{Pod, Zeroable};

use crate::physics::ChannelConstants;

/// The per-channel constants as the GPU reads them: 16 floats, std430 = C layout. Mirrors
/// `BssrdfChannel` in `shaders/include/bssrdf.glsl` (checked by a layout test).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct GpuChannel {
    pub eta: f32,
    pub sigma_tr: f32,
    pub d: f32,
    pub de: f32,
    pub a_dirpole: f32,
    pub c_phi: f32,
    pub c_e: f32,
    /// N/(4π²), the directional dipole's leading factor.
    pub n_over_4pi2: f32,
    /// (1/(3σt))², the back-lit real-source offset.
    pub back_lit_dr2: f32,
    /// α'/(4π), the classical dipole's leading factor.
    pub dipole_scale: f32,
    pub dipole_sigma_tr: f32,
    pub zr: f32,
    pub zv: f32,
    /// 1 where diffusion applies, 0 for a pure-absorber channel.
    pub transports: f32,
    /// σ's and σ't: the Monte Carlo table's single scattering (the similarity relation).
    pub sigma_s_reduced: f32,
    pub sigma_t_reduced: f32,
}

impl From<&ChannelConstants> for GpuChannel {
    fn from(c: &ChannelConstants) -> GpuChannel {
        let pi = std::f64::consts::PI;
        let inv3t = if c.sigma_t > 0.0 { 1.0 / (3.0 * c.sigma_t) } else { 0.0 };
        GpuChannel {
            eta: c.eta as f32,
            sigma_tr: c.sigma_tr as f32,
            d: c.d as f32,
            de: c.de as f32,
            a_dirpole: c.a_dirpole as f32,
            c_phi: c.c_phi as f32,
            c_e: c.c_e as f32,
            n_over_4pi2: (c.n_norm / (4.0 * pi * pi)) as f32,
            back_lit_dr2: (inv3t * inv3t) as f32,
            dipole_scale: (c.alpha_reduced / (4.0 * pi)) as f32,
            dipole_sigma_tr: c.dipole_sigma_tr as f32,
            zr: c.zr as f32,
            zv: c.zv as f32,
            transports: if c.transports { 1.0 } else { 0.0 },
            sigma_s_reduced: c.sigma_s_reduced as f32,
            sigma_t_reduced: c.sigma_t_reduced as f32,
        }
    }
}

/// One object's shading parameters: its material's constants and its tree's size. Mirrors
/// `ObjectParams` in shaders/include/shading_params.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ObjectParams {
    pub channels: [GpuChannel; 3],
    pub mm_per_unit: f32,
    pub point_count: u32,
    pub node_count: u32,
    pub pad: u32,
}

/// How a frame integrates, written from the frame's description when it begins. Mirrors
/// `FrameParams` in shaders/include/shading_params.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameParams {
    pub epsilon: f32,
    pub brute_force: u32,
    /// 1 to count the work per pixel (nodes visited, points evaluated) for `--profile`.
    pub count_work: u32,
    /// 1 to add the microfacet lobe.
    pub specular: u32,
    pub roughness: f32,
    pub pad: [u32; 3],
}
