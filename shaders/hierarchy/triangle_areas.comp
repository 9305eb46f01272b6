#version 460
// Prefix sum of triangle areas in 64-bit fixed point, in one work group. The unit is total area /
// (N · 2^20), so that sample point i's stratum is exactly [i, i + 1) · 2^20 units: integer sums
// stay exact over any number of triangles, where an f32 running sum loses small triangles' areas
// once the sum is large (2^24 times a triangle's area: a few million triangles).
// prefix[0] = 0, prefix[t + 1] = units of triangles 0..t; total_area is the f32 area for A/N.
#include "fixed64.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Vertices { float vertex_data[]; }; // [px,py,pz,nx,ny,nz]
layout(std430, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 2) writeonly buffer AreaPrefix { float total_area; uint pad; uvec2 prefix[]; };
layout(push_constant) uniform AreaConstants { uint triangle_count; uint point_count; } pc;

shared float chunk_area[256];
shared uvec2 chunk_units[256];

vec3 position(uint v) { return vec3(vertex_data[6 * v], vertex_data[6 * v + 1], vertex_data[6 * v + 2]); }
float triangle_area(uint t) {
    vec3 a = position(indices[3 * t]), b = position(indices[3 * t + 1]), c = position(indices[3 * t + 2]);
    return 0.5 * length(cross(b - a, c - a));
}

void main() {
    uint tid = gl_LocalInvocationID.x;
    uint per_thread = (pc.triangle_count + 255u) / 256u;
    uint begin = min(tid * per_thread, pc.triangle_count);
    uint end = min(begin + per_thread, pc.triangle_count);

    // The total area in f32 (only the scale of the units depends on it): Kahan within a chunk,
    // pairwise across chunks, so its relative error stays near 1e-7 at any triangle count.
    float sum = 0.0, compensation = 0.0;
    for (uint t = begin; t < end; ++t) {
        float y = triangle_area(t) - compensation;
        float s = sum + y;
        compensation = (s - sum) - y;
        sum = s;
    }
    chunk_area[tid] = sum;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1) {
        if (tid < stride) chunk_area[tid] += chunk_area[tid + stride];
        barrier();
    }
    float total = chunk_area[0];
    float units_per_area = total > 0.0 ? float(pc.point_count) * 1048576.0 / total : 0.0;

    uvec2 units = uvec2(0u);
    for (uint t = begin; t < end; ++t) units = add64(units, fixed64(triangle_area(t) * units_per_area));
    chunk_units[tid] = units;
    barrier();
    for (uint offset = 1u; offset < 256u; offset <<= 1) {
        uvec2 v = tid >= offset ? chunk_units[tid - offset] : uvec2(0u);
        barrier();
        chunk_units[tid] = add64(chunk_units[tid], v);
        barrier();
    }
    uvec2 running = tid == 0u ? uvec2(0u) : chunk_units[tid - 1u];
    if (tid == 0u) {
        prefix[0] = uvec2(0u);
        total_area = total;
        pad = 0u;
    }
    for (uint t = begin; t < end; ++t) {
        running = add64(running, fixed64(triangle_area(t) * units_per_area));
        prefix[t + 1u] = running;
    }
}
