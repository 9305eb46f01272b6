//! Recording commands: a [`Recorder`] is the only way passes touch a command buffer. Each
//! method declares how its command uses its resources; the recorder inserts the barriers
//! (`barriers.rs`), checks and writes the descriptors (`descriptors.rs`) and records the command.
//! Submission is in `submit.rs`.

use ash::vk;

use super::barriers::{Access, BufferAccess, PendingBarriers};
use super::context::Context;
use super::descriptors::{write_set, Bind};
use super::pipeline::Pipeline;
use super::profiler::GpuProfiler;
use super::resources::{aspect_of, has_stencil, Buffer, Image};
use crate::error::Result;
use crate::runtime;

/// Timestamps are written once all earlier commands are done. BOTTOM_OF_PIPE means that for a
/// timestamp, as ALL_COMMANDS does, without the best-practices layer's warning about the latter.
const TIMESTAMP_STAGE: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::BOTTOM_OF_PIPE;

/// Records commands into a command buffer of the context (see [`Context::submit`]).
pub struct Recorder<'a> {
    pub(super) ctx: &'a Context,
    pub(super) cmd: vk::CommandBuffer,
    descriptor_pool: vk::DescriptorPool,
    profiler: Option<&'a mut GpuProfiler>,
    pub(super) inside_rendering: bool,
    open_scopes: Vec<usize>,
    /// Barriers declared for the next command, recorded together just before it.
    pub(super) pending: PendingBarriers,
}

impl<'a> Recorder<'a> {
    /// A recorder for `cmd`, which is recording; without a descriptor pool (null) it cannot
    /// dispatch or draw.
    pub(super) fn new(
        ctx: &'a Context,
        cmd: vk::CommandBuffer,
        descriptor_pool: vk::DescriptorPool,
        profiler: Option<&'a mut GpuProfiler>,
    ) -> Recorder<'a> {
        Recorder {
            ctx,
            cmd,
            descriptor_pool,
            profiler,
            inside_rendering: false,
            open_scopes: Vec::new(),
            pending: PendingBarriers::default(),
        }
    }

    /// Ends an open rendering scope; the profiler, to resolve after the submission.
    pub(super) fn finish(mut self) -> Option<&'a mut GpuProfiler> {
        self.end_rendering();
        self.profiler.take()
    }

    fn device(&self) -> &ash::Device {
        self.ctx.device()
    }

    pub fn context(&self) -> &Context {
        self.ctx
    }

    /// Checks `binds` and the push constants against `pipeline`, declares each bound resource for
    /// `stage` (the barriers wait in the pending batch), then binds the pipeline with a new set 0.
    fn bind(&mut self, pipeline: &Pipeline, binds: &[Bind], push_constants: &[u8], stage: Stage) -> Result<()> {
        pipeline.check_binds(binds)?;
        if push_constants.len() as u32 != pipeline.push_constant_size {
            return Err(runtime!(
                "pipeline {}: {} bytes of push constants, its shaders declare {}",
                pipeline.name,
                push_constants.len(),
                pipeline.push_constant_size
            ));
        }
        for bind in binds {
            self.declare(bind, stage)?;
        }
        self.flush_barriers();
        let device = self.ctx.device();
        if !binds.is_empty() {
            let set = write_set(device, self.descriptor_pool, pipeline, binds)?;
            // SAFETY: the set matches the pipeline's layout and lives until the pool's reset.
            unsafe { device.cmd_bind_descriptor_sets(self.cmd, pipeline.bind_point, pipeline.layout, 0, &[set], &[]) };
        }
        // SAFETY: recording into our command buffer; the push-constant range is the layout's.
        unsafe {
            device.cmd_bind_pipeline(self.cmd, pipeline.bind_point, pipeline.raw);
            if !push_constants.is_empty() {
                device.cmd_push_constants(self.cmd, pipeline.layout, pipeline.push_stages, 0, push_constants);
            }
        }
        Ok(())
    }

    /// Runs a compute pipeline over `groups` work groups.
    pub fn dispatch(
        &mut self,
        pipeline: &Pipeline,
        binds: &[Bind],
        push_constants: &[u8],
        groups: [u32; 3],
    ) -> Result<()> {
        let max = self.ctx.limits().max_compute_work_group_count;
        if groups.iter().zip(max).any(|(g, m)| *g > m) {
            return Err(runtime!("{}: dispatch of {groups:?} groups exceeds the device's {max:?}", pipeline.name));
        }
        self.bind(pipeline, binds, push_constants, Stage::Compute)?;
        if groups.contains(&0) {
            return Ok(());
        }
        // SAFETY: a compute pipeline and its set are bound.
        unsafe { self.device().cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]) };
        Ok(())
    }

    /// Starts dynamic rendering into `colors` (cleared when a value is given) and `depth`,
    /// over `layer` of layered targets. Resources that draws read must be declared first.
    pub fn begin_rendering(
        &mut self,
        colors: &[(&Image, Option<[f32; 4]>)],
        depth: Option<(&Image, Option<f32>)>,
        layer: u32,
    ) -> Result<()> {
        for (img, clear) in colors {
            if clear.is_some() && img.layers == 1 {
                self.discard_image(img);
            }
            self.track_image(img, Access::COLOR_ATTACHMENT)?;
        }
        if let Some((img, clear)) = depth {
            // A layout transition from UNDEFINED would discard every layer, not just this one.
            if clear.is_some() && img.layers == 1 {
                self.discard_image(img);
            }
            let access =
                if has_stencil(img.format) { Access::DEPTH_STENCIL_ATTACHMENT } else { Access::DEPTH_ATTACHMENT };
            self.track_image(img, access)?;
        }
        self.flush_barriers();
        // A depth format with stencil is attached as both (stencil cleared to 0 with the depth).
        let stencil = depth.is_some_and(|(img, _)| has_stencil(img.format));
        let extent = colors.first().map(|c| c.0.extent).or(depth.map(|d| d.0.extent)).unwrap_or_default();
        let views = |img: &Image| -> Result<vk::ImageView> {
            if img.layers == 1 {
                Ok(img.view)
            } else {
                img.layer_views
                    .get(layer as usize)
                    .copied()
                    .ok_or_else(|| runtime!("{}: no layer {layer} ({} layers)", img.name, img.layers))
            }
        };
        let color_infos: Vec<_> = colors
            .iter()
            .map(|(img, clear)| {
                Ok(vk::RenderingAttachmentInfo::default()
                    .image_view(views(img)?)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(if clear.is_some() { vk::AttachmentLoadOp::CLEAR } else { vk::AttachmentLoadOp::LOAD })
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue { color: vk::ClearColorValue { float32: clear.unwrap_or_default() } }))
            })
            .collect::<Result<_>>()?;
        let depth_info = depth
            .map(|(img, clear)| {
                Ok::<_, crate::Error>(
                    vk::RenderingAttachmentInfo::default()
                        .image_view(views(img)?)
                        .image_layout(if has_stencil(img.format) {
                            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                        } else {
                            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL
                        })
                        .load_op(if clear.is_some() { vk::AttachmentLoadOp::CLEAR } else { vk::AttachmentLoadOp::LOAD })
                        .store_op(vk::AttachmentStoreOp::STORE)
                        .clear_value(vk::ClearValue {
                            depth_stencil: vk::ClearDepthStencilValue { depth: clear.unwrap_or(1.0), stencil: 0 },
                        }),
                )
            })
            .transpose()?;
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent };
        let mut info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&color_infos);
        if let Some(d) = &depth_info {
            info = info.depth_attachment(d);
            if stencil {
                info = info.stencil_attachment(d);
            }
        }
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: extent.width as f32,
            height: extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: attachments are in the layouts named above (barriers recorded just above).
        unsafe {
            self.device().cmd_begin_rendering(self.cmd, &info);
            self.device().cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.device().cmd_set_scissor(self.cmd, 0, &[area]);
        }
        self.inside_rendering = true;
        Ok(())
    }

    pub fn end_rendering(&mut self) {
        if self.inside_rendering {
            unsafe { self.device().cmd_end_rendering(self.cmd) };
            self.inside_rendering = false;
        }
    }

    /// Restricts drawing to a rectangle of the current rendering scope (tiled rendering).
    pub fn set_scissor(&mut self, x: u32, y: u32, width: u32, height: u32) {
        let rect =
            vk::Rect2D { offset: vk::Offset2D { x: x as i32, y: y as i32 }, extent: vk::Extent2D { width, height } };
        unsafe { self.device().cmd_set_scissor(self.cmd, 0, &[rect]) };
    }

    pub fn set_depth_bias(&mut self, constant: f32, slope: f32) {
        unsafe { self.device().cmd_set_depth_bias(self.cmd, constant, 0.0, slope) };
    }

    /// Draws `count` vertices (or indices, with an index buffer of u32) inside a rendering scope.
    #[allow(clippy::too_many_arguments)]
    pub fn draw(
        &mut self,
        pipeline: &Pipeline,
        binds: &[Bind],
        push_constants: &[u8],
        vertices: Option<&Buffer>,
        indices: Option<&Buffer>,
        count: u32,
        instances: u32,
    ) -> Result<()> {
        if !self.inside_rendering {
            return Err(runtime!("draw with {} outside a rendering scope", pipeline.name));
        }
        if let Some(v) = vertices {
            self.track_buffer(v, BufferAccess::VERTEX_INPUT)?;
        }
        if let Some(i) = indices {
            self.track_buffer(i, BufferAccess::INDEX_INPUT)?;
        }
        self.bind(pipeline, binds, push_constants, Stage::Graphics)?;
        // SAFETY: graphics pipeline bound inside a rendering scope.
        unsafe {
            if let Some(v) = vertices {
                self.device().cmd_bind_vertex_buffers(self.cmd, 0, &[v.raw], &[0]);
            }
            match indices {
                Some(i) => {
                    self.device().cmd_bind_index_buffer(self.cmd, i.raw, 0, vk::IndexType::UINT32);
                    self.device().cmd_draw_indexed(self.cmd, count, instances, 0, 0, 0);
                }
                None => self.device().cmd_draw(self.cmd, count, instances, 0, 0),
            }
        }
        Ok(())
    }

    /// Declares the resources of a later draw before its rendering scope begins (barriers cannot
    /// be recorded inside one).
    pub fn prepare_draw_reads(&mut self, binds: &[Bind]) -> Result<()> {
        binds.iter().try_for_each(|bind| self.declare(bind, Stage::Graphics))?;
        self.flush_barriers();
        Ok(())
    }

    /// Declares how the shaders of `stage` use a bound resource; a barrier, if needed, joins the
    /// pending batch.
    fn declare(&mut self, bind: &Bind, stage: Stage) -> Result<()> {
        // Inside a rendering scope, a write declared before begin_rendering (prepare_draw_reads)
        // is already ordered: declaring it again for the draw is not a new hazard.
        let declared_write = |b: &Buffer| self.inside_rendering && b.state.get().last_write == stage.write().memory();
        match bind {
            Bind::Read(b) => self.track_buffer(b, stage.read().memory()),
            Bind::Write(b) if declared_write(b) => Ok(()),
            Bind::Write(b) => self.track_buffer(b, stage.write().memory()),
            Bind::Uniform(b) => {
                self.track_buffer(b, BufferAccess { stage: stage.flags(), ..BufferAccess::UNIFORM_READ })
            }
            Bind::Texels(b) => {
                if b.texel_view == vk::BufferView::null() {
                    return Err(runtime!("buffer {} has no texel view (made without UNIFORM_TEXEL_BUFFER)", b.name));
                }
                self.track_buffer(b, BufferAccess { stage: stage.flags(), ..BufferAccess::TEXEL_READ })
            }
            Bind::Sampled(img, _) => self.track_image(img, stage.sampled()),
            Bind::StorageImageRead(img) => self.track_image(img, stage.read()),
            Bind::StorageImageWrite(img) => self.track_image(img, stage.write()),
        }
    }

    pub fn copy_buffer(&mut self, src: &Buffer, dst: &Buffer, bytes: u64) -> Result<()> {
        if bytes > src.size || bytes > dst.size {
            return Err(runtime!(
                "copy of {bytes} bytes from {} ({}) to {} ({})",
                src.name,
                src.size,
                dst.name,
                dst.size
            ));
        }
        self.track_buffer(src, BufferAccess::TRANSFER_READ)?;
        self.track_buffer(dst, BufferAccess::TRANSFER_WRITE)?;
        self.flush_barriers();
        let region = [vk::BufferCopy { src_offset: 0, dst_offset: 0, size: bytes }];
        unsafe { self.device().cmd_copy_buffer(self.cmd, src.raw, dst.raw, &region) };
        Ok(())
    }

    pub fn fill_buffer(&mut self, dst: &Buffer, value: u32) -> Result<()> {
        self.use_buffer(dst, BufferAccess::TRANSFER_WRITE)?;
        unsafe { self.device().cmd_fill_buffer(self.cmd, dst.raw, 0, vk::WHOLE_SIZE, value) };
        Ok(())
    }

    /// Copies layer 0 of a colour image into a buffer, tightly packed, then makes it host-readable.
    pub fn copy_image_to_buffer(&mut self, src: &Image, dst: &Buffer) -> Result<()> {
        self.track_image(src, Access::TRANSFER_READ)?;
        self.track_buffer(dst, BufferAccess::TRANSFER_WRITE)?;
        self.flush_barriers();
        let region = [layer0_region(src)];
        unsafe {
            self.device().cmd_copy_image_to_buffer(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst.raw,
                &region,
            )
        };
        self.use_buffer(dst, BufferAccess::HOST_READ)
    }

    /// Fills layer 0 of a colour image from a tightly packed buffer (uploads, tests); the image's
    /// earlier contents are discarded.
    pub fn copy_buffer_to_image(&mut self, src: &Buffer, dst: &Image) -> Result<()> {
        let texel = match dst.format {
            vk::Format::R32G32B32A32_SFLOAT => 16,
            vk::Format::R8G8B8A8_UNORM | vk::Format::R8G8B8A8_SRGB | vk::Format::R32_SFLOAT => 4,
            f => return Err(runtime!("copy_buffer_to_image into {}: format {f:?} not supported", dst.name)),
        };
        let bytes = texel * dst.extent.width as u64 * dst.extent.height as u64;
        if src.size < bytes {
            return Err(runtime!("copy of {} ({} bytes) into {} needs {bytes} bytes", src.name, src.size, dst.name));
        }
        self.track_buffer(src, BufferAccess::TRANSFER_READ)?;
        self.discard_image(dst);
        self.track_image(dst, Access::TRANSFER_WRITE)?;
        self.flush_barriers();
        let region = [layer0_region(dst)];
        // SAFETY: the image is in TRANSFER_DST_OPTIMAL (barrier above); the buffer holds the region.
        unsafe {
            self.device().cmd_copy_buffer_to_image(
                self.cmd,
                src.raw,
                dst.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            )
        };
        Ok(())
    }

    /// Scales all of `src` onto all of a swapchain image (not a tracked [`Image`]), whose earlier
    /// contents are discarded, and leaves it ready to present. Blitting converts between the
    /// source's RGBA and the swapchain's channel order.
    pub(crate) fn blit_to_swapchain(
        &mut self,
        src: &Image,
        dst: vk::Image,
        dst_view: vk::ImageView,
        dst_extent: vk::Extent2D,
        overlay: Option<(&mut super::overlay::Overlay, &super::overlay::OverlayFrame)>,
    ) -> Result<()> {
        self.use_image(src, Access::TRANSFER_READ)?;
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        // Chained to the acquire semaphore's wait at ALL_TRANSFER: the layout change happens after
        // the presentation engine has let go of the image.
        let to_transfer = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::NONE)
            .dst_stage_mask(vk::PipelineStageFlags2::BLIT)
            .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .old_layout(vk::ImageLayout::UNDEFINED)
            .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(dst)
            .subresource_range(range)];
        let layers = vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        };
        let corner = |e: vk::Extent2D| vk::Offset3D { x: e.width as i32, y: e.height as i32, z: 1 };
        let region = [vk::ImageBlit {
            src_subresource: layers,
            src_offsets: [vk::Offset3D::default(), corner(src.extent)],
            dst_subresource: layers,
            dst_offsets: [vk::Offset3D::default(), corner(dst_extent)],
        }];
        // With an overlay, the blit's result is drawn over as a colour attachment.
        let to_overlay = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::BLIT)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)
            .dst_access_mask(vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE)
            .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .new_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(dst)
            .subresource_range(range)];
        let (last_stage, last_access, last_layout) = if overlay.is_some() {
            (
                vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            )
        } else {
            (vk::PipelineStageFlags2::BLIT, vk::AccessFlags2::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        };
        // Then to the present layout, before the semaphore the present waits on (signalled at
        // ALL_COMMANDS, which takes in the transition). BOTTOM_OF_PIPE, not ALL_COMMANDS: the
        // same for a barrier with no later access, without the best-practices layer's warning.
        let to_present = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(last_stage)
            .src_access_mask(last_access)
            .dst_stage_mask(vk::PipelineStageFlags2::BOTTOM_OF_PIPE)
            .dst_access_mask(vk::AccessFlags2::NONE)
            .old_layout(last_layout)
            .new_layout(vk::ImageLayout::PRESENT_SRC_KHR)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(dst)
            .subresource_range(range)];
        // SAFETY: `dst` is an acquired swapchain image; `src` is in TRANSFER_SRC_OPTIMAL (above).
        unsafe {
            let device = self.device();
            device.cmd_pipeline_barrier2(self.cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_transfer));
            device.cmd_blit_image(
                self.cmd,
                src.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                dst,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
                vk::Filter::LINEAR,
            );
        }
        if let Some((overlay, frame)) = overlay {
            let attachment = [vk::RenderingAttachmentInfo::default()
                .image_view(dst_view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE)];
            let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: dst_extent };
            let info = vk::RenderingInfo::default().render_area(area).layer_count(1).color_attachments(&attachment);
            // SAFETY: the image is in COLOR_ATTACHMENT_OPTIMAL (barrier below, before the scope).
            unsafe {
                let device = self.device();
                device
                    .cmd_pipeline_barrier2(self.cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_overlay));
                device.cmd_begin_rendering(self.cmd, &info);
            }
            let drawn = overlay.record(self.cmd, dst_extent, frame);
            unsafe { self.device().cmd_end_rendering(self.cmd) };
            drawn?;
        }
        unsafe {
            self.device()
                .cmd_pipeline_barrier2(self.cmd, &vk::DependencyInfo::default().image_memory_barriers(&to_present));
        }
        Ok(())
    }

    /// Makes a buffer written on the GPU readable by the host after the submission's fence.
    pub fn host_read(&mut self, buffer: &Buffer) -> Result<()> {
        self.use_buffer(buffer, BufferAccess::HOST_READ)
    }

    /// Opens a named timestamp scope (no-op without a profiler). Scopes may nest.
    pub fn begin_scope(&mut self, name: &str) {
        if let Some(p) = self.profiler.as_deref_mut() {
            if let Some((pool, query, index)) = p.open(name) {
                // SAFETY: the query was reset on the host before this submission.
                unsafe { self.ctx.device().cmd_write_timestamp2(self.cmd, TIMESTAMP_STAGE, pool, query) };
                self.open_scopes.push(index);
            }
        }
    }

    /// Records `f` inside a named timestamp scope (see [`begin_scope`](Self::begin_scope)).
    pub fn scope<T>(&mut self, name: &str, f: impl FnOnce(&mut Self) -> Result<T>) -> Result<T> {
        self.begin_scope(name);
        let t = f(self)?;
        self.end_scope();
        Ok(t)
    }

    pub fn end_scope(&mut self) {
        let Some(index) = self.open_scopes.pop() else { return };
        if let Some(p) = self.profiler.as_deref_mut() {
            let (pool, query) = p.close(index);
            unsafe { self.ctx.device().cmd_write_timestamp2(self.cmd, TIMESTAMP_STAGE, pool, query) };
        }
    }
}

/// All of layer 0 of `image`, tightly packed in a buffer from offset 0.
fn layer0_region(image: &Image) -> vk::BufferImageCopy {
    vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: aspect_of(image.format),
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D { width: image.extent.width, height: image.extent.height, depth: 1 },
    }
}

#[derive(Clone, Copy)]
enum Stage {
    Compute,
    Graphics,
}

impl Stage {
    fn flags(self) -> vk::PipelineStageFlags2 {
        match self {
            Stage::Compute => vk::PipelineStageFlags2::COMPUTE_SHADER,
            Stage::Graphics => vk::PipelineStageFlags2::VERTEX_SHADER | vk::PipelineStageFlags2::FRAGMENT_SHADER,
        }
    }
    fn read(self) -> Access {
        Access { stage: self.flags(), ..Access::COMPUTE_READ }
    }
    fn write(self) -> Access {
        Access { stage: self.flags(), ..Access::COMPUTE_WRITE }
    }
    fn sampled(self) -> Access {
        Access { stage: self.flags(), ..Access::COMPUTE_SAMPLED }
    }
}
