// The per-tile source lists of the tile-cut pass (shaders/tile_cut.comp), read by the shade pass.
// Header per tile: (first entry, point entries | the near field's point entries << 16, node
// entries, NEAR_FIELD_TILE (some pixel of the tile lit: the list is for the near field), 0 (none
// is: no pixel runs it) or WALK_FROM_ROOT); the entries of a tile are its points (those within the near
// field's reach of the tile first), then its nodes, from `first` on; then, in a tile with a far
// field, its far points and far nodes (tile_cut.comp's far_headers, read by far_field.comp only). WALK_FROM_ROOT,
// NEAR_FIELD_TILE, MAX_CUT_STEPS and MAX_LIST_EVALUATIONS come from src/gpu/constants.rs.
#ifndef TILE_LISTS_GLSL
#define TILE_LISTS_GLSL
#include "gpu_constants.glsl"
#endif
