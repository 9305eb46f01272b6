//! Looking at the hierarchy: `--show samples` draws the sample points coloured by irradiance,
//! `--show tree --level K` the boxes of the nodes K levels below the root.
//! Reads: sorted points (or a line vertex buffer). Writes: the colour target (depth-tested).

use glam::Vec3;

use crate::error::Result;
use crate::gpu::{DebugConstants, TreeNode, LEAF_BIT};
use crate::vk::{
    self, Bind, Buffer, Context, CullModeFlags, Format, GraphicsDesc, Image, Pipeline, PrimitiveTopology, Recorder,
};

use super::shade::{COLOR_FORMAT, DEPTH_FORMAT};

pub struct DebugViewPass {
    points: Pipeline,
    lines: Pipeline,
}

impl DebugViewPass {
    pub fn new(ctx: &Context) -> Result<DebugViewPass> {
        let desc = |vertex_shader, topology, stride, attributes: &'static [(u32, Format, u32)]| GraphicsDesc {
            vertex_shader,
            fragment_shader: Some("debug/color.frag"),
            vertex_stride: stride,
            vertex_attributes: attributes,
            topology,
            color_formats: &[COLOR_FORMAT],
            depth_format: Some(DEPTH_FORMAT),
            depth_test: true,
            depth_bias: false,
            cull_mode: CullModeFlags::NONE,
            additive_blend: false,
            specialization: &[],
        };
        Ok(DebugViewPass {
            points: Pipeline::graphics(ctx, &desc("debug/points.vert", PrimitiveTopology::POINT_LIST, 0, &[]))?,
            lines: Pipeline::graphics(
                ctx,
                &desc(
                    "debug/lines.vert",
                    PrimitiveTopology::LINE_LIST,
                    24,
                    &[(0, Format::R32G32B32_SFLOAT, 0), (1, Format::R32G32B32_SFLOAT, 12)],
                ),
            )?,
        })
    }

    /// Draws the points over the shaded image (depth-tested against it).
    pub fn record_points(
        &self,
        rec: &mut Recorder,
        color: &Image,
        depth: &Image,
        points: &Buffer,
        count: u32,
        constants: &DebugConstants,
    ) -> Result<()> {
        rec.prepare_draw_reads(&[Bind::Read(points)])?;
        rec.begin_rendering(&[(color, None)], Some((depth, None)), 0)?;
        rec.draw(&self.points, &[Bind::Read(points)], bytemuck::bytes_of(constants), None, None, count, 1)?;
        rec.end_rendering();
        Ok(())
    }

    pub fn record_lines(
        &self,
        rec: &mut Recorder,
        color: &Image,
        depth: &Image,
        lines: &Buffer,
        vertex_count: u32,
        constants: &DebugConstants,
    ) -> Result<()> {
        rec.use_buffer(lines, vk::Access::VERTEX_INPUT)?;
        rec.begin_rendering(&[(color, None)], Some((depth, None)), 0)?;
        rec.draw(&self.lines, &[], bytemuck::bytes_of(constants), Some(lines), None, vertex_count, 1)?;
        rec.end_rendering();
        Ok(())
    }
}

/// Line-list vertices `[x, y, z, r, g, b]` of the boxes of the nodes `level` levels below the root,
/// coloured by their share of the root's power.
pub fn tree_level_lines(nodes: &[TreeNode], level: u32) -> Vec<[f32; 6]> {
    let mut current = vec![0u32];
    for _ in 0..level {
        current = current
            .iter()
            .flat_map(|&k| [nodes[k as usize].left, nodes[k as usize].right])
            .filter(|c| c & LEAF_BIT == 0)
            .collect();
    }
    let root_power = nodes.first().map(|n| n.power.max_element()).unwrap_or(1.0).max(1e-30);
    let mut out = Vec::new();
    for k in current {
        let node = &nodes[k as usize];
        let (lo, hi) = node.bounds();
        let share = (node.power.max_element() / root_power * (1u32 << level.min(20)) as f32).min(1.0);
        let color = Vec3::new(0.2 + 0.8 * share, 0.9, 0.2 + 0.8 * (1.0 - share));
        let corner = |i: u32| {
            Vec3::new(
                [lo.x, hi.x][(i & 1) as usize],
                [lo.y, hi.y][(i >> 1 & 1) as usize],
                [lo.z, hi.z][(i >> 2) as usize],
            )
        };
        for (a, b) in [(0, 1), (2, 3), (4, 5), (6, 7), (0, 2), (1, 3), (4, 6), (5, 7), (0, 4), (1, 5), (2, 6), (3, 7)] {
            for p in [corner(a), corner(b)] {
                out.push([p.x, p.y, p.z, color.x, color.y, color.z]);
            }
        }
    }
    out
}
