#version 460
// Radix sort, step 1 of 3 per 8-bit digit: each thread counts the digits of one tile of 256 keys
// into column `tile` of the digit-major count table counts[digit * tiles + tile].
#include "radix.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Keys { uvec2 keys[]; };
layout(std430, binding = 1) buffer Counts { uint counts[]; };

void main() {
    uint tile = gl_GlobalInvocationID.x;
    if (tile >= pc.tile_count) return;
    for (uint d = 0u; d < 256u; ++d) counts[d * pc.tile_count + tile] = 0u;
    uint end = min((tile + 1u) * TILE, pc.count);
    for (uint i = tile * TILE; i < end; ++i) counts[digit_of(keys[i]) * pc.tile_count + tile] += 1u;
}
