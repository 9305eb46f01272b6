//! Shader modules, descriptor-set layouts and compute / graphics pipelines (dynamic rendering).
//!
//! A pipeline declares its bindings as a list of [`BindingKind`]s (binding i = entry i, set 0) and
//! a push-constant size; the recorder allocates and writes a descriptor set per use.

use std::sync::Arc;

use ash::vk;

use super::context::{Context, Shared};
use crate::error::Result;
use crate::runtime;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    StorageBuffer,
    UniformBuffer,
    /// Combined image + sampler.
    SampledImage,
    StorageImage,
    /// A buffer read as RGBA32UI texels (`usamplerBuffer`).
    TexelBuffer,
}

impl BindingKind {
    pub(crate) fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            BindingKind::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            BindingKind::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            BindingKind::SampledImage => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            BindingKind::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            BindingKind::TexelBuffer => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
        }
    }
}

pub struct Pipeline {
    shared: Arc<Shared>,
    pub(crate) raw: vk::Pipeline,
    pub(crate) layout: vk::PipelineLayout,
    pub(crate) set_layout: vk::DescriptorSetLayout,
    pub(crate) bind_point: vk::PipelineBindPoint,
    pub(crate) bindings: Vec<BindingKind>,
    pub(crate) push_constant_size: u32,
    pub(crate) stages: vk::ShaderStageFlags,
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

/// A shader module that lives only while pipelines are created from it.
struct Module<'a> {
    device: &'a ash::Device,
    raw: vk::ShaderModule,
}

impl<'a> Module<'a> {
    fn new(ctx: &'a Context, name: &str) -> Result<Module<'a>> {
        let code =
            crate::shaders::spirv(name).ok_or_else(|| runtime!("shader {name} is not embedded in the binary"))?;
        let info = vk::ShaderModuleCreateInfo::default().code(&code);
        // SAFETY: the SPIR-V was produced and validated by shaderc at build time.
        let raw = unsafe { ctx.device().create_shader_module(&info, None) }
            .map_err(|e| runtime!("vkCreateShaderModule {name}: {e}"))?;
        Ok(Module { device: ctx.device(), raw })
    }
}

impl Drop for Module<'_> {
    fn drop(&mut self) {
        unsafe { self.device.destroy_shader_module(self.raw, None) };
    }
}

/// Creates and destroys a shader module for every embedded shader, so the driver (and the
/// validation layer) see each one. Returns the names checked.
pub fn check_all_shaders(ctx: &Context) -> Result<Vec<&'static str>> {
    let mut names = Vec::new();
    for name in crate::shaders::names() {
        Module::new(ctx, name)?;
        names.push(name);
    }
    Ok(names)
}

/// Creates the set-0 layout and the pipeline layout for `bindings` and `push_constant_size`.
fn layouts(
    ctx: &Context,
    bindings: &[BindingKind],
    push_constant_size: u32,
    stages: vk::ShaderStageFlags,
) -> Result<(vk::DescriptorSetLayout, vk::PipelineLayout)> {
    let device = ctx.device();
    let vk_bindings: Vec<_> = bindings
        .iter()
        .enumerate()
        .map(|(i, kind)| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(i as u32)
                .descriptor_type(kind.descriptor_type())
                .descriptor_count(1)
                .stage_flags(stages)
        })
        .collect();
    let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&vk_bindings);
    // SAFETY: valid device.
    let set_layout = unsafe { device.create_descriptor_set_layout(&info, None) }
        .map_err(|e| runtime!("vkCreateDescriptorSetLayout: {e}"))?;
    let ranges = [vk::PushConstantRange { stage_flags: stages, offset: 0, size: push_constant_size }];
    let set_layouts = [set_layout];
    let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
    if push_constant_size > 0 {
        layout_info = layout_info.push_constant_ranges(&ranges);
    }
    match unsafe { device.create_pipeline_layout(&layout_info, None) } {
        Ok(layout) => Ok((set_layout, layout)),
        Err(e) => {
            unsafe { device.destroy_descriptor_set_layout(set_layout, None) };
            Err(runtime!("vkCreatePipelineLayout: {e}"))
        }
    }
}

fn check_push_size(ctx: &Context, name: &str, size: u32) -> Result<()> {
    let max = ctx.limits().max_push_constants_size;
    if size > max {
        return Err(runtime!("pipeline {name}: {size} bytes of push constants exceed the device's {max}"));
    }
    Ok(())
}

impl Pipeline {
    pub fn compute(ctx: &Context, shader: &str, bindings: &[BindingKind], push_constant_size: u32) -> Result<Pipeline> {
        check_push_size(ctx, shader, push_constant_size)?;
        let module = Module::new(ctx, shader)?;
        let stages = vk::ShaderStageFlags::COMPUTE;
        let (set_layout, layout) = layouts(ctx, bindings, push_constant_size, stages)?;
        let stage = vk::PipelineShaderStageCreateInfo::default().stage(stages).module(module.raw).name(c"main");
        let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout)];
        // SAFETY: valid module and layout.
        let raw = unsafe { ctx.device().create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
        let raw = match raw {
            Ok(p) => p[0],
            Err((_, e)) => {
                unsafe {
                    ctx.device().destroy_pipeline_layout(layout, None);
                    ctx.device().destroy_descriptor_set_layout(set_layout, None);
                }
                return Err(runtime!("compute pipeline {shader}: {e}"));
            }
        };
        Ok(Pipeline {
            shared: ctx.shared.clone(),
            raw,
            layout,
            set_layout,
            bind_point: vk::PipelineBindPoint::COMPUTE,
            bindings: bindings.to_vec(),
            push_constant_size,
            stages,
            name: shader.to_string(),
        })
    }

    pub fn graphics(ctx: &Context, desc: &GraphicsDesc) -> Result<Pipeline> {
        let name = format!("{}+{}", desc.vertex_shader, desc.fragment_shader.unwrap_or("-"));
        check_push_size(ctx, &name, desc.push_constant_size)?;
        let vert = Module::new(ctx, desc.vertex_shader)?;
        let frag = desc.fragment_shader.map(|f| Module::new(ctx, f)).transpose()?;
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let (set_layout, layout) = layouts(ctx, desc.bindings, desc.push_constant_size, stages)?;

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
            .depth_write_enable(desc.depth_format.is_some() && desc.depth_test && !desc.depth_equal)
            .depth_compare_op(if desc.depth_equal { vk::CompareOp::EQUAL } else { vk::CompareOp::LESS_OR_EQUAL });
        // Shade each pixel once: of the fragments that pass the EQUAL depth test (coincident
        // triangles all do), only the first in primitive order passes "stencil == reference",
        // and it increments the stencil so that the rest fail, before the shader runs.
        let stencil_format = desc.depth_format.filter(|&f| super::resources::has_stencil(f));
        let once = desc.depth_equal && stencil_format.is_some();
        let once_op = vk::StencilOpState {
            fail_op: vk::StencilOp::KEEP,
            pass_op: vk::StencilOp::INCREMENT_AND_WRAP,
            depth_fail_op: vk::StencilOp::KEEP,
            compare_op: vk::CompareOp::EQUAL,
            compare_mask: 0xff,
            write_mask: 0xff,
            reference: 0,
        };
        let depth = if once { depth.stencil_test_enable(true).front(once_op).back(once_op) } else { depth };
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
        if once {
            dynamic_states.push(vk::DynamicState::STENCIL_REFERENCE);
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
            .layout(layout)
            .push_next(&mut rendering)];
        // SAFETY: every pointer refers to locals alive for the call.
        let raw = match unsafe { ctx.device().create_graphics_pipelines(vk::PipelineCache::null(), &info, None) } {
            Ok(p) => p[0],
            Err((_, e)) => {
                unsafe {
                    ctx.device().destroy_pipeline_layout(layout, None);
                    ctx.device().destroy_descriptor_set_layout(set_layout, None);
                }
                return Err(runtime!("graphics pipeline {name}: {e}"));
            }
        };
        Ok(Pipeline {
            shared: ctx.shared.clone(),
            raw,
            layout,
            set_layout,
            bind_point: vk::PipelineBindPoint::GRAPHICS,
            bindings: desc.bindings.to_vec(),
            push_constant_size: desc.push_constant_size,
            stages,
            name,
        })
    }
}

/// Fixed-function state of a graphics pipeline that draws into dynamic-rendering attachments.
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
    /// Test depth for equality without writing it (shading after a depth pre-pass). With a
    /// depth format that has stencil, also shade each pixel once whatever the mesh: stencil
    /// EQUAL to the dynamic reference (`Recorder::set_stencil_reference`), incremented on pass.
    pub depth_equal: bool,
    pub depth_bias: bool,
    pub cull_mode: vk::CullModeFlags,
    pub additive_blend: bool,
    /// Values of the shaders' specialisation constants, by constant_id (0, 1, ...).
    pub specialization: &'a [u32],
    pub bindings: &'a [BindingKind],
    pub push_constant_size: u32,
}
