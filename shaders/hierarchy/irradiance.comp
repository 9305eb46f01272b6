#version 460
// Irradiance entering each point from each light: I · max(0, n·l) · Ft(eta, n·l) · visibility and
// the direction toward it (the directional dipole's wi), one PointLight per light; and their sum
// and irradiance-weighted mean direction in the point itself (for views and tools).
#include "points.glsl"
#include "bssrdf.glsl"
#include "lights.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Points { SurfacePoint points[]; };
layout(std430, binding = 1) readonly buffer Lights { LightSet light_set; mat4 layer_matrices[]; };
layout(binding = 2) uniform sampler2DArrayShadow shadow_map;
layout(std430, binding = 3) writeonly buffer PointLights { PointLight point_lights[]; };
layout(push_constant) uniform IrradianceConstants { uint point_count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.point_count) return;
    SurfacePoint p = points[i];
    vec3 irradiance = vec3(0.0);
    vec3 weighted_dir = vec3(0.0);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        GpuLight light = light_set.lights[k];
        vec3 toward;
        uint layer;
        vec3 incident = light_at(light, p.position, toward, layer);
        float cos_theta = dot(p.normal, toward);
        uint record = i * light_set.light_count + k;
        point_lights[record] = PointLight(vec3(0.0), encode_oct(toward));
        if (cos_theta <= 0.0) continue;
        // Offset along the normal by a few shadow-map texels so lit surfaces do not shadow themselves.
        vec4 clip = layer_matrices[layer] * vec4(p.position + p.normal * light_set.normal_offset, 1.0);
        vec3 ndc = clip.xyz / clip.w;
        float visibility = texture(shadow_map, vec4(ndc.xy * 0.5 + 0.5, float(layer), ndc.z));
        vec3 e = incident * cos_theta * fresnel_transmittance(light_set.eta, cos_theta) * visibility;
        point_lights[record].irradiance = e;
        irradiance += e;
        weighted_dir += dot(e, vec3(0.2126, 0.7152, 0.0722)) * toward;
    }
    points[i].irradiance = irradiance;
    points[i].light_dir = dot(weighted_dir, weighted_dir) > 0.0 ? normalize(weighted_dir) : vec3(0.0);
}
