#version 460
// The surface pass: the mesh rasterised once, to the G-buffer the shade pass reads.
#include "shade_constants.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;

void main() {
    world_position = in_position;
    world_normal = in_normal;
    gl_Position = pc.view_projection * vec4(in_position, 1.0);
}
