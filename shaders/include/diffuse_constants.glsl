// Push constants of the opaque (diffuse) objects' passes. Mirrored by `DiffuseSurfaceConstants`
// and `DiffuseConstants` in src/gpu/shade.rs; tests/layouts.rs compares the offsets.
#ifndef DIFFUSE_CONSTANTS_GLSL
#define DIFFUSE_CONSTANTS_GLSL
#ifdef DIFFUSE_SURFACE
layout(push_constant, std430) uniform DiffuseSurfaceConstants {
    mat4 view_projection;
    vec4 tex1;        // rgb: reflectance (the checkerboard's first); w: uscale
    vec4 tex2;        // rgb: the checkerboard's second reflectance; w: vscale
    uint object;      // the G-buffer's id of this object (position w = object + 1)
    uint checker;     // 1: a checkerboard over the mesh's uv, 2: the image, 0: tex1 everywhere
    uint pad0;
    uint pad1;
} pc;
#else
layout(push_constant, std430) uniform DiffuseConstants {
    uint first_opaque; // G-buffer ids (position w - 1) from here on are opaque objects
    uint pad0;
    uint pad1;
    uint pad2;
} pc;
#endif
#endif
