//! Shader modules, descriptor-set layouts and compute / graphics pipelines (dynamic rendering).
//!
//! A pipeline's layout comes from its shaders: set 0's bindings and the push-constant range are
//! the union of what each stage's SPIR-V declares ([`crate::shaders::reflect`]). The recorder
//! checks each use's [`Bind`](super::Bind) list against it, then allocates and writes a set.

use std::sync::Arc;

use ash::vk;

use super::context::{Context, Shared};
use crate::error::Result;
use crate::runtime;
use crate::shaders::{DescriptorKind, Stage};

/// One binding of a pipeline's set 0, merged over the stages that declare it.
#[derive(Clone, Debug)]
pub(crate) struct LayoutBinding {
    pub kind: DescriptorKind,
    /// No stage writes through it (`readonly` everywhere it is declared).
    pub read_only: bool,
    pub stages: vk::ShaderStageFlags,
    /// The shaders that declare it and its name there, for errors: `shade.frag (work)`.
    pub declared_in: String,
}

pub(crate) fn descriptor_type(kind: DescriptorKind) -> vk::DescriptorType {
    match kind {
        DescriptorKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
        DescriptorKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
        DescriptorKind::CombinedImageSampler => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        DescriptorKind::SampledImage => vk::DescriptorType::SAMPLED_IMAGE,
        DescriptorKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        DescriptorKind::Sampler => vk::DescriptorType::SAMPLER,
        DescriptorKind::UniformTexelBuffer => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
    }
}

pub struct Pipeline {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Pipeline,
    pub(crate) layout: vk::PipelineLayout,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) bind_point: vk::PipelineBindPoint,
    /// Binding i of set 0 is entry i (the shaders' bindings are numbered 0..n without gaps).
    pub(crate) bindings: Vec<LayoutBinding>,
    pub(crate) push_constant_size: u32,
    /// The stages that declare the push-constant block.
    pub(crate) push_stages: vk::ShaderStageFlags,
    pub name: String,
}

impl Drop for Pipeline {
    fn drop(&mut self) {
        // SAFETY: submissions are waited for before pipelines drop.
        unsafe {
            let d = &self.shared.device;
            d.destroy_pipeline(self.raw, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A shader module that lives only while pipelines are created from it, with its reflection.
struct Module<'a> {
    device: &'a ash::Device,
    raw: vk::ShaderModule,
    name: &'a str,
    reflection: crate::shaders::Reflection,
}

impl<'a> Module<'a> {
    fn new(ctx: &'a Context, name: &'a str) -> Result<Module<'a>> {
        let code =
            crate::shaders::spirv(name).ok_or_else(|| runtime!("shader {name} is not embedded in the binary"))?;
        let reflection = crate::shaders::reflect_spirv(&code).map_err(|e| runtime!("shader {name}: {e}"))?;
        let info = vk::ShaderModuleCreateInfo::default().code(&code);
        // SAFETY: the SPIR-V was produced and validated by shaderc at build time.
        let raw = unsafe { ctx.device().create_shader_module(&info, None) }
            .map_err(|e| runtime!("vkCreateShaderModule {name}: {e}"))?;
        Ok(Module { device: ctx.device(), raw, name, reflection })
    }

    /// The module, checked to be a shader of `stage`.
    fn expect(self, stage: vk::ShaderStageFlags) -> Result<Module<'a>> {
        let found = stage_flags(self.reflection.stage);
        if found != stage {
            return Err(runtime!("shader {} is a {found:?} shader, used as {stage:?}", self.name));
        }
        Ok(self)
    }
}

impl Drop for Module<'_> {
    fn drop(&mut self) {
        unsafe { self.device.destroy_shader_module(self.raw, None) };
    }
}

fn stage_flags(stage: Stage) -> vk::ShaderStageFlags {
    match stage {
        Stage::Vertex => vk::ShaderStageFlags::VERTEX,
        Stage::Fragment => vk::ShaderStageFlags::FRAGMENT,
        Stage::Compute => vk::ShaderStageFlags::COMPUTE,
        Stage::Other(_) => vk::ShaderStageFlags::empty(),
    }
}

/// Creates and destroys a shader module for every embedded shader, so the driver (and the
/// validation layer) see each one, and reflects each. Returns the names checked.
pub fn check_all_shaders(ctx: &Context) -> Result<Vec<&'static str>> {
    let mut names = Vec::new();
    for name in crate::shaders::names() {
        Module::new(ctx, name)?;
        names.push(name);
    }
    Ok(names)
}

/// What a pipeline's stages declare together: set 0's bindings and the push-constant block.
struct ShaderLayout {
    bindings: Vec<LayoutBinding>,
    push_constant_size: u32,
    push_stages: vk::ShaderStageFlags,
}

/// Merges the reflection of a pipeline's modules. A binding declared by several stages must have
/// one kind; it is read-only if every stage declares it so.
fn merge_reflection(pipeline: &str, modules: &[&Module]) -> Result<ShaderLayout> {
    let mut bindings: Vec<Option<LayoutBinding>> = Vec::new();
    let (mut push_constant_size, mut push_stages) = (0, vk::ShaderStageFlags::empty());
    for module in modules {
        let stage = stage_flags(module.reflection.stage);
        for b in &module.reflection.bindings {
            let at = format!("pipeline {pipeline}: {} set {} binding {} ({})", module.name, b.set, b.binding, b.name);
            if b.set != 0 {
                return Err(runtime!("{at}: only descriptor set 0 is supported"));
            }
            if b.count != 1 {
                return Err(runtime!("{at}: arrays of descriptors are not supported"));
            }
            if matches!(b.kind, DescriptorKind::SampledImage | DescriptorKind::Sampler) {
                return Err(runtime!("{at}: {:?} descriptors are not supported (use a combined sampler)", b.kind));
            }
            let i = b.binding as usize;
            if bindings.len() <= i {
                bindings.resize(i + 1, None);
            }
            let declared_in = format!("{} ({})", module.name, b.name);
            match &mut bindings[i] {
                None => {
                    bindings[i] =
                        Some(LayoutBinding { kind: b.kind, read_only: b.read_only, stages: stage, declared_in })
                }
                Some(merged) if merged.kind == b.kind => {
                    merged.read_only &= b.read_only;
                    merged.stages |= stage;
                    merged.declared_in = format!("{}, {declared_in}", merged.declared_in);
                }
                Some(merged) => {
                    return Err(runtime!(
                        "{at}: declared as {:?}, but as {:?} in {}",
                        b.kind,
                        merged.kind,
                        merged.declared_in
                    ))
                }
            }
        }
        if module.reflection.push_constants.is_some() {
            push_constant_size = push_constant_size.max(module.reflection.push_constant_size());
            push_stages |= stage;
        }
    }
    let bindings = bindings
        .into_iter()
        .enumerate()
        .map(|(i, b)| {
            b.ok_or_else(|| {
                runtime!("pipeline {pipeline}: no shader declares binding {i}, but a higher one: number them 0..n")
            })
        })
        .collect::<Result<_>>()?;
    Ok(ShaderLayout { bindings, push_constant_size, push_stages })
}

/// A pipeline's merged reflection with its set-0 layout and pipeline layout, which are destroyed
/// on drop unless a pipeline takes them ([`Layouts::into_pipeline`]).
struct Layouts<'a> {
    device: &'a ash::Device,
    shader: ShaderLayout,
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
}

impl Drop for Layouts<'_> {
    fn drop(&mut self) {
        // SAFETY: no pipeline took the layouts, so nothing else uses them; null handles are ignored.
        unsafe {
            self.device.destroy_pipeline_layout(self.layout, None);
            self.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

impl Layouts<'_> {
    /// Creates the set-0 layout and the pipeline layout that `modules` declare together.
    fn new<'a>(ctx: &'a Context, name: &str, modules: &[&Module]) -> Result<Layouts<'a>> {
        let shader = merge_reflection(name, modules)?;
        let max = ctx.limits().max_push_constants_size;
        if shader.push_constant_size > max {
            return Err(runtime!(
                "pipeline {name}: {} bytes of push constants exceed the device's {max}",
                shader.push_constant_size
            ));
        }
        let device = ctx.device();
        let vk_bindings: Vec<_> = shader
            .bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(descriptor_type(b.kind))
                    .descriptor_count(1)
                    .stage_flags(b.stages)
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&vk_bindings);
        // SAFETY: valid device.
        let set_layout = unsafe { device.create_descriptor_set_layout(&info, None) }
            .map_err(|e| runtime!("vkCreateDescriptorSetLayout: {e}"))?;
        let mut layouts = Layouts { device, shader, set_layout, layout: vk::PipelineLayout::null() };
        let ranges = [vk::PushConstantRange {
            stage_flags: layouts.shader.push_stages,
            offset: 0,
            size: layouts.shader.push_constant_size,
        }];
        let set_layouts = [set_layout];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if layouts.shader.push_constant_size > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        // SAFETY: valid device; the create-info points to locals alive for the call.
        layouts.layout = unsafe { device.create_pipeline_layout(&layout_info, None) }
            .map_err(|e| runtime!("vkCreatePipelineLayout: {e}"))?;
        Ok(layouts)
    }

    /// The pipeline was created: it owns the layouts from now on.
    fn into_pipeline(
        mut self,
        ctx: &Context,
        raw: vk::Pipeline,
        bind_point: vk::PipelineBindPoint,
        name: String,
    ) -> Pipeline {
        let shader = std::mem::replace(
            &mut self.shader,
            ShaderLayout { bindings: Vec::new(), push_constant_size: 0, push_stages: vk::ShaderStageFlags::empty() },
        );
        Pipeline {
            shared: ctx.shared.clone(),
            raw,
            layout: std::mem::take(&mut self.layout),
            set_layout: std::mem::take(&mut self.set_layout),
            bind_point,
            bindings: shader.bindings,
            push_constant_size: shader.push_constant_size,
            push_stages: shader.push_stages,
            name,
        }
    }
}

impl Pipeline {
    /// A compute pipeline running `shader` (its path under `shaders/`); its layout is what the
    /// shader declares.
    pub fn compute(ctx: &Context, shader: &str) -> Result<Pipeline> {
        Pipeline::compute_specialized(ctx, shader, &[])
    }

    /// A compute pipeline whose specialisation constant i (constant_id = i) is `specialization[i]`.
    pub fn compute_specialized(ctx: &Context, shader: &str, specialization: &[u32]) -> Result<Pipeline> {
        let module = Module::new(ctx, shader)?.expect(vk::ShaderStageFlags::COMPUTE)?;
        let layouts = Layouts::new(ctx, shader, &[&module])?;
        let entries: Vec<vk::SpecializationMapEntry> = (0..specialization.len() as u32)
            .map(|i| vk::SpecializationMapEntry { constant_id: i, offset: 4 * i, size: 4 })
            .collect();
        let specialization_info =
            vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(specialization));
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.raw)
            .name(c"main")
            .specialization_info(&specialization_info);
        let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(layouts.layout)];
        // SAFETY: valid module and layout.
        let raw = unsafe { ctx.device().create_compute_pipelines(vk::PipelineCache::null(), &info, None) }
            .map_err(|(_, e)| runtime!("compute pipeline {shader}: {e}"))?[0];
        Ok(layouts.into_pipeline(ctx, raw, vk::PipelineBindPoint::COMPUTE, shader.to_string()))
    }

    /// The number of bytes of push constants each use must give (0 without a block).
    pub fn push_constant_size(&self) -> u32 {
        self.push_constant_size
    }

    pub fn graphics(ctx: &Context, desc: &GraphicsDesc) -> Result<Pipeline> {
        let name = format!("{}+{}", desc.vertex_shader, desc.fragment_shader.unwrap_or("-"));
        let vert = Module::new(ctx, desc.vertex_shader)?.expect(vk::ShaderStageFlags::VERTEX)?;
        let frag =
            desc.fragment_shader.map(|f| Module::new(ctx, f)?.expect(vk::ShaderStageFlags::FRAGMENT)).transpose()?;
        let modules: Vec<&Module> = std::iter::once(&vert).chain(&frag).collect();
        let layouts = Layouts::new(ctx, &name, &modules)?;

        // Specialisation constant i (constant_id = i) of both stages is desc.specialization[i].
        let entries: Vec<vk::SpecializationMapEntry> = (0..desc.specialization.len() as u32)
            .map(|i| vk::SpecializationMapEntry { constant_id: i, offset: 4 * i, size: 4 })
            .collect();
        let specialization =
            vk::SpecializationInfo::default().map_entries(&entries).data(bytemuck::cast_slice(desc.specialization));
        let mut stage_infos = vec![vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vert.raw)
            .name(c"main")
            .specialization_info(&specialization)];
        if let Some(frag) = &frag {
            stage_infos.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(frag.raw)
                    .name(c"main")
                    .specialization_info(&specialization),
            );
        }
        let vertex_bindings = [vk::VertexInputBindingDescription {
            binding: 0,
            stride: desc.vertex_stride,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        let attributes: Vec<_> = desc
            .vertex_attributes
            .iter()
            .map(|&(location, format, offset)| vk::VertexInputAttributeDescription {
                location,
                binding: 0,
                format,
                offset,
            })
            .collect();
        let mut vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
        if desc.vertex_stride > 0 {
            vertex_input =
                vertex_input.vertex_binding_descriptions(&vertex_bindings).vertex_attribute_descriptions(&attributes);
        }
        let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(desc.topology);
        let viewport = vk::PipelineViewportStateCreateInfo::default().viewport_count(1).scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(desc.cull_mode)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .depth_bias_enable(desc.depth_bias)
            .line_width(1.0);
        let multisample =
            vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_format.is_some() && desc.depth_test)
            .depth_write_enable(desc.depth_format.is_some() && desc.depth_test)
            .depth_compare_op(vk::CompareOp::LESS_OR_EQUAL);
        let stencil_format = desc.depth_format.filter(|&f| super::resources::has_stencil(f));
        let blend_attachments: Vec<_> = desc
            .color_formats
            .iter()
            .map(|_| {
                let a =
                    vk::PipelineColorBlendAttachmentState::default().color_write_mask(vk::ColorComponentFlags::RGBA);
                if desc.additive_blend {
                    a.blend_enable(true)
                        .src_color_blend_factor(vk::BlendFactor::ONE)
                        .dst_color_blend_factor(vk::BlendFactor::ONE)
                        .color_blend_op(vk::BlendOp::ADD)
                        .src_alpha_blend_factor(vk::BlendFactor::ONE)
                        .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                        .alpha_blend_op(vk::BlendOp::MAX)
                } else {
                    a
                }
            })
            .collect();
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let mut dynamic_states = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        if desc.depth_bias {
            dynamic_states.push(vk::DynamicState::DEPTH_BIAS);
        }
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(desc.color_formats)
            .depth_attachment_format(desc.depth_format.unwrap_or(vk::Format::UNDEFINED))
            .stencil_attachment_format(stencil_format.unwrap_or(vk::Format::UNDEFINED));

        let info = [vk::GraphicsPipelineCreateInfo::default()
            .stages(&stage_infos)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layouts.layout)
            .push_next(&mut rendering)];
        // SAFETY: every pointer refers to locals alive for the call.
        let raw = unsafe { ctx.device().create_graphics_pipelines(vk::PipelineCache::null(), &info, None) }
            .map_err(|(_, e)| runtime!("graphics pipeline {name}: {e}"))?[0];
        Ok(layouts.into_pipeline(ctx, raw, vk::PipelineBindPoint::GRAPHICS, name))
    }
}

/// Shaders and fixed-function state of a graphics pipeline that draws into dynamic-rendering
/// attachments. Its layout is what the shaders declare.
pub struct GraphicsDesc<'a> {
    pub vertex_shader: &'a str,
    /// `None` for depth-only passes (shadow maps).
    pub fragment_shader: Option<&'a str>,
    /// Bytes per vertex of binding 0; 0 when the shader pulls vertices itself.
    pub vertex_stride: u32,
    /// `(location, format, byte offset)` of each vertex attribute.
    pub vertex_attributes: &'a [(u32, vk::Format, u32)],
    pub topology: vk::PrimitiveTopology,
    pub color_formats: &'a [vk::Format],
    pub depth_format: Option<vk::Format>,
    pub depth_test: bool,
    pub depth_bias: bool,
    pub cull_mode: vk::CullModeFlags,
    pub additive_blend: bool,
    /// Values of the shaders' specialisation constants, by constant_id (0, 1, ...).
    pub specialization: &'a [u32],
}
