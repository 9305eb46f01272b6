//! The surface and shade passes. The surface pass rasterises every object's mesh once into a
//! G-buffer (depth, world position, normal, texture: shaders/surface.frag); the shade pass is a
//! full-screen triangle per tile that, per pixel, integrates the BSSRDF over the tree
//! (shaders/shade.frag), plus the surface's microfacet reflection. Surface reads: vertices,
//! indices, uvs, textures; writes: depth, position, normal, texture, and clears colour and work
//! counters. Shade reads: the object's and the frame's parameters, tree nodes, sorted points,
//! their light records, lights, shadow maps, position, normal and texture (the pixel's scatter
//! weight); writes: colour, work counters.

use std::collections::HashMap;

use crate::error::Result;
use crate::gpu::{ShadeConstants, SurfaceConstants};
use crate::physics::Model;
use crate::vk::{
    self, Bind, Buffer, Context, CullModeFlags, Format, GraphicsDesc, Image, Pipeline, PrimitiveTopology, Recorder,
    Sampler,
};

pub const COLOR_FORMAT: Format = Format::R32G32B32A32_SFLOAT;
pub const DEPTH_FORMAT: Format = Format::D32_SFLOAT;
/// The G-buffer: world position (w = 1 where covered) and interpolated normal, f32 so that shading
/// sees the values a fragment shader on the mesh would have.
pub const SURFACE_FORMAT: Format = Format::R32G32B32A32_SFLOAT;

/// (Point, light) records per brute-force draw: keeps every fragment invocation's loop short
/// (llvmpipe ends loops after ~65k iterations; a real GPU's watchdog dislikes long draws too).
pub const POINTS_PER_DRAW: u32 = 8192;

/// Everything a shading draw reads, and the targets it writes.
pub struct ShadeInputs<'a> {
    pub color: &'a Image,
    pub depth: &'a Image,
    pub position: &'a Image,
    pub normal: &'a Image,
    /// The G-buffer's texture: a translucent pixel's scatter weight.
    pub albedo: &'a Image,
    pub vertices: &'a Buffer,
    pub indices: &'a Buffer,
    pub index_count: u32,
    /// The object's parameters (`ObjectParams`) and the frame's (`FrameParams`).
    pub object_params: &'a Buffer,
    pub frame_params: &'a Buffer,
    pub nodes: &'a Buffer,
    pub points: &'a Buffer,
    pub work: &'a Buffer,
    pub lights: &'a Buffer,
    pub shadow_map: &'a Image,
    /// The mesh's normal at each shadow-map texel (read with texelFetch: single scattering).
    pub shadow_normals: &'a Image,
    pub shadow_sampler: &'a Sampler,
    /// The shadow map's depth, unfiltered (single scattering).
    pub depth_sampler: &'a Sampler,
    /// Each light's own record of each point (brute force only).
    pub point_lights: &'a Buffer,
    pub point_flux: &'a Buffer,
    pub node_flux: &'a Buffer,
    pub point_spread: &'a Buffer,
    /// The object's Sd table (`gpu::SdTable`: the classical dipole's or beam diffusion's).
    pub sd_table: &'a Buffer,
    /// The tile-cut pass's lists (headers and entries), and their tiles' pixels per side.
    pub tile_headers: &'a Buffer,
    /// The far-field pass's nine sums per 8x8 tile (read where the frame uses the far field).
    pub far_field: &'a Buffer,
    pub tile_entries: &'a Buffer,
    pub list_tile: u32,
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
    /// The object shaded (its pixels; others are left as they are).
    pub object: u32,
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
                units.push(ShadeUnit { x, y, width: w, height: h, first_point, point_count, object: 0 });
            }
        }
    }
    units
}

/// What the surface pass writes: the frame's colour (cleared), depth and G-buffer, and the work
/// counters (cleared).
pub struct SurfaceTargets<'a> {
    pub color: &'a Image,
    pub depth: &'a Image,
    pub position: &'a Image,
    pub normal: &'a Image,
    pub albedo: &'a Image,
    pub work: &'a Buffer,
}

/// An object's draw into the G-buffer.
pub struct SurfaceDraw<'a> {
    pub vertices: &'a Buffer,
    pub indices: &'a Buffer,
    pub index_count: u32,
    /// One uv per vertex.
    pub uvs: &'a Buffer,
    /// One mean curvature per vertex (zeros but for the Monte Carlo table's objects).
    pub curvature: &'a Buffer,
    /// Its texture's image and sampler (gpu_world::SurfaceTexture).
    pub texture: (&'a Image, &'a Sampler),
    pub constants: SurfaceConstants,
}

pub struct ShadePass {
    /// Every object's mesh to the G-buffer (depth, position, normal, texture).
    surface: Pipeline,
    /// Shading per variant and blending (additive for brute force in several draws), made on
    /// first use.
    shading: HashMap<(ShadeVariant, bool), Pipeline>,
}

/// Bytes per vertex: position and normal, 3 floats each.
const VERTEX_STRIDE: u32 = 24;

/// A full-screen triangle (`shade.vert`) running `fragment_shader` over the colour target: the
/// shade pass, and the diffuse pass of opaque objects.
pub fn full_screen_pipeline(
    ctx: &Context,
    fragment_shader: &str,
    additive_blend: bool,
    specialization: &[u32],
) -> Result<Pipeline> {
    Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            vertex_shader: "shade.vert",
            fragment_shader: Some(fragment_shader),
            vertex_stride: 0,
            vertex_attributes: &[],
            topology: PrimitiveTopology::TRIANGLE_LIST,
            color_formats: &[COLOR_FORMAT],
            depth_format: None,
            depth_test: false,
            depth_bias: false,
            cull_mode: CullModeFlags::NONE,
            additive_blend,
            specialization,
        },
    )
}

/// What the shade pass's pipeline is specialised for (shade.frag's specialisation constants):
/// llvmpipe runs both sides of every branch, so a feature chosen by a uniform would cost every
/// pixel its code even where it is off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ShadeVariant {
    pub model: Model,
    /// The near field split off (`--near-field`).
    pub near_field: bool,
    /// One light (an environment's samples count as lights): a point's lights cannot spread,
    /// so its sigma directions (PointSpread) are compiled out.
    pub one_light: bool,
}

impl ShadeVariant {
    /// The specialisation constants, in constant_id order.
    fn specialization(&self) -> [u32; 3] {
        [self.model.gpu_code(), self.near_field as u32, self.one_light as u32]
    }
}

fn shading_pipeline(ctx: &Context, variant: ShadeVariant, additive_blend: bool) -> Result<Pipeline> {
    // The module compiled for the model (build.rs), its constant_id 0 unused.
    let module = format!("shade.frag.model{}", variant.model.gpu_code());
    full_screen_pipeline(ctx, &module, additive_blend, &variant.specialization())
}

/// A mesh (positions and normals) to the G-buffer, depth-tested, through `vertex_shader` and
/// `fragment_shader`.
fn surface_pipeline(ctx: &Context, vertex_shader: &str, fragment_shader: &str) -> Result<Pipeline> {
    Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            vertex_shader,
            fragment_shader: Some(fragment_shader),
            vertex_stride: VERTEX_STRIDE,
            vertex_attributes: &[(0, Format::R32G32B32_SFLOAT, 0), (1, Format::R32G32B32_SFLOAT, 12)],
            topology: PrimitiveTopology::TRIANGLE_LIST,
            color_formats: &[SURFACE_FORMAT, SURFACE_FORMAT, SURFACE_FORMAT],
            depth_format: Some(DEPTH_FORMAT),
            depth_test: true,
            depth_bias: false,
            cull_mode: CullModeFlags::NONE,
            additive_blend: false,
            specialization: &[],
        },
    )
}

impl ShadePass {
    pub fn new(ctx: &Context) -> Result<ShadePass> {
        let surface = surface_pipeline(ctx, "surface.vert", "surface.frag")?;
        Ok(ShadePass { surface, shading: HashMap::new() })
    }

    /// Makes the shading pipeline of `variant` (and its additive twin for brute force) if not
    /// made yet: each is a compilation on llvmpipe, so only what a frame uses is made.
    pub fn prepare(&mut self, ctx: &Context, variant: ShadeVariant, brute_force: bool) -> Result<()> {
        for additive in [false, true].into_iter().take(1 + brute_force as usize) {
            if let std::collections::hash_map::Entry::Vacant(slot) = self.shading.entry((variant, additive)) {
                slot.insert(shading_pipeline(ctx, variant, additive)?);
            }
        }
        Ok(())
    }

    /// Clears the colour target and the work counters and rasterises every object's mesh into
    /// the G-buffer, each with its id (position w = id + 1) and texture: the translucent objects
    /// first, then the opaque ones (the frame lists them).
    pub fn record_surface(&self, rec: &mut Recorder, targets: &SurfaceTargets, draws: &[SurfaceDraw]) -> Result<()> {
        rec.fill_buffer(targets.work, 0)?;
        rec.begin_rendering(&[(targets.color, Some([0.0; 4]))], None, 0)?;
        rec.end_rendering();
        for o in draws {
            rec.use_buffer(o.vertices, vk::Access::VERTEX_INPUT)?;
            rec.use_buffer(o.indices, vk::Access::INDEX_INPUT)?;
            rec.prepare_draw_reads(&[
                Bind::Read(o.uvs),
                Bind::Sampled(o.texture.0, o.texture.1),
                Bind::Read(o.curvature),
            ])?;
        }
        let clear = Some([0.0; 4]);
        let gbuffer = [(targets.position, clear), (targets.normal, clear), (targets.albedo, clear)];
        rec.begin_rendering(&gbuffer, Some((targets.depth, Some(1.0))), 0)?;
        for o in draws {
            let (v, i) = (Some(o.vertices), Some(o.indices));
            let binds = [Bind::Read(o.uvs), Bind::Sampled(o.texture.0, o.texture.1), Bind::Read(o.curvature)];
            rec.draw(&self.surface, &binds, vk::bytes_of(&o.constants), v, i, o.index_count, 1)?;
        }
        rec.end_rendering();
        Ok(())
    }

    /// Shades one unit: its rectangle, over its range of points for brute force (added by
    /// blending to what earlier ranges left), else by walking the tree. `prepare` made the
    /// pipelines of `model`.
    pub fn record_unit(
        &self,
        rec: &mut Recorder,
        inputs: &ShadeInputs,
        constants: &ShadeConstants,
        unit: &ShadeUnit,
        variant: ShadeVariant,
    ) -> Result<()> {
        let binds = [
            Bind::Uniform(inputs.object_params),
            Bind::Texels(inputs.nodes),
            Bind::Texels(inputs.points),
            Bind::Write(inputs.work),
            Bind::Read(inputs.lights),
            Bind::Sampled(inputs.shadow_map, inputs.shadow_sampler),
            Bind::Texels(inputs.point_lights),
            Bind::Texels(inputs.node_flux),
            Bind::StorageImageRead(inputs.position),
            Bind::StorageImageRead(inputs.normal),
            Bind::Texels(inputs.tile_headers),
            Bind::Texels(inputs.tile_entries),
            Bind::Texels(inputs.sd_table),
            Bind::Uniform(inputs.frame_params),
            Bind::Texels(inputs.point_flux),
            Bind::Texels(inputs.point_spread),
            Bind::Sampled(inputs.shadow_map, inputs.depth_sampler),
            Bind::StorageImageRead(inputs.albedo),
            Bind::Texels(inputs.far_field),
            Bind::Sampled(inputs.shadow_normals, inputs.depth_sampler),
        ];
        let mut c = *constants;
        c.point_range = glam::UVec4::new(unit.first_point, unit.point_count, unit.object, inputs.list_tile);
        let additive = unit.point_count > 0;
        let pipeline = self
            .shading
            .get(&(variant, additive))
            .ok_or_else(|| crate::runtime!("shade: the pipeline of {variant:?} was not prepared"))?;
        // One rendering scope per unit: every draw writes the work counters, and the barrier
        // between two writes cannot sit inside a rendering scope.
        rec.prepare_draw_reads(&binds)?;
        rec.begin_rendering(&[(inputs.color, None)], None, 0)?;
        rec.set_scissor(unit.x, unit.y, unit.width, unit.height);
        rec.draw(pipeline, &binds, vk::bytes_of(&c), None, None, 3, 1)?;
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
