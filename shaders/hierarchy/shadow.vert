#version 460
// The shadow maps: each light's depth (one layer per directional light, six per point light),
// and the mesh's own smooth normal and mean curvature there (shadow.frag).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(push_constant) uniform ShadowConstants { mat4 light_matrix; } pc;
// One mean curvature per vertex (1/scene unit; gpu_world::curvature_buffer, smoothed over the
// material's diffusion length: the surface pass's), or a single 0 read for every vertex.
layout(std430, binding = 0) readonly buffer Curvatures { float mean_curvature[]; };
layout(location = 0) out vec3 world_normal;
layout(location = 1) out float curvature;
invariant gl_Position;
void main() {
    world_normal = in_normal;
    curvature = mean_curvature[min(gl_VertexIndex, mean_curvature.length() - 1)];
    gl_Position = pc.light_matrix * vec4(in_position, 1.0);
}
