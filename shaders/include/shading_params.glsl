// The shading passes' two parameter blocks: one per object (its material and its tree's size),
// one per frame (how the frame integrates). Mirrored by ObjectParams and FrameParams in
// src/gpu/subsurface.rs (checked by tests/layouts.rs).
#ifndef SHADING_PARAMS_GLSL
#define SHADING_PARAMS_GLSL
#include "bssrdf.glsl"
struct ObjectParams {
    BssrdfChannel channels[3]; // R, G, B, per mm (constants computed in f64 on the CPU)
    float mm_per_unit;         // scene scale: positions × mm_per_unit = mm
    uint point_count;
    uint node_count;
    float spacing_mm;          // the sample points' spacing: sqrt(area / point_count), mm
    // The near field (shade.frag): sources are weighted by w(r), a smoothstep from 0 at
    // near_start_mm to 1 at near_end_mm, and the pixel's own irradiance times
    // ∫(1 - w) Sd dA over its tangent plane is added. near_scale_mm is the length the
    // quadrature's inner radii are graded by (the smallest diffusion coefficient D).
    float near_start_mm;
    float near_end_mm;
    float near_scale_mm;
    float pad0;
};
struct FrameParams {
    float epsilon;             // a node is one source when area / distance² < epsilon
    uint brute_force;          // 1: every point, no tree
    uint count_work;           // 1: add this pixel's work to the counters (--profile)
    uint specular;             // 1: add the microfacet lobe (--no-specular: 0)
    float roughness;           // of the microfacet lobe; alpha = roughness²
    uint near_field;           // 1: split each pixel's sum into the near field and the far (see ObjectParams)
    uint far_field;            // 1: sources far from an 8x8 tile are summed at nine of its pixels (far_field.comp)
    uint scattering;           // the Monte Carlo table's terms: 0 both, 1 single scattering alone, 2 multiple alone
};
#endif
