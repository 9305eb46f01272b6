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
    /// The sample points' spacing, sqrt(area / point count), in mm.
    pub spacing_mm: f32,
    /// The near field (shade.frag): every source of the sum is weighted by a smoothstep from 0
    /// at `near_start_mm` to 1 at `near_end_mm` from the pixel, and the pixel's own irradiance
    /// times ∫(1 − w) Sd dA over its tangent plane is added (a fixed quadrature).
    pub near_start_mm: f32,
    pub near_end_mm: f32,
    /// The length the quadrature's inner radii are graded by: the smallest diffusion coefficient.
    pub near_scale_mm: f32,
    pub pad: f32,
}

/// Where the near field begins and ends, in point spacings: the far sum's weight rises from 0
/// at one spacing to 1 at four.
pub const NEAR_START_SPACINGS: f32 = 1.0;
pub const NEAR_END_SPACINGS: f32 = 4.0;

impl ObjectParams {
    /// The near field's radii for points `spacing_mm` apart, and its quadrature's scale from the
    /// channels' diffusion coefficients.
    pub fn near_field(spacing_mm: f32, channels: &[GpuChannel; 3]) -> (f32, f32, f32) {
        let (start, end) = (NEAR_START_SPACINGS * spacing_mm, NEAR_END_SPACINGS * spacing_mm);
        let d = channels.iter().filter(|c| c.transports != 0.0).map(|c| c.d).fold(f32::INFINITY, f32::min);
        let scale = if d.is_finite() { d.clamp(1e-3 * start, start) } else { start };
        (start, end, scale)
    }
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
    /// 1 to split each pixel's sum into the near field and the far (see [`ObjectParams`]).
    pub near_field: u32,
    /// 1 to sum the sources far from an 8x8 list tile at nine of its pixels and interpolate
    /// (shaders/far_field.comp).
    pub far_field: u32,
    /// The Monte Carlo table's terms: 0 both, 1 single scattering alone, 2 multiple alone
    /// ([`crate::frame_desc::Scattering::code`]).
    pub scattering: u32,
}
