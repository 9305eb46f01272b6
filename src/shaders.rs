//! The SPIR-V of every shader under `shaders/`, compiled by `build.rs` and embedded in the binary so
//! that it runs from any folder.

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// The SPIR-V words of `name` (its path under `shaders/`, e.g. `"shade.frag"`).
pub fn spirv(name: &str) -> Option<Vec<u32>> {
    let bytes = SHADERS.iter().find(|(n, _)| *n == name)?.1;
    // include_bytes! gives no alignment guarantee: copy into u32 words.
    Some(bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
}

/// Names of all embedded shaders.
pub fn names() -> impl Iterator<Item = &'static str> {
    SHADERS.iter().map(|(n, _)| *n)
}

/// Byte offsets of the members of the struct type named `type_name` in a shader's SPIR-V, read
/// from its `OpMemberDecorate … Offset` decorations. Tests use it to check that a Rust mirror of a
/// GLSL struct has the same layout. `None` if the shader or the name is not found.
pub fn member_offsets(shader: &str, type_name: &str) -> Option<Vec<u32>> {
    const OP_NAME: u32 = 5;
    const OP_MEMBER_DECORATE: u32 = 72;
    const DECORATION_OFFSET: u32 = 35;
    let words = spirv(shader)?;
    // glslang may emit a struct twice under one name: laid out (with offsets) as a buffer's member
    // type, and plain for a function-local copy. The laid-out one is the one that counts.
    let mut type_ids = Vec::new();
    let mut offsets: Vec<(u32, u32, u32)> = Vec::new();
    let mut i = 5; // skip the header
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let opcode = words[i] & 0xffff;
        if count == 0 || i + count > words.len() {
            return None;
        }
        let operands = &words[i + 1..i + count];
        if opcode == OP_NAME && operands.len() >= 2 {
            let bytes: Vec<u8> = operands[1..].iter().flat_map(|w| w.to_le_bytes()).take_while(|b| *b != 0).collect();
            if bytes == type_name.as_bytes() {
                type_ids.push(operands[0]);
            }
        }
        let is_offset = opcode == OP_MEMBER_DECORATE && operands.len() >= 4 && operands[2] == DECORATION_OFFSET;
        if is_offset && type_ids.contains(&operands[0]) {
            offsets.push((operands[0], operands[1], operands[3]));
        }
        i += count;
    }
    let laid_out = offsets.first().map(|o| o.0).or(type_ids.first().copied())?;
    let mut offsets: Vec<(u32, u32)> =
        offsets.into_iter().filter(|o| o.0 == laid_out).map(|(_, member, offset)| (member, offset)).collect();
    offsets.sort();
    Some(offsets.into_iter().map(|(_, offset)| offset).collect())
}

/// A shader stage, from the SPIR-V entry point's execution model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    Vertex,
    Fragment,
    Compute,
    /// Any other execution model (its SPIR-V number).
    Other(u32),
}

/// What kind of descriptor a binding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DescriptorKind {
    /// `buffer` (`StorageBuffer` storage class, or `Uniform` + `BufferBlock` in old SPIR-V).
    StorageBuffer,
    /// `uniform` block.
    UniformBuffer,
    /// `sampler2D`, `sampler2DArrayShadow`, ...: image and sampler in one descriptor.
    CombinedImageSampler,
    /// `texture2D`, ...: an image sampled with a separate sampler.
    SampledImage,
    /// `image2D`, ...
    StorageImage,
    /// `sampler`.
    Sampler,
    /// `samplerBuffer`, `usamplerBuffer`: a buffer read as texels.
    UniformTexelBuffer,
}

/// One descriptor a shader declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DescriptorBinding {
    pub set: u32,
    pub binding: u32,
    pub kind: DescriptorKind,
    /// Array length (1 for a single descriptor, 0 for an unsized array).
    pub count: u32,
    /// The shader cannot write through it: a storage buffer or image that is `NonWritable` (GLSL
    /// `readonly`; on the variable, or on every member of the buffer's block), or any other kind.
    pub read_only: bool,
    /// The variable's name, else its block's (debug info), else empty.
    pub name: String,
}

/// What a shader module declares to the pipeline layout: its descriptors and its push constants.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Reflection {
    pub stage: Stage,
    /// Sorted by (set, binding).
    pub bindings: Vec<DescriptorBinding>,
    /// Byte range of the push-constant block: its first member's offset to the end of the block,
    /// rounded up to the block's alignment as std430 does for a struct (`None` without one).
    pub push_constants: Option<std::ops::Range<u32>>,
}

impl Reflection {
    /// Bytes of push constants the shader reads, counted from 0 (0 without a block).
    pub fn push_constant_size(&self) -> u32 {
        self.push_constants.as_ref().map_or(0, |r| r.end)
    }
}

/// The descriptors and push constants of the embedded shader `name` (see [`reflect_spirv`]).
pub fn reflect(name: &str) -> Result<Reflection, String> {
    let words = spirv(name).ok_or_else(|| format!("shader {name} is not embedded in the binary"))?;
    reflect_spirv(&words).map_err(|e| format!("shader {name}: {e}"))
}

/// Reads descriptor set and binding numbers, descriptor kinds, `NonWritable` decorations and the
/// push-constant block's size from SPIR-V words (after zeux/niagara's `parseShader`). Only what a
/// pipeline layout needs: one entry point, types it can size.
pub fn reflect_spirv(words: &[u32]) -> Result<Reflection, String> {
    const MAGIC: u32 = 0x0723_0203;
    const OP_NAME: u32 = 5;
    const OP_ENTRY_POINT: u32 = 15;
    const OP_TYPE_INT: u32 = 21;
    const OP_TYPE_FLOAT: u32 = 22;
    const OP_TYPE_VECTOR: u32 = 23;
    const OP_TYPE_MATRIX: u32 = 24;
    const OP_TYPE_IMAGE: u32 = 25;
    const OP_TYPE_SAMPLER: u32 = 26;
    const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
    const OP_TYPE_ARRAY: u32 = 28;
    const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
    const OP_TYPE_STRUCT: u32 = 30;
    const OP_TYPE_POINTER: u32 = 32;
    const OP_CONSTANT: u32 = 43;
    const OP_VARIABLE: u32 = 59;
    const OP_DECORATE: u32 = 71;
    const OP_MEMBER_DECORATE: u32 = 72;
    const DECORATION_BLOCK: u32 = 2;
    const DECORATION_BUFFER_BLOCK: u32 = 3;
    const DECORATION_ROW_MAJOR: u32 = 4;
    const DECORATION_ARRAY_STRIDE: u32 = 6;
    const DECORATION_MATRIX_STRIDE: u32 = 7;
    const DECORATION_NON_WRITABLE: u32 = 24;
    const DECORATION_BINDING: u32 = 33;
    const DECORATION_DESCRIPTOR_SET: u32 = 34;
    const DECORATION_OFFSET: u32 = 35;
    const STORAGE_UNIFORM_CONSTANT: u32 = 0;
    const STORAGE_UNIFORM: u32 = 2;
    const STORAGE_PUSH_CONSTANT: u32 = 9;
    const STORAGE_STORAGE_BUFFER: u32 = 12;

    /// What the walk keeps of each id.
    #[derive(Clone, Default)]
    struct Id {
        opcode: u32,
        /// The instruction's operands after the result id.
        args: Vec<u32>,
        name: String,
        set: Option<u32>,
        binding: Option<u32>,
        non_writable: bool,
        block: bool,
        buffer_block: bool,
        array_stride: Option<u32>,
        /// Per struct member: offset, matrix stride, row-major, NonWritable.
        members: Vec<Member>,
    }
    #[derive(Clone, Copy, Default)]
    struct Member {
        offset: Option<u32>,
        matrix_stride: Option<u32>,
        row_major: bool,
        non_writable: bool,
    }

    if words.len() < 5 || words[0] != MAGIC {
        return Err("not SPIR-V (bad header)".into());
    }
    let bound = words[3] as usize;
    let mut ids = vec![Id::default(); bound];
    let mut stage = None;
    fn member(ids: &mut [Id], id: u32, index: u32) -> Option<&mut Member> {
        let members = &mut ids.get_mut(id as usize)?.members;
        if members.len() <= index as usize {
            members.resize(index as usize + 1, Member::default());
        }
        Some(&mut members[index as usize])
    }
    let mut i = 5;
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let opcode = words[i] & 0xffff;
        if count == 0 || i + count > words.len() {
            return Err(format!("truncated instruction at word {i}"));
        }
        let ops = &words[i + 1..i + count];
        let id_of = |k: usize| ops.get(k).map(|&w| w as usize).filter(|&w| w < bound);
        match opcode {
            OP_ENTRY_POINT if !ops.is_empty() => {
                if stage.is_some() {
                    return Err("more than one entry point".into());
                }
                stage = Some(match ops[0] {
                    0 => Stage::Vertex,
                    4 => Stage::Fragment,
                    5 => Stage::Compute,
                    other => Stage::Other(other),
                });
            }
            OP_NAME => {
                if let Some(id) = id_of(0) {
                    let bytes: Vec<u8> =
                        ops[1..].iter().flat_map(|w| w.to_le_bytes()).take_while(|b| *b != 0).collect();
                    ids[id].name = String::from_utf8_lossy(&bytes).into_owned();
                }
            }
            OP_DECORATE if ops.len() >= 2 => {
                if let Some(id) = id_of(0) {
                    let target = &mut ids[id];
                    match ops[1] {
                        DECORATION_DESCRIPTOR_SET => target.set = ops.get(2).copied(),
                        DECORATION_BINDING => target.binding = ops.get(2).copied(),
                        DECORATION_NON_WRITABLE => target.non_writable = true,
                        DECORATION_BLOCK => target.block = true,
                        DECORATION_BUFFER_BLOCK => target.buffer_block = true,
                        DECORATION_ARRAY_STRIDE => target.array_stride = ops.get(2).copied(),
                        _ => {}
                    }
                }
            }
            OP_MEMBER_DECORATE if ops.len() >= 3 => {
                if let Some(m) = member(&mut ids, ops[0], ops[1]) {
                    match ops[2] {
                        DECORATION_OFFSET => m.offset = ops.get(3).copied(),
                        DECORATION_MATRIX_STRIDE => m.matrix_stride = ops.get(3).copied(),
                        DECORATION_ROW_MAJOR => m.row_major = true,
                        DECORATION_NON_WRITABLE => m.non_writable = true,
                        _ => {}
                    }
                }
            }
            // Types and variables: result id first, except OpConstant and OpVariable (type, result).
            OP_TYPE_INT..=OP_TYPE_POINTER => {
                if let Some(id) = id_of(0) {
                    ids[id].opcode = opcode;
                    ids[id].args = ops[1..].to_vec();
                    if opcode == OP_TYPE_STRUCT && ids[id].members.len() < ops.len() - 1 {
                        ids[id].members.resize(ops.len() - 1, Member::default());
                    }
                }
            }
            OP_CONSTANT | OP_VARIABLE => {
                if let Some(id) = id_of(1) {
                    ids[id].opcode = opcode;
                    ids[id].args = std::iter::once(ops[0]).chain(ops[2..].iter().copied()).collect();
                }
            }
            _ => {}
        }
        i += count;
    }
    let stage = stage.ok_or("no entry point")?;

    let get = |id: u32| ids.get(id as usize).filter(|t| t.opcode != 0).ok_or(format!("undefined id {id}"));
    // std430 size and alignment of a type inside a block (matrices and arrays by their strides).
    fn layout(ids: &[Id], id: u32, matrix: Option<(u32, bool)>, depth: u32) -> Result<(u32, u32), String> {
        let t = ids.get(id as usize).filter(|t| t.opcode != 0).ok_or(format!("undefined type {id}"))?;
        if depth > 32 {
            return Err("types nested too deeply".into());
        }
        let arg = |k: usize| t.args.get(k).copied().ok_or(format!("malformed type {id}"));
        Ok(match t.opcode {
            OP_TYPE_INT | OP_TYPE_FLOAT => (arg(0)? / 8, arg(0)? / 8),
            OP_TYPE_VECTOR => {
                let (scalar, _) = layout(ids, arg(0)?, None, depth + 1)?;
                let n = arg(1)?;
                (scalar * n, scalar * if n == 3 { 4 } else { n })
            }
            OP_TYPE_MATRIX => {
                let (stride, row_major) = matrix.ok_or(format!("matrix type {id} without a MatrixStride"))?;
                let column = ids.get(arg(0)? as usize).ok_or(format!("malformed matrix {id}"))?;
                let (columns, rows) = (arg(1)?, column.args.get(1).copied().unwrap_or(4));
                let vectors = if row_major { rows } else { columns };
                let (_, align) = layout(ids, arg(0)?, None, depth + 1)?;
                (vectors * stride, align)
            }
            OP_TYPE_ARRAY => {
                let length = ids.get(arg(1)? as usize).and_then(|c| c.args.get(1)).copied();
                let length = length.ok_or(format!("array type {id}: length is not a constant"))?;
                let stride = t.array_stride.ok_or(format!("array type {id} without an ArrayStride"))?;
                let (_, align) = layout(ids, arg(0)?, matrix, depth + 1)?;
                (length * stride, align)
            }
            OP_TYPE_RUNTIME_ARRAY => {
                let (_, align) = layout(ids, arg(0)?, matrix, depth + 1)?;
                (0, align)
            }
            OP_TYPE_STRUCT => {
                let (mut end, mut align) = (0, 1);
                for (k, &member) in t.args.iter().enumerate() {
                    let m = t.members.get(k).copied().unwrap_or_default();
                    let offset = m.offset.ok_or(format!("struct {} member {k} without an Offset", t.name))?;
                    let (size, a) = layout(ids, member, m.matrix_stride.map(|s| (s, m.row_major)), depth + 1)?;
                    end = end.max(offset + size);
                    align = align.max(a);
                }
                (end.next_multiple_of(align), align)
            }
            other => return Err(format!("type {id} (opcode {other}) has no size in a block")),
        })
    }

    let mut bindings = Vec::new();
    let mut push_constants: Option<std::ops::Range<u32>> = None;
    for var in ids.iter().filter(|v| v.opcode == OP_VARIABLE) {
        let (pointer, storage) = (var.args[0], var.args.get(1).copied().unwrap_or(u32::MAX));
        let pointer = get(pointer)?;
        let mut ty_id = *pointer.args.get(1).ok_or("malformed pointer type")?;
        if storage == STORAGE_PUSH_CONSTANT {
            let block = get(ty_id)?;
            let first = block.members.iter().filter_map(|m| m.offset).min().unwrap_or(0);
            let (size, _) = layout(&ids, ty_id, None, 0)?;
            if push_constants.is_some() {
                return Err("more than one push-constant block".into());
            }
            push_constants = Some(first..size);
            continue;
        }
        if ![STORAGE_UNIFORM_CONSTANT, STORAGE_UNIFORM, STORAGE_STORAGE_BUFFER].contains(&storage) {
            continue;
        }
        // Arrays of descriptors: unwrap to the element type.
        let mut count = 1;
        let mut ty = get(ty_id)?;
        if ty.opcode == OP_TYPE_ARRAY || ty.opcode == OP_TYPE_RUNTIME_ARRAY {
            count = match ty.opcode {
                OP_TYPE_ARRAY => get(ty.args[1])?.args.get(1).copied().ok_or("array length is not a constant")?,
                _ => 0,
            };
            ty_id = ty.args[0];
            ty = get(ty_id)?;
        }
        let kind = match (storage, ty.opcode) {
            (STORAGE_STORAGE_BUFFER, _) => DescriptorKind::StorageBuffer,
            (STORAGE_UNIFORM, _) if ty.buffer_block => DescriptorKind::StorageBuffer,
            (STORAGE_UNIFORM, _) if ty.block => DescriptorKind::UniformBuffer,
            // OpTypeImage: Dim is args[1] (5: buffer), Sampled args[5] (1: sampled, 2: storage).
            (STORAGE_UNIFORM_CONSTANT, OP_TYPE_SAMPLED_IMAGE)
                if get(ty.args[0]).is_ok_and(|image| image.args.get(1) == Some(&5)) =>
            {
                DescriptorKind::UniformTexelBuffer
            }
            (STORAGE_UNIFORM_CONSTANT, OP_TYPE_SAMPLED_IMAGE) => DescriptorKind::CombinedImageSampler,
            (STORAGE_UNIFORM_CONSTANT, OP_TYPE_SAMPLER) => DescriptorKind::Sampler,
            (STORAGE_UNIFORM_CONSTANT, OP_TYPE_IMAGE) if ty.args.get(1) == Some(&5) && ty.args.get(5) == Some(&1) => {
                DescriptorKind::UniformTexelBuffer
            }
            (STORAGE_UNIFORM_CONSTANT, OP_TYPE_IMAGE) if ty.args.get(1) != Some(&5) => match ty.args.get(5) {
                Some(1) => DescriptorKind::SampledImage,
                Some(2) => DescriptorKind::StorageImage,
                _ => return Err(format!("{}: image whose use (sampled or storage) is not known", var.name)),
            },
            _ => return Err(format!("{}: unsupported descriptor type (opcode {})", var.name, ty.opcode)),
        };
        let (Some(set), Some(binding)) = (var.set, var.binding) else {
            return Err(format!("{}: descriptor without a set and binding", var.name));
        };
        // glslang puts `readonly` of a buffer on each member of its block; other tools on the variable.
        let read_only = match kind {
            DescriptorKind::StorageBuffer => {
                var.non_writable || (!ty.members.is_empty() && ty.members.iter().all(|m| m.non_writable))
            }
            DescriptorKind::StorageImage => var.non_writable,
            // Uniform buffers, sampled images and samplers cannot be written.
            _ => true,
        };
        let name = if var.name.is_empty() { ty.name.clone() } else { var.name.clone() };
        bindings.push(DescriptorBinding { set, binding, kind, count, read_only, name });
    }
    bindings.sort_by_key(|b| (b.set, b.binding));
    if let Some(w) = bindings.windows(2).find(|w| (w[0].set, w[0].binding) == (w[1].set, w[1].binding)) {
        return Err(format!("set {} binding {} declared twice", w[0].set, w[0].binding));
    }
    Ok(Reflection { stage, bindings, push_constants })
}
