#version 460
// Placeholder surface shading until the subsurface pass exists: Lambert from one light plus a
// little ambient. Output is linear radiance; alpha marks covered pixels.
#include "common.glsl"
#include "shade_constants.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 0) out vec4 radiance;

void main() {
    vec3 n = normalize(world_normal);
    // Seen from behind (open meshes): shade the side that faces the viewer.
    if (dot(n, pc.eye.xyz - world_position) < 0.0) n = -n;
    vec3 toward = pc.light_toward.xyz;
    vec3 irradiance = pc.light_irradiance.rgb;
    if (pc.light_toward.w > 0.5) {
        vec3 d = pc.light_toward.xyz - world_position;
        float d2 = max(dot(d, d), 1e-12);
        toward = d * inversesqrt(d2);
        irradiance /= d2;
    }
    float cos_theta = max(dot(n, toward), 0.0);
    vec3 albedo = pc.albedo.rgb;
    vec3 lo = albedo / PI * irradiance * (cos_theta + pc.albedo.a);
    radiance = vec4(lo, 1.0);
}
