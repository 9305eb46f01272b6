// Lights as the GPU reads them. Mirrored by GpuLight / LightSetHeader in src/gpu/lights.rs.
#ifndef LIGHTS_GLSL
#define LIGHTS_GLSL
#include "gpu_constants.glsl"
struct GpuLight {
    vec4 position;   // xyz: direction toward the light (w = 0) or its position (w = 1)
    vec4 intensity;  // rgb: irradiance at normal incidence (directional) or radiant intensity (point)
    uint first_layer; // its first shadow-map layer (point lights use 6: +x -x +y -y +z -z)
    uint pad0;
    uint pad1;
    uint pad2;
};
struct LightSet {
    uint light_count;
    float eta;            // relative index of the medium, for Ft
    float normal_offset;  // shadow lookup offset along the normal, scene units
    float pad;
    GpuLight lights[MAX_LIGHTS];
};

// Cube face of a direction from a point light: +x, -x, +y, -y, +z, -z (as in src/passes/shadow.rs).
uint cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0u : 1u;
    if (a.y >= a.z) return d.y >= 0.0 ? 2u : 3u;
    return d.z >= 0.0 ? 4u : 5u;
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
    layer += cube_face(-d);
    return light.intensity.rgb / d2;
}
#endif
