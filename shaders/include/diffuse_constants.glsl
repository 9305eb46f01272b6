// Push constants of the opaque (diffuse) objects' shading pass. Mirrored by `DiffuseConstants`
// in src/gpu/shade.rs; tests/layouts.rs compares the offsets.
#ifndef DIFFUSE_CONSTANTS_GLSL
#define DIFFUSE_CONSTANTS_GLSL
layout(push_constant, std430) uniform DiffuseConstants {
    uint first_opaque; // G-buffer ids (position w - 1) from here on are opaque objects
    uint pad0;
    uint pad1;
    uint pad2;
} pc;
#endif
