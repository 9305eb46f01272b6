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

#[test]
fn bssrdf_structs_match_glsl() {
    use translucent::passes::bssrdf_eval::BssrdfQueryGpu;
    use translucent::physics::GpuChannel;
    let channel = member_offsets("bssrdf_eval.comp", "BssrdfChannel").expect("BssrdfChannel");
    assert_eq!(channel, (0..16).map(|i| i * 4).collect::<Vec<u32>>());
    assert_eq!(size_of::<GpuChannel>(), 64);
    let query = member_offsets("bssrdf_eval.comp", "BssrdfQuery").expect("BssrdfQuery");
    let rust = vec![
        offset_of!(BssrdfQueryGpu, channel) as u32,
        offset_of!(BssrdfQueryGpu, xi) as u32,
        offset_of!(BssrdfQueryGpu, ni) as u32,
        offset_of!(BssrdfQueryGpu, wi) as u32,
        offset_of!(BssrdfQueryGpu, xo) as u32,
        offset_of!(BssrdfQueryGpu, no) as u32,
    ];
    assert_eq!(query, rust);
}
