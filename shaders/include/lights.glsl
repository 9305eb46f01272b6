// Lights as the GPU reads them. Mirrored by GpuLight / LightSetHeader in src/passes/irradiance.rs.
#ifndef LIGHTS_GLSL
#define LIGHTS_GLSL
const uint MAX_LIGHTS = 8u;
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
#endif
