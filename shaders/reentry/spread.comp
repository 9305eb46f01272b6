#version 460
// Re-entry, stage 3: each sorted point takes the light its patch and the two patches beside it
// on the Morton curve received (weighed by how alike their normals are and how near they are, so
// that an ear's two sides, neighbours on the curve, do not trade light), times the table's
// incidence factor at its mean direction and the point's scatter weight, and adds it to its
// irradiance and merged record (a light from that direction): the tree's summaries are then
// made again from them (passes/reentry.rs).
#include "points.glsl"
#include "bssrdf.glsl"
#include "reentry.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) buffer Sorted { SurfacePoint points[]; };
layout(std430, binding = 1) buffer SortedPointFluxes { PointFlux point_flux[]; };
layout(std430, binding = 2) readonly buffer Reentry { vec4 reentry[]; };
layout(binding = 3) uniform usamplerBuffer dipole_table;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count || pc.patch_count == 0u) return;
    vec3 x = points[i].position, n = points[i].normal;
    uint own = min(i / pc.stride, pc.patch_count - 1u);
    vec3 e = vec3(0.0), toward = vec3(0.0);
    float weights = 0.0;
    for (int o = -1; o <= 1; ++o) {
        int p = int(own) + o;
        if (p < 0 || p >= int(pc.patch_count)) continue;
        uint at = patch_point(uint(p));
        // Only position and normal, which no invocation writes.
        float alike = max(dot(n, points[at].normal), 0.0);
        vec3 d = points[at].position - x;
        float w = alike * alike / (1.0 + dot(d, d) / (pc.patch_spacing * pc.patch_spacing));
        e += w * reentry[2u * uint(p)].xyz;
        toward += w * reentry[2u * uint(p) + 1u].xyz;
        weights += w;
    }
    if (!(weights > 0.0)) return;
    e /= weights;
    if (!(e.x + e.y + e.z > 0.0)) return;
    vec3 wi = dot(toward, toward) > 0.0 ? normalize(toward) : n;
    float cos_i = max(dot(wi, n), 0.0);
    float cos_t = sqrt(max(1.0 - (1.0 - cos_i * cos_i) / (pc.eta * pc.eta), 0.0));
    e *= table_incidence_factor(dipole_table, cos_t) * scatter_weight_of(points[i]);
    points[i].irradiance += e;
    for (uint c = 0u; c < 3u; ++c) point_flux[i].incident[c] += e[c] * vec4(wi, cos_t);
}
