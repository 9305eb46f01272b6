// Constants and helpers shared by every pass.
#ifndef COMMON_GLSL
#define COMMON_GLSL
const float PI = 3.14159265358979323846;
// Rec. 709 luminance weights: how the passes weigh a colour by one number.
const vec3 LUMINANCE = vec3(0.2126, 0.7152, 0.0722);
#endif
