// Constants and helpers shared by every pass.
#ifndef COMMON_GLSL
#define COMMON_GLSL
const float PI = 3.14159265358979323846;
#endif
