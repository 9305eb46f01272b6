#version 460
// Opaque objects: Lambertian reflection of every light, shadowed by every object, per pixel of
// the G-buffer whose id is an opaque object's: Lo = ρ/π · Σ_k E_k · max(0, n·l_k) · V_k.
#include "diffuse_constants.glsl"
// The lights and the shadow maps fitted to the opaque objects.
#define LIGHTS_BINDING 3
#include "lights.glsl"

layout(location = 0) out vec4 radiance;

layout(binding = 0, rgba32f) uniform readonly image2D surface_position;
layout(binding = 1, rgba32f) uniform readonly image2D surface_normal;
layout(binding = 2, rgba32f) uniform readonly image2D surface_albedo;
layout(binding = 4) uniform sampler2DArrayShadow shadow_map;

const float PI = 3.14159265358979;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 surface = imageLoad(surface_position, pixel);
    // Background and translucent objects: their own passes wrote them.
    if (surface.w < float(pc.first_opaque + 1u)) discard;
    vec3 x = surface.xyz;
    vec3 n = normalize(imageLoad(surface_normal, pixel).xyz);
    vec3 rho = imageLoad(surface_albedo, pixel).rgb;
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        vec3 toward;
        uint layer;
        vec3 incident = light_at(light_of(k), x, toward, layer);
        float cos_i = dot(n, toward);
        if (cos_i <= 0.0) continue;
        vec4 clip = layer_matrix(layer) * vec4(x + n * light_set.normal_offset, 1.0);
        vec3 ndc = clip.xyz / clip.w;
        float visibility = texture(shadow_map, vec4(ndc.xy * 0.5 + 0.5, float(layer), ndc.z));
        sum += incident * cos_i * visibility;
    }
    radiance = vec4(rho / PI * sum, 1.0);
}
