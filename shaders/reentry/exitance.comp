#version 460
// Re-entry, stage 1: each patch's exitance M, the light that leaves the object there (W/m² per
// channel, all directions): the sources' sum as the shade pass makes it (sources.glsl, the Monte
// Carlo table's), walked from the root with a cut of its own, times ∫ Ft cos dω (the table's Sd
// is M / ∫ Ft cos dω, mc_profile.rs). The sources within a reach of a few point spacings are
// weighed down and the patch's own irradiance times the flat profile's integral over them
// stands in (the shade pass's near field, in closed form for a point with no tilt). No exit
// tilt: all directions at once. Flat: the patch's own curvature is not read (each pair still
// takes its own, source_curvature).
#include "points.glsl"
#include "shading_params.glsl"
#include "reentry.glsl"

layout(constant_id = 0) const uint MODEL = 0u;
layout(constant_id = 1) const bool ONE_LIGHT = false;

layout(local_size_x = 8) in;

layout(std140, binding = 0) uniform Object { ObjectParams object_params; };
layout(binding = 1) uniform usamplerBuffer nodes;
layout(binding = 2) uniform usamplerBuffer points;
layout(binding = 3) uniform usamplerBuffer node_flux;
layout(binding = 4) uniform usamplerBuffer point_flux;
layout(binding = 5) uniform usamplerBuffer point_spread;
layout(binding = 6) uniform usamplerBuffer dipole_table;
layout(std430, binding = 7) writeonly buffer Exitance { vec4 exitance[]; };

#include "sources.glsl"

uint next_after(uint last) {
    return walk_next_after(nodes, object_params.point_count, object_params.node_count, last);
}

void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k >= pc.patch_count) return;
    uint index = patch_point(k);
    vec3 xo = texel_float(points, index * POINT_TEXELS).xyz;
    vec3 no = texel_float(points, index * POINT_TEXELS + 1u).xyz;
    vec4 own = texel_float(points, index * POINT_TEXELS + 2u);
    vec3 own_weight = vec3(unpackHalf2x16(floatBitsToUint(own.w)), texel_float(points, index * POINT_TEXELS + 3u).w);
    begin_sources(vec4(no, 0.0));
    float reach = pc.near.w / object_params.mm_per_unit;
    vec3 sum = vec3(0.0);
    uint item = 0u; // the root
    uint steps = 0u;
    while (item != WALK_END && steps < MAX_CUT_STEPS) {
        ++steps;
        uint i = item & ~LEAF_BIT;
        if ((item & LEAF_BIT) != 0u) {
            vec3 xi, power;
            vec4 incident[3];
            float area;
            point_source(i, xi, power, incident, area);
            float w = smoothstep(0.5 * reach, reach, length(xi - xo));
            if (w > 0.0 && power != vec3(0.0)) {
                vec3 ni = texel_float(points, i * POINT_TEXELS + 1u).xyz;
                // Its light across the object is weighed alike (across() adds it apart).
                vec3 before = across_sum;
                uint made;
                sum += w * point_evaluated(i, xi, ni, power, incident, xo, no, xo, made);
                across_sum = before + w * (across_sum - before);
            }
            item = next_after(i);
            continue;
        }
        vec4 power_area = texel_float(nodes, i * NODE_TEXELS);
        uvec4 range = texel(nodes, i * NODE_TEXELS + 3u);
        uint after = next_after(range.z + range.w - 1u);
        if (power_area.xyz == vec3(0.0)) {
            item = after;
            continue;
        }
        uvec4 center_left = texel(nodes, i * NODE_TEXELS + 1u);
        vec3 lo, hi;
        unpack_box(texel(nodes, i * NODE_TEXELS + 2u).xyz, lo, hi);
        vec3 outside = max(max(lo - xo, xo - hi), vec3(0.0));
        vec3 to_center = uintBitsToFloat(center_left.xyz) - xo;
        // Whole where the reach misses its box (every point of it has w = 1) and it is small
        // enough from here.
        if (dot(outside, outside) >= reach * reach && power_area.w < pc.epsilon * dot(to_center, to_center)) {
            vec3 ni = decode_oct(range.x);
            vec3 center, offset, power;
            vec4 incident[3];
            float area;
            node_sigma(i, ni, xo, center, offset, power, incident, area);
            sum += merged_source(center + offset, ni, power, incident, vec3(0.0), xo, no,
                                 sigma_point_curvature(center + offset, ni, offset, xo, no), true)
                 + merged_source(center - offset, ni, power, incident, vec3(0.0), xo, no,
                                 sigma_point_curvature(center - offset, ni, -offset, xo, no), true);
            item = after;
        } else {
            item = center_left.w; // open it: its left child next
        }
    }
    vec3 near = own.xyz * pc.near.xyz;
    vec3 m = (sum + across_sum + near) * own_weight * pc.exit_integral;
    // Never negative or non-finite (a spent walk budget leaves the rest out, never adds).
    exitance[k] = vec4(mix(vec3(0.0), max(m, vec3(0.0)), equal(m, m)), 0.0);
}
