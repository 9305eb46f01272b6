#version 460
// Radix sort, step 3: each thread moves its tile's pairs, in order, to their slots (stable).
#include "radix.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer KeysIn { uvec2 keys_in[]; };
layout(std430, binding = 1) readonly buffer ValuesIn { uint values_in[]; };
layout(std430, binding = 2) writeonly buffer KeysOut { uvec2 keys_out[]; };
layout(std430, binding = 3) writeonly buffer ValuesOut { uint values_out[]; };
layout(std430, binding = 4) buffer Offsets { uint offsets[]; };

void main() {
    uint tile = gl_GlobalInvocationID.x;
    if (tile >= pc.tile_count) return;
    uint end = min((tile + 1u) * TILE, pc.count);
    for (uint i = tile * TILE; i < end; ++i) {
        uvec2 key = keys_in[i];
        uint slot = digit_of(key) * pc.tile_count + tile;
        uint destination = offsets[slot];
        offsets[slot] = destination + 1u;
        keys_out[destination] = key;
        values_out[destination] = values_in[i];
    }
}
