#version 460
// The normal the light meets, interpolated from the mesh's vertex normals (the shading normal a
// path tracer refracts at), octahedron-encoded in 2×16-bit snorm: single scattering refracts
// the light there where it enters (shade.frag's light_entry); the depths' own differences gave
// the facets' normals.
#include "points.glsl"
layout(location = 0) in vec3 world_normal;
layout(location = 0) out uint encoded_normal;
void main() { encoded_normal = encode_oct(normalize(world_normal)); }
