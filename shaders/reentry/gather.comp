#version 460
// Re-entry, stage 2: the light each patch receives from the others through the air, and enters
// by: E_k = Σ_j M_j A cos θk cos θj / (π r² + A) · Ft(cos θk), over the patches j that face it
// (both cosines above ~3°, as joined_inside's lean) and that it sees: the chord between them is
// outside the object at 1/4, 1/2 and 3/4 of the way (the inside grid, mesh::occupancy; chords
// shorter than two cells are taken as seen). M/π is the exitant radiance (Lambertian: the
// table's exit lobe is near it), and the disk's form factor (π r² + A) keeps neighbours
// bounded. A convex object has no pair facing each other: nothing. Also the
// luminance-weighted sum of the directions toward the sources (for the merged record).
#include "points.glsl"
#include "bssrdf.glsl"
#include "reentry.glsl"

layout(local_size_x = 64) in;

layout(binding = 0) uniform usamplerBuffer points;
layout(std430, binding = 1) readonly buffer Exitance { vec4 exitance[]; };
layout(binding = 2) uniform usamplerBuffer dipole_table;
// Per patch: (E rgb, 0), (Σ luminance(E) ω, 0).
layout(std430, binding = 3) writeonly buffer Reentry { vec4 reentry[]; };

const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);
const float FACING = 0.05;

// Whether the chord from a to b (scene units) is in the air at 1/4, 1/2 and 3/4 of the way: in
// cells whose centres are outside (the grid before it was grown: the grown one calls the air
// within a cell of the surface inside, and drew 0.24 of the Skin1 bunny's light that enters
// again in red where this draws 0.39).
bool through_air(Occupancy grid, vec3 a, vec3 b) {
    vec3 start = (a - grid.corner.xyz) / grid.cell, d = (b - a) / grid.cell;
    if (dot(d, d) < 4.0) return true;
    return !centre_occupied(dipole_table, OCCUPANCY_BASE, start + 0.5 * d)
        && !centre_occupied(dipole_table, OCCUPANCY_BASE, start + 0.25 * d)
        && !centre_occupied(dipole_table, OCCUPANCY_BASE, start + 0.75 * d);
}

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= pc.patch_count) return;
    Occupancy grid = occupancy_header(dipole_table, OCCUPANCY_BASE);
    uint index = patch_point(k);
    vec3 xk = texel_float(points, index * POINT_TEXELS).xyz;
    vec3 nk = texel_float(points, index * POINT_TEXELS + 1u).xyz;
    vec3 sum = vec3(0.0), toward = vec3(0.0);
    for (uint j = 0u; j < pc.patch_count && grid.corner.w != 0.0; ++j) {
        vec3 m = exitance[j].xyz;
        if (j == k || m == vec3(0.0)) continue;
        uint other = patch_point(j);
        vec3 d = texel_float(points, other * POINT_TEXELS).xyz - xk;
        float r2 = dot(d, d);
        if (!(r2 > 0.0)) continue;
        vec3 nj = texel_float(points, other * POINT_TEXELS + 1u).xyz;
        float inv_r = inversesqrt(r2);
        float cos_k = dot(nk, d) * inv_r, cos_j = -dot(nj, d) * inv_r;
        if (cos_k <= FACING || cos_j <= FACING) continue;
        if (!through_air(grid, xk, xk + d)) continue;
        vec3 e = m * (pc.patch_area * cos_k * cos_j / (3.14159265 * r2 + pc.patch_area))
               * fresnel_transmittance(pc.eta, cos_k);
        sum += e;
        toward += dot(e, LUMA) * (d * inv_r);
    }
    reentry[2u * k] = vec4(sum, 0.0);
    reentry[2u * k + 1u] = vec4(toward, 0.0);
}
