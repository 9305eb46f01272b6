// The far field of an 8x8 tile (tile_cut.comp decides which sources are far, far_field.comp sums
// them at sixteen of the tile's pixels, shade.frag interpolates the sixteen sums at its pixel):
// the sum over sources far from a tile varies slowly across it, so it is worth evaluating at
// sixteen pixels instead of sixty-four. The sixteen are the tile's pixels at offsets
// (FAR_NODES[i], FAR_NODES[j]); a pixel at offset (u, v) takes
// Σ far_weights(u)[i] · far_weights(v)[j] · sum[4j + i]: Lagrange's cubic interpolation on each
// axis, exact at the sixteen and for any sum cubic in u and v.
#ifndef FAR_FIELD_GLSL
#define FAR_FIELD_GLSL
#include "gpu_constants.glsl" // FAR_FIELD_TILE (8), FAR_FIELD_SAMPLES (16)
const int FAR_NODES[4] = int[](0, 2, 5, 7);

// Lagrange's basis on the nodes 0, 2, 5 and 7 at u (pixels from the tile's corner).
vec4 far_weights(float u) {
    return vec4((u - 2.0) * (u - 5.0) * (u - 7.0) / -70.0, u * (u - 5.0) * (u - 7.0) / 30.0,
                u * (u - 2.0) * (u - 7.0) / -30.0, u * (u - 2.0) * (u - 5.0) / 70.0);
}
#endif
