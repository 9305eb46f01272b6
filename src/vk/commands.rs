//! Recording and submitting command buffers.
//!
//! [`Context::submit`] records one command buffer through a [`Recorder`], submits it with a fence
//! and waits. The recorder's methods are the only way passes touch a command buffer: each declares
//! how it uses its resources, and the recorder inserts the synchronization2 barriers.

use std::cell::RefCell;

use ash::vk;

use super::context::Context;
use super::pipeline::{descriptor_type, Pipeline};
use super::profiler::GpuProfiler;
use super::resources::{aspect_of, has_stencil, Access, Buffer, Image, Sampler, Transition};
use crate::error::Result;
use crate::runtime;
use crate::shaders::DescriptorKind;

/// Per-context objects for recording: one command buffer, its fence and a descriptor pool that is
/// reset after every submission (one submission in flight at a time).
pub(crate) struct Commands {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    descriptor_pool: vk::DescriptorPool,
}

const SETS_PER_SUBMIT: u32 = 512;

/// Timestamps are written once all earlier commands are done. BOTTOM_OF_PIPE means that for a
/// timestamp, as ALL_COMMANDS does, without the best-practices layer's warning about the latter.
const TIMESTAMP_STAGE: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::BOTTOM_OF_PIPE;

/// A transient command pool and one primary command buffer from it, for `queue_family`.
///
/// # Safety
/// `device` must be valid; the caller destroys the pool (which frees the buffer).
pub(crate) unsafe fn command_pool_with_one_buffer(
    device: &ash::Device,
    queue_family: u32,
) -> Result<(vk::CommandPool, vk::CommandBuffer)> {
    let pool = device
        .create_command_pool(
            &vk::CommandPoolCreateInfo::default()
                .queue_family_index(queue_family)
                .flags(vk::CommandPoolCreateFlags::TRANSIENT),
            None,
        )
        .map_err(|e| runtime!("vkCreateCommandPool: {e}"))?;
    let cmd = device
        .allocate_command_buffers(
            &vk::CommandBufferAllocateInfo::default()
                .command_pool(pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1),
        )
        .map_err(|e| {
            device.destroy_command_pool(pool, None);
            runtime!("vkAllocateCommandBuffers: {e}")
        })?[0];
    Ok((pool, cmd))
}

impl Commands {
    pub(crate) fn new(device: &ash::Device, queue_family: u32) -> Result<Commands> {
        // SAFETY: valid device; each object is destroyed in `destroy`.
        unsafe {
            let (pool, cmd) = command_pool_with_one_buffer(device, queue_family)?;
            let fence = device
                .create_fence(&vk::FenceCreateInfo::default(), None)
                .map_err(|e| runtime!("vkCreateFence: {e}"))?;
            let sizes = [
                vk::DescriptorPoolSize {
                    ty: vk::DescriptorType::STORAGE_BUFFER,
                    descriptor_count: SETS_PER_SUBMIT * 8,
                },
                vk::DescriptorPoolSize { ty: vk::DescriptorType::UNIFORM_BUFFER, descriptor_count: SETS_PER_SUBMIT },
                vk::DescriptorPoolSize {
                    ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                    descriptor_count: SETS_PER_SUBMIT * 2,
                },
                vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_IMAGE, descriptor_count: SETS_PER_SUBMIT },
            ];
            let descriptor_pool = device
                .create_descriptor_pool(
                    &vk::DescriptorPoolCreateInfo::default().max_sets(SETS_PER_SUBMIT).pool_sizes(&sizes),
                    None,
                )
                .map_err(|e| runtime!("vkCreateDescriptorPool: {e}"))?;
            Ok(Commands { pool, cmd, fence, descriptor_pool })
        }
    }

    pub(crate) fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: called once, after the device is idle.
        unsafe {
            device.destroy_descriptor_pool(self.descriptor_pool, None);
            device.destroy_fence(self.fence, None);
            device.destroy_command_pool(self.pool, None);
        }
    }
}

/// A resource bound to a pipeline, with how the shader uses it.
pub enum Bind<'a> {
    /// Storage buffer the shader only reads.
    Read(&'a Buffer),
    /// Storage buffer the shader writes (and may read).
    Write(&'a Buffer),
    Uniform(&'a Buffer),
    /// Combined image sampler, read in `SHADER_READ_ONLY_OPTIMAL`.
    Sampled(&'a Image, &'a Sampler),
    StorageImageRead(&'a Image),
    StorageImageWrite(&'a Image),
}

impl Bind<'_> {
    fn describe(&self) -> &'static str {
        match self {
            Bind::Read(_) => "Bind::Read",
            Bind::Write(_) => "Bind::Write",
            Bind::Uniform(_) => "Bind::Uniform",
            Bind::Sampled(..) => "Bind::Sampled",
            Bind::StorageImageRead(_) => "Bind::StorageImageRead",
            Bind::StorageImageWrite(_) => "Bind::StorageImageWrite",
        }
    }
}

impl Pipeline {
    /// Checks a use's resources against the shaders' bindings: one per binding, in binding order,
    /// of the declared kind; a read-only use only where the shader cannot write, a writing one only
    /// where it is not `readonly`.
    pub(crate) fn check_binds(&self, binds: &[Bind]) -> Result<()> {
        if binds.len() != self.bindings.len() {
            return Err(runtime!(
                "pipeline {}: {} resources bound, its shaders declare {} bindings",
                self.name,
                binds.len(),
                self.bindings.len()
            ));
        }
        for (i, (bind, binding)) in binds.iter().zip(&self.bindings).enumerate() {
            let at = || format!("pipeline {}: binding {i}, {}", self.name, binding.declared_in);
            let kind_ok = matches!(
                (bind, binding.kind),
                (Bind::Read(_) | Bind::Write(_), DescriptorKind::StorageBuffer)
                    | (Bind::Uniform(_), DescriptorKind::UniformBuffer)
                    | (Bind::Sampled(..), DescriptorKind::CombinedImageSampler)
                    | (Bind::StorageImageRead(_) | Bind::StorageImageWrite(_), DescriptorKind::StorageImage)
            );
            if !kind_ok {
                return Err(runtime!("{}: {} given for a {:?}", at(), bind.describe(), binding.kind));
            }
            match bind {
                Bind::Read(_) | Bind::StorageImageRead(_) if !binding.read_only => {
                    return Err(runtime!(
                        "{}: {} of a resource the shader may write (not `readonly`): use the writing Bind",
                        at(),
                        bind.describe()
                    ))
                }
                Bind::Write(_) | Bind::StorageImageWrite(_) if binding.read_only => {
                    return Err(runtime!(
                        "{}: {} of a resource the shader declares `readonly`: use the reading Bind",
                        at(),
                        bind.describe()
                    ))
                }
                _ => {}
            }
        }
        Ok(())
    }
}

/// Records commands into the context's command buffer.
pub struct Recorder<'a> {
    ctx: &'a Context,
    cmd: vk::CommandBuffer,
    descriptor_pool: vk::DescriptorPool,
    profiler: Option<&'a mut GpuProfiler>,
    inside_rendering: bool,
    open_scopes: Vec<usize>,
}

impl Context {
    /// Records commands with `record`, submits them and waits until the GPU has finished.
    /// With a profiler, its timestamp scopes are resolved after the wait.
    pub fn submit<T>(
        &self,
        profiler: Option<&mut GpuProfiler>,
        record: impl FnOnce(&mut Recorder) -> Result<T>,
    ) -> Result<T> {
        let commands = self.commands.borrow();
        let device = self.device();
        // SAFETY: the previous submission was waited for, so the buffer and pool are free to reuse.
        unsafe {
            device
                .reset_descriptor_pool(commands.descriptor_pool, vk::DescriptorPoolResetFlags::empty())
                .map_err(|e| runtime!("vkResetDescriptorPool: {e}"))?;
            device
                .reset_command_pool(commands.pool, vk::CommandPoolResetFlags::empty())
                .map_err(|e| runtime!("vkResetCommandPool: {e}"))?;
            device
                .begin_command_buffer(
                    commands.cmd,
                    &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .map_err(|e| runtime!("vkBeginCommandBuffer: {e}"))?;
        }
        let mut rec = Recorder {
            ctx: self,
            cmd: commands.cmd,
            descriptor_pool: commands.descriptor_pool,
            profiler,
            inside_rendering: false,
            open_scopes: Vec::new(),
        };
        let result = record(&mut rec);
        if rec.inside_rendering {
            rec.end_rendering();
        }
        let profiler = rec.profiler.take();
        // SAFETY: recording finished (also on error, so the buffer is not left recording).
        unsafe { device.end_command_buffer(commands.cmd) }.map_err(|e| runtime!("vkEndCommandBuffer: {e}"))?;
        let value = result?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(commands.cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        // SAFETY: the queue is used from this thread only; the fence is unsignalled.
        unsafe {
            device.queue_submit2(self.queue, &submit, commands.fence).map_err(|e| runtime!("vkQueueSubmit2: {e}"))?;
            device
                .wait_for_fences(&[commands.fence], true, u64::MAX)
                .map_err(|e| runtime!("vkWaitForFences: {e} (device lost?)"))?;
            device.reset_fences(&[commands.fence]).map_err(|e| runtime!("vkResetFences: {e}"))?;
        }
        if let Some(p) = profiler {
            p.resolve()?;
        }
        Ok(value)
    }
}

impl Context {
    /// Records `cmd` (from `pool`, reset first) with `record` and submits it without waiting: it
    /// waits for `wait` (an acquired swapchain image) before its transfers, signals `signal` (for
    /// the present) and `fence` (so the caller knows when `cmd` may be recorded again). For
    /// presentation only: the recorder has no descriptor pool, so it can copy and blit but not
    /// dispatch or draw.
    pub(crate) fn submit_presentation(
        &self,
        pool: vk::CommandPool,
        cmd: vk::CommandBuffer,
        fence: vk::Fence,
        wait: vk::Semaphore,
        signal: vk::Semaphore,
        record: impl FnOnce(&mut Recorder) -> Result<()>,
    ) -> Result<()> {
        let device = self.device();
        // SAFETY: the caller waited for `fence`, so `cmd` is no longer in use.
        unsafe {
            device
                .reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
                .map_err(|e| runtime!("vkResetCommandPool: {e}"))?;
            device
                .begin_command_buffer(
                    cmd,
                    &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .map_err(|e| runtime!("vkBeginCommandBuffer: {e}"))?;
        }
        let mut rec = Recorder {
            ctx: self,
            cmd,
            descriptor_pool: vk::DescriptorPool::null(),
            profiler: None,
            inside_rendering: false,
            open_scopes: Vec::new(),
        };
        let result = record(&mut rec);
        // SAFETY: recording finished (also on error, so the buffer is not left recording).
        unsafe { device.end_command_buffer(cmd) }.map_err(|e| runtime!("vkEndCommandBuffer: {e}"))?;
        result?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        // The swapchain image is first touched by the transfer that clears its layout.
        let waits =
            [vk::SemaphoreSubmitInfo::default().semaphore(wait).stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)];
        let signals =
            [vk::SemaphoreSubmitInfo::default().semaphore(signal).stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let submit = [vk::SubmitInfo2::default()
            .command_buffer_infos(&cmds)
            .wait_semaphore_infos(&waits)
            .signal_semaphore_infos(&signals)];
        // SAFETY: the queue is used from this thread only; the fence is reset just before its submission.
        unsafe {
            device.reset_fences(&[fence]).map_err(|e| runtime!("vkResetFences: {e}"))?;
            device.queue_submit2(self.queue, &submit, fence).map_err(|e| runtime!("vkQueueSubmit2: {e}"))?;
        }
        Ok(())
    }
}

impl<'a> Recorder<'a> {
    fn device(&self) -> &ash::Device {
        self.ctx.device()
    }

    pub fn context(&self) -> &Context {
        self.ctx
    }

    fn barrier_check(&self, what: &str) -> Result<()> {
        if self.inside_rendering {
            return Err(runtime!(
                "{what} needs a barrier inside a rendering scope: declare its use before begin_rendering"
            ));
        }
        Ok(())
    }

    /// Declares that the next commands use `buffer` as `access`, inserting a barrier if needed.
    pub fn use_buffer(&mut self, buffer: &Buffer, access: Access) -> Result<()> {
        let mut state = buffer.state.get();
        let t = state.transition(access, false);
        buffer.state.set(state);
        if let Some((ss, sa, ds, da, _, _)) = t {
            self.barrier_check(&buffer.name)?;
            let b = [vk::BufferMemoryBarrier2::default()
                .src_stage_mask(ss)
                .src_access_mask(sa)
                .dst_stage_mask(ds)
                .dst_access_mask(da)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(buffer.raw)
                .offset(0)
                .size(vk::WHOLE_SIZE)];
            // SAFETY: recording into our command buffer.
            unsafe {
                self.device().cmd_pipeline_barrier2(self.cmd, &vk::DependencyInfo::default().buffer_memory_barriers(&b))
            };
        }
        Ok(())
    }

    /// Declares that the next commands use `image` as `access` (in `access.layout`).
    pub fn use_image(&mut self, image: &Image, access: Access) -> Result<()> {
        let mut state = image.state.get();
        let t: Option<Transition> = state.transition(access, true);
        image.state.set(state);
        if let Some((ss, sa, ds, da, old, new)) = t {
            self.barrier_check(&image.name)?;
            let b = [vk::ImageMemoryBarrier2::default()
                .src_stage_mask(ss)
                .src_access_mask(sa)
                .dst_stage_mask(ds)
                .dst_access_mask(da)
                .old_layout(old)
                .new_layout(new)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image.raw)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: aspect_of(image.format),
                    base_mip_level: 0,
                    level_count: 1,
                    base_array_layer: 0,
                    layer_count: image.layers,
                })];
            unsafe {
                self.device().cmd_pipeline_barrier2(self.cmd, &vk::DependencyInfo::default().image_memory_barriers(&b))
            };
        }
        Ok(())
    }

    /// Makes the image's contents irrelevant: the next use may start from `UNDEFINED`.
    pub fn discard_image(&mut self, image: &Image) {
        let mut state = image.state.get();
        state.layout = vk::ImageLayout::UNDEFINED;
        image.state.set(state);
    }

    /// Allocates and writes set 0 for `pipeline`, transitioning each bound resource for `stage`.
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
        let device = self.ctx.device();
        if !binds.is_empty() {
            let layouts = [pipeline.set_layout];
            // SAFETY: pool and layout are valid; the pool is reset only after the fence wait.
            let set = unsafe {
                device.allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default()
                        .descriptor_pool(self.descriptor_pool)
                        .set_layouts(&layouts),
                )
            }
            .map_err(|e| runtime!("vkAllocateDescriptorSets ({} sets per submission): {e}", SETS_PER_SUBMIT))?[0];
            let buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = binds
                .iter()
                .map(|b| match b {
                    Bind::Read(b) | Bind::Write(b) | Bind::Uniform(b) => {
                        [vk::DescriptorBufferInfo { buffer: b.raw, offset: 0, range: vk::WHOLE_SIZE }]
                    }
                    _ => [vk::DescriptorBufferInfo::default()],
                })
                .collect();
            let image_infos: Vec<[vk::DescriptorImageInfo; 1]> = binds
                .iter()
                .map(|b| match b {
                    Bind::Sampled(img, sampler) => [vk::DescriptorImageInfo {
                        sampler: sampler.raw,
                        image_view: img.view,
                        image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    }],
                    Bind::StorageImageRead(img) | Bind::StorageImageWrite(img) => [vk::DescriptorImageInfo {
                        sampler: vk::Sampler::null(),
                        image_view: img.view,
                        image_layout: vk::ImageLayout::GENERAL,
                    }],
                    _ => [vk::DescriptorImageInfo::default()],
                })
                .collect();
            let writes: Vec<_> = binds
                .iter()
                .enumerate()
                .map(|(i, b)| {
                    let w = vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(i as u32)
                        .descriptor_type(descriptor_type(pipeline.bindings[i].kind));
                    match b {
                        Bind::Read(_) | Bind::Write(_) | Bind::Uniform(_) => w.buffer_info(&buffer_infos[i]),
                        _ => w.image_info(&image_infos[i]),
                    }
                })
                .collect();
            unsafe {
                device.update_descriptor_sets(&writes, &[]);
                device.cmd_bind_descriptor_sets(self.cmd, pipeline.bind_point, pipeline.layout, 0, &[set], &[]);
            }
        }
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
            self.use_image(img, Access::COLOR_ATTACHMENT)?;
        }
        if let Some((img, clear)) = depth {
            // A layout transition from UNDEFINED would discard every layer, not just this one.
            if clear.is_some() && img.layers == 1 {
                self.discard_image(img);
            }
            let access =
                if has_stencil(img.format) { Access::DEPTH_STENCIL_ATTACHMENT } else { Access::DEPTH_ATTACHMENT };
            self.use_image(img, access)?;
        }
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
        // SAFETY: attachments are in the layouts named above (barriers recorded by use_image).
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

    /// The stencil reference of pipelines that test it (see `GraphicsDesc::depth_equal`).
    pub fn set_stencil_reference(&mut self, reference: u32) {
        unsafe { self.device().cmd_set_stencil_reference(self.cmd, vk::StencilFaceFlags::FRONT_AND_BACK, reference) };
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
            self.use_buffer(v, Access::VERTEX_INPUT)?;
        }
        if let Some(i) = indices {
            self.use_buffer(i, Access::INDEX_INPUT)?;
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
        binds.iter().try_for_each(|bind| self.declare(bind, Stage::Graphics))
    }

    /// Declares how the shaders of `stage` use a bound resource, recording a barrier if needed.
    fn declare(&mut self, bind: &Bind, stage: Stage) -> Result<()> {
        // Inside a rendering scope, a write declared before begin_rendering (prepare_draw_reads)
        // is already ordered: declaring it again for the draw is not a new hazard.
        let declared_write = |b: &Buffer| self.inside_rendering && b.state.get().last_write == stage.write();
        match bind {
            Bind::Read(b) => self.use_buffer(b, stage.read()),
            Bind::Write(b) if declared_write(b) => Ok(()),
            Bind::Write(b) => self.use_buffer(b, stage.write()),
            Bind::Uniform(b) => self.use_buffer(b, Access { stage: stage.flags(), ..Access::UNIFORM_READ }),
            Bind::Sampled(img, _) => self.use_image(img, stage.sampled()),
            Bind::StorageImageRead(img) => self.use_image(img, stage.read()),
            Bind::StorageImageWrite(img) => self.use_image(img, stage.write()),
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
        self.use_buffer(src, Access { layout: vk::ImageLayout::UNDEFINED, ..Access::TRANSFER_READ })?;
        self.use_buffer(dst, Access { layout: vk::ImageLayout::UNDEFINED, ..Access::TRANSFER_WRITE })?;
        let region = [vk::BufferCopy { src_offset: 0, dst_offset: 0, size: bytes }];
        unsafe { self.device().cmd_copy_buffer(self.cmd, src.raw, dst.raw, &region) };
        Ok(())
    }

    pub fn fill_buffer(&mut self, dst: &Buffer, value: u32) -> Result<()> {
        self.use_buffer(dst, Access { layout: vk::ImageLayout::UNDEFINED, ..Access::TRANSFER_WRITE })?;
        unsafe { self.device().cmd_fill_buffer(self.cmd, dst.raw, 0, vk::WHOLE_SIZE, value) };
        Ok(())
    }

    /// Copies layer 0 of a colour image into a buffer, tightly packed, then makes it host-readable.
    pub fn copy_image_to_buffer(&mut self, src: &Image, dst: &Buffer) -> Result<()> {
        self.use_image(src, Access::TRANSFER_READ)?;
        self.use_buffer(dst, Access { layout: vk::ImageLayout::UNDEFINED, ..Access::TRANSFER_WRITE })?;
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
        self.use_buffer(dst, Access::HOST_READ)
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
        self.use_buffer(src, Access { layout: vk::ImageLayout::UNDEFINED, ..Access::TRANSFER_READ })?;
        self.discard_image(dst);
        self.use_image(dst, Access::TRANSFER_WRITE)?;
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
        self.use_buffer(buffer, Access::HOST_READ)
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

pub(crate) type CommandsCell = RefCell<Commands>;
