//! Descriptors: the resources a dispatch or draw binds ([`Bind`]), checked against the pipeline's
//! reflected bindings, and the set 0 written for each use from a pool reset per submission.

use ash::vk;

use super::pipeline::{descriptor_type, Pipeline};
use super::resources::{Buffer, Image, Sampler};
use crate::error::Result;
use crate::runtime;
use crate::shaders::DescriptorKind;

/// Descriptor sets one submission may allocate (one per dispatch or draw with bindings).
pub(crate) const SETS_PER_SUBMIT: u32 = 512;

/// A resource bound to a pipeline, with how the shader uses it. A dispatch or draw lists one per
/// binding of its shaders, in binding order.
#[derive(Clone, Copy)]
pub enum Bind<'a> {
    /// Storage buffer the shader only reads (`readonly` in GLSL).
    Read(&'a Buffer),
    /// Storage buffer the shader writes (and may read).
    Write(&'a Buffer),
    Uniform(&'a Buffer),
    /// A buffer made with UNIFORM_TEXEL_BUFFER usage, read through its RGBA32UI texel view.
    Texels(&'a Buffer),
    /// Combined image sampler, read in `SHADER_READ_ONLY_OPTIMAL`.
    Sampled(&'a Image, &'a Sampler),
    /// Storage image the shader only reads (`readonly`).
    StorageImageRead(&'a Image),
    StorageImageWrite(&'a Image),
}

impl Bind<'_> {
    fn describe(&self) -> &'static str {
        match self {
            Bind::Read(_) => "Bind::Read",
            Bind::Write(_) => "Bind::Write",
            Bind::Uniform(_) => "Bind::Uniform",
            Bind::Texels(_) => "Bind::Texels",
            Bind::Sampled(..) => "Bind::Sampled",
            Bind::StorageImageRead(_) => "Bind::StorageImageRead",
            Bind::StorageImageWrite(_) => "Bind::StorageImageWrite",
        }
    }
}

impl Pipeline {
    /// Checks a use's resources against the shaders' bindings: one per binding, in binding order,
    /// of the declared kind; a reading `Bind` only where no shader can write, a writing one only
    /// where the binding is not `readonly`.
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
                    | (Bind::Texels(_), DescriptorKind::UniformTexelBuffer)
                    | (Bind::Sampled(..), DescriptorKind::CombinedImageSampler)
                    | (Bind::StorageImageRead(_) | Bind::StorageImageWrite(_), DescriptorKind::StorageImage)
            );
            if !kind_ok {
                return Err(runtime!("{}: {} given for a {:?}", at(), bind.describe(), binding.kind));
            }
            match bind {
                Bind::Read(_) | Bind::StorageImageRead(_) if !binding.read_only => {
                    return Err(runtime!(
                        "{}: {} of a resource the shader may write (not `readonly`): bind it as written",
                        at(),
                        bind.describe()
                    ))
                }
                Bind::Write(_) | Bind::StorageImageWrite(_) if binding.read_only => {
                    return Err(runtime!(
                        "{}: {} of a resource the shader declares `readonly`: bind it as read",
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

/// The pool every submission's sets come from (reset after the submission's fence).
///
/// # Safety
/// `device` must be valid; the caller destroys the pool.
pub(crate) unsafe fn create_descriptor_pool(device: &ash::Device) -> Result<vk::DescriptorPool> {
    let sizes = [
        vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: SETS_PER_SUBMIT * 8 },
        vk::DescriptorPoolSize { ty: vk::DescriptorType::UNIFORM_BUFFER, descriptor_count: SETS_PER_SUBMIT },
        vk::DescriptorPoolSize {
            ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            descriptor_count: SETS_PER_SUBMIT * 2,
        },
        vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_IMAGE, descriptor_count: SETS_PER_SUBMIT * 4 },
        vk::DescriptorPoolSize { ty: vk::DescriptorType::UNIFORM_TEXEL_BUFFER, descriptor_count: SETS_PER_SUBMIT * 8 },
    ];
    device
        .create_descriptor_pool(
            &vk::DescriptorPoolCreateInfo::default().max_sets(SETS_PER_SUBMIT).pool_sizes(&sizes),
            None,
        )
        .map_err(|e| runtime!("vkCreateDescriptorPool: {e}"))
}

/// Allocates set 0 of `pipeline` from `pool` and points its bindings at `binds` (already checked
/// with [`Pipeline::check_binds`]).
pub(crate) fn write_set(
    device: &ash::Device,
    pool: vk::DescriptorPool,
    pipeline: &Pipeline,
    binds: &[Bind],
) -> Result<vk::DescriptorSet> {
    let layouts = [pipeline.set_layout];
    // SAFETY: pool and layout are valid; the pool is reset only after the fence wait.
    let set = unsafe {
        device.allocate_descriptor_sets(
            &vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts),
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
                Bind::Texels(b) => w.texel_buffer_view(std::slice::from_ref(&b.texel_view)),
                _ => w.image_info(&image_infos[i]),
            }
        })
        .collect();
    // SAFETY: the set was just allocated and is not in use; the infos outlive the call.
    unsafe { device.update_descriptor_sets(&writes, &[]) };
    Ok(set)
}
