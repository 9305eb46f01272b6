#version 460
// Prefix sum of triangle areas (prefix[0] = 0, prefix[t + 1] = area of triangles 0..t), in one
// work group: each thread sums a contiguous chunk, the chunk sums are scanned in shared memory.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Vertices { float vertex_data[]; }; // [px,py,pz,nx,ny,nz]
layout(std430, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 2) writeonly buffer Prefix { float prefix[]; };
layout(push_constant) uniform AreaConstants { uint triangle_count; } pc;

shared float chunk_sum[256];

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
    float sum = 0.0;
    for (uint t = begin; t < end; ++t) sum += triangle_area(t);
    chunk_sum[tid] = sum;
    barrier();
    for (uint offset = 1u; offset < 256u; offset <<= 1) {
        float v = tid >= offset ? chunk_sum[tid - offset] : 0.0;
        barrier();
        chunk_sum[tid] += v;
        barrier();
    }
    float running = tid == 0u ? 0.0 : chunk_sum[tid - 1u];
    if (tid == 0u) prefix[0] = 0.0;
    for (uint t = begin; t < end; ++t) {
        running += triangle_area(t);
        prefix[t + 1u] = running;
    }
}
