#version 460
// Puts the points in Morton order: sorted[i] = points[order[i]].
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { SurfacePoint points[]; };
layout(std430, binding = 1) readonly buffer Order { uint order[]; };
layout(std430, binding = 2) writeonly buffer Sorted { SurfacePoint sorted_points[]; };
layout(push_constant) uniform GatherConstants { uint point_count; } pc;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < pc.point_count) sorted_points[i] = points[order[i]];
}
