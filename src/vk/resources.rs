//! Buffers, images and samplers, each owning its memory and destroyed on drop, and the access
//! states that the recorder turns into synchronization2 barriers.

use std::cell::Cell;
use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;

use super::context::{Context, Shared};
use crate::error::Result;
use crate::runtime;

/// How a pass uses a resource: pipeline stage, memory access and (for images) layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Access {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
}

const WRITE_ACCESS: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::SHADER_WRITE.as_raw()
        | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw()
        | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags2::TRANSFER_WRITE.as_raw()
        | vk::AccessFlags2::HOST_WRITE.as_raw()
        | vk::AccessFlags2::MEMORY_WRITE.as_raw(),
);

impl Access {
    const fn new(stage: vk::PipelineStageFlags2, access: vk::AccessFlags2, layout: vk::ImageLayout) -> Access {
        Access { stage, access, layout }
    }
    pub const NONE: Access =
        Access::new(vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE, vk::ImageLayout::UNDEFINED);
    pub const COMPUTE_READ: Access = Access::new(
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::ImageLayout::GENERAL,
    );
    pub const COMPUTE_WRITE: Access = Access::new(
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw() | vk::AccessFlags2::SHADER_STORAGE_READ.as_raw(),
        ),
        vk::ImageLayout::GENERAL,
    );
    // SHADER_READ rather than sync2's narrower SHADER_SAMPLED_READ: the best-practices layer
    // (1.3.239) expects SHADER_READ with SHADER_READ_ONLY_OPTIMAL and warns otherwise.
    pub const COMPUTE_SAMPLED: Access = Access::new(
        vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_READ,
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    );
    pub const FRAGMENT_READ: Access = Access::new(
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::ImageLayout::GENERAL,
    );
    pub const FRAGMENT_WRITE: Access = Access::new(
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw() | vk::AccessFlags2::SHADER_STORAGE_READ.as_raw(),
        ),
        vk::ImageLayout::GENERAL,
    );
    pub const FRAGMENT_SAMPLED: Access = Access::new(
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::SHADER_READ,
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    );
    pub const VERTEX_READ: Access = Access::new(
        vk::PipelineStageFlags2::VERTEX_SHADER,
        vk::AccessFlags2::SHADER_STORAGE_READ,
        vk::ImageLayout::GENERAL,
    );
    pub const VERTEX_INPUT: Access = Access::new(
        vk::PipelineStageFlags2::VERTEX_ATTRIBUTE_INPUT,
        vk::AccessFlags2::VERTEX_ATTRIBUTE_READ,
        vk::ImageLayout::UNDEFINED,
    );
    pub const INDEX_INPUT: Access =
        Access::new(vk::PipelineStageFlags2::INDEX_INPUT, vk::AccessFlags2::INDEX_READ, vk::ImageLayout::UNDEFINED);
    pub const INDIRECT: Access = Access::new(
        vk::PipelineStageFlags2::DRAW_INDIRECT,
        vk::AccessFlags2::INDIRECT_COMMAND_READ,
        vk::ImageLayout::UNDEFINED,
    );
    /// A uniform texel buffer's reads (the stage is set per use).
    pub const TEXEL_READ: Access = Access::new(
        vk::PipelineStageFlags2::FRAGMENT_SHADER,
        vk::AccessFlags2::SHADER_SAMPLED_READ,
        vk::ImageLayout::UNDEFINED,
    );
    pub const UNIFORM_READ: Access = Access::new(
        vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::VERTEX_SHADER.as_raw()
                | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw()
                | vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw(),
        ),
        vk::AccessFlags2::UNIFORM_READ,
        vk::ImageLayout::UNDEFINED,
    );
    pub const COLOR_ATTACHMENT: Access = Access::new(
        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw() | vk::AccessFlags2::COLOR_ATTACHMENT_READ.as_raw(),
        ),
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    );
    pub const DEPTH_ATTACHMENT: Access = Access::new(
        vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
        vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
    );
    /// A depth attachment whose format also has stencil (both aspects in one layout).
    pub const DEPTH_STENCIL_ATTACHMENT: Access = Access::new(
        vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw(),
        ),
        vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    );
    pub const TRANSFER_READ: Access = Access::new(
        vk::PipelineStageFlags2::TRANSFER,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    );
    pub const TRANSFER_WRITE: Access = Access::new(
        vk::PipelineStageFlags2::TRANSFER,
        vk::AccessFlags2::TRANSFER_WRITE,
        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
    );
    pub const HOST_READ: Access =
        Access::new(vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ, vk::ImageLayout::UNDEFINED);

    pub fn writes(&self) -> bool {
        self.access.intersects(WRITE_ACCESS)
    }
}

/// A barrier: (source stage, source access, destination stage, destination access, old layout,
/// new layout).
pub(crate) type Transition = (
    vk::PipelineStageFlags2,
    vk::AccessFlags2,
    vk::PipelineStageFlags2,
    vk::AccessFlags2,
    vk::ImageLayout,
    vk::ImageLayout,
);

/// What the recorder remembers about a resource between uses: the last write, and the reads that
/// have already been made to see it (so repeated reads need no barrier).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TrackedState {
    pub last_write: Access,
    pub reads_since_write: Access,
    pub layout: vk::ImageLayout,
}

impl TrackedState {
    pub(crate) const fn new() -> TrackedState {
        TrackedState { last_write: Access::NONE, reads_since_write: Access::NONE, layout: vk::ImageLayout::UNDEFINED }
    }

    /// The barrier `(src_stage, src_access, dst_stage, dst_access, old_layout, new_layout)` needed
    /// before `next`, or `None`; updates the state as if it was recorded.
    pub(crate) fn transition(&mut self, next: Access, is_image: bool) -> Option<Transition> {
        let layout_change = is_image && next.layout != self.layout;
        let old_layout = self.layout;
        if next.writes() || layout_change {
            // Write-after-read and write-after-write: wait for every earlier access.
            let src_stage = self.last_write.stage | self.reads_since_write.stage;
            let src_access = self.last_write.access & WRITE_ACCESS;
            let first_use = src_stage == vk::PipelineStageFlags2::NONE && old_layout == vk::ImageLayout::UNDEFINED;
            self.last_write = next;
            self.reads_since_write = if next.writes() { Access::NONE } else { next };
            self.layout = next.layout;
            if first_use && !layout_change {
                return None;
            }
            return Some((src_stage, src_access, next.stage, next.access, old_layout, next.layout));
        }
        // Read after write: make the write visible to this stage and access once.
        let covered =
            self.reads_since_write.stage.contains(next.stage) && self.reads_since_write.access.contains(next.access);
        if covered || self.last_write.stage == vk::PipelineStageFlags2::NONE {
            self.reads_since_write.stage |= next.stage;
            self.reads_since_write.access |= next.access;
            return None;
        }
        self.reads_since_write.stage |= next.stage;
        self.reads_since_write.access |= next.access;
        Some((
            self.last_write.stage,
            self.last_write.access & WRITE_ACCESS,
            next.stage,
            next.access,
            self.layout,
            self.layout,
        ))
    }
}

pub struct Buffer {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Buffer,
    /// A view of the whole buffer as RGBA32UI texels, made when its usage includes
    /// UNIFORM_TEXEL_BUFFER (`Bind::Texels`): llvmpipe fetches texels with vector gathers, where
    /// it loads storage buffers one lane at a time.
    pub(crate) texel_view: vk::BufferView,
    allocation: Option<Allocation>,
    pub size: u64,
    pub name: String,
    pub(crate) state: Cell<TrackedState>,
}

impl Buffer {
    /// A buffer of `size` bytes. `CpuToGpu`/`GpuToCpu` buffers are mapped for `write`/`read`.
    pub fn new(
        ctx: &Context,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        let size = size.max(4);
        let device = ctx.device();
        let info = vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid device and create-info.
        let raw = unsafe { device.create_buffer(&info, None) }.map_err(|e| runtime!("vkCreateBuffer {name}: {e}"))?;
        let requirements = unsafe { device.get_buffer_memory_requirements(raw) };
        let allocation = ctx.shared.allocator.lock().unwrap().allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        });
        let allocation = match allocation {
            Ok(a) => a,
            Err(e) => {
                unsafe { device.destroy_buffer(raw, None) };
                return Err(runtime!("out of GPU memory for buffer {name} ({size} bytes): {e}"));
            }
        };
        if let Err(e) = unsafe { device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) } {
            unsafe { device.destroy_buffer(raw, None) };
            let _ = ctx.shared.allocator.lock().unwrap().free(allocation);
            return Err(runtime!("vkBindBufferMemory {name}: {e}"));
        }
        let mut texel_view = vk::BufferView::null();
        if usage.contains(vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER) {
            let texels = size / 16;
            let max = ctx.limits().max_texel_buffer_elements as u64;
            let view = if texels > max {
                Err(runtime!("buffer {name}: {texels} texels exceed this device's {max} per texel buffer"))
            } else {
                let info = vk::BufferViewCreateInfo::default()
                    .buffer(raw)
                    .format(vk::Format::R32G32B32A32_UINT)
                    .offset(0)
                    .range(texels * 16);
                // SAFETY: the buffer is bound to memory and made with UNIFORM_TEXEL_BUFFER usage.
                unsafe { device.create_buffer_view(&info, None) }
                    .map_err(|e| runtime!("vkCreateBufferView {name}: {e}"))
            };
            match view {
                Ok(v) => texel_view = v,
                Err(e) => {
                    unsafe { device.destroy_buffer(raw, None) };
                    let _ = ctx.shared.allocator.lock().unwrap().free(allocation);
                    return Err(e);
                }
            }
        }
        Ok(Buffer {
            shared: ctx.shared.clone(),
            raw,
            texel_view,
            allocation: Some(allocation),
            size,
            name: name.to_string(),
            state: Cell::new(TrackedState::new()),
        })
    }

    /// Copies `data` into a host-visible buffer at byte `offset`.
    pub fn write<T: bytemuck::Pod>(&mut self, offset: u64, data: &[T]) -> Result<()> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let name = self.name.clone();
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| runtime!("buffer {name} is not host-visible"))?;
        let start = offset as usize;
        let end = start + bytes.len();
        if end > slice.len() {
            return Err(runtime!(
                "buffer {name}: write of {} bytes at {offset} overflows its {} bytes",
                bytes.len(),
                slice.len()
            ));
        }
        slice[start..end].copy_from_slice(bytes);
        Ok(())
    }

    /// Reads `count` elements of `T` from a host-visible buffer (after the GPU work has completed).
    pub fn read<T: bytemuck::Pod>(&self, count: usize) -> Result<Vec<T>> {
        let slice = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .ok_or_else(|| runtime!("buffer {} is not host-visible", self.name))?;
        let bytes = count * std::mem::size_of::<T>();
        if bytes > slice.len() {
            return Err(runtime!("buffer {}: read of {bytes} bytes beyond its {} bytes", self.name, slice.len()));
        }
        // Copy through an aligned Vec: the mapping need not be aligned for T.
        let mut out = vec![T::zeroed(); count];
        bytemuck::cast_slice_mut::<T, u8>(&mut out).copy_from_slice(&slice[..bytes]);
        Ok(out)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: the GPU is idle with respect to this buffer: every submission waits on its fence.
        unsafe {
            self.shared.device.destroy_buffer_view(self.texel_view, None);
            self.shared.device.destroy_buffer(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.shared.allocator.lock().unwrap().free(a);
        }
    }
}

pub struct Image {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Image,
    pub(crate) view: vk::ImageView,
    /// One 2D view per layer of an array image, to render into a single layer.
    pub(crate) layer_views: Vec<vk::ImageView>,
    allocation: Option<Allocation>,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub layers: u32,
    pub name: String,
    pub(crate) state: Cell<TrackedState>,
}

/// Whether a depth format also has a stencil aspect.
pub(crate) fn has_stencil(format: vk::Format) -> bool {
    aspect_of(format).contains(vk::ImageAspectFlags::STENCIL)
}

pub(crate) fn aspect_of(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D16_UNORM | vk::Format::D32_SFLOAT | vk::Format::X8_D24_UNORM_PACK32 => vk::ImageAspectFlags::DEPTH,
        vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT => {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        }
        _ => vk::ImageAspectFlags::COLOR,
    }
}

impl Image {
    /// A 2D image (or 2D array with `layers` > 1) in device memory, with a view of all layers.
    pub fn new_2d(
        ctx: &Context,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        layers: u32,
        usage: vk::ImageUsageFlags,
    ) -> Result<Image> {
        let device = ctx.device();
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid device and create-info.
        let raw = unsafe { device.create_image(&info, None) }.map_err(|e| runtime!("vkCreateImage {name}: {e}"))?;
        let requirements = unsafe { device.get_image_memory_requirements(raw) };
        let allocation = match ctx.shared.allocator.lock().unwrap().allocate(&AllocationCreateDesc {
            name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        }) {
            Ok(a) => a,
            Err(e) => {
                unsafe { device.destroy_image(raw, None) };
                return Err(runtime!("out of GPU memory for image {name}: {e}"));
            }
        };
        let view_type = if layers > 1 { vk::ImageViewType::TYPE_2D_ARRAY } else { vk::ImageViewType::TYPE_2D };
        let result =
            unsafe { device.bind_image_memory(raw, allocation.memory(), allocation.offset()) }.and_then(|_| {
                let view_info = vk::ImageViewCreateInfo::default()
                    .image(raw)
                    .view_type(view_type)
                    .format(format)
                    .subresource_range(vk::ImageSubresourceRange {
                        aspect_mask: aspect_of(format),
                        base_mip_level: 0,
                        level_count: 1,
                        base_array_layer: 0,
                        layer_count: layers,
                    });
                unsafe { device.create_image_view(&view_info, None) }
            });
        let view = match result {
            Ok(v) => v,
            Err(e) => {
                unsafe { device.destroy_image(raw, None) };
                let _ = ctx.shared.allocator.lock().unwrap().free(allocation);
                return Err(runtime!("image {name}: {e}"));
            }
        };
        let mut layer_views = Vec::new();
        if layers > 1 {
            for layer in 0..layers {
                let info = vk::ImageViewCreateInfo::default()
                    .image(raw)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format)
                    .subresource_range(vk::ImageSubresourceRange {
                        aspect_mask: aspect_of(format),
                        base_mip_level: 0,
                        level_count: 1,
                        base_array_layer: layer,
                        layer_count: 1,
                    });
                match unsafe { device.create_image_view(&info, None) } {
                    Ok(v) => layer_views.push(v),
                    Err(e) => {
                        unsafe {
                            for v in layer_views {
                                device.destroy_image_view(v, None);
                            }
                            device.destroy_image_view(view, None);
                            device.destroy_image(raw, None);
                        }
                        let _ = ctx.shared.allocator.lock().unwrap().free(allocation);
                        return Err(runtime!("image {name} layer view: {e}"));
                    }
                }
            }
        }
        Ok(Image {
            shared: ctx.shared.clone(),
            raw,
            view,
            layer_views,
            allocation: Some(allocation),
            format,
            extent,
            layers,
            name: name.to_string(),
            state: Cell::new(TrackedState::new()),
        })
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: every submission is waited for before resources can be dropped.
        unsafe {
            for v in &self.layer_views {
                self.shared.device.destroy_image_view(*v, None);
            }
            self.shared.device.destroy_image_view(self.view, None);
            self.shared.device.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.shared.allocator.lock().unwrap().free(a);
        }
    }
}

pub struct Sampler {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Sampler,
}

impl Sampler {
    /// Clamped sampler; `compare` makes it a depth-comparison sampler for shadow maps.
    pub fn new(ctx: &Context, linear: bool, compare: bool) -> Result<Sampler> {
        let filter = if linear { vk::Filter::LINEAR } else { vk::Filter::NEAREST };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_BORDER)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_BORDER)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_BORDER)
            .border_color(vk::BorderColor::FLOAT_OPAQUE_WHITE)
            .compare_enable(compare)
            .compare_op(vk::CompareOp::LESS_OR_EQUAL)
            .max_lod(0.0);
        // SAFETY: valid device.
        let raw = unsafe { ctx.device().create_sampler(&info, None) }.map_err(|e| runtime!("vkCreateSampler: {e}"))?;
        Ok(Sampler { shared: ctx.shared.clone(), raw })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        unsafe { self.shared.device.destroy_sampler(self.raw, None) };
    }
}
