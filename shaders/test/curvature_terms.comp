#version 460
// For tests/bssrdf_gpu.rs only: the Monte Carlo table's curvature terms as the shade pass reads
// them (bssrdf.glsl: `curvature_ratio`, `curvature_exit`, `exit_terms`), against their Rust
// mirrors (gpu::sd_table::CurvatureRatios::lookup, lookup_exit, exit_tilt_at, harmonics_at,
// radial_at).
#include "gpu_constants.glsl"
#include "bssrdf.glsl"

layout(local_size_x = 64) in;

// Per query two: the chord r (mm), the pair's curvature κ (1/mm), the exit cosine and the far
// light's share; sin²θi of the light per channel (rgb) and the exit's mean sin²θi (w).
layout(std430, binding = 0) readonly buffer Queries { vec4 queries[]; };
// Per query seven: the ratio, the exit's ratio, the tilt's c and g, the harmonics b₂ and b₃, the
// radial change a (rgb).
layout(std430, binding = 1) writeonly buffer Results { vec4 results[]; };
// An object's table (its curvature rows from CURVATURE_BASE).
layout(binding = 2) uniform usamplerBuffer table;
layout(push_constant) uniform Constants { uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec4 q = queries[2u * i];
    vec3 sin2_i = queries[2u * i + 1u].xyz;
    float exit_sin2 = queries[2u * i + 1u].w;
    vec4 rows = curvature_rows(table, q.y);
    vec3 c, g, b2, b3, a;
    exit_terms(table, rows.w, q.x, true, c, g, b2, b3, a);
    results[7u * i] = vec4(curvature_ratio(table, rows, q.x, sin2_i), 0.0);
    results[7u * i + 1u] = vec4(curvature_exit(table, rows, q.z, q.w, exit_sin2), 0.0);
    results[7u * i + 2u] = vec4(c, 0.0);
    results[7u * i + 3u] = vec4(g, 0.0);
    results[7u * i + 4u] = vec4(b2, 0.0);
    results[7u * i + 5u] = vec4(b3, 0.0);
    results[7u * i + 6u] = vec4(a, 0.0);
}
