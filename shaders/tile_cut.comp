#version 460
// The cut per screen tile (list_tile² pixels, 4 or 8: passes/tile_cut.rs): the sources that are far and small enough for
// every pixel of the tile, found once, so that the shade pass's lanes for the tile (a SIMD group
// on llvmpipe, a warp on a GPU) evaluate the same list in step instead of each walking the tree.
// One invocation per tile: the tile's surface positions bound a box T; walking from the root, a
// node is used whole for the whole tile when it is whole for every point of T (its box misses T
// and area < epsilon · distance² from its centre to T), so each pixel's sum is its own cut or a
// finer one, never coarser; a node that some pixel must open is opened for all of them, down to
// points (leaves), evaluated singly. Every pixel thus evaluates the same list in step: handing
// the nodes near the tile to each pixel's own walk instead (a private stack per lane, divergent)
// made that walk three quarters of the default frame's shade pass, where the finer common list
// costs 22% more evaluations (BENCHMARKS.md, "A clean frame"). The walk runs twice: once to count, then, after
// one atomic allocation in the list buffer, to write; a tile whose list does not fit is marked
// for a walk from the root per pixel (the host then grows the buffer for the next try).
// An 8x8 tile whose pixels lie on one smooth patch, small against the shortest diffusion length,
// also splits off its far sources (far_field_start()): listed after the others, summed by
// far_field.comp at sixteen of its pixels and interpolated by the shade pass.
#include "points.glsl"
#include "shading_params.glsl"
#include "tile_lists.glsl"
#include "far_field.glsl"
#define LIGHTS_BINDING 8
#define SHADOW_MAP_BINDING 9
#include "lights.glsl"
// One SIMD group of llvmpipe per work group; a row of tiles per dispatch row.
layout(local_size_x = 8) in;

layout(std140, binding = 0) uniform Object { ObjectParams object_params; };
layout(binding = 1) uniform usamplerBuffer nodes;
layout(binding = 2) uniform usamplerBuffer points;
layout(binding = 3, rgba32f) uniform readonly image2D surface_position;
layout(std430, binding = 4) writeonly buffer Headers { uvec4 headers[]; };
layout(std430, binding = 5) writeonly buffer Entries { uint entries[]; };
layout(std430, binding = 6) buffer Allocation { uint allocated; } allocation;
layout(std140, binding = 7) uniform Frame { FrameParams frame_params; };
layout(binding = 10, rgba32f) uniform readonly image2D surface_normal;
// Per tile, its far sources for far_field.comp: (first entry, points, nodes, 1), or 0 where the
// tile has no far field (every source in the shade pass's per-pixel list).
layout(std430, binding = 11) writeonly buffer FarHeaders { uvec4 far_headers[]; };
layout(push_constant) uniform TileCutConstants {
    uvec2 tiles;      // tiles across and down
    uvec2 pixels;     // image width and height
    uint capacity;    // entries the list buffer holds
    uint object;      // the object whose pixels and tree these lists are of
    uint list_tile;   // pixels per side of a tile
    uint model;       // the shade pass's model (MODEL_DIRECTIONAL...): whether the normal enters Sd
} pc;

const uint END = WALK_END;

// The squared distance from p to the box [lo, hi] (0 inside).
float distance2_to_box(vec3 p, vec3 lo, vec3 hi) {
    vec3 d = max(max(lo - p, p - hi), vec3(0.0));
    return dot(d, d);
}

// The squared distance between the boxes [lo, hi] and [a, b] (0 where they overlap).
float box_distance2(vec3 lo, vec3 hi, vec3 a, vec3 b) {
    vec3 d = max(max(lo - b, a - hi), vec3(0.0));
    return dot(d, d);
}

// The subtree after the one whose last point is `last` (points.glsl).
uint next_after(uint last) {
    return walk_next_after(nodes, object_params.point_count, object_params.node_count, last);
}

// Counts (write = false) or writes (write = true, at `first`) the tile's list; returns the counts
// of the points and nodes each pixel evaluates (x, y), of the far points (z) and of the points
// within the near field's reach of the tile (w, part of x); `far_nodes`: the far nodes. The
// entries are, from `first`: the points within reach (only they need the control variate,
// shade.frag), the other points, the nodes, then the far points and the far nodes (far_field.comp
// sums those at nine pixels for the whole tile). `near`: whether the list is for the near field
// (some pixel of the tile lit); `far2`: the squared distance from the tile's box (scene units)
// from which a source is far (3.4e38 where the tile has no far field).
uvec4 walk(vec3 tile_lo, vec3 tile_hi, bool near, float far2, bool write, uint first, uvec4 counts,
           out uint far_nodes) {
    uvec4 n = uvec4(0u);
    far_nodes = 0u;
    uint far_first = first + counts.x + counts.y;
    float near_end = object_params.near_end_mm / object_params.mm_per_unit;
    float near_end2 = near_end * near_end;
    uint item = 0u; // the root
    uint steps = 0u;
    while (item != END) {
        ++steps;
        uint index = item & ~LEAF_BIT;
        if ((item & LEAF_BIT) != 0u) {
            float d2 = distance2_to_box(texel_float(points, index * POINT_TEXELS).xyz, tile_lo, tile_hi);
            bool reachable = near && d2 < near_end2;
            if (texel_float(points, index * POINT_TEXELS + 2u).xyz != vec3(0.0) || reachable) {
                if (d2 >= far2) {
                    // Lit (an unlit point is listed only within reach, never far).
                    if (write) entries[far_first + n.z] = index;
                    ++n.z;
                } else {
                    // Within reach: at [0, counts.w); beyond it: after them.
                    if (write) entries[first + (reachable ? n.w : counts.w + n.x - n.w)] = index;
                    ++n.x;
                    if (reachable) ++n.w;
                }
            }
            item = next_after(index);
            continue;
        }
        vec4 power_area = texel_float(nodes, index * NODE_TEXELS);
        uvec4 range = texel(nodes, index * NODE_TEXELS + 3u);
        uint after = next_after(range.z + range.w - 1u);
        uvec4 center_left = texel(nodes, index * NODE_TEXELS + 1u);
        uvec4 box_right = texel(nodes, index * NODE_TEXELS + 2u);
        vec3 lo, hi;
        unpack_box(box_right.xyz, lo, hi);
        float box_d2 = box_distance2(lo, hi, tile_lo, tile_hi);
        // Unlit nodes matter only to the near field's control variate (shade.frag), within its
        // reach of the tile.
        if (power_area.xyz == vec3(0.0) && !(near && box_d2 < near_end2)) {
            item = after;
            continue;
        }
        bool overlaps = all(lessThanEqual(lo, tile_hi)) && all(lessThanEqual(tile_lo, hi));
        float d2 = distance2_to_box(uintBitsToFloat(center_left.xyz), tile_lo, tile_hi);
        // A node within the near field's reach of the tile is opened down to its points: only
        // points enter the control variate (shade.frag, near_correction()).
        bool within_reach = near && box_d2 < near_end2;
        bool whole = !overlaps && !within_reach && power_area.w < frame_params.epsilon * d2;
        // Budgets: the list's evaluations against llvmpipe's loop budget (the shade pass loops
        // over them), and this walk's steps; past them a node is used whole, as the pixel walk
        // does.
        uint evaluations = n.x + 2u * n.y + n.z + 2u * far_nodes;
        bool must_stop = steps > MAX_CUT_STEPS || evaluations > MAX_LIST_EVALUATIONS;
        if (whole || must_stop) {
            if (box_d2 >= far2) {
                if (write) entries[far_first + counts.z + far_nodes] = index;
                ++far_nodes;
            } else {
                if (write) entries[first + counts.x + n.y] = index;
                ++n.y;
            }
            item = after;
        } else {
            item = center_left.w; // open it: its left child next
        }
    }
    return n;
}

// The far field's bound on the error of interpolating a source's Sd across the tile
// (far_field.glsl, cubic on each axis), K = (σ + 4.4/d)·h, h the tile's largest side and d the
// source's distance from it (mm): Sd falls as e^(−σr)/r^3 at most, whose fourth derivative is
// at most (σ + 4.4/r)^4 times it, and the interpolation's error is at most
// |u(u − 2)(u − 5)(u − 7)|/24 ≤ 1.15 px⁴ times that per axis, pixels h/7 apart: 9.6e-4 K⁴ of the
// source's contribution for two axes, 0.1% at K = 1.
const float FAR_FIELD_K = 1.0;
// How far the tile's pixels may lie from the surface the sixteen interpolate (their positions
// and, for the directional dipole, normals, interpolated as the sums are: a mesh's creases
// inside a tile leave them off it): Sd's relative change over a distance δ is at most
// (σ + 3/d)·δ; the directional dipole's over a turn of the normal by ε (radians) of the order of
// ε. The other models' Sd is radial: the normal does not enter.
const float FAR_FIELD_POSITION_TOLERANCE = 5e-3;
const float FAR_FIELD_NORMAL_TOLERANCE = 2e-2;

// Where the tile's far field begins (mm from the tile's box), or 0 where the tile has none: it
// needs all its pixels on this object, a box small against the shortest diffusion length
// (σh < K/2), and positions and normals that the sixteen pixels interpolate within the
// tolerances (no silhouette or fold inside the tile). `lit`: the tile's list is for the near
// field, whose sources within reach each pixel evaluates with its control variate (so the far
// field begins beyond the reach).
float far_field_start(ivec2 origin, vec3 lo, vec3 hi, bool lit) {
    float s = object_params.mm_per_unit;
    float h = max(max(hi.x - lo.x, hi.y - lo.y), hi.z - lo.z) * s;
    float sigma = max(max(object_params.channels[0].sigma_tr, object_params.channels[1].sigma_tr),
                      object_params.channels[2].sigma_tr);
    if (!(sigma * h < 0.5 * FAR_FIELD_K)) return 0.0;
    float start = max(4.4 * h / (FAR_FIELD_K - sigma * h), lit ? object_params.near_end_mm : 0.0);
    // The normal is checked only where it enters Sd (a uniform branch: no lane pays for it
    // otherwise).
    bool normal_enters = pc.model == MODEL_DIRECTIONAL;
    vec3 x[FAR_FIELD_SAMPLES];
    vec3 n[FAR_FIELD_SAMPLES];
    for (uint k = 0u; k < FAR_FIELD_SAMPLES; ++k) {
        ivec2 p = origin + ivec2(FAR_NODES[k % 4u], FAR_NODES[k / 4u]);
        x[k] = imageLoad(surface_position, p).xyz;
        n[k] = normal_enters ? normalize(imageLoad(surface_normal, p).xyz) : vec3(0.0);
    }
    float position_error = 0.0, normal_error = 0.0;
    for (int v = 0; v < int(FAR_FIELD_TILE); ++v) {
        vec4 wv = far_weights(float(v));
        for (int u = 0; u < int(FAR_FIELD_TILE); ++u) {
            vec4 wu = far_weights(float(u));
            ivec2 p = origin + ivec2(u, v);
            vec3 xq = vec3(0.0);
            for (uint k = 0u; k < FAR_FIELD_SAMPLES; ++k) xq += (wu[k % 4u] * wv[k / 4u]) * x[k];
            position_error = max(position_error, length(imageLoad(surface_position, p).xyz - xq));
            if (normal_enters) {
                vec3 nq = vec3(0.0);
                for (uint k = 0u; k < FAR_FIELD_SAMPLES; ++k) nq += (wu[k % 4u] * wv[k / 4u]) * n[k];
                normal_error = max(normal_error, length(normalize(imageLoad(surface_normal, p).xyz) - nq));
            }
        }
    }
    if (!((sigma + 3.0 / start) * position_error * s <= FAR_FIELD_POSITION_TOLERANCE)) return 0.0;
    if (!(normal_error <= FAR_FIELD_NORMAL_TOLERANCE)) return 0.0;
    return start;
}

void main() {
    uvec2 tile_xy = gl_GlobalInvocationID.xy;
    if (tile_xy.x >= pc.tiles.x || tile_xy.y >= pc.tiles.y) return;
    uint tile = tile_xy.y * pc.tiles.x + tile_xy.x;
    int size = int(pc.list_tile);
    ivec2 origin = ivec2(tile_xy) * size;
    vec3 lo = vec3(3.4e38), hi = vec3(-3.4e38);
    uint covered = 0u;
    // Whether any pixel of the tile is lit, as the shade pass finds its own irradiance
    // (own_light(), light_irradiance()): only a lit pixel runs the near field's control variate,
    // so a tile with none needs neither the points within reach opened nor the unlit ones listed.
    // Most of a back-lit object is such (the default frame: shade pass 1.75x faster with them
    // left out). The shade pass reads the flag from the header, so the two cannot disagree.
    bool lit = false;
    bool near_field = frame_params.near_field != 0u;
    for (int y = 0; y < size; ++y) {
        for (int x = 0; x < size; ++x) {
            ivec2 p = origin + ivec2(x, y);
            if (p.x >= int(pc.pixels.x) || p.y >= int(pc.pixels.y)) continue;
            vec4 s = imageLoad(surface_position, p);
            if (s.w != float(pc.object + 1u)) continue;
            lo = min(lo, s.xyz);
            hi = max(hi, s.xyz);
            ++covered;
            if (near_field && !lit) {
                vec3 n = normalize(imageLoad(surface_normal, p).xyz);
                for (uint k = 0u; k < light_set.light_count && !lit; ++k) {
                    vec3 toward;
                    lit = light_irradiance(light_of(k), s.xyz, n, toward) != vec3(0.0);
                }
            }
        }
    }
    far_headers[tile] = uvec4(0u);
    if (covered == 0u || object_params.node_count == 0u) {
        headers[tile] = uvec4(0u);
        return;
    }
    float far_start = 0.0;
    if (frame_params.far_field != 0u && size == int(FAR_FIELD_TILE) && covered == FAR_FIELD_TILE * FAR_FIELD_TILE) {
        far_start = far_field_start(origin, lo, hi, lit) / object_params.mm_per_unit;
    }
    float far2 = far_start > 0.0 ? far_start * far_start : 3.4e38;
    uint far_nodes;
    uvec4 counts = walk(lo, hi, lit, far2, false, 0u, uvec4(0u), far_nodes);
    uint total = counts.x + counts.y + counts.z + far_nodes;
    // The header packs the point count with the near points' (16 bits each): the lists'
    // evaluation budget keeps both far below 2^16.
    if (counts.x >= 65536u) {
        headers[tile] = uvec4(0u, 0u, 0u, WALK_FROM_ROOT);
        return;
    }
    uint first = atomicAdd(allocation.allocated, total);
    if (first + total > pc.capacity || first + total < first) {
        headers[tile] = uvec4(0u, 0u, 0u, WALK_FROM_ROOT);
        return;
    }
    walk(lo, hi, lit, far2, true, first, counts, far_nodes);
    headers[tile] = uvec4(first, counts.x | (counts.w << 16), counts.y, lit ? NEAR_FIELD_TILE : 0u);
    if (far_start > 0.0) far_headers[tile] = uvec4(first + counts.x + counts.y, counts.z, far_nodes, 1u);
}
