// The per-tile source lists of the tile-cut pass (shaders/tile_cut.comp), read by the shade pass.
// Mirrored by src/passes/tile_cut.rs (TILE_SIZE, WALK_FROM_ROOT; a test compares them).
// Header per tile: (first entry, point entries, node entries, frontier entries); the entries of
// a tile are its points, then its nodes, then its frontier nodes, from `first` on.
#ifndef TILE_LISTS_GLSL
#define TILE_LISTS_GLSL
// Pixels per tile side: 8x8 = 64 pixels, a multiple of llvmpipe's 4x4 fragment blocks and of a
// GPU warp or wave.
const uint TILE_SIZE = 8u;
// A header's frontier count meaning "no list: every pixel walks from the root" (the list did not
// fit in the buffer this frame).
const uint WALK_FROM_ROOT = 0xffffffffu;
// Steps of one tile's walk in the cut pass (it walks twice; llvmpipe ends an invocation's loops
// after ~65k iterations in total).
const uint MAX_CUT_STEPS = 24000u;
// Evaluations in one tile's list (the shade pass loops once per evaluation), past which the cut
// pass uses nodes whole.
const uint MAX_LIST_EVALUATIONS = 16384u;
#endif
