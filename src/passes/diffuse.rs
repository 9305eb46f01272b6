//! The diffuse pass (shaders/diffuse.frag): opaque objects' Lambertian reflection of every light,
//! shadowed by every object, per pixel of the G-buffer that an opaque object covers. A full-screen
//! triangle; other pixels are left as the shade pass wrote them. Reads: the G-buffer's position,
//! normal and albedo, the opaque objects' lights and shadow maps. Writes: colour.
//! (Their surfaces are drawn into the G-buffer by the surface pass: `ShadePass::record_surface`.)

use crate::error::Result;
use crate::gpu::DiffuseConstants;
use crate::shadows::Shadows;
use crate::vk::{self, Bind, Context, Image, Pipeline, Recorder};

pub struct DiffusePass {
    pipeline: Pipeline,
}

impl DiffusePass {
    pub fn new(ctx: &Context) -> Result<DiffusePass> {
        let pipeline = crate::passes::shade::full_screen_pipeline(ctx, "diffuse.frag", false, &[])?;
        Ok(DiffusePass { pipeline })
    }

    /// Shades the pixels whose G-buffer id is `first_opaque` or above.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        rec: &mut Recorder,
        color: &Image,
        (position, normal, albedo): (&Image, &Image, &Image),
        shadows: &Shadows,
        first_opaque: u32,
    ) -> Result<()> {
        let binds = [
            Bind::StorageImageRead(position),
            Bind::StorageImageRead(normal),
            Bind::StorageImageRead(albedo),
            Bind::Read(&shadows.lights),
            Bind::Sampled(&shadows.shadow_map, &shadows.shadow_sampler),
        ];
        let constants = DiffuseConstants { first_opaque, pad: [0; 3] };
        rec.prepare_draw_reads(&binds)?;
        rec.begin_rendering(&[(color, None)], None, 0)?;
        rec.draw(&self.pipeline, &binds, vk::bytes_of(&constants), None, None, 3, 1)?;
        rec.end_rendering();
        Ok(())
    }
}
