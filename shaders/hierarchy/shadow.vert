#version 460
// Depth only: the shadow maps (one layer per directional light, six per point light) and the
// camera's depth pre-pass of the shade pass.
layout(location = 0) in vec3 in_position;
layout(push_constant) uniform ShadowConstants { mat4 light_matrix; } pc;
invariant gl_Position;
void main() { gl_Position = pc.light_matrix * vec4(in_position, 1.0); }
