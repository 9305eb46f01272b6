// Unsigned 64-bit integers as uvec2 (low, high), so no shaderInt64 is needed: exact sums where
// f32 would round (the triangle-area prefix sum of the sampling pass).
#ifndef FIXED64_GLSL
#define FIXED64_GLSL
uvec2 add64(uvec2 a, uvec2 b) {
    uint carry;
    uint low = uaddCarry(a.x, b.x, carry);
    return uvec2(low, a.y + b.y + carry);
}
// a <= b
bool less_equal64(uvec2 a, uvec2 b) { return a.y < b.y || (a.y == b.y && a.x <= b.x); }
// a - 1 (a > 0)
uvec2 decrement64(uvec2 a) { return a.x == 0u ? uvec2(0xffffffffu, a.y - 1u) : uvec2(a.x - 1u, a.y); }
// A non-negative float below 2^64 rounded to the nearest integer. The split is exact: for x ≥ 2^32
// the float's last bit is worth at least 2^9, so x − high · 2^32 is a float too.
uvec2 fixed64(float x) {
    x = roundEven(max(x, 0.0));
    float high = floor(x * (1.0 / 4294967296.0));
    return uvec2(uint(x - high * 4294967296.0), uint(high));
}
#endif
