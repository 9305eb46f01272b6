//! The Vulkan layer: the only module with `unsafe` Vulkan calls. Passes use its safe types:
//! [`Context`], [`Buffer`], [`Image`], [`Pipeline`], and a [`Recorder`] that turns declared
//! resource uses into synchronization2 barriers.

mod barriers;
mod commands;
mod context;
mod descriptors;
mod guard;
mod overlay;
mod pipeline;
mod profiler;
mod resources;
mod submit;
mod swapchain;

pub use ash::vk::{BufferUsageFlags, CullModeFlags, Extent2D, Format, ImageUsageFlags, PrimitiveTopology};
pub use barriers::{Access, BufferAccess};
pub use commands::Recorder;
pub use context::{list_devices, Context, ContextOptions, DeviceInfo, ValidationCounts};
pub use descriptors::Bind;
pub use overlay::{Overlay, OverlayFrame};
pub use pipeline::{check_all_shaders, GraphicsDesc, Pipeline};
pub use profiler::{GpuProfiler, TimedScope};
pub use resources::{Buffer, Image, MemoryLocation, Sampler};
pub use swapchain::{PresentMode, Presented, Presenter, FRAMES_IN_FLIGHT};

/// Reinterprets a plain value as bytes for push constants.
pub fn bytes_of<T: bytemuck::Pod>(value: &T) -> &[u8] {
    bytemuck::bytes_of(value)
}

/// A device-local buffer holding `data`, uploaded through a staging buffer.
pub fn upload_buffer<T: bytemuck::Pod>(
    ctx: &Context,
    name: &str,
    data: &[T],
    usage: BufferUsageFlags,
) -> crate::Result<Buffer> {
    let bytes = std::mem::size_of_val(data) as u64;
    let mut staging = Buffer::new(
        ctx,
        &format!("{name} (staging)"),
        bytes,
        BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )?;
    staging.write(0, data)?;
    let buffer = Buffer::new(ctx, name, bytes, usage | BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly)?;
    ctx.submit(None, |rec| rec.copy_buffer(&staging, &buffer, bytes))?;
    Ok(buffer)
}

/// Copies `count` elements of a device buffer back to the host (tests, tools; not per frame).
pub fn download_buffer<T: bytemuck::Pod>(ctx: &Context, buffer: &Buffer, count: usize) -> crate::Result<Vec<T>> {
    if count == 0 {
        return Ok(Vec::new());
    }
    let bytes = (count * std::mem::size_of::<T>()) as u64;
    let staging = Buffer::new(
        ctx,
        &format!("{} (download)", buffer.name),
        bytes,
        BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?;
    ctx.submit(None, |rec| {
        rec.copy_buffer(buffer, &staging, bytes)?;
        rec.host_read(&staging)
    })?;
    staging.read(count)
}
