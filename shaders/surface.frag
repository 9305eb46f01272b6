#version 460
// Every object's surface in the G-buffer: position (w = its id + 1), normal (w = the mean
// curvature, 1/scene unit), and its texture
// here (surface_texture.glsl): an opaque object's Lambertian reflectance, a translucent one's
// scatter weight (1 where it has no texture). Shading from these, not per triangle, keeps every
// SIMD group (llvmpipe) or warp of the shade pass full: the mesh's triangles are about a pixel
// in size, and a triangle's fragments are shaded together in blocks of 4x4 or quads, mostly empty.
#include "surface_constants.glsl"
#include "surface_texture.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in float curvature;
layout(location = 0) out vec4 position;
layout(location = 1) out vec4 normal;
layout(location = 2) out vec4 albedo;
layout(binding = 1) uniform sampler2D texture_map;

void main() {
    position = vec4(world_position, float(pc.object + 1u));
    normal = vec4(world_normal, curvature);
    albedo = vec4(surface_texture(pc.texture_kind, pc.tex1, pc.tex2, texture_map, uv), 1.0);
}
