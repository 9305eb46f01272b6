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
