#version 460
// Radix sort, step 2: exclusive prefix sum over the whole count table (digit-major, tiles minor),
// giving each (digit, tile) its first output slot. One work group; each thread scans a chunk.
#include "radix.glsl"
layout(local_size_x = 256) in;
layout(std430, binding = 0) buffer Counts { uint counts[]; };
shared uint chunk_sum[256];

void main() {
    uint tid = gl_LocalInvocationID.x;
    uint total = pc.tile_count * 256u;
    uint per_thread = (total + 255u) / 256u;
    uint begin = min(tid * per_thread, total);
    uint end = min(begin + per_thread, total);
    uint sum = 0u;
    for (uint k = begin; k < end; ++k) sum += counts[k];
    chunk_sum[tid] = sum;
    barrier();
    for (uint offset = 1u; offset < 256u; offset <<= 1) {
        uint v = tid >= offset ? chunk_sum[tid - offset] : 0u;
        barrier();
        chunk_sum[tid] += v;
        barrier();
    }
    uint running = tid == 0u ? 0u : chunk_sum[tid - 1u];
    for (uint k = begin; k < end; ++k) {
        uint c = counts[k];
        counts[k] = running;
        running += c;
    }
}
