// Parameters of the subsurface pass. Mirrored by SubsurfaceParams in src/gpu/subsurface.rs.
#ifndef SUBSURFACE_PARAMS_GLSL
#define SUBSURFACE_PARAMS_GLSL
#include "bssrdf.glsl"
struct SubsurfaceParams {
    BssrdfChannel channels[3]; // R, G, B, per mm (constants computed in f64 on the CPU)
    float mm_per_unit;         // scene scale: positions × mm_per_unit = mm
    float epsilon;             // a node is one source when area / distance² < epsilon
    uint model;                // 0 directional dipole, 1 classical dipole
    uint brute_force;          // 1: every point, no tree
    uint point_count;
    uint node_count;
    uint count_work;           // 1: add this pixel's work to the counters (--profile)
    uint specular;             // 1: add the microfacet lobe (--no-specular: 0)
    float roughness;           // of the microfacet lobe; alpha = roughness²
    uint pad0;
    uint pad1;
    uint pad2;
};
#endif
