//! Presentation to a window: the surface, its swapchain, and two frame slots so that one frame's
//! copy to the screen can still be running while the next frame is recorded.
//!
//! Each frame blits a tone-mapped image (any size: previews are scaled up) into the acquired
//! swapchain image. A window of zero size (minimised) presents nothing; a resize, an out-of-date
//! or a suboptimal swapchain makes the next present rebuild the swapchain first.

use std::sync::Arc;

use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};

use super::commands::Recorder;
use super::context::{Context, Shared};
use super::resources::Image;
use crate::error::Result;
use crate::{bad_input, runtime};

/// Frames whose presentation may be in flight at once.
pub const FRAMES_IN_FLIGHT: usize = 2;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PresentMode {
    /// Waits for vertical blank; always available.
    Fifo,
    FifoRelaxed,
    Mailbox,
    Immediate,
}

impl PresentMode {
    fn raw(self) -> vk::PresentModeKHR {
        match self {
            PresentMode::Fifo => vk::PresentModeKHR::FIFO,
            PresentMode::FifoRelaxed => vk::PresentModeKHR::FIFO_RELAXED,
            PresentMode::Mailbox => vk::PresentModeKHR::MAILBOX,
            PresentMode::Immediate => vk::PresentModeKHR::IMMEDIATE,
        }
    }

    fn name(mode: vk::PresentModeKHR) -> String {
        match mode {
            vk::PresentModeKHR::FIFO => "fifo".into(),
            vk::PresentModeKHR::FIFO_RELAXED => "fifo-relaxed".into(),
            vk::PresentModeKHR::MAILBOX => "mailbox".into(),
            vk::PresentModeKHR::IMMEDIATE => "immediate".into(),
            m => format!("{m:?}").to_lowercase(),
        }
    }
}

/// What a call to [`Presenter::present`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    /// The image went to the screen.
    Shown,
    /// Nothing shown: the window has zero size (minimised), or the swapchain was out of date and
    /// is rebuilt on the next call.
    Skipped,
}

/// Per-frame objects, used round-robin: a slot is reused only after its fence says its commands
/// have finished.
struct FrameSlot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    image_available: vk::Semaphore,
}

pub struct Presenter {
    shared: Arc<Shared>,
    surface_loader: ash::khr::surface::Instance,
    swapchain_loader: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    swapchain: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    /// Colour views of the images, for the overlay's drawing.
    views: Vec<vk::ImageView>,
    /// One per swapchain image, not per slot: nothing says when a present has finished waiting on
    /// its semaphore, but the image's next acquire does.
    render_finished: Vec<vk::Semaphore>,
    format: vk::SurfaceFormatKHR,
    present_mode: vk::PresentModeKHR,
    extent: vk::Extent2D,
    slots: Vec<FrameSlot>,
    next_slot: usize,
    /// The window's size in pixels, as its last resize said.
    window_size: vk::Extent2D,
    /// Rebuild the swapchain before the next present.
    stale: bool,
    /// Swapchains built so far (the first included).
    pub swapchains_built: u32,
}

impl Presenter {
    /// A surface for the window and its swapchain. `window_size` is used when the surface leaves
    /// the size to the swapchain.
    pub fn new(
        ctx: &Context,
        display: RawDisplayHandle,
        window: RawWindowHandle,
        window_size: (u32, u32),
        mode: PresentMode,
    ) -> Result<Presenter> {
        let shared = ctx.shared.clone();
        let surface_loader = ash::khr::surface::Instance::new(&shared.entry, &shared.instance);
        let swapchain_loader = ash::khr::swapchain::Device::new(&shared.instance, &shared.device);
        // SAFETY: the handles come from a live window that the caller keeps alive longer than the
        // presenter (it drops the presenter first).
        let surface = unsafe { ash_window::create_surface(&shared.entry, &shared.instance, display, window, None) }
            .map_err(|e| runtime!("cannot create a Vulkan surface for the window: {e}"))?;
        // From here on, `Drop` cleans up whatever exists.
        let mut presenter = Presenter {
            shared,
            surface_loader,
            swapchain_loader,
            surface,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            views: Vec::new(),
            render_finished: Vec::new(),
            format: vk::SurfaceFormatKHR::default(),
            present_mode: vk::PresentModeKHR::FIFO,
            extent: vk::Extent2D::default(),
            slots: Vec::new(),
            next_slot: 0,
            window_size: vk::Extent2D { width: window_size.0, height: window_size.1 },
            stale: true,
            swapchains_built: 0,
        };
        let pd = ctx.physical_device;
        // SAFETY: valid physical device and surface.
        let supported =
            unsafe { presenter.surface_loader.get_physical_device_surface_support(pd, ctx.queue_family, surface) }
                .map_err(|e| runtime!("vkGetPhysicalDeviceSurfaceSupportKHR: {e}"))?;
        if !supported {
            return Err(runtime!("{} cannot present to this window from its graphics queue", ctx.info.name));
        }
        let formats = unsafe { presenter.surface_loader.get_physical_device_surface_formats(pd, surface) }
            .map_err(|e| runtime!("vkGetPhysicalDeviceSurfaceFormatsKHR: {e}"))?;
        presenter.format = choose_format(&formats).ok_or_else(|| {
            runtime!("the window offers no 8-bit RGBA/BGRA format in the sRGB colour space: {formats:?}")
        })?;
        let modes = unsafe { presenter.surface_loader.get_physical_device_surface_present_modes(pd, surface) }
            .map_err(|e| runtime!("vkGetPhysicalDeviceSurfacePresentModesKHR: {e}"))?;
        if !modes.contains(&mode.raw()) {
            let offered: Vec<String> = modes.iter().map(|m| PresentMode::name(*m)).collect();
            return Err(bad_input!(
                "--present-mode {}: this window does not offer it (it offers {})",
                PresentMode::name(mode.raw()),
                offered.join(", ")
            ));
        }
        presenter.present_mode = mode.raw();
        // SAFETY: plain queries and creations on a valid device; destroyed in Drop.
        let features =
            unsafe { presenter.shared.instance.get_physical_device_format_properties(pd, presenter.format.format) };
        if !features.optimal_tiling_features.contains(vk::FormatFeatureFlags::BLIT_DST) {
            return Err(runtime!(
                "the window's format {:?} cannot be blitted to on {}",
                presenter.format.format,
                ctx.info.name
            ));
        }
        for _ in 0..FRAMES_IN_FLIGHT {
            let slot = presenter.create_slot(ctx.queue_family)?;
            presenter.slots.push(slot);
        }
        Ok(presenter)
    }

    fn create_slot(&self, queue_family: u32) -> Result<FrameSlot> {
        let device = &self.shared.device;
        // SAFETY: valid device; the objects are destroyed in Drop.
        unsafe {
            let (pool, cmd) = super::submit::command_pool_with_one_buffer(device, queue_family)?;
            // Signalled, so that the first wait on an unused slot returns at once.
            let fence = device
                .create_fence(&vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED), None)
                .map_err(|e| runtime!("vkCreateFence: {e}"))?;
            let image_available = device
                .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                .map_err(|e| runtime!("vkCreateSemaphore: {e}"))?;
            Ok(FrameSlot { pool, cmd, fence, image_available })
        }
    }

    /// The format of the images that [`present`](Self::present) takes: 8-bit RGBA, sRGB-encoded
    /// bytes either way. With an `_SRGB` swapchain the source is `_SRGB` too, so that the blit
    /// decodes and re-encodes (no change) instead of encoding twice.
    pub fn source_format(&self) -> vk::Format {
        if is_srgb(self.format.format) {
            vk::Format::R8G8B8A8_SRGB
        } else {
            vk::Format::R8G8B8A8_UNORM
        }
    }

    /// The swapchain's format (for the log).
    pub fn surface_format(&self) -> vk::Format {
        self.format.format
    }

    /// The size of the swapchain images (zero before the first present or while minimised).
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }

    /// The window now has this size (zero when minimised); the swapchain follows at the next present.
    pub fn resize(&mut self, width: u32, height: u32) {
        let size = vk::Extent2D { width, height };
        if size != self.window_size {
            self.window_size = size;
            self.stale = true;
        }
    }

    /// Shows `source` in the window, scaled to it. `before` records into the same command buffer
    /// first (e.g. the copy that fills `source`).
    pub fn present(
        &mut self,
        ctx: &Context,
        source: &Image,
        before: impl FnOnce(&mut Recorder) -> Result<()>,
        overlay: Option<(&mut super::overlay::Overlay, &super::overlay::OverlayFrame)>,
    ) -> Result<Presented> {
        if self.window_size.width == 0 || self.window_size.height == 0 {
            return Ok(Presented::Skipped);
        }
        if self.stale && !self.rebuild(ctx)? {
            return Ok(Presented::Skipped);
        }
        let slot = &self.slots[self.next_slot];
        let device = &self.shared.device;
        // SAFETY: valid fence; waiting makes the slot's command buffer and semaphore free.
        unsafe { device.wait_for_fences(&[slot.fence], true, u64::MAX) }
            .map_err(|e| runtime!("vkWaitForFences: {e} (device lost?)"))?;
        // SAFETY: the semaphore is unsignalled (its last signal was waited on by the slot's last submission).
        let acquired = unsafe {
            self.swapchain_loader.acquire_next_image(self.swapchain, u64::MAX, slot.image_available, vk::Fence::null())
        };
        let index = match acquired {
            Ok((index, suboptimal)) => {
                // Still usable: show this frame, rebuild before the next.
                self.stale |= suboptimal;
                index as usize
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.stale = true;
                return Ok(Presented::Skipped);
            }
            Err(e) => return Err(runtime!("vkAcquireNextImageKHR: {e}")),
        };
        let (image, view, extent, finished) =
            (self.images[index], self.views[index], self.extent, self.render_finished[index]);
        ctx.submit_presentation(slot.pool, slot.cmd, slot.fence, slot.image_available, finished, |rec| {
            before(rec)?;
            rec.blit_to_swapchain(source, image, view, extent, overlay)
        })?;
        self.next_slot = (self.next_slot + 1) % self.slots.len();
        let waits = [finished];
        let swapchains = [self.swapchain];
        let indices = [index as u32];
        let info =
            vk::PresentInfoKHR::default().wait_semaphores(&waits).swapchains(&swapchains).image_indices(&indices);
        // SAFETY: the image was acquired and its commands submitted with `finished` to signal.
        match unsafe { self.swapchain_loader.queue_present(ctx.queue, &info) } {
            Ok(suboptimal) => self.stale |= suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => self.stale = true,
            Err(e) => return Err(runtime!("vkQueuePresentKHR: {e}")),
        }
        Ok(Presented::Shown)
    }

    /// Builds the swapchain for the surface's current size; false when that size is zero.
    fn rebuild(&mut self, ctx: &Context) -> Result<bool> {
        let pd = ctx.physical_device;
        // SAFETY: valid physical device and surface.
        let caps = unsafe { self.surface_loader.get_physical_device_surface_capabilities(pd, self.surface) }
            .map_err(|e| runtime!("vkGetPhysicalDeviceSurfaceCapabilitiesKHR: {e}"))?;
        let extent = if caps.current_extent.width == u32::MAX {
            // The surface lets the swapchain decide: the window's size, within the limits.
            vk::Extent2D {
                width: self.window_size.width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: self.window_size.height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        } else {
            caps.current_extent
        };
        if extent.width == 0 || extent.height == 0 {
            return Ok(false);
        }
        let usage = vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::COLOR_ATTACHMENT;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(runtime!("the window's swapchain images cannot be blitted to and drawn on"));
        }
        // Everything that used the old swapchain and its semaphores must be done before they go.
        ctx.wait_idle()?;
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let alpha = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|a| caps.supported_composite_alpha.contains(*a))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        let old = self.swapchain;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format.format)
            .image_color_space(self.format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(alpha)
            .present_mode(self.present_mode)
            .clipped(true)
            .old_swapchain(old);
        // SAFETY: the device is idle; the old swapchain is retired by this call and destroyed below.
        let swapchain = unsafe { self.swapchain_loader.create_swapchain(&info, None) }
            .map_err(|e| runtime!("vkCreateSwapchainKHR ({}x{}): {e}", extent.width, extent.height))?;
        unsafe {
            if old != vk::SwapchainKHR::null() {
                self.swapchain_loader.destroy_swapchain(old, None);
            }
            for s in self.render_finished.drain(..) {
                self.shared.device.destroy_semaphore(s, None);
            }
            for v in self.views.drain(..) {
                self.shared.device.destroy_image_view(v, None);
            }
        }
        self.swapchain = swapchain;
        self.images = unsafe { self.swapchain_loader.get_swapchain_images(swapchain) }
            .map_err(|e| runtime!("vkGetSwapchainImagesKHR: {e}"))?;
        for &image in &self.images {
            let info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(self.format.format)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    base_mip_level: 0,
                    level_count: 1,
                    base_array_layer: 0,
                    layer_count: 1,
                });
            // SAFETY: a swapchain image of this device; destroyed before the swapchain.
            let view = unsafe { self.shared.device.create_image_view(&info, None) }
                .map_err(|e| runtime!("vkCreateImageView: {e}"))?;
            self.views.push(view);
            let s = unsafe { self.shared.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), None) }
                .map_err(|e| runtime!("vkCreateSemaphore: {e}"))?;
            self.render_finished.push(s);
        }
        self.extent = extent;
        self.stale = false;
        self.swapchains_built += 1;
        log::info!(
            "swapchain {}x{}, {} images, {:?}, {}",
            extent.width,
            extent.height,
            self.images.len(),
            self.format.format,
            PresentMode::name(self.present_mode)
        );
        Ok(true)
    }
}

impl Drop for Presenter {
    fn drop(&mut self) {
        let device = &self.shared.device;
        // SAFETY: after the device is idle nothing uses these objects; each is destroyed once.
        unsafe {
            let _ = device.device_wait_idle();
            for slot in self.slots.drain(..) {
                device.destroy_semaphore(slot.image_available, None);
                device.destroy_fence(slot.fence, None);
                device.destroy_command_pool(slot.pool, None);
            }
            for s in self.render_finished.drain(..) {
                device.destroy_semaphore(s, None);
            }
            for v in self.views.drain(..) {
                device.destroy_image_view(v, None);
            }
            if self.swapchain != vk::SwapchainKHR::null() {
                self.swapchain_loader.destroy_swapchain(self.swapchain, None);
            }
            self.surface_loader.destroy_surface(self.surface, None);
        }
    }
}

fn is_srgb(format: vk::Format) -> bool {
    matches!(format, vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB)
}

/// An 8-bit RGBA/BGRA format in the sRGB colour space; UNORM first, since the tone-mapping pass
/// already encodes sRGB (an `_SRGB` swapchain works too, see `source_format`).
fn choose_format(formats: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    let preference =
        [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM, vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB];
    preference.iter().find_map(|want| {
        formats.iter().copied().find(|f| f.format == *want && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
    })
}
