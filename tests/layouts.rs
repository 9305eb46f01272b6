//! Structs shared between Rust and GLSL: the Rust mirror must have the offsets the SPIR-V declares.

use std::mem::{offset_of, size_of};

use translucent::passes::shade::ShadeConstants;
use translucent::shaders::member_offsets;

#[test]
fn shade_constants_match_glsl() {
    let glsl = member_offsets("shade.frag", "ShadeConstants").expect("ShadeConstants in shade.frag");
    let rust = vec![
        offset_of!(ShadeConstants, view_projection) as u32,
        offset_of!(ShadeConstants, light_toward) as u32,
        offset_of!(ShadeConstants, light_irradiance) as u32,
        offset_of!(ShadeConstants, eye) as u32,
        offset_of!(ShadeConstants, albedo) as u32,
    ];
    assert_eq!(glsl, rust);
    assert_eq!(size_of::<ShadeConstants>(), 128);
}
