//! The shade pass: rasterises the mesh and, per fragment, integrates the BSSRDF over the tree
//! (shaders/shade.frag). Reads: vertices, indices, parameters, tree nodes, sorted points.
//! Writes: colour and depth targets.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

use crate::error::Result;
use crate::scene::Light;
use crate::vk::{
    self, Bind, BindingKind, Buffer, Context, CullModeFlags, Format, GraphicsDesc, Image, Pipeline, PrimitiveTopology,
    Recorder,
};

pub const COLOR_FORMAT: Format = Format::R32G32B32A32_SFLOAT;
pub const DEPTH_FORMAT: Format = Format::D32_SFLOAT;

/// Mirrors `ShadeConstants` in shaders/include/shade_constants.glsl (std430 push constants).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ShadeConstants {
    pub view_projection: Mat4,
    pub light_toward: Vec4,
    pub light_irradiance: Vec4,
    pub eye: Vec4,
    /// Brute force: first point and count of one draw; draws are added by blending.
    pub point_range: glam::UVec4,
}

/// Points per brute-force draw: keeps every fragment invocation's loop short (llvmpipe ends loops
/// after ~65k iterations; a real GPU's watchdog dislikes long draws too).
pub const POINTS_PER_DRAW: u32 = 8192;

/// Mirrors `SubsurfaceParams` in shaders/include/subsurface_params.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SubsurfaceParams {
    pub channels: [crate::physics::GpuChannel; 3],
    pub mm_per_unit: f32,
    pub epsilon: f32,
    pub model: u32,
    pub brute_force: u32,
    pub point_count: u32,
    pub node_count: u32,
    /// 1 to count the work per pixel (nodes visited, points evaluated) for `--profile`.
    pub count_work: u32,
    pub pad: u32,
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
}

impl ShadeConstants {
    pub fn new(view_projection: Mat4, eye: glam::Vec3, light: &Light) -> ShadeConstants {
        let (toward, irradiance) = match *light {
            Light::Directional { toward, irradiance } => (toward.normalize().extend(0.0), irradiance.extend(0.0)),
            Light::Point { position, intensity } => (position.extend(1.0), intensity.extend(0.0)),
        };
        ShadeConstants {
            view_projection,
            light_toward: toward,
            light_irradiance: irradiance,
            eye: eye.extend(1.0),
            point_range: glam::UVec4::ZERO,
        }
    }
}

pub struct ShadePass {
    /// Depth only, so that the expensive fragment shader runs once per pixel (EQUAL test).
    depth_prepass: Pipeline,
    pipeline: Pipeline,
    /// The same shader with additive blending, for brute force in several draws.
    additive: Pipeline,
}

/// Bytes per vertex: position and normal, 3 floats each.
const VERTEX_STRIDE: u32 = 24;

impl ShadePass {
    pub fn new(ctx: &Context) -> Result<ShadePass> {
        let shading = |additive_blend: bool| {
            Pipeline::graphics(
                ctx,
                &GraphicsDesc {
                    vertex_shader: "shade.vert",
                    fragment_shader: Some("shade.frag"),
                    vertex_stride: VERTEX_STRIDE,
                    vertex_attributes: &[(0, Format::R32G32B32_SFLOAT, 0), (1, Format::R32G32B32_SFLOAT, 12)],
                    topology: PrimitiveTopology::TRIANGLE_LIST,
                    color_formats: &[COLOR_FORMAT],
                    depth_format: Some(DEPTH_FORMAT),
                    depth_test: true,
                    depth_equal: true,
                    depth_bias: false,
                    cull_mode: CullModeFlags::NONE,
                    additive_blend,
                    bindings: &[BindingKind::StorageBuffer; 4],
                    push_constant_size: std::mem::size_of::<ShadeConstants>() as u32,
                },
            )
        };
        let pipeline = shading(false)?;
        let additive = shading(true)?;
        let depth_prepass = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                vertex_shader: "hierarchy/shadow.vert",
                fragment_shader: None,
                vertex_stride: VERTEX_STRIDE,
                vertex_attributes: &[(0, Format::R32G32B32_SFLOAT, 0)],
                topology: PrimitiveTopology::TRIANGLE_LIST,
                color_formats: &[],
                depth_format: Some(DEPTH_FORMAT),
                depth_test: true,
                depth_equal: false,
                depth_bias: false,
                cull_mode: CullModeFlags::NONE,
                additive_blend: false,
                bindings: &[],
                push_constant_size: 64,
            },
        )?;
        Ok(ShadePass { depth_prepass, pipeline, additive })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        color: &Image,
        depth: &Image,
        vertices: &Buffer,
        indices: &Buffer,
        index_count: u32,
        constants: &ShadeConstants,
        params: &Buffer,
        nodes: &Buffer,
        points: &Buffer,
        work: &Buffer,
        brute_force_points: Option<u32>,
    ) -> Result<()> {
        rec.fill_buffer(work, 0)?;
        let binds = [Bind::Read(params), Bind::Read(nodes), Bind::Read(points), Bind::Write(work)];
        rec.use_buffer(vertices, vk::Access::VERTEX_INPUT)?;
        rec.use_buffer(indices, vk::Access::INDEX_INPUT)?;
        rec.prepare_draw_reads(&binds)?;
        rec.begin_rendering(&[], Some((depth, Some(1.0))), 0)?;
        let matrix = constants.view_projection;
        rec.draw(&self.depth_prepass, &[], vk::bytes_of(&matrix), Some(vertices), Some(indices), index_count, 1)?;
        rec.end_rendering();
        match brute_force_points {
            None => {
                rec.begin_rendering(&[(color, Some([0.0; 4]))], Some((depth, None)), 0)?;
                let c = vk::bytes_of(constants);
                rec.draw(&self.pipeline, &binds, c, Some(vertices), Some(indices), index_count, 1)?;
                rec.end_rendering();
            }
            Some(total) => {
                // One rendering scope per draw: every draw writes the work counters, and the
                // barrier between two writes cannot sit inside a rendering scope.
                for first in (0..total.max(1)).step_by(POINTS_PER_DRAW as usize) {
                    let clear = (first == 0).then_some([0.0; 4]);
                    let mut c = *constants;
                    c.point_range = glam::UVec4::new(first, POINTS_PER_DRAW, 0, 0);
                    rec.prepare_draw_reads(&binds)?;
                    rec.begin_rendering(&[(color, clear)], Some((depth, None)), 0)?;
                    rec.draw(&self.additive, &binds, vk::bytes_of(&c), Some(vertices), Some(indices), index_count, 1)?;
                    rec.end_rendering();
                }
            }
        }
        Ok(())
    }
}
