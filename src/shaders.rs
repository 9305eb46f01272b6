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
