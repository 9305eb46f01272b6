#version 460
// For tests/bssrdf_gpu.rs only: the slab's lit face over the half-space's as the shade pass reads
// it (bssrdf.glsl: `slab_reflected_rows`, `slab_reflected_ratio`), against its Rust mirror
// (physics::slab_profile::SlabChannel::reflected_ratio).
#include "gpu_constants.glsl"
#include "bssrdf.glsl"

layout(local_size_x = 64) in;

// Per query: ρ and t (mm).
layout(std430, binding = 0) readonly buffer Queries { vec2 queries[]; };
// Per query: the ratio per channel (rgb) and whether a sheet was read (w: 1, 0 none).
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };
// An object's table (its light across from SLAB_BASE).
layout(binding = 2) uniform usamplerBuffer table;
layout(push_constant) uniform Constants { uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec2 q = queries[i];
    vec4 rows = slab_reflected_rows(slab_header_of(table), q.y);
    results[i] = vec4(slab_reflected_ratio(table, rows, q.x), rows.w);
}
