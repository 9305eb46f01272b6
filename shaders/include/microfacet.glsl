// The surface's own reflection: a GGX (Trowbridge–Reitz) microfacet lobe with the exact dielectric
// Fresnel reflectance, mirrored by src/physics/microfacet.rs (f64, tested against closed forms).
//   f(wi, wo) = D(h) G2(wi, wo) F(eta, wi·h) / (4 |n·wi| |n·wo|),  h = normalize(wi + wo)
//   D(h) = a² / (π ((n·h)² (a² − 1) + 1)²),  a = roughness²
//   G2 = 1 / (1 + Λ(wi) + Λ(wo)) (height-correlated Smith), Λ(w) = (√(1 + a² tan²θ) − 1) / 2
// The light that this lobe reflects is what Ft(eta, ·) keeps out of the subsurface term.
#ifndef MICROFACET_GLSL
#define MICROFACET_GLSL
#include "common.glsl"
#include "bssrdf.glsl"

float ggx_lambda(float alpha2, float cos_theta) {
    float c2 = cos_theta * cos_theta;
    return 0.5 * (sqrt(1.0 + alpha2 * (1.0 - c2) / c2) - 1.0);
}

// f(wi, wo) · cos θi for unit vectors; 0 when either side is below the surface.
float microfacet_reflect_cos(vec3 n, vec3 wi, vec3 wo, float roughness, float eta) {
    float cos_i = dot(n, wi);
    float cos_o = dot(n, wo);
    if (cos_i <= 0.0 || cos_o <= 0.0) return 0.0;
    vec3 h = normalize(wi + wo);
    float alpha2 = max(roughness * roughness * roughness * roughness, 1e-12);
    float nh = max(dot(n, h), 0.0);
    float t = nh * nh * (alpha2 - 1.0) + 1.0;
    float d = alpha2 / (PI * t * t);
    float g2 = 1.0 / (1.0 + ggx_lambda(alpha2, cos_i) + ggx_lambda(alpha2, cos_o));
    float f = fresnel_reflectance(eta, dot(wi, h));
    return d * g2 * f / (4.0 * cos_o);
}
#endif
