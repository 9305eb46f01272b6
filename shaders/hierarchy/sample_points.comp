#version 460
// N points uniform by area: point i sits at cumulative area (i + jitter_i)/N · total (stratified),
// its triangle found by binary search in the prefix sum, its barycentrics from the R2
// low-discrepancy sequence, so points are evenly spread rather than clumped.
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Vertices { float vertex_data[]; };
layout(std430, binding = 1) readonly buffer Indices { uint indices[]; };
layout(std430, binding = 2) readonly buffer Prefix { float prefix[]; };
layout(std430, binding = 3) writeonly buffer Points { SurfacePoint points[]; };
layout(push_constant) uniform SampleConstants { uint point_count; uint triangle_count; uint seed; } pc;

vec3 position(uint v) { return vec3(vertex_data[6 * v], vertex_data[6 * v + 1], vertex_data[6 * v + 2]); }
vec3 normal_of(uint v) { return vec3(vertex_data[6 * v + 3], vertex_data[6 * v + 4], vertex_data[6 * v + 5]); }

// PCG hash (Jarzynski and Olano 2020) to a float in [0, 1).
float hash01(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return float((word >> 22u) ^ word) * (1.0 / 4294967296.0);
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    float total = prefix[pc.triangle_count];
    float target_area = (float(i) + hash01(i ^ pc.seed)) / float(pc.point_count) * total;
    uint lo = 0u, hi = pc.triangle_count;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (prefix[mid] <= target_area) lo = mid; else hi = mid;
    }
    uint t = lo;
    vec2 r = fract(vec2(0.5) + float(i) * vec2(0.7548776662466927, 0.5698402909980532));
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
    p.area = total / float(pc.point_count);
    p.normal = n;
    p.triangle = t;
    p.irradiance = vec3(0.0);
    p.pad0 = 0.0;
    p.light_dir = vec3(0.0);
    p.pad1 = 0.0;
    points[i] = p;
}
