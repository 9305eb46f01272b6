// Push constants of the surface pass (surface.vert, surface.frag): one object's draw into the
// G-buffer. Mirrored by `SurfaceConstants` in src/gpu/shade.rs; tests/layouts.rs compares the
// offsets.
#ifndef SURFACE_CONSTANTS_GLSL
#define SURFACE_CONSTANTS_GLSL
layout(push_constant, std430) uniform SurfaceConstants {
    mat4 view_projection;
    vec4 tex1;          // rgb: the texture's value (the checkerboard's first); w: uscale
    vec4 tex2;          // rgb: the checkerboard's second value; w: vscale
    uint object;        // the G-buffer's id of this object (position w = object + 1)
    uint texture_kind;  // surface_texture.glsl's TEXTURE_*
    uint pad0;
    uint pad1;
} pc;
#endif
