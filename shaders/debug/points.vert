#version 460
// --show samples: the sorted sample points as dots coloured by their irradiance.
#include "points.glsl"
layout(std430, binding = 0) readonly buffer Sorted { SurfacePoint points[]; };
layout(push_constant) uniform DebugConstants { mat4 view_projection; vec4 color_scale; } pc;
layout(location = 0) out vec3 color;
void main() {
    SurfacePoint p = points[gl_VertexIndex];
    gl_Position = pc.view_projection * vec4(p.position, 1.0);
    gl_Position.z -= 2e-4 * gl_Position.w; // in front of the surface it lies on
    gl_PointSize = pc.color_scale.w;
    color = p.irradiance * pc.color_scale.rgb + vec3(0.02, 0.02, 0.05);
}
