// Push constants of the background pass. Mirrored by `BackgroundConstants` in src/gpu/shade.rs;
// tests/layouts.rs compares the offsets.
#ifndef BACKGROUND_CONSTANTS_GLSL
#define BACKGROUND_CONSTANTS_GLSL
layout(push_constant, std430) uniform BackgroundConstants {
    // Pixel → direction in the map's frame: to_map · (right·tan·aspect, -up·tan, forward), as
    // columns, applied to (ndc x, ndc y, 1).
    vec4 ray_x;
    vec4 ray_y;
    vec4 ray_z;
    vec4 constant;   // rgb: a constant map's radiance; w: the scale
    uint kind;       // BACKGROUND_NONE, _CONSTANT, _LATLONG, _OCTAHEDRAL
    uint width;      // the map's texels
    uint height;
    uint pad;
} pc;
const uint BACKGROUND_NONE = 0u;
const uint BACKGROUND_CONSTANT = 1u;
const uint BACKGROUND_LATLONG = 2u;
const uint BACKGROUND_OCTAHEDRAL = 3u;
#endif
