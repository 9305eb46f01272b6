//! The Vulkan layer under the validation layer: it must be clean, and the checks that say so must
//! be able to fail.

mod common;

use common::{assert_clean, validated_context};
use std::sync::atomic::Ordering;

#[test]
fn context_is_clean_under_validation() {
    let (ctx, counts) = validated_context();
    assert!(ctx.validation);
    drop(ctx);
    assert_clean(&counts);
}

#[test]
fn deliberate_misuse_is_counted() {
    let (ctx, counts) = validated_context();
    ctx.debug_provoke_validation_error();
    drop(ctx);
    assert!(counts.errors.load(Ordering::SeqCst) > 0, "a zero-sized buffer must be reported by the layer");
}

#[test]
fn leaked_object_is_counted() {
    let (ctx, counts) = validated_context();
    ctx.debug_leak_object();
    drop(ctx);
    assert!(counts.total() > 0, "an undestroyed sampler must be reported when the device is destroyed");
}

#[test]
fn every_shader_makes_a_module() {
    let (ctx, counts) = validated_context();
    let names = translucent::vk::check_all_shaders(&ctx).expect("shader modules");
    for expected in ["shade.vert", "shade.frag"] {
        assert!(names.contains(&expected), "{expected} is not embedded");
    }
    drop(ctx);
    assert_clean(&counts);
}
