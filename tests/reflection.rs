//! Pipeline layouts come from the shaders: the SPIR-V reflection they are built from, and the
//! checks of each dispatch's `Bind` list against it.

mod common;

use common::{assert_clean, validated_context};
use translucent::shaders::{reflect, reflect_spirv, spirv, DescriptorBinding, DescriptorKind, Reflection, Stage};
use translucent::vk::{self, Bind, Buffer, BufferUsageFlags, Extent2D, Format, Image, ImageUsageFlags, Pipeline};

fn binding(binding: u32, kind: DescriptorKind, read_only: bool, name: &str) -> DescriptorBinding {
    DescriptorBinding { set: 0, binding, kind, count: 1, read_only, name: name.to_string() }
}

#[test]
fn shade_frag_declares_its_buffers_texels_and_images() {
    let r = reflect("shade.frag").unwrap();
    assert_eq!(r.stage, Stage::Fragment);
    let numbers: Vec<u32> = r.bindings.iter().map(|b| b.binding).collect();
    assert_eq!(numbers, (0..numbers.len() as u32).collect::<Vec<_>>(), "bindings 0..n in order");
    assert_eq!(r.bindings.len(), 20, "{:?}", r.bindings);
    for b in &r.bindings {
        assert_eq!((b.set, b.count), (0, 1), "{b:?}");
        let expected = match b.binding {
            // The object's and the frame's parameters: uniform buffers.
            0 | 13 => (DescriptorKind::UniformBuffer, true),
            // The work counters, the one buffer the shader writes.
            3 => (DescriptorKind::StorageBuffer, false),
            // The lights and shadow-map matrices.
            4 => (DescriptorKind::StorageBuffer, true),
            // sampler2DArrayShadow, the same map's depth (sampler2DArray) and the mesh's normal at
            // each of its texels (usampler2DArray): combined image samplers.
            5 | 16 | 19 => (DescriptorKind::CombinedImageSampler, true),
            // The G-buffer's position, normal and texture (the scatter weight), read.
            8 | 9 | 17 => (DescriptorKind::StorageImage, true),
            // Nodes, points, their light records, the tile lists, the dipole table and the far
            // field's sums: texels.
            _ => (DescriptorKind::UniformTexelBuffer, true),
        };
        assert_eq!((b.kind, b.read_only), expected, "{b:?}");
    }
    // ShadeConstants: mat4, vec4, uvec4.
    assert_eq!(r.push_constants, Some(0..96));
    assert_eq!(reflect("shade.vert").unwrap().stage, Stage::Vertex);
}

#[test]
fn test_shader_reflects_every_kind() {
    let r = reflect("test/reflection.comp").unwrap();
    let expected = Reflection {
        stage: Stage::Compute,
        bindings: vec![
            binding(0, DescriptorKind::StorageBuffer, true, "inputs"),
            binding(1, DescriptorKind::StorageBuffer, false, "Outputs"),
            binding(2, DescriptorKind::UniformBuffer, true, "params"),
            binding(3, DescriptorKind::CombinedImageSampler, true, "tex"),
            binding(4, DescriptorKind::StorageImage, true, "src_image"),
            // writeonly is not readonly: the shader writes it.
            binding(5, DescriptorKind::StorageImage, false, "dst_image"),
        ],
        // vec4, vec4, uint: members end at 36, the block (aligned to 16 as std430) at 48.
        push_constants: Some(0..48),
    };
    assert_eq!(r, expected);
    assert_eq!(r.push_constant_size(), 48);
}

#[test]
fn every_embedded_shader_reflects() {
    for name in translucent::shaders::names() {
        let r = reflect(name).unwrap_or_else(|e| panic!("{e}"));
        let expected_stage = match name.rsplit('.').next() {
            Some("comp") => Stage::Compute,
            Some("vert") => Stage::Vertex,
            _ => Stage::Fragment,
        };
        assert_eq!(r.stage, expected_stage, "{name}");
        assert!(r.bindings.iter().all(|b| b.set == 0 && b.count == 1), "{name}: {:?}", r.bindings);
        assert!(r.push_constant_size() <= 128, "{name}: {} bytes of push constants", r.push_constant_size());
    }
}

/// The words of `test/reflection.comp` with the `NonWritable` member decoration of the `Inputs`
/// block replaced by `replacement` (4 words).
fn with_inputs_decoration_replaced(replacement: impl Fn(u32) -> [u32; 4]) -> Vec<u32> {
    let mut words = spirv("test/reflection.comp").unwrap();
    let id_named = |words: &[u32], wanted: &str| {
        let mut i = 5;
        while i < words.len() {
            let (count, opcode) = ((words[i] >> 16) as usize, words[i] & 0xffff);
            if opcode == 5 {
                let bytes: Vec<u8> =
                    words[i + 2..i + count].iter().flat_map(|w| w.to_le_bytes()).take_while(|b| *b != 0).collect();
                if bytes == wanted.as_bytes() {
                    return words[i + 1];
                }
            }
            i += count;
        }
        panic!("no OpName {wanted}");
    };
    let (block, variable) = (id_named(&words, "Inputs"), id_named(&words, "inputs"));
    let mut i = 5;
    let mut replaced = 0;
    while i < words.len() {
        let (count, opcode) = ((words[i] >> 16) as usize, words[i] & 0xffff);
        // OpMemberDecorate Inputs <member> NonWritable
        if opcode == 72 && count == 4 && words[i + 1] == block && words[i + 3] == 24 {
            words[i..i + 4].copy_from_slice(&replacement(variable));
            replaced += 1;
        }
        i += count;
    }
    assert_eq!(replaced, 1, "Inputs has one member, decorated NonWritable");
    words
}

#[test]
fn readonly_is_found_on_the_members_or_on_the_variable() {
    const NOP: u32 = 1 << 16;
    // `OpDecorate inputs NonWritable` and a nop: the decoration on the variable, as other
    // compilers put it.
    let on_variable = with_inputs_decoration_replaced(|var| [(3 << 16) | 71, var, 24, NOP]);
    let r = reflect_spirv(&on_variable).unwrap();
    assert!(r.bindings[0].read_only, "{:?}", r.bindings[0]);
    // No decoration at all: writable.
    let nowhere = with_inputs_decoration_replaced(|_| [NOP; 4]);
    let r = reflect_spirv(&nowhere).unwrap();
    assert!(!r.bindings[0].read_only, "{:?}", r.bindings[0]);
}

#[test]
fn malformed_spirv_is_an_error() {
    assert!(reflect_spirv(&[]).is_err());
    assert!(reflect_spirv(&[1, 2, 3, 4, 5]).is_err());
    let mut words = spirv("test/reflection.comp").unwrap();
    // The header and the first word of OpCapability (two words).
    words.truncate(6);
    assert!(reflect_spirv(&words).is_err(), "a truncated instruction");
    assert!(reflect("no/such.comp").unwrap_err().contains("no/such.comp"));
}

/// A dispatch of `test/reflection.comp` with the right binds runs; wrong ones are rejected before
/// anything is recorded, with the shader and the binding named.
#[test]
fn binds_are_checked_against_the_shader() {
    let (ctx, counts) = validated_context();
    {
        let pipeline = Pipeline::compute(&ctx, "test/reflection.comp").unwrap();
        assert_eq!(pipeline.push_constant_size(), 48);
        let n = 100u32;
        let values: Vec<u32> = (0..n).collect();
        let inputs = vk::upload_buffer(&ctx, "inputs", &values, BufferUsageFlags::STORAGE_BUFFER).unwrap();
        let usage = BufferUsageFlags::STORAGE_BUFFER | BufferUsageFlags::TRANSFER_SRC;
        let outputs = Buffer::new(&ctx, "outputs", 4 * n as u64, usage, vk::MemoryLocation::GpuOnly).unwrap();
        let params = vk::upload_buffer(&ctx, "params", &[3u32, 0, 0, 0], BufferUsageFlags::UNIFORM_BUFFER).unwrap();
        let extent = Extent2D { width: 1, height: 1 };
        let image_usage = ImageUsageFlags::SAMPLED | ImageUsageFlags::STORAGE;
        let image = |name| Image::new_2d(&ctx, name, Format::R8G8B8A8_UNORM, extent, 1, image_usage).unwrap();
        let (tex, src, dst) = (image("tex"), image("src"), image("dst"));
        let sampler = vk::Sampler::new(&ctx, false, false).unwrap();
        let mut constants = [0u32; 12];
        constants[8] = n;
        let push = bytemuck::cast_slice::<u32, u8>(&constants);

        let dispatch = |binds: &[Bind], push: &[u8]| {
            ctx.submit(None, |rec| rec.dispatch(&pipeline, binds, push, [n.div_ceil(64), 1, 1]))
        };
        let good = [
            Bind::Read(&inputs),
            Bind::Write(&outputs),
            Bind::Uniform(&params),
            Bind::Sampled(&tex, &sampler),
            Bind::StorageImageRead(&src),
            Bind::StorageImageWrite(&dst),
        ];
        dispatch(&good, push).unwrap();
        let results: Vec<u32> = vk::download_buffer(&ctx, &outputs, n as usize).unwrap();
        assert_eq!(results, (0..n).map(|i| 3 * i + i).collect::<Vec<_>>());

        let rejected = |binds: &[Bind], push: &[u8], wanted: &[&str]| {
            let e = dispatch(binds, push).expect_err("rejected").to_string();
            for w in wanted {
                assert!(e.contains(w), "{e:?} should name {w:?}");
            }
        };
        let mut binds = good;
        binds[1] = Bind::Read(&outputs);
        rejected(&binds, push, &["test/reflection.comp", "binding 1", "Bind::Read", "readonly"]);
        let mut binds = good;
        binds[0] = Bind::Write(&inputs);
        rejected(&binds, push, &["test/reflection.comp", "binding 0", "Bind::Write", "readonly"]);
        let mut binds = good;
        binds[4] = Bind::StorageImageWrite(&src);
        rejected(&binds, push, &["binding 4", "src_image", "readonly"]);
        let mut binds = good;
        binds[5] = Bind::StorageImageRead(&dst);
        rejected(&binds, push, &["binding 5", "dst_image"]);
        let mut binds = good;
        binds[2] = Bind::Read(&params);
        rejected(&binds, push, &["binding 2", "UniformBuffer"]);
        rejected(&good[..5], push, &["test/reflection.comp", "5 resources", "6 bindings"]);
        rejected(&good, &push[..36], &["test/reflection.comp", "36 bytes", "48"]);
    }
    drop(ctx);
    assert_clean(&counts);
}
