#version 460
// Evaluates Sd for a list of queries (the `bssrdf --gpu` command and the GPU-vs-CPU tests).
#include "bssrdf.glsl"
#include "gpu_constants.glsl"

layout(local_size_x = 64) in;

// Mirrors BssrdfQueryGpu in src/gpu/passes.rs.
struct BssrdfQuery {
    BssrdfChannel channel;
    vec4 xi;
    vec4 ni;
    vec4 wi;
    vec4 xo;
    vec4 no;
    uvec4 table; // x: the row's Sd table in `tables` (photon beam diffusion; channel 0 holds it)
};

layout(std430, binding = 0) readonly buffer Queries { BssrdfQuery queries[]; };
layout(std430, binding = 1) writeonly buffer Results { float sd[]; };
// Photon beam diffusion's or the Monte Carlo table's Sd tables (gpu::SdTable), one per distinct medium, end to end; a
// placeholder for the other models.
layout(binding = 2) uniform usamplerBuffer tables;

layout(push_constant) uniform EvalConstants {
    uint count;
    uint model; // 0 directional dipole, 1 classical dipole, 2 photon beam diffusion, 3 Monte Carlo table,
                // EVAL_JOINED_INSIDE: joined_inside of the pair (1 or 0)
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    BssrdfQuery q = queries[i];
    float value;
    if (pc.model == EVAL_JOINED_INSIDE) {
        // `tables` holds one object's inside from texel 0 (mesh::occupancy).
        value = joined_inside(tables, 0, occupancy_header(tables, 0), q.xi.xyz, q.ni.xyz, q.xo.xyz, q.no.xyz) ? 1.0 : 0.0;
    } else if (pc.model == MODEL_DIRECTIONAL) {
        value = dirpole_sd(q.channel, q.xi.xyz, q.ni.xyz, q.wi.xyz, q.xo.xyz, q.no.xyz);
    } else if (pc.model == MODEL_PBD || pc.model == MODEL_MC) {
        // As the shade pass reads it.
        int base = int(q.table.x * DIPOLE_TABLE_SIZE);
        value = sd_table_at(tables, base, sd_table_header_at(tables, base), length(q.xo.xyz - q.xi.xyz)).x;
    } else {
        value = dipole_sd(q.channel, length(q.xo.xyz - q.xi.xyz));
    }
    sd[i] = value;
}
