#version 460
// --show tree: node boxes as line segments (positions and colours from the vertex buffer).
layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_color;
layout(push_constant) uniform DebugConstants { mat4 view_projection; vec4 color_scale; } pc;
layout(location = 0) out vec3 color;
void main() {
    gl_Position = pc.view_projection * vec4(in_position, 1.0);
    gl_Position.z -= 1e-3 * gl_Position.w;
    color = in_color * pc.color_scale.rgb;
}
