#version 460
// Irradiance entering each point from every light: E_k = I · max(0, n·l) · Ft(eta, n·l) ·
// visibility (times the point's scatter weight where the object is textured), merged into one PointFlux whatever the number of lights (the E-weighted sums of
// the directions toward them and of their refracted cosines, per channel); their sum and irradiance-weighted mean direction in the
// point itself (for views and tools); and, for brute force only (per_light_records = 1), each
// light's own PointLight.
#include "points.glsl"
#include "bssrdf.glsl"
#define LIGHTS_BINDING 1
#define SHADOW_MAP_BINDING 2
#include "lights.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Points { SurfacePoint points[]; };
layout(std430, binding = 3) writeonly buffer PointLights { PointLight point_lights[]; };
layout(std430, binding = 4) writeonly buffer PointFluxes { PointFlux point_flux[]; };
layout(std430, binding = 5) writeonly buffer PointSpreads { PointSpread point_spread[]; };
// The object's Sd table, for its angular factors' incidence part (1 but for the Monte Carlo table).
layout(binding = 6) uniform usamplerBuffer sd_table;
layout(push_constant) uniform IrradianceConstants { uint point_count; uint per_light_records; } pc;

// The two sigma axes of the directions' covariance (PointSpread): Jacobi rotations of the 3×3
// symmetric matrix (a few sweeps converge it to float precision), its two largest eigenpairs.
PointSpread spread_of(float weight, vec3 first, mat3 second) {
    PointSpread s;
    s.axis[0] = s.axis[1] = vec4(0.0);
    if (weight <= 0.0) return s;
    vec3 mean = first / weight;
    mat3 a = second / weight - outerProduct(mean, mean);
    mat3 v = mat3(1.0);
    for (int sweep = 0; sweep < 5; ++sweep) {
        for (int k = 0; k < 3; ++k) {
            int p = k == 2 ? 1 : 0, q = k == 0 ? 1 : 2;
            float apq = a[q][p];
            if (abs(apq) < 1e-12) continue;
            float theta = 0.5 * (a[q][q] - a[p][p]) / apq;
            float t = sign(theta) / (abs(theta) + sqrt(theta * theta + 1.0));
            if (theta == 0.0) t = 1.0;
            float c = inversesqrt(t * t + 1.0), sn = t * c;
            mat3 r = mat3(1.0);
            r[p][p] = c; r[q][q] = c; r[q][p] = sn; r[p][q] = -sn;
            a = transpose(r) * a * r;
            v = v * r;
        }
    }
    vec3 l = max(vec3(a[0][0], a[1][1], a[2][2]), vec3(0.0));
    // The two largest.
    int smallest = l.x <= l.y && l.x <= l.z ? 0 : (l.y <= l.z ? 1 : 2);
    int j0 = smallest == 0 ? 1 : 0, j1 = smallest == 2 ? 1 : 2;
    s.axis[0] = vec4(v[j0] * sqrt(2.0 * l[j0]), 0.0);
    s.axis[1] = vec4(v[j1] * sqrt(2.0 * l[j1]), 0.0);
    // One light (or lights of one direction): no spread, one evaluation.
    // (float rounding leaves about 1e-8 of one direction's: a spread below 1e-3 rad is none.)
    if (l[j0] < 1e-6) s.axis[0] = vec4(0.0);
    if (l[j1] < 1e-6) s.axis[1] = vec4(0.0);
    return s;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    SurfacePoint p = points[i];
    vec3 irradiance = vec3(0.0);
    vec3 weighted_dir = vec3(0.0);
    PointFlux flux;
    flux.incident[0] = flux.incident[1] = flux.incident[2] = vec4(0.0);
    // Luminance-weighted first and second moments of the refracted directions.
    float weight = 0.0;
    vec3 first = vec3(0.0);
    mat3 second = mat3(0.0);
    vec3 scatter_weight = scatter_weight_of(p);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        vec3 toward;
        // light_irradiance (lights.glsl): the shade pass computes its pixel's own the same way;
        // the table's incidence factor (1 but for the Monte Carlo table) on top.
        vec3 e = light_irradiance(light_of(k), p.position, p.normal, toward);
        vec4 term = flux_term(toward, p.normal);
        e *= table_incidence_factor(sd_table, term.w);
        // The object's texture here (1 without one): what enters is weighed by it, so that every
        // sum over points and nodes carries the source's colour (gpu_world::SurfaceTexture).
        e *= scatter_weight;
        if (pc.per_light_records != 0u) point_lights[i * light_set.light_count + k] = PointLight(e, encode_oct(toward));
        if (e == vec3(0.0)) continue;
        vec3 wi = term.xyz;
        for (uint c = 0u; c < 3u; ++c) flux.incident[c] += e[c] * term;
        float y = dot(e, vec3(0.2126, 0.7152, 0.0722));
        vec3 w12 = refract_in(wi, p.normal, light_set.eta);
        weight += y;
        first += y * w12;
        second += y * outerProduct(w12, w12);
        irradiance += e;
        weighted_dir += dot(e, vec3(0.2126, 0.7152, 0.0722)) * toward;
    }
    points[i].irradiance = irradiance;
    points[i].light_dir = dot(weighted_dir, weighted_dir) > 0.0 ? normalize(weighted_dir) : vec3(0.0);
    point_flux[i] = flux;
    point_spread[i] = spread_of(weight, first, second);
}
