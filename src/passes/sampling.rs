//! Surface sampling: the triangle-area prefix sum (64-bit fixed point), then N points uniform by area.
//! Reads: vertices, indices, the object's texture (its scatter weight, at each point's uv).
//! Writes: area prefix sum, points (unsorted).

use crate::error::Result;
use crate::gpu::SampleConstants;
use crate::gpu_world::SurfaceTexture;
use crate::vk::{Bind, Buffer, Context, Pipeline, Recorder};

/// Bytes of the triangle-area prefix sum for `triangles` triangles: the total area (f32 and
/// padding), then T + 1 64-bit fixed-point sums (shaders/hierarchy/triangle_areas.comp).
pub fn prefix_bytes(triangles: u32) -> u64 {
    8 + (triangles as u64 + 1) * 8
}

pub struct SamplingPass {
    areas: Pipeline,
    points: Pipeline,
}

impl SamplingPass {
    pub fn new(ctx: &Context) -> Result<SamplingPass> {
        Ok(SamplingPass {
            areas: Pipeline::compute(ctx, "hierarchy/triangle_areas.comp")?,
            points: Pipeline::compute(ctx, "hierarchy/sample_points.comp")?,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        vertices: &Buffer,
        indices: &Buffer,
        texture: &SurfaceTexture,
        triangle_count: u32,
        prefix: &Buffer,
        points: &Buffer,
        point_count: u32,
        seed: u32,
    ) -> Result<()> {
        // The bytes the shaders will touch for these counts, against the buffers bound: the
        // validation layer's GPU-assisted mode, which would catch a write past the end, does not
        // run on lavapipe (see README "Validation").
        let n = point_count as u64;
        let t = triangle_count as u64;
        // A texture reads one uv (8 bytes) per vertex (24 bytes each).
        let uv_bytes = if texture.kind != 0 { vertices.size / 24 * 8 } else { 0 };
        let needs =
            [(indices, t * 12), (prefix, prefix_bytes(triangle_count)), (points, n * 64), (&texture.uvs, uv_bytes)];
        for (buffer, needed) in needs {
            if buffer.size < needed {
                return Err(crate::runtime!(
                    "sampling: {} holds {} bytes; {triangle_count} triangles and {point_count} points need {needed}",
                    buffer.name,
                    buffer.size
                ));
            }
        }
        rec.dispatch(
            &self.areas,
            &[Bind::Read(vertices), Bind::Read(indices), Bind::Write(prefix)],
            bytemuck::bytes_of(&[triangle_count, point_count]),
            [1, 1, 1],
        )?;
        let constants = SampleConstants {
            point_count,
            triangle_count,
            seed,
            texture_kind: texture.kind,
            tex1: texture.tex1,
            tex2: texture.tex2,
        };
        rec.dispatch(
            &self.points,
            &[
                Bind::Read(vertices),
                Bind::Read(indices),
                Bind::Read(prefix),
                Bind::Write(points),
                Bind::Read(&texture.uvs),
                Bind::Sampled(&texture.image, &texture.sampler),
            ],
            bytemuck::bytes_of(&constants),
            [point_count.div_ceil(64), 1, 1],
        )
    }
}
