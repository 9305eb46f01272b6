#version 460
// Depth-only pass from a light: one layer of the shadow map per directional light, six per point light.
layout(location = 0) in vec3 in_position;
layout(push_constant) uniform ShadowConstants { mat4 light_matrix; } pc;
void main() { gl_Position = pc.light_matrix * vec4(in_position, 1.0); }
