#version 460
// Where the light meets the mesh: the normal interpolated from its vertex normals (the shading
// normal a path tracer refracts at), octahedron-encoded in 2×16-bit snorm, and the mesh's mean
// curvature (1/scene unit, as f32 bits). Single scattering refracts the light there where it
// enters (shade.frag's light_entry; the depths' own differences gave the facets' normals) and
// the beam focuses by the curvature there (lens_gain; the pixel's own stood for it before).
#include "points.glsl"
layout(location = 0) in vec3 world_normal;
layout(location = 1) in float curvature;
layout(location = 0) out uvec2 normal_curvature;
void main() { normal_curvature = uvec2(encode_oct(normalize(world_normal)), floatBitsToUint(curvature)); }
