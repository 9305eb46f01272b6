#version 460
// The environment behind the objects: every pixel that no surface covers shows the radiance
// arriving along its camera ray (black without an environment), the texel it falls in, as
// src/environment.rs's `radiance_toward` reads it, with alpha 1 (it is part of the picture: PNGs
// show it, auto exposure and `compare` count it); without one, black with alpha 0 (no coverage).
// Covered pixels are left to the passes that shade them.
#include "background_constants.glsl"

layout(location = 0) out vec4 radiance;
layout(binding = 0, rgba32f) uniform readonly image2D surface_position;
layout(binding = 1) uniform sampler2D environment;

const float PI = 3.14159265358979;

// Mitsuba 3's latitude-longitude convention (environment.rs `direction_to_uv`).
vec2 latlong_uv(vec3 d) {
    float u = atan(d.x, -d.z) / (2.0 * PI);
    return vec2(fract(u), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

// pbrt-v4's EqualAreaSphereToSquare (environment.rs `equal_area_sphere_to_square`).
vec2 octahedral_uv(vec3 d) {
    vec3 a = abs(d);
    float r = sqrt(max(1.0 - a.z, 0.0));
    float big = max(a.x, a.y);
    float b = big == 0.0 ? 0.0 : min(a.x, a.y) / big;
    float phi = atan(b) * 2.0 / PI;
    if (a.x < a.y) phi = 1.0 - phi;
    float v = phi * r;
    float u = r - v;
    if (d.z < 0.0) {
        float t = u;
        u = 1.0 - v;
        v = 1.0 - t;
    }
    u = d.x < 0.0 ? -u : u;
    v = d.y < 0.0 ? -v : v;
    return vec2(0.5 * (u + 1.0), 0.5 * (v + 1.0));
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    if (imageLoad(surface_position, pixel).w != 0.0) discard;
    if (pc.kind == BACKGROUND_NONE) {
        radiance = vec4(0.0);
        return;
    }
    if (pc.kind == BACKGROUND_CONSTANT) {
        radiance = vec4(pc.constant.rgb * pc.constant.w, 1.0);
        return;
    }
    vec2 ndc = gl_FragCoord.xy / vec2(imageSize(surface_position)) * 2.0 - 1.0;
    vec3 d = normalize(pc.ray_x.xyz * ndc.x + pc.ray_y.xyz * ndc.y + pc.ray_z.xyz);
    vec2 uv = pc.kind == BACKGROUND_LATLONG ? latlong_uv(d) : octahedral_uv(d);
    ivec2 texel = min(ivec2(uv * vec2(pc.width, pc.height)), ivec2(pc.width - 1u, pc.height - 1u));
    radiance = vec4(texelFetch(environment, texel, 0).rgb * pc.constant.w, 1.0);
}
