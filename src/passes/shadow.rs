//! Shadow maps: the depth of every object seen from each light, one layer of a 2D-array depth
//! image per directional light, six (+x −x +y −y +z −z) per point light, one perspective layer
//! per spot light (six, as a point light, when its cone is wider than 60°), fitted to the object
//! that receives the shadows, with the mesh's interpolated normal and mean curvature at each texel
//! (where single scattering's light enters and how its beam focuses, shade.frag). Reads: every
//! object's vertices, indices and curvature. Writes: the shadow map and its normals.

use glam::{Mat4, Vec3};

use crate::error::Result;
use crate::scene::{Light, SPOT_CUBE_ABOVE_DEG};
use crate::vk::{
    self, Bind, Buffer, Context, CullModeFlags, Format, GraphicsDesc, Image, Pipeline, PrimitiveTopology, Recorder,
};

pub const SHADOW_FORMAT: Format = Format::D32_SFLOAT;
/// The normal at each shadow-map texel, octahedron-encoded in 2×16-bit snorm (points.glsl's
/// `encode_oct`), and the mesh's mean curvature there (f32 bits); R32G32_UINT is a colour
/// attachment on every Vulkan device.
pub const SHADOW_NORMAL_FORMAT: Format = Format::R32G32_UINT;

/// A mesh that casts shadows: its vertices, indices, index count and per-vertex mean curvature
/// (`gpu_world::curvature_buffer`; one 0 for a mesh without).
pub type Caster<'a> = (&'a Buffer, &'a Buffer, u32, &'a Buffer);

/// The light's view-projection matrices (one per layer: one, or six cube faces +x −x +y −y +z −z
/// where the light's GpuLight is `cube`; never more layers than `Light::shadow_layers`) for a
/// receiver in the sphere (centre, radius), with the box of the other objects that may cast shadows on it (`casters`). The maps
/// cover the receiver's sphere; their depth range reaches toward the light as far as casters lie
/// in front of the receiver, and no farther, so that a receiver alone, or beside objects that are
/// not between it and the light, gets the same maps as before.
pub fn light_matrices(light: &Light, centre: Vec3, radius: f32, casters: Option<(Vec3, Vec3)>) -> Vec<Mat4> {
    let corners = |(lo, hi): (Vec3, Vec3)| {
        (0..8).map(move |i| Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][i >> 2]))
    };
    match *light {
        Light::Directional { toward, .. } => {
            let d = toward.normalize();
            let up = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
            // How far casters over the receiver's footprint rise toward the light beyond its sphere.
            let view = Mat4::look_at_rh(centre + d * 2.0 * radius, centre, up);
            let extra = casters.map_or(0.0, |b| {
                let (lo, hi) = corners(b)
                    .map(|p| view.transform_point3(p))
                    .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(p), hi.max(p)));
                let over = lo.x < radius && hi.x > -radius && lo.y < radius && hi.y > -radius;
                // View space looks down −z from 2r above the centre: z = −r is the sphere's top.
                if over {
                    (hi.z + radius).max(0.0)
                } else {
                    0.0
                }
            });
            let view = Mat4::look_at_rh(centre + d * (2.0 * radius + extra), centre, up);
            let (near, far) = (0.5 * radius, 3.5 * radius + extra);
            vec![Mat4::orthographic_rh(-radius, radius, -radius, radius, near, far) * view]
        }
        Light::Point { position, .. } | Light::Spot { position, .. } => {
            // One perspective map over the narrower of two cones that hold every point of the
            // receiver the light reaches (and so every caster between them): from outside the
            // receiver's sphere, the one around the direction to its centre that holds the
            // sphere; a spot's own. Six cube faces where both are wider than 60°: a point light
            // inside or near the receiver, a wide spot. (A far point light had cube faces too: at
            // 50 units the default bunny covered 20 × 35 texels of one, and its single scattering
            // was a ninth of a spot's at the same place.)
            let widest = SPOT_CUBE_ABOVE_DEG.to_radians();
            let cone = match *light {
                Light::Spot { axis, cone_deg, .. } => Some((axis, cone_deg.to_radians())),
                _ => None,
            };
            let to_centre = centre - position;
            let distance = to_centre.length();
            let holds = (radius / distance).asin(); // NaN inside the sphere
                                                    // A little wider, as the cube faces are, so the cone's edge stays inside the map: 1%
                                                    // around the sphere (whose radius has its own 1%), 1% and half a degree around a
                                                    // spot's cone. (Half a degree around the sphere too wasted half of a far light's map:
                                                    // the bunny 50 units away is 2.5° across.)
            let (dir, half) = if distance > radius && holds <= widest && cone.is_none_or(|(_, c)| holds < c) {
                (to_centre / distance, holds * 1.01)
            } else {
                match cone {
                    Some((axis, c)) if c <= widest => (axis, c * 1.01 + 0.5f32.to_radians()),
                    _ => return cube_faces(position, centre, radius, casters),
                }
            };
            let (near, far) = near_far(position, centre, radius, casters);
            let up = if dir.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
            vec![Mat4::perspective_rh(2.0 * half, 1.0, near, far) * Mat4::look_at_rh(position, position + dir, up)]
        }
    }
}

/// The depth range of a light at `position` for a receiver in the sphere (centre, radius): the
/// sphere's, reaching toward the light as far as the casters' nearest point to it.
fn near_far(position: Vec3, centre: Vec3, radius: f32, casters: Option<(Vec3, Vec3)>) -> (f32, f32) {
    let distance = (position - centre).length();
    let far = distance + radius * 1.01;
    let mut near = distance - radius * 1.01;
    if let Some((lo, hi)) = casters {
        // The casters' nearest point to the light.
        near = near.min((position.clamp(lo, hi) - position).length());
    }
    (near.max(far * 1e-4), far)
}

/// The six 91° cube faces of a light at `position` (+x −x +y −y +z −z).
fn cube_faces(position: Vec3, centre: Vec3, radius: f32, casters: Option<(Vec3, Vec3)>) -> Vec<Mat4> {
    let (near, far) = near_far(position, centre, radius, casters);
    // A face measures depth along its axis, not the distance: a point at distance D seen at its
    // corner (tan 45.5° off the axis both ways) lies at D / √(1 + 2 tan² 45.5°) ≈ D / 1.75 along
    // it. With the distance as the near plane an object off a face's axis was clipped out of the
    // map (the default bunny under `--light point:0,30,40`: no single scattering, no shadow).
    let corner = 1.0 / (1.0 + 2.0 * 45.5f32.to_radians().tan().powi(2)).sqrt();
    let near = (near * corner).max(far * 1e-4);
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
            Mat4::perspective_rh(91f32.to_radians(), 1.0, near, far) * Mat4::look_at_rh(position, position + dir, up)
        })
        .collect()
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
                fragment_shader: Some("hierarchy/shadow.frag"),
                vertex_stride: 24,
                vertex_attributes: &[(0, Format::R32G32B32_SFLOAT, 0), (1, Format::R32G32B32_SFLOAT, 12)],
                topology: PrimitiveTopology::TRIANGLE_LIST,
                color_formats: &[SHADOW_NORMAL_FORMAT],
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

    /// Every mesh of `casters` into each layer of `shadow_map` and of `normals`.
    pub fn record(
        &self,
        rec: &mut Recorder,
        casters: &[Caster],
        (shadow_map, normals): (&Image, &Image),
        matrices: &[Mat4],
    ) -> Result<()> {
        for (layer, matrix) in matrices.iter().enumerate() {
            for &(vertices, indices, _, curvature) in casters {
                rec.use_buffer(vertices, vk::Access::VERTEX_INPUT)?;
                rec.use_buffer(indices, vk::Access::INDEX_INPUT)?;
                rec.prepare_draw_reads(&[Bind::Read(curvature)])?;
            }
            rec.begin_rendering(&[(normals, Some([0.0; 4]))], Some((shadow_map, Some(1.0))), layer as u32)?;
            rec.set_depth_bias(0.0, 1.5);
            for &(vertices, indices, count, curvature) in casters {
                let matrix = bytemuck::bytes_of(matrix);
                rec.draw(&self.pipeline, &[Bind::Read(curvature)], matrix, Some(vertices), Some(indices), count, 1)?;
            }
            rec.end_rendering();
        }
        Ok(())
    }
}
