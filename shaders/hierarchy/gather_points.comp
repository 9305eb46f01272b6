#version 460
// Puts the points, their merged light records and (for brute force) their per-light records in
// Morton order: sorted[i] = points[order[i]].
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Points { SurfacePoint points[]; };
layout(std430, binding = 1) readonly buffer Order { uint order[]; };
layout(std430, binding = 2) writeonly buffer Sorted { SurfacePoint sorted_points[]; };
layout(std430, binding = 3) readonly buffer PointLights { PointLight point_lights[]; };
layout(std430, binding = 4) writeonly buffer SortedPointLights { PointLight sorted_point_lights[]; };
layout(std430, binding = 5) readonly buffer PointFluxes { PointFlux point_flux[]; };
layout(std430, binding = 6) writeonly buffer SortedPointFluxes { PointFlux sorted_point_flux[]; };
layout(std430, binding = 7) readonly buffer PointSpreads { PointSpread point_spread[]; };
layout(std430, binding = 8) writeonly buffer SortedPointSpreads { PointSpread sorted_point_spread[]; };
// per_light_count: lights with their own records (0 unless brute force).
layout(push_constant) uniform GatherConstants { uint point_count; uint per_light_count; } pc;
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    uint from = order[i];
    sorted_points[i] = points[from];
    sorted_point_flux[i] = point_flux[from];
    sorted_point_spread[i] = point_spread[from];
    for (uint k = 0u; k < pc.per_light_count; ++k)
        sorted_point_lights[i * pc.per_light_count + k] = point_lights[from * pc.per_light_count + k];
}
