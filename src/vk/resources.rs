//! Buffers, images and samplers, each owning its memory and destroyed on drop. Each buffer and
//! image carries the access state that the recorder turns into barriers (`barriers.rs`).

use std::cell::Cell;
use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;

use super::barriers::TrackedState;
use super::context::{Context, Shared};
use crate::error::Result;
use crate::runtime;

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

impl Sampler {
    /// A linear sampler that repeats its image (textures over a mesh's uv).
    pub fn repeating(ctx: &Context) -> Result<Sampler> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::REPEAT)
            .address_mode_v(vk::SamplerAddressMode::REPEAT)
            .address_mode_w(vk::SamplerAddressMode::REPEAT)
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
