//! The shade pass: rasterises the mesh and, per fragment, integrates the BSSRDF over the tree
//! (shaders/shade.frag), plus the surface's microfacet reflection. Reads: vertices, indices,
//! parameters, tree nodes, sorted points, their light records, lights and shadow maps. Writes: colour and depth
//! targets, work counters.

use glam::Mat4;

use crate::error::Result;
use crate::gpu::ShadeConstants;
use crate::vk::{
    self, Bind, BindingKind, Buffer, Context, CullModeFlags, Format, GraphicsDesc, Image, Pipeline, PrimitiveTopology,
    Recorder, Sampler,
};

pub const COLOR_FORMAT: Format = Format::R32G32B32A32_SFLOAT;
/// Depth, and stencil to shade each pixel once even where triangles coincide (every copy of a
/// repeated triangle passes the EQUAL depth test): see `GraphicsDesc::depth_equal`.
pub const DEPTH_FORMAT: Format = Format::D32_SFLOAT_S8_UINT;

/// (Point, light) records per brute-force draw: keeps every fragment invocation's loop short
/// (llvmpipe ends loops after ~65k iterations; a real GPU's watchdog dislikes long draws too).
pub const POINTS_PER_DRAW: u32 = 8192;

/// Everything a shading draw reads, and the targets it writes.
pub struct ShadeInputs<'a> {
    pub color: &'a Image,
    pub depth: &'a Image,
    pub vertices: &'a Buffer,
    pub indices: &'a Buffer,
    pub index_count: u32,
    pub params: &'a Buffer,
    pub nodes: &'a Buffer,
    pub points: &'a Buffer,
    pub work: &'a Buffer,
    pub lights: &'a Buffer,
    pub shadow_map: &'a Image,
    pub shadow_sampler: &'a Sampler,
    pub point_lights: &'a Buffer,
    pub node_lights: &'a Buffer,
}

/// One piece of a frame's shading: a rectangle of pixels and, for brute force, a range of points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadeUnit {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
    pub first_point: u32,
    pub point_count: u32,
}

/// Tiles of `tile` pixels over `width` x `height`, each repeated for every range of
/// `POINTS_PER_DRAW` points when brute force sums `brute_force_points` points.
pub fn shade_units(width: u32, height: u32, tile: u32, brute_force_points: Option<u32>) -> Vec<ShadeUnit> {
    let ranges: Vec<(u32, u32)> = match brute_force_points {
        None => vec![(0, 0)],
        Some(n) => (0..n.max(1)).step_by(POINTS_PER_DRAW as usize).map(|f| (f, POINTS_PER_DRAW)).collect(),
    };
    let mut units = Vec::new();
    for y in (0..height).step_by(tile as usize) {
        for x in (0..width).step_by(tile as usize) {
            for &(first_point, point_count) in &ranges {
                let (w, h) = (tile.min(width - x), tile.min(height - y));
                units.push(ShadeUnit { x, y, width: w, height: h, first_point, point_count });
            }
        }
    }
    units
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
        use BindingKind::*;
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
                    bindings: &[
                        StorageBuffer,
                        StorageBuffer,
                        StorageBuffer,
                        StorageBuffer,
                        StorageBuffer,
                        SampledImage,
                        StorageBuffer,
                        StorageBuffer,
                    ],
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

    /// Clears the colour target and the work counters and lays down depth, so that the shading
    /// draws run their fragment shader once per pixel.
    pub fn record_depth(&self, rec: &mut Recorder, inputs: &ShadeInputs, view_projection: &Mat4) -> Result<()> {
        rec.fill_buffer(inputs.work, 0)?;
        rec.begin_rendering(&[(inputs.color, Some([0.0; 4]))], None, 0)?;
        rec.end_rendering();
        rec.begin_rendering(&[], Some((inputs.depth, Some(1.0))), 0)?;
        let (v, i) = (Some(inputs.vertices), Some(inputs.indices));
        rec.draw(&self.depth_prepass, &[], vk::bytes_of(view_projection), v, i, inputs.index_count, 1)?;
        rec.end_rendering();
        Ok(())
    }

    /// Shades one unit: its rectangle, over its range of points for brute force (added by
    /// blending to what earlier ranges left), else by walking the tree.
    pub fn record_unit(
        &self,
        rec: &mut Recorder,
        inputs: &ShadeInputs,
        constants: &ShadeConstants,
        unit: &ShadeUnit,
    ) -> Result<()> {
        let binds = [
            Bind::Read(inputs.params),
            Bind::Read(inputs.nodes),
            Bind::Read(inputs.points),
            Bind::Write(inputs.work),
            Bind::Read(inputs.lights),
            Bind::Sampled(inputs.shadow_map, inputs.shadow_sampler),
            Bind::Read(inputs.point_lights),
            Bind::Read(inputs.node_lights),
        ];
        let mut c = *constants;
        c.point_range = glam::UVec4::new(unit.first_point, unit.point_count, 0, 0);
        let pipeline = if unit.point_count > 0 { &self.additive } else { &self.pipeline };
        // One rendering scope per unit: every draw writes the work counters, and the barrier
        // between two writes cannot sit inside a rendering scope.
        rec.prepare_draw_reads(&binds)?;
        rec.begin_rendering(&[(inputs.color, None)], Some((inputs.depth, None)), 0)?;
        rec.set_scissor(unit.x, unit.y, unit.width, unit.height);
        // The pre-pass clears stencil to 0 and each draw over a pixel adds one: the draw of the
        // k-th range of points expects k (mod 256, the stencil wraps).
        rec.set_stencil_reference((unit.first_point / POINTS_PER_DRAW) & 0xff);
        let (v, i) = (Some(inputs.vertices), Some(inputs.indices));
        rec.draw(pipeline, &binds, vk::bytes_of(&c), v, i, inputs.index_count, 1)?;
        rec.end_rendering();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel is in exactly one tile, once per range of points, and the ranges cover every
    /// point.
    #[test]
    fn units_cover_every_pixel_and_point_once() {
        for (w, h, tile, points) in
            [(96, 96, 128, None), (300, 130, 128, None), (257, 1, 64, Some(20_000)), (1, 1, 128, Some(2))]
        {
            let units = shade_units(w, h, tile, points);
            let mut cover = vec![0u32; (w * h) as usize];
            for u in &units {
                assert!(u.width <= tile && u.height <= tile && u.width > 0 && u.height > 0);
                for y in u.y..u.y + u.height {
                    for x in u.x..u.x + u.width {
                        cover[(y * w + x) as usize] += 1;
                    }
                }
            }
            let ranges = points.map(|n: u32| n.div_ceil(POINTS_PER_DRAW)).unwrap_or(1);
            assert!(cover.iter().all(|&c| c == ranges), "{w}x{h} tile {tile}: {cover:?}");
            if let Some(n) = points {
                let mut seen: Vec<u32> = units.iter().filter(|u| u.x == 0 && u.y == 0).map(|u| u.first_point).collect();
                seen.sort();
                assert_eq!(seen, (0..n).step_by(POINTS_PER_DRAW as usize).collect::<Vec<_>>());
            }
        }
    }
}
