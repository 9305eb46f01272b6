//! The background pass (shaders/background.frag): the environment behind the objects, per pixel
//! that no surface covers (black without one). A full-screen triangle before the objects are
//! shaded. Reads: the G-buffer's position, the environment map. Writes: colour.

use std::sync::Arc;

use glam::{Mat3, Vec3};

use crate::environment::{Environment, Layout, Radiance};
use crate::error::Result;
use crate::gpu::BackgroundConstants;
use crate::scene::Camera;
use crate::vk::{
    self, Bind, Buffer, BufferUsageFlags, Context, Extent2D, Format, Image, ImageUsageFlags, MemoryLocation, Pipeline,
    Recorder, Sampler,
};

pub struct BackgroundPass {
    pipeline: Pipeline,
    /// The map on the GPU (1×1 black when there is none or it is constant) and what it was made from.
    map: Image,
    made_from: Option<Arc<Environment>>,
    sampler: Sampler,
}

impl BackgroundPass {
    pub fn new(ctx: &Context) -> Result<BackgroundPass> {
        let pipeline = crate::passes::shade::full_screen_pipeline(ctx, "background.frag", false, &[])?;
        Ok(BackgroundPass {
            pipeline,
            map: upload(ctx, 1, 1, &[[0.0; 4]])?,
            made_from: None,
            sampler: Sampler::repeating(ctx)?,
        })
    }

    /// Makes the GPU's map follow `environment` (uploaded when it changed).
    pub fn sync(&mut self, ctx: &Context, environment: Option<&Arc<Environment>>) -> Result<()> {
        let same = match (environment, &self.made_from) {
            (Some(a), Some(b)) => Arc::ptr_eq(a, b) || a.radiance == b.radiance,
            (None, None) => true,
            _ => false,
        };
        if same {
            self.made_from = environment.cloned();
            return Ok(());
        }
        ctx.wait_idle()?;
        self.map = match environment.map(|e| &e.radiance) {
            Some(Radiance::Image { width, height, texels, .. }) => {
                let max = ctx.limits().max_image_dimension2_d;
                if *width > max || *height > max {
                    return Err(crate::bad_input!(
                        "--env: {width}x{height}: this device allows at most {max} texels a side"
                    ));
                }
                let rgba: Vec<[f32; 4]> = texels.iter().map(|t| [t[0], t[1], t[2], 1.0]).collect();
                upload(ctx, *width, *height, &rgba)?
            }
            _ => upload(ctx, 1, 1, &[[0.0; 4]])?,
        };
        self.made_from = environment.cloned();
        Ok(())
    }

    /// Fills the uncovered pixels of `color` with the environment seen through `camera`.
    pub fn record(
        &self,
        rec: &mut Recorder,
        color: &Image,
        position: &Image,
        camera: &Camera,
        aspect: f32,
    ) -> Result<()> {
        let binds = [Bind::StorageImageRead(position), Bind::Sampled(&self.map, &self.sampler)];
        let constants = constants(self.made_from.as_deref(), camera, aspect);
        rec.prepare_draw_reads(&binds)?;
        rec.begin_rendering(&[(color, None)], None, 0)?;
        rec.draw(&self.pipeline, &binds, vk::bytes_of(&constants), None, None, 3, 1)?;
        rec.end_rendering();
        Ok(())
    }
}

/// The pass's constants: each pixel's ray in the map's frame, and the map's kind and size.
pub fn constants(environment: Option<&Environment>, camera: &Camera, aspect: f32) -> BackgroundConstants {
    let Some(env) = environment else { return BackgroundConstants::default() };
    let forward = (camera.target - camera.eye).normalize_or(Vec3::NEG_Z);
    let right = forward.cross(camera.up).normalize_or(Vec3::X);
    let up = right.cross(forward);
    let t = (camera.fov_y_deg.to_radians() * 0.5).tan();
    // Vulkan's y points down the image: the top row (ndc y = −1) looks along +up.
    let to_map = env.to_world.transpose() * Mat3::from_cols(right * (t * aspect), -up * t, forward);
    let (kind, width, height) = match &env.radiance {
        Radiance::Constant(_) => (1, 1, 1),
        Radiance::Image { width, height, layout: Layout::LatLong, .. } => (2, *width, *height),
        Radiance::Image { width, height, layout: Layout::Octahedral, .. } => (3, *width, *height),
    };
    let constant = match env.radiance {
        Radiance::Constant(l) => l,
        _ => Vec3::ZERO,
    };
    BackgroundConstants {
        ray_x: to_map.x_axis.extend(0.0),
        ray_y: to_map.y_axis.extend(0.0),
        ray_z: to_map.z_axis.extend(0.0),
        constant: constant.extend(env.scale),
        kind,
        width,
        height,
        pad: 0,
    }
}

fn upload(ctx: &Context, width: u32, height: u32, texels: &[[f32; 4]]) -> Result<Image> {
    let usage = ImageUsageFlags::SAMPLED | ImageUsageFlags::TRANSFER_DST;
    let image =
        Image::new_2d(ctx, "environment map", Format::R32G32B32A32_SFLOAT, Extent2D { width, height }, 1, usage)?;
    let mut staging = Buffer::new(
        ctx,
        "environment map (staging)",
        std::mem::size_of_val(texels) as u64,
        BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )?;
    staging.write(0, texels)?;
    ctx.submit(None, |rec| rec.copy_buffer_to_image(&staging, &image))?;
    Ok(image)
}
