#version 460
// N points uniform by area: point i sits at cumulative area (i + jitter_i)/N · total (stratified),
// its triangle found by binary search in the prefix sum, its barycentrics from the R2
// low-discrepancy sequence, so points are evenly spread rather than clumped. Both are integer
// arithmetic, exact at any N: in f32, i · α keeps only 24 bits, so past ~100k points the R2
// values fall onto a coarse lattice (at i = 1.6M, multiples of 1/8) and the points clump.
#include "points.glsl"
#include "fixed64.glsl"
#include "surface_texture.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Vertices { float vertex_data[]; };
layout(std430, binding = 1) readonly buffer Indices { uint indices[]; };
// In units of total area / (N · 2^20): see triangle_areas.comp.
layout(std430, binding = 2) readonly buffer AreaPrefix { float total_area; uint pad; uvec2 prefix[]; };
layout(std430, binding = 3) writeonly buffer Points { SurfacePoint points[]; };
// The object's texture (its scatter weight; surface_texture.glsl) and one uv per vertex.
layout(std430, binding = 4) readonly buffer Uvs { vec2 uvs[]; };
layout(binding = 5) uniform sampler2D texture_map;
layout(push_constant) uniform SampleConstants {
    uint point_count;
    uint triangle_count;
    uint seed;
    uint texture_kind;  // TEXTURE_*: TEXTURE_CONSTANT reads no uv
    vec4 tex1;
    vec4 tex2;
} pc;

vec3 position(uint v) { return vec3(vertex_data[6 * v], vertex_data[6 * v + 1], vertex_data[6 * v + 2]); }
vec3 normal_of(uint v) { return vec3(vertex_data[6 * v + 3], vertex_data[6 * v + 4], vertex_data[6 * v + 5]); }

// PCG hash (Jarzynski and Olano 2020).
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The R2 sequence's generators (Roberts 2018), 1/φ2 and 1/φ2², as 32-bit fractions: i · α mod 1
// is then exact, by integer wrap-around.
const uvec2 R2_ALPHA = uvec2(3242174889u, 2447445414u);

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    // (i + jitter) · 2^20 units, the jitter's 20 bits from the hash; kept below the total so
    // that the point lands on a triangle with area even where rounding left the total short.
    uvec2 target = add64(uvec2(i << 20, i >> 12), uvec2(pcg_hash(i ^ pc.seed) >> 12, 0u));
    uvec2 total_units = prefix[pc.triangle_count];
    if (less_equal64(total_units, target)) target = decrement64(total_units);
    uint lo = 0u, hi = pc.triangle_count;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (less_equal64(prefix[mid], target)) lo = mid; else hi = mid;
    }
    uint t = lo;
    // 24 bits of each 32-bit fraction: exact as floats, uniform in [0, 1).
    uvec2 r_fixed = uvec2(0x80000000u) + i * R2_ALPHA;
    vec2 r = vec2(r_fixed >> 8u) * (1.0 / 16777216.0);
    float s = sqrt(r.x);
    vec3 bary = vec3(1.0 - s, r.y * s, 0.0);
    bary.z = 1.0 - bary.x - bary.y;
    uint ia = indices[3 * t], ib = indices[3 * t + 1], ic = indices[3 * t + 2];
    vec3 a = position(ia), b = position(ib), c = position(ic);
    vec3 n = bary.x * normal_of(ia) + bary.y * normal_of(ib) + bary.z * normal_of(ic);
    vec3 geometric = cross(b - a, c - a);
    n = dot(n, n) > 1e-20 ? normalize(n) : normalize(geometric);

    SurfacePoint p;
    p.position = bary.x * a + bary.y * b + bary.z * c;
    p.area = total_area / float(pc.point_count);
    p.normal = n;
    p.triangle = t;
    p.irradiance = vec3(0.0);
    // The texture at the point's uv: its scatter weight, which the irradiance pass applies.
    vec3 weight = pc.tex1.rgb;
    if (pc.texture_kind != TEXTURE_CONSTANT) {
        vec2 uv = bary.x * uvs[ia] + bary.y * uvs[ib] + bary.z * uvs[ic];
        weight = surface_texture(pc.texture_kind, pc.tex1, pc.tex2, texture_map, uv);
    }
    p.scatter_weight_rg = packHalf2x16(weight.rg);
    p.light_dir = vec3(0.0);
    p.scatter_weight_b = weight.b;
    points[i] = p;
}
