#version 460
// An opaque object's surface in the G-buffer: position (w = its id + 1), normal, and its
// Lambertian reflectance here (pbrt-v4's 2D checkerboard: tex1 where floor(u·uscale) +
// floor(v·vscale) is even, tex2 where odd).
#define DIFFUSE_SURFACE
#include "diffuse_constants.glsl"

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 2) in vec2 uv;
layout(location = 0) out vec4 position;
layout(location = 1) out vec4 normal;
layout(location = 2) out vec4 albedo;
// An image reflectance (checker = 2), over the uv with v up the image as pbrt-v4 reads it.
layout(binding = 1) uniform sampler2D reflectance_map;

void main() {
    position = vec4(world_position, float(pc.object + 1u));
    normal = vec4(world_normal, 0.0);
    vec3 reflectance = pc.tex1.rgb;
    if (pc.checker == 2u) {
        reflectance = texture(reflectance_map, vec2(uv.x, 1.0 - uv.y)).rgb;
    } else if (pc.checker != 0u) {
        int parity = int(floor(uv.x * pc.tex1.w)) + int(floor(uv.y * pc.tex2.w));
        if ((parity & 1) != 0) reflectance = pc.tex2.rgb;
    }
    albedo = vec4(reflectance, 1.0);
}
