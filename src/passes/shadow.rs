//! Shadow maps: the mesh's depth seen from each light, one layer of a 2D-array depth image per
//! directional light and six (+x −x +y −y +z −z) per point light.
//! Reads: vertices, indices. Writes: the shadow map.

use glam::{Mat4, Vec3};

use crate::error::Result;
use crate::scene::Light;
use crate::vk::{
    self, Buffer, Context, CullModeFlags, Format, GraphicsDesc, Image, Pipeline, PrimitiveTopology, Recorder,
};

pub const SHADOW_FORMAT: Format = Format::D32_SFLOAT;

/// The light's view-projection matrices (one per layer) for a scene in the sphere (centre, radius).
pub fn light_matrices(light: &Light, centre: Vec3, radius: f32) -> Vec<Mat4> {
    match *light {
        Light::Directional { toward, .. } => {
            let d = toward.normalize();
            let up = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
            let view = Mat4::look_at_rh(centre + d * 2.0 * radius, centre, up);
            vec![Mat4::orthographic_rh(-radius, radius, -radius, radius, 0.5 * radius, 3.5 * radius) * view]
        }
        Light::Point { position, .. } => {
            let distance = (position - centre).length();
            let far = distance + radius * 1.01;
            let near = (distance - radius * 1.01).max(far * 1e-4);
            let faces = [
                (Vec3::X, Vec3::Y),
                (Vec3::NEG_X, Vec3::Y),
                (Vec3::Y, Vec3::Z),
                (Vec3::NEG_Y, Vec3::Z),
                (Vec3::Z, Vec3::Y),
                (Vec3::NEG_Z, Vec3::Y),
            ];
            faces
                .iter()
                .map(|&(dir, up)| {
                    // A slightly wider cone than 90° so the face edges overlap.
                    Mat4::perspective_rh(91f32.to_radians(), 1.0, near, far)
                        * Mat4::look_at_rh(position, position + dir, up)
                })
                .collect()
        }
    }
}

pub struct ShadowPass {
    pipeline: Pipeline,
}

impl ShadowPass {
    pub fn new(ctx: &Context) -> Result<ShadowPass> {
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                vertex_shader: "hierarchy/shadow.vert",
                fragment_shader: None,
                vertex_stride: 24,
                vertex_attributes: &[(0, Format::R32G32B32_SFLOAT, 0)],
                topology: PrimitiveTopology::TRIANGLE_LIST,
                color_formats: &[],
                depth_format: Some(SHADOW_FORMAT),
                depth_test: true,
                depth_bias: true,
                cull_mode: CullModeFlags::NONE,
                additive_blend: false,
                specialization: &[],
            },
        )?;
        Ok(ShadowPass { pipeline })
    }

    pub fn record(
        &self,
        rec: &mut Recorder,
        vertices: &Buffer,
        indices: &Buffer,
        index_count: u32,
        shadow_map: &Image,
        matrices: &[Mat4],
    ) -> Result<()> {
        for (layer, matrix) in matrices.iter().enumerate() {
            rec.use_buffer(vertices, vk::Access::VERTEX_INPUT)?;
            rec.use_buffer(indices, vk::Access::INDEX_INPUT)?;
            rec.begin_rendering(&[], Some((shadow_map, Some(1.0))), layer as u32)?;
            rec.set_depth_bias(0.0, 1.5);
            rec.draw(&self.pipeline, &[], bytemuck::bytes_of(matrix), Some(vertices), Some(indices), index_count, 1)?;
            rec.end_rendering();
        }
        Ok(())
    }
}
