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
};

layout(std430, binding = 0) readonly buffer Queries { BssrdfQuery queries[]; };
layout(std430, binding = 1) writeonly buffer Results { float sd[]; };

layout(push_constant) uniform EvalConstants {
    uint count;
    uint model; // 0 directional dipole, 1 classical dipole
} pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    BssrdfQuery q = queries[i];
    float value;
    if (pc.model == MODEL_DIRECTIONAL) {
        value = dirpole_sd(q.channel, q.xi.xyz, q.ni.xyz, q.wi.xyz, q.xo.xyz, q.no.xyz);
    } else {
        value = dipole_sd(q.channel, length(q.xo.xyz - q.xi.xyz));
    }
    sd[i] = value;
}
