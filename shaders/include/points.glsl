// Surface samples and the Jensen–Buhler tree nodes. Mirrored by SurfacePoint and TreeNode in
// src/gpu/points.rs; a test compares the SPIR-V member offsets with the Rust structs.
#ifndef POINTS_GLSL
#define POINTS_GLSL
#include "gpu_constants.glsl"

// One irradiance sample on the surface (64 bytes).
struct SurfacePoint {
    vec3 position;
    float area;        // total area / N
    vec3 normal;
    uint triangle;     // the triangle it was sampled on
    vec3 irradiance;   // W/m² per RGB entering the surface: I cos Ft(eta) visibility, summed over
                       // lights, times the scatter weight
    uint scatter_weight_rg; // the object's texture here (1 without one: gpu_world::SurfaceTexture),
                       // r and g as two f16; the irradiance pass weighs what enters by it
    vec3 light_dir;    // irradiance-weighted mean direction toward the lights (unit, or 0 if unlit;
                       // for views and tools: shading uses PointFlux)
    float scatter_weight_b;
};
vec3 scatter_weight_of(SurfacePoint p) { return vec3(unpackHalf2x16(p.scatter_weight_rg), p.scatter_weight_b); }

// What one light brings to one point (16 bytes), at [point · light_count + light]: kept only for
// brute force, the exact sum over lights that the merged records below are measured against.
struct PointLight {
    vec3 irradiance;   // entering the surface from this light (0 where it does not reach)
    uint toward_oct;   // unit direction toward this light, octahedral 2×16-bit snorm
};

// What every light together brings to one point (48 bytes), one record whatever the number of
// lights: per channel c, incident[c].xyz = Σ_k E_k,c ωi,k (the irradiance-weighted sum of the
// directions toward the lights, world space) and incident[c].w = Σ_k E_k,c cos θt,k (of the
// refracted directions' cosines to the normal); E_c = Σ_k E_k,c is the point's irradiance.
// Refraction at a normal n is linear in ωi along the surface, ω12 = -(ωi - (ωi·n)n)/η - n cos θt,
// so these give Σ_k E_k,c ω12,k exactly at the point's own normal (and, for a node, the same
// lights refracted at the node's normal). The directional dipole's source S'(x, ω12, r) is
// affine in ω12 for fixed x and r, and its virtual source is linear in ω12, so
// E_c · S'(x, Σ E ω12 / E_c, r) is the exact sum over lights except through the real source's
// distance dr (which depends on ω12) and the clamp at 0.
struct PointFlux {
    vec4 incident[3];
};

// How the lights' refracted directions spread about their mean at one point (32 bytes): two
// sigma axes a_j = sqrt(2 λ_j) e_j of the luminance-weighted covariance of ω12 (its two largest
// eigenvalues λ_j, eigenvectors e_j), zero for one light. A point evaluated on its own (the near
// field) is then four sources ω̄ ± a_1, ω̄ ± a_2 of a quarter of its power each: they keep the
// mean and the covariance, so the source's curvature in ω12 (through dr) is taken into account
// to second order. Far sources (nodes) use the mean alone: there the curvature does not matter.
struct PointSpread {
    vec4 axis[2];
};

// A node of the Karras (HPG 2012) binary radix tree over the Morton-sorted points (64 bytes).
// Children with LEAF_BIT (gpu_constants.glsl) set are point indices (in sorted order), else node indices.
struct TreeNode {
    vec3 power;        // sum of irradiance × area per RGB, over all lights
    float area;        // sum of point areas
    vec3 center;       // area-weighted mean position: where the walk measures the distance from,
                       // the same whatever the lights, so that lights add exactly
    uint left;
    uvec3 box_half;    // bounding box as 6 halfs, rounded outward: min.xy | min.z max.x | max.yz
    uint right;
    uint normal_oct;   // area-weighted mean normal, octahedral 2×16-bit snorm
    uint light_oct;    // power-weighted mean light direction, octahedral 2×16-bit snorm (for views)
    uint first_point;  // the node's points are sorted points [first_point, first_point + point_count)
    uint point_count;
};

// What every light together brings to one node (64 bytes): the node used whole is one merged
// source (two sigma points) at its power centre.
struct NodeFlux {
    vec4 incident[3];  // per channel: PointFlux's sums times each point's area
    vec3 power_center; // luminance-of-power-weighted mean position (area-weighted where unlit)
    float spread2;     // the same weights' mean squared distance of the points from power_center
};

// The same records read as RGBA32UI texels (usamplerBuffer views of the same buffers, for the
// shade pass: llvmpipe gathers texels as vectors but loads storage buffers one lane at a time).
// Each record is a whole number of texels, in the order of its fields above:
// SurfacePoint: 0 position, area; 1 normal, triangle; 2 irradiance; 3 light_dir.
// TreeNode: 0 power, area; 1 center, left; 2 box_half, right; 3 normal_oct, light_oct,
// first_point, point_count. PointLight: 0 irradiance, toward_oct. PointFlux: 0-2 incident.
// NodeFlux: 0-2 incident; 3 power_center, spread2.
const uint POINT_TEXELS = 4u;
const uint NODE_TEXELS = 4u;
const uint POINT_FLUX_TEXELS = 3u;
const uint NODE_FLUX_TEXELS = 4u;
const uint POINT_SPREAD_TEXELS = 2u;
uvec4 texel(usamplerBuffer records, uint index) { return texelFetch(records, int(index)); }
vec4 texel_float(usamplerBuffer records, uint index) { return uintBitsToFloat(texelFetch(records, int(index))); }

// The walk's end, and the subtree after the one whose last point is `last`, in depth-first order
// (left child first): it starts at point last + 1, and in Karras's layout an internal node's
// range has the node's own index at one end, so it is internal node last + 1 if that node's
// range starts there, else the point itself. No stack: llvmpipe keeps a private array per lane,
// and the walk's pushes and pops cost more than this one extra texel. (tile_cut.comp, and the
// re-entry's exitance walk.)
const uint WALK_END = 0xffffffffu;
uint walk_next_after(usamplerBuffer tree_nodes, uint point_count, uint node_count, uint last) {
    uint next = last + 1u;
    if (next >= point_count) return WALK_END;
    if (next < node_count && texelFetch(tree_nodes, int(next * NODE_TEXELS + 3u)).z == next) return next;
    return next | LEAF_BIT;
}

// Octahedral encoding of a unit vector (Cigolle et al. 2014) into 2×16-bit snorm.
vec2 oct_wrap(vec2 v) {
    return (1.0 - abs(v.yx)) * vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}
uint encode_oct(vec3 n) {
    float l1 = abs(n.x) + abs(n.y) + abs(n.z);
    if (l1 == 0.0) return packSnorm2x16(vec2(0.0)) ; // zero vector: decodes to (0,0,1)
    vec2 p = n.xy / l1;
    if (n.z < 0.0) p = oct_wrap(p);
    return packSnorm2x16(p);
}
vec3 decode_oct(uint e) {
    vec2 p = unpackSnorm2x16(e);
    vec3 n = vec3(p, 1.0 - abs(p.x) - abs(p.y));
    if (n.z < 0.0) n.xy = oct_wrap(n.xy);
    return normalize(n);
}

// Half-float bounds rounded outward, so the stored box always contains the exact one.
uint half_bits(float x) { return packHalf2x16(vec2(x, 0.0)) & 0xffffu; }
float half_value(uint h) { return unpackHalf2x16(h).x; }
uint half_down(float x) {
    uint h = half_bits(x);
    if (half_value(h) > x) h = (x > 0.0) ? h - 1u : ((h & 0x7fffu) == 0u ? 0x8001u : h + 1u);
    return h;
}
uint half_up(float x) {
    uint h = half_bits(x);
    if (half_value(h) < x) h = (x >= 0.0) ? ((h & 0x7fffu) == 0u ? 1u : h + 1u) : h - 1u;
    return h;
}
uvec3 pack_box(vec3 lo, vec3 hi) {
    return uvec3(half_down(lo.x) | (half_down(lo.y) << 16),
                 half_down(lo.z) | (half_up(hi.x) << 16),
                 half_up(hi.y) | (half_up(hi.z) << 16));
}
void unpack_box(uvec3 b, out vec3 lo, out vec3 hi) {
    lo = vec3(half_value(b.x & 0xffffu), half_value(b.x >> 16), half_value(b.y & 0xffffu));
    hi = vec3(half_value(b.y >> 16), half_value(b.z & 0xffffu), half_value(b.z >> 16));
}
#endif
