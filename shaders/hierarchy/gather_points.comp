#version 460
// Puts the points and their per-light records in Morton order: sorted[i] = points[order[i]].
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { SurfacePoint points[]; };
layout(std430, binding = 1) readonly buffer Order { uint order[]; };
layout(std430, binding = 2) writeonly buffer Sorted { SurfacePoint sorted_points[]; };
layout(std430, binding = 3) readonly buffer PointLights { PointLight point_lights[]; };
layout(std430, binding = 4) writeonly buffer SortedPointLights { PointLight sorted_point_lights[]; };
layout(push_constant) uniform GatherConstants { uint point_count; uint light_count; } pc;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    uint from = order[i];
    sorted_points[i] = points[from];
    for (uint k = 0u; k < pc.light_count; ++k)
        sorted_point_lights[i * pc.light_count + k] = point_lights[from * pc.light_count + k];
}
