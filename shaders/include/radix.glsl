// Shared by the three radix-sort steps: an LSD sort of (uvec2 key, uint value) by 8-bit digits.
// Tiles are processed serially by one thread each, which keeps the sort stable and simple.
#ifndef RADIX_GLSL
#define RADIX_GLSL
#include "gpu_constants.glsl"
const uint TILE = RADIX_TILE;
layout(push_constant) uniform RadixConstants { uint count; uint tile_count; uint shift; } pc;
uint digit_of(uvec2 key) {
    return (pc.shift < 32u ? (key.x >> pc.shift) : (key.y >> (pc.shift - 32u))) & 255u;
}
#endif
