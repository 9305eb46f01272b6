#version 460
// The surface pass: an object's mesh, with its texture coordinates (read per vertex from a
// buffer), rasterised once to the G-buffer the shade and diffuse passes read.
#include "surface_constants.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
// One uv per vertex (zeros for a mesh without them: its texture is then constant).
layout(std430, binding = 0) readonly buffer Uvs { vec2 uvs[]; };
// One mean curvature per vertex (1/scene unit; gpu_world::curvature_buffer), zeros but for the
// Monte Carlo table's objects.
layout(std430, binding = 2) readonly buffer Curvatures { float mean_curvature[]; };

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;
layout(location = 2) out vec2 uv;
layout(location = 3) out float curvature;

void main() {
    world_position = in_position;
    world_normal = in_normal;
    uv = uvs[gl_VertexIndex];
    curvature = mean_curvature[gl_VertexIndex];
    gl_Position = pc.view_projection * vec4(in_position, 1.0);
}
