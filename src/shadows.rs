//! A set of lights as the GPU reads it, with the shadow maps fitted to one receiver: the lights
//! buffer (`LightSet` and each shadow layer's matrix, lights.glsl), the 2D-array shadow map and
//! its comparison sampler. Each translucent object's hierarchy has one; opaque objects share one.

use glam::{Mat4, Vec3};

use crate::error::Result;
use crate::gpu::{GpuLight, LightSetHeader};
use crate::passes::shadow;
use crate::scene::Light;
use crate::vk::{Buffer, BufferUsageFlags, Context, Extent2D, Image, ImageUsageFlags, MemoryLocation, Sampler};
use crate::{bad_input, runtime};

pub struct Shadows {
    /// `LightSetHeader`, the lights, then one matrix per shadow-map layer.
    pub lights: Buffer,
    pub shadow_map: Image,
    /// The mesh's normal and mean curvature at each texel of `shadow_map`
    /// (`shadow::SHADOW_NORMAL_FORMAT`).
    pub shadow_normals: Image,
    pub shadow_sampler: Sampler,
    /// Nearest, no comparison: the depth itself (the Monte Carlo table's single scattering
    /// measures how far light travels inside from it).
    pub depth_sampler: Sampler,
    pub(crate) layer_matrices: Vec<Mat4>,
    /// The box of the other objects that may cast shadows on the receiver (see `set_casters`).
    casters: Option<(Vec3, Vec3)>,
    eta: f32,
    resolution: u32,
    /// Lights the buffer and layers were made for (later light sets may not exceed it).
    pub light_count: u32,
}

impl Shadows {
    /// For `lights` at `resolution` texels per side (per cube face for point lights); `eta` is the
    /// receiver's relative index (its Fresnel transmittance), 1 for an opaque receiver.
    pub fn new(ctx: &Context, lights: &[Light], resolution: u32, eta: f32) -> Result<Shadows> {
        if lights.is_empty() {
            return Err(bad_input!("--light: at least one light is needed"));
        }
        let layers: u32 = lights.iter().map(Light::shadow_layers).sum();
        Ok(Shadows {
            lights: Buffer::new(
                ctx,
                "lights",
                (std::mem::size_of::<LightSetHeader>() + 64 * (lights.len() + layers as usize)) as u64,
                BufferUsageFlags::STORAGE_BUFFER,
                MemoryLocation::CpuToGpu,
            )?,
            shadow_map: Image::new_2d(
                ctx,
                "shadow map",
                shadow::SHADOW_FORMAT,
                Extent2D { width: resolution, height: resolution },
                layers.max(2), // an array view even for one light (sampler2DArrayShadow)
                ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | ImageUsageFlags::SAMPLED,
            )?,
            shadow_normals: Image::new_2d(
                ctx,
                "shadow-map normals",
                shadow::SHADOW_NORMAL_FORMAT,
                Extent2D { width: resolution, height: resolution },
                layers.max(2),
                // Transfer: tests read it back.
                ImageUsageFlags::COLOR_ATTACHMENT | ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_SRC,
            )?,
            shadow_sampler: Sampler::new(ctx, true, true)?,
            depth_sampler: Sampler::new(ctx, false, false)?,
            layer_matrices: Vec::new(),
            casters: None,
            eta,
            resolution,
            light_count: lights.len() as u32,
        })
    }

    /// Each layer's view-projection matrix (set by `set_lights`).
    pub fn layer_matrices(&self) -> &[Mat4] {
        &self.layer_matrices
    }

    /// Writes the lights and their shadow matrices for a receiver in the sphere (centre, radius).
    /// The number of shadow-map layers each light needs must stay what it was at creation.
    pub fn set_lights(&mut self, centre: Vec3, radius: f32, lights: &[Light]) -> Result<()> {
        if lights.len() != self.light_count as usize {
            return Err(runtime!("{} lights given, the shadow maps were made for {}", lights.len(), self.light_count));
        }
        let radius = radius.max(1e-6) * 1.01;
        let header = LightSetHeader {
            light_count: lights.len() as u32,
            eta: self.eta,
            // Two shadow-map texels of the orthographic maps.
            normal_offset: 2.0 * 2.0 * radius / self.resolution as f32,
            // In 16-byte words after the header: 4 per light.
            matrix_base: 4 * lights.len() as u32,
        };
        let mut gpu_lights = Vec::with_capacity(lights.len());
        self.layer_matrices.clear();
        for light in lights {
            light.validate()?;
            // One layer, or six cube faces (a point light near the receiver, a wide spot): as
            // `light_matrices` fits them, within the layers allocated for the light.
            let matrices = shadow::light_matrices(light, centre, radius, self.casters);
            let mut gpu = GpuLight {
                first_layer: self.layer_matrices.len() as u32,
                cube: (matrices.len() == 6) as u32,
                ..GpuLight::default()
            };
            match *light {
                Light::Directional { toward, irradiance } => {
                    (gpu.position, gpu.intensity) = (toward.normalize().extend(0.0), irradiance.extend(0.0))
                }
                Light::Point { position, intensity } => {
                    (gpu.position, gpu.intensity) = (position.extend(1.0), intensity.extend(0.0))
                }
                Light::Spot { position, axis, intensity, cone_deg, delta_deg } => {
                    let (cos_total, cos_start) = Light::spot_cosines(cone_deg, delta_deg);
                    (gpu.position, gpu.intensity) = (position.extend(1.0), intensity.extend(0.0));
                    (gpu.axis, gpu.cos_falloff_start, gpu.spot) = (axis.extend(cos_total), cos_start, 1);
                }
            }
            gpu_lights.push(gpu);
            self.layer_matrices.extend(matrices);
        }
        if self.layer_matrices.len() as u32 > self.shadow_map.layers {
            return Err(runtime!(
                "lights need {} shadow layers, {} allocated",
                self.layer_matrices.len(),
                self.shadow_map.layers
            ));
        }
        let header_bytes = std::mem::size_of::<LightSetHeader>() as u64;
        self.lights.write(0, &[header])?;
        self.lights.write(header_bytes, &gpu_lights)?;
        self.lights.write(header_bytes + 64 * lights.len() as u64, &self.layer_matrices)?;
        Ok(())
    }

    /// The box of the world's other objects (`None`: the receiver is alone), whose shadows the
    /// maps must see; takes effect with the next `set_lights`.
    pub fn set_casters(&mut self, casters: Option<(Vec3, Vec3)>) {
        self.casters = casters;
    }

    pub fn casters(&self) -> Option<(Vec3, Vec3)> {
        self.casters
    }

    pub fn eta(&self) -> f32 {
        self.eta
    }

    /// The receiver's relative index of refraction (a material change); written at once.
    pub fn set_eta(&mut self, eta: f32) -> Result<()> {
        self.eta = eta;
        self.lights.write(std::mem::offset_of!(LightSetHeader, eta) as u64, &[eta])
    }
}
