#version 460
// 63-bit Morton codes (21 bits per axis, interleaved x, y, z from bit 0) of the points quantised in
// the mesh bounds, kept as uvec2 (low, high) so no 64-bit integers are needed; and the identity
// permutation to sort along.
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { SurfacePoint points[]; };
layout(std430, binding = 1) writeonly buffer Keys { uvec2 keys[]; };
layout(std430, binding = 2) writeonly buffer Values { uint values[]; };
layout(push_constant) uniform MortonConstants { vec4 bounds_min; vec4 bounds_extent; uint point_count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    vec3 q = clamp((points[i].position - pc.bounds_min.xyz) / max(pc.bounds_extent.xyz, vec3(1e-30)), 0.0, 1.0);
    uvec3 cell = uvec3(q * 2097151.0);
    uvec2 key = uvec2(0u);
    for (uint bit = 0u; bit < 21u; ++bit) {
        for (uint axis = 0u; axis < 3u; ++axis) {
            uint value = (cell[axis] >> bit) & 1u;
            uint position = 3u * bit + axis;
            if (position < 32u) key.x |= value << position; else key.y |= value << (position - 32u);
        }
    }
    keys[i] = key;
    values[i] = i;
}
