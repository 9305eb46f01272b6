// Light that leaves the object and enters it again (passes/reentry.rs): what the three stages
// share. The object's sorted points are cut into `patch_count` runs of `stride` points along the
// Morton curve (the last run takes the rest), each a patch about √(area / patches) across; a
// patch is read at its run's middle point. Mirrored by ReentryConstants in src/passes/reentry.rs
// (tests/layouts.rs compares the offsets).
#ifndef REENTRY_GLSL
#define REENTRY_GLSL
layout(push_constant) uniform ReentryConstants {
    uint patch_count;
    uint stride;       // points per patch (the last one: the rest too)
    uint point_count;
    float epsilon;     // the exitance walk's: a node is whole when area < epsilon · distance²
    // The exitance's own part: per channel ∫ (1 − w(r)) Sd(r) 2πr dr over the half-space's flat
    // profile, w rising from 0 at half the reach to 1 at the reach (w, mm); the sources within
    // the reach are weighed by w.
    vec4 near;
    float exit_integral; // ∫ Ft(θo) cos θo dω: a source's exitance per unit of Sd · power
    float patch_area;    // scene units²
    float eta;
    float patch_spacing; // √patch_area, scene units
} pc;

// The sorted point a patch is read at: its run's middle.
uint patch_point(uint k) {
    return k * pc.stride + pc.stride / 2u;
}
#endif
