// Lights as the GPU reads them. Mirrored by GpuLight / LightSetHeader in src/gpu/lights.rs.
#ifndef LIGHTS_GLSL
#define LIGHTS_GLSL
#include "gpu_constants.glsl"
struct GpuLight {
    vec4 position;   // xyz: direction toward the light (w = 0) or its position (w = 1: point, spot)
    vec4 intensity;  // rgb: irradiance at normal incidence (directional) or radiant intensity (point,
                     // spot: along its axis)
    vec4 axis;       // spot lights: xyz the cone's axis from the light (unit), w cos(cone angle)
    uint first_layer; // its first shadow-map layer
    uint cube;       // 1: six layers, the cube faces +x -x +y -y +z -z (a point light or spot near
                     // the receiver, a wide spot); 0: one (shadow::light_matrices)
    float cos_falloff_start; // spot lights: cos(cone angle - delta), where the falloff begins
    uint spot;       // 1: a spot light (its falloff applies)
};
// The light set's buffer (binding LIGHTS_BINDING, defined by the shader before it includes this
// file): a header (mirrored by LightSetHeader), then `light_count` lights as 4 vec4 each (GpuLight
// in order: position, intensity, axis, then first_layer, cube, cos_falloff_start, spot as bits),
// then from `matrix_base` one mat4 per shadow-map layer. As many lights as memory holds: one
// runtime array of words, since a block may end in only one.
#ifdef LIGHTS_BINDING
layout(std430, binding = LIGHTS_BINDING) readonly buffer Lights {
    uint light_count;
    float eta;            // relative index of the medium, for Ft
    float normal_offset;  // shadow lookup offset along the normal, scene units
    uint matrix_base;     // the first layer matrix, in vec4 words
    vec4 words[];
} light_set;

GpuLight light_of(uint k) {
    uint b = 4u * k;
    uvec4 bits = floatBitsToUint(light_set.words[b + 3u]);
    return GpuLight(light_set.words[b], light_set.words[b + 1u], light_set.words[b + 2u], bits.x, bits.y,
                    uintBitsToFloat(bits.z), bits.w);
}

mat4 layer_matrix(uint layer) {
    uint b = light_set.matrix_base + 4u * layer;
    return mat4(light_set.words[b], light_set.words[b + 1u], light_set.words[b + 2u], light_set.words[b + 3u]);
}
#endif

// Cube face of a direction from a point light: +x, -x, +y, -y, +z, -z (as in src/passes/shadow.rs).
uint cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0u : 1u;
    if (a.y >= a.z) return d.y >= 0.0 ? 2u : 3u;
    return d.z >= 0.0 ? 4u : 5u;
}

// A spot light's falloff at cos θ off its axis: pbrt-v4's SpotLight::I (src/pbrt/lights.cpp),
// smoothstep from cos(cone angle) up to cos(cone angle - delta), with pbrt's SmoothStep
// (src/pbrt/util/math.h): a step when the two are equal (delta 0). GLSL's own smoothstep is
// undefined there.
float spot_falloff(float cos_theta, float cos_total, float cos_start) {
    float c = clamp(cos_theta, -1.0, 1.0);
    if (cos_total == cos_start) return c < cos_total ? 0.0 : 1.0;
    float t = clamp((c - cos_total) / (cos_start - cos_total), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// What `light` sends to the point x: the unit direction toward it, the irradiance on a surface
// facing it (returned), and the shadow-map layer that sees x.
vec3 light_at(GpuLight light, vec3 x, out vec3 toward, out uint layer) {
    layer = light.first_layer;
    if (light.position.w == 0.0) {
        toward = normalize(light.position.xyz);
        return light.intensity.rgb;
    }
    vec3 d = light.position.xyz - x;
    float d2 = max(dot(d, d), 1e-20);
    toward = d * inversesqrt(d2);
    if (light.cube != 0u) layer += cube_face(-d);
    vec3 e = light.intensity.rgb / d2;
    if (light.spot != 0u) e *= spot_falloff(dot(-toward, light.axis.xyz), light.axis.w, light.cos_falloff_start);
    return e;
}

// The per-light irradiance that enters the surface, shared by the irradiance pass (per sample
// point) and the shade pass (the pixel's own, for the near field), so that the two cannot
// drift apart. Declares the shadow maps at binding SHADOW_MAP_BINDING (defined by the shader
// before it includes this file, with LIGHTS_BINDING).
#if defined(LIGHTS_BINDING) && defined(SHADOW_MAP_BINDING)
#include "bssrdf.glsl"
#include "points.glsl"
layout(binding = SHADOW_MAP_BINDING) uniform sampler2DArrayShadow shadow_map;

// The shadow map's visibility of x (normal n) in `layer`, looked up from x offset along the normal
// by a few shadow-map texels, so that lit surfaces do not shadow themselves.
float shadow_visibility(uint layer, vec3 x, vec3 n) {
    vec4 clip = layer_matrix(layer) * vec4(x + n * light_set.normal_offset, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    return texture(shadow_map, vec4(ndc.xy * 0.5 + 0.5, float(layer), ndc.z));
}

// The irradiance `light` sends into the surface at x (normal n): I · max(0, n·l) · Ft(eta, n·l) ·
// visibility, 0 where it does not reach; `toward` is the unit direction toward it.
vec3 light_irradiance(GpuLight light, vec3 x, vec3 n, out vec3 toward) {
    uint layer;
    vec3 incident = light_at(light, x, toward, layer);
    float cos_theta = dot(n, toward);
    if (cos_theta <= 0.0) return vec3(0.0);
    float visibility = shadow_visibility(layer, x, n);
    return incident * cos_theta * fresnel_transmittance(light_set.eta, cos_theta) * visibility;
}

// One light's term per unit irradiance in a merged record (PointFlux) at normal n: the direction
// toward it as brute force decodes it from its record (so that one light's merged record is that
// light's own), and the cosine of its refracted direction as refract_in computes it.
vec4 flux_term(vec3 toward, vec3 n) {
    vec3 wi = decode_oct(encode_oct(toward));
    float cos_i = dot(wi, n);
    float cos_t = sqrt(max(1.0 - (1.0 - cos_i * cos_i) / (light_set.eta * light_set.eta), 0.0));
    return vec4(wi, cos_t);
}
#endif
#endif
