// Push constants of the shade pass. Mirrored by `ShadeConstants` in src/gpu/shade.rs; a test
// compares the member offsets in the SPIR-V with the Rust struct.
#ifndef SHADE_CONSTANTS_GLSL
#define SHADE_CONSTANTS_GLSL
layout(push_constant, std430) uniform ShadeConstants {
    mat4 view_projection;
    vec4 eye;              // xyz: camera position
    uvec4 point_range;     // brute force: first point and count of this draw (draws add up);
                           // z: the object drawn (surface pass) or shaded (shade pass);
                           // w: pixels per side of its tile lists' tiles (shade pass)
} pc;
#endif
