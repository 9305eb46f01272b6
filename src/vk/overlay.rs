//! A user interface over the presented image: egui's meshes drawn by egui-ash-renderer into the
//! swapchain image, after the blit and before the present (see [`Presenter::present`]).
//!
//! [`Presenter::present`]: super::Presenter::present

use std::sync::{Arc, Mutex};

use ash::vk;
use egui_ash_renderer::allocator::GpuAllocator;
use egui_ash_renderer::{DynamicRendering, Options, RenderMode, Renderer};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use gpu_allocator::AllocationSizes;

use super::context::{Context, Shared};
use super::swapchain::FRAMES_IN_FLIGHT;
use crate::error::Result;
use crate::runtime;

/// What the overlay draws in one frame: egui's tessellated shapes and its scale.
pub struct OverlayFrame<'a> {
    pub primitives: &'a [egui::ClippedPrimitive],
    pub pixels_per_point: f32,
}

pub struct Overlay {
    // Field order is drop order: the renderer frees its memory into the allocator, which goes
    // before the device (`shared`).
    renderer: Renderer<GpuAllocator>,
    _allocator: Arc<Mutex<Allocator>>,
    /// For egui's texture uploads (the renderer submits them itself and waits).
    upload_pool: vk::CommandPool,
    shared: Arc<Shared>,
}

impl Overlay {
    /// An overlay for swapchain images of `format` (UNORM or SRGB).
    pub fn new(ctx: &Context, format: vk::Format) -> Result<Overlay> {
        let shared = ctx.shared.clone();
        let srgb = matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB);
        // An allocator of its own (sub-allocating from small blocks): the context's is not shared
        // in the `Arc<Mutex<_>>` egui-ash-renderer takes.
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: shared.instance.clone(),
            device: shared.device.clone(),
            physical_device: ctx.physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: AllocationSizes::new(4 << 20, 4 << 20),
        })
        .map_err(|e| runtime!("gpu-allocator for the panel: {e}"))?;
        let allocator = Arc::new(Mutex::new(allocator));
        let renderer = Renderer::with_gpu_allocator(
            allocator.clone(),
            shared.device.clone(),
            RenderMode::DynamicRendering(DynamicRendering {
                color_attachment_format: format,
                depth_attachment_format: None,
                stencil_attachment_format: None,
            }),
            Options { in_flight_frames: FRAMES_IN_FLIGHT, srgb_framebuffer: srgb, ..Default::default() },
        )
        .map_err(|e| runtime!("egui renderer: {e}"))?;
        // SAFETY: valid device; destroyed in Drop.
        let upload_pool = unsafe {
            shared.device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(ctx.queue_family)
                    .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                None,
            )
        }
        .map_err(|e| runtime!("vkCreateCommandPool: {e}"))?;
        Ok(Overlay { renderer, _allocator: allocator, upload_pool, shared })
    }

    /// Uploads the textures egui made or changed (its font atlas); call before drawing.
    pub fn set_textures(&mut self, ctx: &Context, delta: &egui::TexturesDelta) -> Result<()> {
        if delta.set.is_empty() {
            return Ok(());
        }
        // A replaced texture is destroyed at once, and a present in flight may still sample it.
        ctx.wait_idle()?;
        for (id, deltas) in &delta.set {
            for image in deltas {
                self.renderer
                    .set_texture(ctx.queue, self.upload_pool, *id, image)
                    .map_err(|e| runtime!("egui texture upload: {e}"))?;
            }
        }
        Ok(())
    }

    /// Frees the textures egui let go of; call after the frame that last used them was presented.
    pub fn free_textures(&mut self, ctx: &Context, delta: &egui::TexturesDelta) -> Result<()> {
        if delta.free.is_empty() {
            return Ok(());
        }
        ctx.wait_idle()?;
        for id in &delta.free {
            self.renderer.free_texture(*id).map_err(|e| runtime!("egui texture: {e}"))?;
        }
        Ok(())
    }

    /// Records the draws into `cmd`, inside a rendering scope on `view` (set up by the caller).
    pub(crate) fn record(&mut self, cmd: vk::CommandBuffer, extent: vk::Extent2D, frame: &OverlayFrame) -> Result<()> {
        self.renderer
            .cmd_draw(cmd, extent, frame.pixels_per_point, frame.primitives)
            .map_err(|e| runtime!("egui draw: {e}"))
    }
}

impl Drop for Overlay {
    fn drop(&mut self) {
        // SAFETY: the device is idle after the wait; the pool's buffers were freed by the renderer.
        unsafe {
            let _ = self.shared.device.device_wait_idle();
            self.shared.device.destroy_command_pool(self.upload_pool, None);
        }
    }
}
