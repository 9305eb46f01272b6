#version 460
// The far field of each 8x8 list tile: the sum of the tile's far sources (tile_cut.comp lists
// them after the ones each pixel evaluates) at sixteen of its pixels (include/far_field.glsl), which
// the shade pass interpolates at each of the 64. The far sources of pbrt-v2's sphere at 1024² are
// most of each pixel's list (BENCHMARKS.md, "The far field per tile"), so the tile pays 16
// evaluations of them where its pixels paid 64. The sums are the shade pass's own (sources.glsl),
// before the exit's Fresnel factor and scatter weight, which the shade pass applies per pixel.
// One invocation per (tile, sample): the sixteen of a tile walk the same list in step.
#include "points.glsl"
#include "shading_params.glsl"
#include "tile_lists.glsl"
#include "far_field.glsl"

// As in shade.frag: the model and whether there is one light, fixed per pipeline.
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
layout(binding = 7, rgba32f) uniform readonly image2D surface_position;
layout(binding = 8, rgba32f) uniform readonly image2D surface_normal;
// Per tile (tile_cut.comp): first far entry, far points, far nodes, 1 (0: no far field).
layout(binding = 9) uniform usamplerBuffer far_headers;
layout(binding = 10) uniform usamplerBuffer tile_entries;
// Per tile, its sixteen sums (rgb; w unused), sample k at offsets FAR_NODES[k % 4], FAR_NODES[k / 4].
layout(std430, binding = 11) writeonly buffer FarField { vec4 far_field[]; };
layout(push_constant) uniform FarFieldConstants {
    uvec2 tiles;  // 8x8 tiles across and down
    uint object;  // the object whose pixels and tree these are
    uint pad;
    vec4 eye;     // the camera's position (xyz): the exit's tilt toward it
} pc;

#include "sources.glsl"

uint tile_entry(uint i) { return texel(tile_entries, i >> 2)[i & 3u]; }

void main() {
    uint tile_x = gl_GlobalInvocationID.x / FAR_FIELD_SAMPLES;
    uint sample_index = gl_GlobalInvocationID.x % FAR_FIELD_SAMPLES;
    uint tile_y = gl_GlobalInvocationID.y;
    if (tile_x >= pc.tiles.x || tile_y >= pc.tiles.y) return;
    uint tile = tile_y * pc.tiles.x + tile_x;
    uvec4 header = texel(far_headers, tile);
    vec3 sum = vec3(0.0);
    if (header.w != 0u) {
        ivec2 origin = ivec2(tile_x, tile_y) * int(FAR_FIELD_TILE);
        ivec2 pixel = origin + ivec2(FAR_NODES[sample_index % 4u], FAR_NODES[sample_index / 4u]);
        vec3 xo = imageLoad(surface_position, pixel).xyz;
        vec4 normal_curvature = imageLoad(surface_normal, pixel);
        vec3 no = normalize(normal_curvature.xyz);
        // Whether a point's lights spread enough to show is decided once for the tile (at its
        // centre), so that the sixteen sums are of one function.
        vec3 centre = imageLoad(surface_position, origin + ivec2(int(FAR_FIELD_TILE) / 2)).xyz;
        begin_sources(normal_curvature);
        begin_thickness(xo, no);
        if (MODEL == MODEL_MC) {
            vec3 wo = normalize(pc.eye.xyz - xo);
            exit_along = wo - dot(wo, no) * no;
            exit_normal = no;
        }
        uint entry = header.x;
        for (uint e = 0u; e < header.y; ++e) {
            uint index = tile_entry(entry + e);
            vec3 xi, power;
            vec4 incident[3];
            float area;
            point_source(index, xi, power, incident, area);
            vec3 ni = texel_float(points, index * POINT_TEXELS + 1u).xyz;
            uint made;
            sum += point_evaluated(index, xi, ni, power, incident, xo, no, centre, made);
        }
        entry += header.y;
        for (uint e = 0u; e < header.z; ++e) {
            uint index = tile_entry(entry + e);
            vec3 ni = decode_oct(texel(nodes, index * NODE_TEXELS + 3u).x);
            vec3 center, offset, power;
            vec4 incident[3];
            float area;
            node_sigma(index, ni, xo, center, offset, power, incident, area);
            sum += merged_source(center + offset, ni, power, incident, vec3(0.0), xo, no,
                                 sigma_point_curvature(center + offset, ni, offset, xo, no), true)
                 + merged_source(center - offset, ni, power, incident, vec3(0.0), xo, no,
                                 sigma_point_curvature(center - offset, ni, -offset, xo, no), true);
        }
    }
    // w: the luminance of the part from beyond a chord R√2 (far_light, the exit's rows).
    far_field[tile * FAR_FIELD_SAMPLES + sample_index] = vec4(sum, far_light.x);
}
