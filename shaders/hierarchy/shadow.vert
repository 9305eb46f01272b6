#version 460
// The shadow maps: each light's depth (one layer per directional light, six per point light)
// and the mesh's own smooth normal there (shadow.frag).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
layout(push_constant) uniform ShadowConstants { mat4 light_matrix; } pc;
layout(location = 0) out vec3 world_normal;
invariant gl_Position;
void main() {
    world_normal = in_normal;
    gl_Position = pc.light_matrix * vec4(in_position, 1.0);
}
