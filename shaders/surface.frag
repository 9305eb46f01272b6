#version 460
// The surface each pixel sees (a G-buffer): its world position (w = the object's index + 1 where
// an object covers the pixel, 0 elsewhere after the clear) and the interpolated normal, for the
// full-screen shade pass. Shading from these, not per triangle, keeps every SIMD group (llvmpipe) or warp of the
// shade pass full: the mesh's triangles are about a pixel in size, and a triangle's fragments
// are shaded together in blocks of 4x4 or quads, mostly empty.
#include "shade_constants.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 0) out vec4 position;
layout(location = 1) out vec4 normal;
// The reflectance of opaque objects (surface_diffuse.frag); none here.
layout(location = 2) out vec4 albedo;

void main() {
    position = vec4(world_position, float(pc.point_range.z + 1u));
    normal = vec4(world_normal, 0.0);
    albedo = vec4(0.0);
}
