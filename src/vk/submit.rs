//! Submitting command buffers.
//!
//! [`Context::submit`] records one command buffer through a [`Recorder`], submits it with a fence
//! and waits; [`Context::submit_presentation`] records a swapchain frame's and returns at once.

use std::cell::RefCell;

use ash::vk;

use super::commands::Recorder;
use super::context::Context;
use super::descriptors::create_descriptor_pool;
use super::guard::Guard;
use super::profiler::GpuProfiler;
use crate::error::Result;
use crate::runtime;

/// Per-context objects for recording: one command buffer, its fence and a descriptor pool that is
/// reset after every submission (one submission in flight at a time).
pub(crate) struct Commands {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    descriptor_pool: vk::DescriptorPool,
}

pub(crate) type CommandsCell = RefCell<Commands>;

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
    // SAFETY (cleanup): if the allocation fails, nothing else has the pool.
    let pool = Guard::new(pool, |p| device.destroy_command_pool(p, None));
    let cmd = device
        .allocate_command_buffers(
            &vk::CommandBufferAllocateInfo::default()
                .command_pool(*pool)
                .level(vk::CommandBufferLevel::PRIMARY)
                .command_buffer_count(1),
        )
        .map_err(|e| runtime!("vkAllocateCommandBuffers: {e}"))?[0];
    Ok((pool.defuse(), cmd))
}

impl Commands {
    pub(crate) fn new(device: &ash::Device, queue_family: u32) -> Result<Commands> {
        // SAFETY: valid device; each object is destroyed in `destroy`, or by its guard if a later
        // one cannot be created.
        unsafe {
            let (pool, cmd) = command_pool_with_one_buffer(device, queue_family)?;
            let pool = Guard::new(pool, |p| device.destroy_command_pool(p, None));
            let fence = device
                .create_fence(&vk::FenceCreateInfo::default(), None)
                .map_err(|e| runtime!("vkCreateFence: {e}"))?;
            let fence = Guard::new(fence, |f| device.destroy_fence(f, None));
            let descriptor_pool = create_descriptor_pool(device)?;
            Ok(Commands { pool: pool.defuse(), cmd, fence: fence.defuse(), descriptor_pool })
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
        let mut rec = Recorder::new(self, commands.cmd, commands.descriptor_pool, profiler);
        let result = record(&mut rec);
        let profiler = rec.finish();
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
        let mut rec = Recorder::new(self, cmd, vk::DescriptorPool::null(), None);
        let result = record(&mut rec);
        rec.finish();
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
