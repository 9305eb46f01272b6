// The BSSRDF in f32, mirroring src/physics/ (f64): exact Fresnel, the classical dipole
// (Jensen et al. 2001), the directional dipole (Frisvad et al. 2014) and the tabulated radial
// profiles (the classical dipole's, photon beam diffusion's: Habel et al. 2013). Material constants come
// precomputed in f64 on the CPU (BssrdfChannel = GpuChannel in src/gpu/subsurface.rs): the 3C2
// polynomial behind CE cancels from ~1600 to ~0.4 and must not be evaluated in f32.
// Conventions: normals outward, wi from the surface toward the light, eta = n_inside/n_outside.
#ifndef BSSRDF_GLSL
#define BSSRDF_GLSL
#include "gpu_constants.glsl"

struct BssrdfChannel {
    float eta;
    float sigma_tr;
    float d;
    float de;
    float a_dirpole;
    float c_phi;
    float c_e;
    float n_over_4pi2;
    float back_lit_dr2;
    float dipole_scale;
    float dipole_sigma_tr;
    float zr;
    float zv;
    float transports;
    float sigma_s_reduced;
    float sigma_t_reduced;
};

// Unpolarised Fresnel reflectance for relative index eta, cos_i to the normal; 1 under total
// internal reflection.
float fresnel_reflectance(float eta, float cos_i) {
    cos_i = min(abs(cos_i), 1.0);
    float sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if (sin_t2 >= 1.0) return 1.0;
    float cos_t = sqrt(1.0 - sin_t2);
    float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

float fresnel_transmittance(float eta, float cos_i) {
    return 1.0 - fresnel_reflectance(eta, cos_i);
}

// Classical dipole Sd = Rd(r)/pi, Rd = (a'/4pi)[zr(1+s dr)e^{-s dr}/dr^3 + zv(1+s dv)e^{-s dv}/dv^3].
float dipole_sd(BssrdfChannel c, float r) {
    if (c.transports == 0.0) return 0.0;
    float s = c.dipole_sigma_tr;
    float dr = sqrt(r * r + c.zr * c.zr);
    float dv = sqrt(r * r + c.zv * c.zv);
    float real_term = c.zr * (1.0 + s * dr) * exp(-s * dr) / (dr * dr * dr);
    float virtual_term = c.zv * (1.0 + s * dv) * exp(-s * dv) / (dv * dv * dv);
    return c.dipole_scale * (real_term + virtual_term) * (1.0 / 3.14159265358979323846);
}

// A radial Sd per channel from its table (mirrors gpu::SdTable; the classical dipole's or photon
// beam diffusion's): entry i holds Sd / scale (scale = the peak / 2^15, f16 stays normal down to
// 2e-9 of it) at u = i/(DIPOLE_TABLE_SIZE - 1) of u = r/(r + reach), r in mm,
// linear between entries. Texel 0 (`header`, read once) holds the scales and the reach;
// texel 1 + i holds entries i and i + 1 per channel as two f16, so a lookup is one fetch where
// the classical dipole's closed form costs 6 square roots, exponentials and divisions.
// DIPOLE_TABLE_SIZE comes from src/gpu/constants.rs. `base`: the table's first texel where
// several lie end to end (bssrdf_eval.comp), DIPOLE_TABLE_SIZE texels each.
vec4 sd_table_header_at(usamplerBuffer table, int base) { return uintBitsToFloat(texelFetch(table, base)); }
vec3 sd_table_at(usamplerBuffer table, int base, vec4 header, float r) {
    float x = r / (r + header.w) * float(DIPOLE_TABLE_SIZE - 1u);
    float i = min(floor(x), float(DIPOLE_TABLE_SIZE - 2u));
    uvec3 pairs = texelFetch(table, base + int(i) + 1).xyz;
    vec2 red = unpackHalf2x16(pairs.x), green = unpackHalf2x16(pairs.y), blue = unpackHalf2x16(pairs.z);
    return header.xyz * mix(vec3(red.x, green.x, blue.x), vec3(red.y, green.y, blue.y), x - i);
}
vec4 dipole_table_header(usamplerBuffer table) { return sd_table_header_at(table, 0); }

// A table model's angular factors after its Sd table (mirrors gpu::sd_table::AngularFactors; 1
// for the dipole and beam diffusion, the Monte Carlo table's measured ones for `mc`): texel
// DIPOLE_TABLE_SIZE + k holds the incidence factor f(θt) at node k (nodes equally spaced in
// cos θt from w, grazing entry, to 1), then per node MC_EXIT_BINS texels the exit factor
// h(θt, θo) per bin of cos²θo; linear between nodes (bin centres), as a + (b - a)t so that ones
// stay exactly 1.
vec3 table_incidence_factor(usamplerBuffer table, float cos_t) {
    int base = int(DIPOLE_TABLE_SIZE);
    float lo = uintBitsToFloat(texelFetch(table, base).w);
    float x = clamp((cos_t - lo) / (1.0 - lo), 0.0, 1.0) * float(MC_INCIDENCE_NODES - 1u);
    float i = min(floor(x), float(MC_INCIDENCE_NODES - 2u));
    vec3 a = uintBitsToFloat(texelFetch(table, base + int(i)).xyz);
    vec3 b = uintBitsToFloat(texelFetch(table, base + int(i) + 1).xyz);
    return a + (b - a) * (x - i);
}
vec3 table_exit_factor(usamplerBuffer table, float cos_t, float cos_o) {
    int base = int(DIPOLE_TABLE_SIZE);
    float lo = uintBitsToFloat(texelFetch(table, base).w);
    float x = clamp((cos_t - lo) / (1.0 - lo), 0.0, 1.0) * float(MC_INCIDENCE_NODES - 1u);
    float i = min(floor(x), float(MC_INCIDENCE_NODES - 2u));
    float y = clamp(cos_o * cos_o * float(MC_EXIT_BINS) - 0.5, 0.0, float(MC_EXIT_BINS - 1u));
    float j = min(floor(y), float(MC_EXIT_BINS - 2u));
    int row = base + int(MC_INCIDENCE_NODES) + int(i) * int(MC_EXIT_BINS) + int(j);
    vec3 a0 = uintBitsToFloat(texelFetch(table, row).xyz), b0 = uintBitsToFloat(texelFetch(table, row + 1).xyz);
    vec3 a1 = uintBitsToFloat(texelFetch(table, row + int(MC_EXIT_BINS)).xyz);
    vec3 b1 = uintBitsToFloat(texelFetch(table, row + int(MC_EXIT_BINS) + 1).xyz);
    vec3 h0 = a0 + (b0 - a0) * (y - j), h1 = a1 + (b1 - a1) * (y - j);
    return h0 + (h1 - h0) * (x - i);
}
vec3 dipole_sd_table(usamplerBuffer table, vec4 header, float r) { return sd_table_at(table, 0, header, r); }
// The same, and from the same texel the Monte Carlo table's azimuthal harmonic b(r) per channel
// (mirrors SdTable::azimuth_at, physics::mc_profile::McProfile::azimuth): light entering along a
// refracted direction whose part along the surface is m (|m| = sin θt) leaves at xo as
// M(r)·f(θt)·(1 + b(r) m·d̂), d̂ the direction from xi to xo along the surface; three 10-bit
// signed fixed-point values in [−2, 2] in the texel's w (entry ⌊x⌋'s; 0 for the other tables).
vec3 sd_table_azimuth(usamplerBuffer table, vec4 header, float r, out vec3 azimuth) {
    float x = r / (r + header.w) * float(DIPOLE_TABLE_SIZE - 1u);
    float i = min(floor(x), float(DIPOLE_TABLE_SIZE - 2u));
    uvec4 pairs = texelFetch(table, int(i) + 1);
    ivec3 b = ivec3(uvec3(pairs.w, pairs.w >> 10, pairs.w >> 20) & 0x3ffu);
    azimuth = vec3(b - ivec3(greaterThanEqual(b, ivec3(512))) * 1024) / 255.5;
    vec2 red = unpackHalf2x16(pairs.x), green = unpackHalf2x16(pairs.y), blue = unpackHalf2x16(pairs.z);
    return header.xyz * mix(vec3(red.x, green.x, blue.x), vec3(red.y, green.y, blue.y), x - i);
}
const int SLAB_BASE = int(DIPOLE_TABLE_SIZE + MC_INCIDENCE_NODES * (1u + MC_EXIT_BINS));
const float SLAB_FIRST_LOG2 = float(SLAB_FIRST_NODE_LOG2_PLUS_8) - 8.0;
vec4 slab_header_of(usamplerBuffer table) { return uintBitsToFloat(texelFetch(table, SLAB_BASE)); }
float slab_node_thickness(float k) { return exp2(0.5 * k + SLAB_FIRST_LOG2); }
vec3 slab_lookup(usamplerBuffer table, int j, float x) {
    float i = clamp(floor(x), 0.0, float(SLAB_ENTRIES - 1u));
    float f = clamp(x - i, 0.0, 1.0);
    uvec3 pairs = texelFetch(table, SLAB_BASE + 1 + j * int(SLAB_ENTRIES) + int(i)).xyz;
    vec2 red = unpackHalf2x16(pairs.x), green = unpackHalf2x16(pairs.y), blue = unpackHalf2x16(pairs.z);
    return mix(vec3(red.x, green.x, blue.x), vec3(red.y, green.y, blue.y), f);
}
vec3 slab_transmission(usamplerBuffer table, vec4 header, float rho, float t) {
    float unit_mm = header.x;
    if (!(t > 0.0) || !(unit_mm > 0.0)) return vec3(0.0);
    float x = 4.0 * (log2(t / unit_mm) - SLAB_FIRST_LOG2);
    float last = float(SLAB_LOOKUP_NODES - 1u);
    if (x >= last) return vec3(0.0);
    x = max(x, 0.0);
    float j = min(floor(x), last - 1.0);
    float reach = max(t, exp2(SLAB_FIRST_LOG2) * unit_mm) + unit_mm;
    float u = rho / (rho + reach) * float(SLAB_ENTRIES) - 0.5;
    vec3 v = mix(slab_lookup(table, int(j), u), slab_lookup(table, int(j) + 1, u), x - j);
    return header.yzw * v / (reach * reach) * (1.0 - smoothstep(last - 2.0, last, x));
}
vec3 slab_exit_factor(usamplerBuffer table, vec4 header, float t, float cos_o) {
    float unit_mm = header.x;
    float tt = max(t / unit_mm, slab_node_thickness(0.0));
    float last = float(SLAB_THICKNESS_NODES - 1u);
    float x = clamp(2.0 * (log2(tt) - (float(SLAB_FIRST_NODE_LOG2_PLUS_8) - 8.0)), 0.0, last);
    float k = min(floor(x), last - 1.0);
    float t0 = slab_node_thickness(k), t1 = slab_node_thickness(k + 1.0);
    float a = clamp((tt - t0) / (t1 - t0), 0.0, 1.0);
    float y = clamp(cos_o * cos_o * float(MC_EXIT_BINS) - 0.5, 0.0, float(MC_EXIT_BINS - 1u));
    float j = min(floor(y), float(MC_EXIT_BINS - 2u));
    int row = SLAB_BASE + 1 + int(SLAB_LOOKUP_NODES * SLAB_ENTRIES) + int(k) * int(MC_EXIT_BINS) + int(j);
    vec3 a0 = uintBitsToFloat(texelFetch(table, row).xyz), b0 = uintBitsToFloat(texelFetch(table, row + 1).xyz);
    vec3 a1 = uintBitsToFloat(texelFetch(table, row + int(MC_EXIT_BINS)).xyz);
    vec3 b1 = uintBitsToFloat(texelFetch(table, row + int(MC_EXIT_BINS) + 1).xyz);
    vec3 h0 = a0 + (b0 - a0) * (y - j), h1 = a1 + (b1 - a1) * (y - j);
    return h0 + (h1 - h0) * a;
}
// The transmitted fraction's change with incidence per channel (mirrors
// SlabChannel::oblique_factor): light refracted in at sin²θt = `sin2_t` (per channel) through
// thickness t (mm); rows q at sin²θt = q/(SLAB_OBLIQUE_ROWS − 1) of 1/η² (at most 0.9),
// linear between rows and between nodes.
vec3 slab_oblique_factor(usamplerBuffer table, vec4 header, float t, vec3 sin2_t, float eta) {
    float unit_mm = header.x;
    float tt = max(t / unit_mm, slab_node_thickness(0.0));
    float last = float(SLAB_THICKNESS_NODES - 1u);
    float x = clamp(2.0 * (log2(tt) - SLAB_FIRST_LOG2), 0.0, last);
    float k = min(floor(x), last - 1.0);
    float t0 = slab_node_thickness(k), t1 = slab_node_thickness(k + 1.0);
    float a = clamp((tt - t0) / (t1 - t0), 0.0, 1.0);
    float row_sin2 = min(1.0 / (eta * eta), 0.9) / float(SLAB_OBLIQUE_ROWS - 1u); // OBLIQUE_LARGEST_SIN2
    int base = SLAB_BASE + 1 + int(SLAB_LOOKUP_NODES * SLAB_ENTRIES + SLAB_THICKNESS_NODES * MC_EXIT_BINS)
             + int(k) * int(SLAB_OBLIQUE_ROWS);
    vec3 factor;
    for (int c = 0; c < 3; ++c) {
        float y = clamp(sin2_t[c] / row_sin2, 0.0, float(SLAB_OBLIQUE_ROWS - 1u));
        float q = min(floor(y), float(SLAB_OBLIQUE_ROWS - 2u));
        int row = base + int(q);
        float f0 = mix(uintBitsToFloat(texelFetch(table, row)[c]), uintBitsToFloat(texelFetch(table, row + 1)[c]), y - q);
        int next = row + int(SLAB_OBLIQUE_ROWS);
        float f1 = mix(uintBitsToFloat(texelFetch(table, next)[c]), uintBitsToFloat(texelFetch(table, next + 1)[c]), y - q);
        factor[c] = mix(f0, f1, a);
    }
    return factor;
}

// The slab's lit face (mirrors SlabChannel::reflected_ratio): R_slab(ρ; t)/R_hs(ρ), what a flat
// slab of thickness t lets out again through the face it was lit on over what the half-space
// does at the same ρ (light that comes back from deep in a half-space leaves a thin slab through
// its far face). After the oblique rows, per lookup node SLAB_ENTRIES texels, texel i holding
// entries i and i + 1 per channel as two f16. `slab_reflected_rows` (once per pixel, t in mm):
// x the lookup node below t, y the weight of the one above, z reach = t + L, w 1 (0: no slab,
// t past the last node or no table).
const int SLAB_REFLECTED_BASE = SLAB_BASE + 1 + int(SLAB_LOOKUP_NODES * SLAB_ENTRIES + SLAB_THICKNESS_NODES * MC_EXIT_BINS)
                              + int(SLAB_THICKNESS_NODES * SLAB_OBLIQUE_ROWS);
vec4 slab_reflected_rows(vec4 header, float t) {
    float unit_mm = header.x;
    if (!(t > 0.0) || !(unit_mm > 0.0)) return vec4(0.0);
    float x = 4.0 * (log2(t / unit_mm) - SLAB_FIRST_LOG2);
    float last = float(SLAB_LOOKUP_NODES - 1u);
    if (!(x < last)) return vec4(0.0);
    x = max(x, 0.0);
    float j = min(floor(x), last - 1.0);
    return vec4(j, x - j, max(t, exp2(SLAB_FIRST_LOG2) * unit_mm) + unit_mm, 1.0);
}
vec3 slab_reflected_at(usamplerBuffer table, int j, float x) {
    float i = clamp(floor(x), 0.0, float(SLAB_ENTRIES - 1u));
    float f = clamp(x - i, 0.0, 1.0);
    uvec3 pairs = texelFetch(table, SLAB_REFLECTED_BASE + j * int(SLAB_ENTRIES) + int(i)).xyz;
    vec2 red = unpackHalf2x16(pairs.x), green = unpackHalf2x16(pairs.y), blue = unpackHalf2x16(pairs.z);
    return mix(vec3(red.x, green.x, blue.x), vec3(red.y, green.y, blue.y), f);
}
vec3 slab_reflected_ratio(usamplerBuffer table, vec4 rows, float rho) {
    if (rows.w == 0.0) return vec3(1.0);
    float u = rho / (rho + rows.z) * float(SLAB_ENTRIES) - 0.5;
    return mix(slab_reflected_at(table, int(rows.x), u), slab_reflected_at(table, int(rows.x) + 1, u), rows.y);
}

// The Monte Carlo table's curvature ratios (mirrors gpu::sd_table::CurvatureRatios::lookup,
// physics::curvature_profile::CurvatureChannel::ratio): C(r; κ), a sphere's (κ = 1/R > 0) or a
// cavity's (κ < 0) multiple scattering over the half-space's at chord r, multiplying Sp(r).
// After the light across: texel CURVATURE_BASE holds L (mm; 0: no ratios), then per angle of
// incidence (CURVATURE_INCIDENCES, sin²θi 0, CURVATURE_SIN2_PERCENT_1/100, …_2/100) per side (convex,
// concave) CURVATURE_NODES rows of CURVATURE_TABLE_ENTRIES texels at the centres of
// u = s/(s + 1), s = r|κ| the chord relative to the ball's radius, row j's texel holding per
// channel the ratios of nodes j − 1 (−1: flat, 1) and j (κ_j L = 2^(j + first)) at the same s
// (each node read at the same place on its own ball) as two f16. `curvature_rows` (once per
// pixel): the row of κ (1/mm) and the weight of its upper node, linear in κ from flat to node 0
// and in log κ between nodes, held past the last; z = |κ| (the last node's past it), w = L (0 and
// x = −1: no ratios).
// `curvature_ratio` (per pair): the nearest entry of the two rows of incidence around the pair's
// sin²θi (two fetches), linear in sin²θi between them per channel, held past the last.
const int CURVATURE_BASE = SLAB_REFLECTED_BASE + int(SLAB_LOOKUP_NODES * SLAB_ENTRIES);
const float CURVATURE_FIRST_LOG2 = float(CURVATURE_FIRST_LOG2_PLUS_8) - 8.0;
vec4 curvature_rows_at(float unit_mm, float kappa);
vec4 curvature_rows(usamplerBuffer table, float kappa) {
    return curvature_rows_at(uintBitsToFloat(texelFetch(table, CURVATURE_BASE).x), kappa);
}
// The same with L (texel CURVATURE_BASE, the rows' w) already read: per pair, no fetch.
vec4 curvature_rows_at(float unit_mm, float kappa) {
    if (!(unit_mm > 0.0)) return vec4(-1.0, 0.0, 0.0, 0.0);
    float x = abs(kappa) * unit_mm;
    if (!(x >= 0.0)) x = 0.0; // NaN: flat
    float side = kappa < 0.0 ? float(CURVATURE_NODES) : 0.0;
    float first = exp2(CURVATURE_FIRST_LOG2);
    if (x < first) return vec4(side, x / first, x / unit_mm, unit_mm);
    float k = min(log2(x) - CURVATURE_FIRST_LOG2, float(CURVATURE_NODES - 1u));
    float i = min(floor(k), float(CURVATURE_NODES - 2u));
    // Past the last node its row is read at its own r·κ (mirrors CurvatureChannel::ratio).
    float held = min(x, exp2(CURVATURE_FIRST_LOG2 + float(CURVATURE_NODES - 1u)));
    return vec4(side + i + 1.0, k - i, held / unit_mm, unit_mm);
}
const int CURVATURE_INCIDENCE_ROWS = 2 * int(CURVATURE_NODES * CURVATURE_TABLE_ENTRIES);
vec3 curvature_ratio(usamplerBuffer table, vec4 rows, float r_mm, vec3 sin2_i) {
    if (rows.x < 0.0) return vec3(1.0);
    float s = r_mm * rows.z;
    int e = min(int(s / (s + 1.0) * float(CURVATURE_TABLE_ENTRIES)), int(CURVATURE_TABLE_ENTRIES) - 1);
    // Two rows of incidence, bracketing the channels' mean sin²θi (one light: every channel's);
    // each channel's weight between them clamped (mirrors CurvatureRatios::lookup; NaN: normal).
    const float s1 = float(CURVATURE_SIN2_PERCENT_1) / 100.0, s2 = float(CURVATURE_SIN2_PERCENT_2) / 100.0;
    vec3 q = mix(vec3(0.0), sin2_i, equal(sin2_i, sin2_i));
    bool upper = (q.x + q.y + q.z) / 3.0 >= s1;
    vec3 weight = upper ? clamp((q - s1) / (s2 - s1), 0.0, 1.0) : clamp(q / s1, 0.0, 1.0);
    int t = CURVATURE_BASE + 1 + (upper ? CURVATURE_INCIDENCE_ROWS : 0) + int(rows.x) * int(CURVATURE_TABLE_ENTRIES) + e;
    vec3 at[2];
    for (int j = 0; j < 2; ++j) {
        uvec3 pairs = texelFetch(table, t + j * CURVATURE_INCIDENCE_ROWS).xyz;
        vec2 red = unpackHalf2x16(pairs.x), green = unpackHalf2x16(pairs.y), blue = unpackHalf2x16(pairs.z);
        at[j] = mix(vec3(red.x, green.x, blue.x), vec3(red.y, green.y, blue.y), rows.y);
    }
    return mix(at[0], at[1], weight);
}

// The exit distribution's curvature ratio (mirrors gpu::sd_table::CurvatureRatios::lookup_exit,
// physics::curvature_profile::CurvatureChannel::exit_ratio), multiplying the exit factor h: after
// the ratio rows, per angle of incidence per side the same pairing of nodes in rows of
// MC_EXIT_BINS texels, then the same rows of the light from beyond a chord R√2; linear in
// cos²θo between the bins' centres, held beyond the outer ones. `rows` from curvature_rows;
// `far` the far light's share; `sin2_i` the light's mean sin²θi where it entered, linear
// between the rows of incidence (held past the last).
const int CURVATURE_EXIT_ROWS = 4 * int(CURVATURE_NODES * MC_EXIT_BINS); // per angle of incidence
vec3 curvature_exit(usamplerBuffer table, vec4 rows, float cos_o, float far, float sin2_i) {
    if (rows.x < 0.0) return vec3(1.0);
    const float s1 = float(CURVATURE_SIN2_PERCENT_1) / 100.0, s2 = float(CURVATURE_SIN2_PERCENT_2) / 100.0;
    float q = sin2_i >= 0.0 ? sin2_i : 0.0; // NaN: normal incidence
    bool upper = q >= s1;
    float weight = upper ? clamp((q - s1) / (s2 - s1), 0.0, 1.0) : clamp(q / s1, 0.0, 1.0);
    int base = CURVATURE_BASE + 1 + int(CURVATURE_INCIDENCES) * CURVATURE_INCIDENCE_ROWS
             + (upper ? CURVATURE_EXIT_ROWS : 0) + int(rows.x) * int(MC_EXIT_BINS);
    float y = clamp(cos_o * cos_o * float(MC_EXIT_BINS) - 0.5, 0.0, float(MC_EXIT_BINS - 1u));
    float j = min(floor(y), float(MC_EXIT_BINS - 2u));
    vec3 at[8];
    for (int k = 0; k < 8; ++k) {
        int far_rows = ((k / 2) % 2) * 2 * int(CURVATURE_NODES * MC_EXIT_BINS) + (k / 4) * CURVATURE_EXIT_ROWS;
        uvec3 pairs = texelFetch(table, base + far_rows + int(j) + k % 2).xyz;
        vec2 red = unpackHalf2x16(pairs.x), green = unpackHalf2x16(pairs.y), blue = unpackHalf2x16(pairs.z);
        at[k] = mix(vec3(red.x, green.x, blue.x), vec3(red.y, green.y, blue.y), rows.y);
    }
    vec3 lower_row = mix(mix(at[0], at[1], y - j), mix(at[2], at[3], y - j), far);
    vec3 upper_row = mix(mix(at[4], at[5], y - j), mix(at[6], at[7], y - j), far);
    return mix(lower_row, upper_row, weight);
}

// The Monte Carlo table's terms per distance r after the curvature rows, at one entry for both
// (the nearest of EXIT_TILT_ENTRIES at the centres of u = r/(r + L); `unit_mm` = L, 0: none, the
// other models, and all four 0): the exit tilt [c, g] per channel (mirrors
// gpu::sd_table::CurvatureRatios::exit_tilt_at, physics::mc_profile::McProfile::exit_tilt_at),
// then, EXIT_TILT_ENTRIES texels on, the lean's higher azimuthal harmonics [b₂, b₃]
// (CurvatureRatios::harmonics_at, McProfile::higher_harmonics), then as many on the radial
// profile's change with incidence [a, 0] (CurvatureRatios::radial_at, McProfile::radial_at);
// each texel f16 pairs (x_r, x_g), (x_b, y_r), (y_g, y_b). `with_tilt` false: the tilt is not
// fetched (no exit direction) and is 0.
const int EXIT_TILT_BASE =
    CURVATURE_BASE + 1 + int(CURVATURE_INCIDENCES) * (CURVATURE_INCIDENCE_ROWS + CURVATURE_EXIT_ROWS);
// Six f16 of texel `t` as two vec3: (a_r, a_g), (a_b, b_r), (b_g, b_b).
void two_rgb_halves(usamplerBuffer table, int t, out vec3 a, out vec3 b) {
    uvec3 pairs = texelFetch(table, t).xyz;
    vec2 p = unpackHalf2x16(pairs.x), q = unpackHalf2x16(pairs.y), w = unpackHalf2x16(pairs.z);
    a = vec3(p.x, p.y, q.x);
    b = vec3(q.y, w.x, w.y);
}
void exit_terms(usamplerBuffer table, float unit_mm, float r_mm, bool with_tilt, out vec3 c, out vec3 g, out vec3 b2,
                out vec3 b3, out vec3 a) {
    c = g = b2 = b3 = a = vec3(0.0);
    if (!(unit_mm > 0.0)) return;
    int t = EXIT_TILT_BASE + min(int(r_mm / (r_mm + unit_mm) * float(EXIT_TILT_ENTRIES)), int(EXIT_TILT_ENTRIES) - 1);
    if (with_tilt) two_rgb_halves(table, t, c, g);
    two_rgb_halves(table, t + int(EXIT_TILT_ENTRIES), b2, b3);
    vec3 unused;
    two_rgb_halves(table, t + 2 * int(EXIT_TILT_ENTRIES), a, unused);
}

// After the exit tilt, the object's inside (mesh::occupancy, the Monte Carlo table only): from
// texel `base` (OCCUPANCY_BASE in an object's table) the grid's corner and 1 (0: no grid), its
// cell size, then one bit per cell, x fastest, four words a texel.
const int OCCUPANCY_BASE = EXIT_TILT_BASE + 3 * int(EXIT_TILT_ENTRIES);
// The bits of one grid, in texels (mesh::occupancy::GRID_TEXELS): the grown grid's, then the
// cell centres' (before it was grown).
const int OCCUPANCY_GRID_TEXELS = int(OCCUPANCY_CELLS * OCCUPANCY_CELLS * OCCUPANCY_CELLS / 128u);
// Whether cell `at` (in cells from the corner, floored here) of the grid whose bits start at
// texel `bits` is set; outside the grid no.
bool grid_bit(usamplerBuffer table, int bits, vec3 at) {
    vec3 c = floor(at);
    if (any(lessThan(c, vec3(0.0))) || any(greaterThanEqual(c, vec3(float(OCCUPANCY_CELLS))))) return false;
    uint bit = uint(c.x) + OCCUPANCY_CELLS * (uint(c.y) + OCCUPANCY_CELLS * uint(c.z));
    uint word = texelFetch(table, bits + int(bit >> 7u))[(bit >> 5u) & 3u];
    return (word & (1u << (bit & 31u))) != 0u;
}
// Whether grid cell `at` is inside (the grown grid); outside the grid no.
bool occupied(usamplerBuffer table, int base, vec3 at) {
    return grid_bit(table, base + 2, at);
}
// Whether grid cell `at` has its centre inside (the grid before it was grown: the air's test).
bool centre_occupied(usamplerBuffer table, int base, vec3 at) {
    return grid_bit(table, base + 2 + OCCUPANCY_GRID_TEXELS, at);
}
// The grid's corner (w: 1, or 0 where there is none) and cell size, read once per pixel.
struct Occupancy {
    vec4 corner;
    vec3 cell;
};
Occupancy occupancy_header(usamplerBuffer table, int base) {
    return Occupancy(uintBitsToFloat(texelFetch(table, base)), uintBitsToFloat(texelFetch(table, base + 1).xyz));
}
// Whether light can go from a to b (scene units) inside the object (Occupancy::through_medium):
// along an arc that sags into it by a quarter of the chord's length at its middle, toward
// −(na + nb)/2 (na, nb the ends' normals; no sag where they face each other), tested at 1/4, 1/2
// and 3/4 of the way. Light that dips under a hollow of the surface goes that way at most 17%
// further than the chord; where the arc is in air too (an ear beside the other, across a
// torus's hole) it has no short way. A chord shorter than two cells, or no grid: yes. Written
// out, not looped (llvmpipe's loop budget, see shade.frag).
bool through_medium(usamplerBuffer table, int base, Occupancy grid, vec3 a, vec3 na, vec3 b, vec3 nb) {
    if (grid.corner.w == 0.0) return true;
    vec3 start = (a - grid.corner.xyz) / grid.cell, d = (b - a) / grid.cell;
    if (dot(d, d) < 4.0) return true;
    vec3 sag = (-0.25 * 0.5 * length(b - a)) * (na + nb) / grid.cell;
    return occupied(table, base, start + d * 0.5 + sag) && occupied(table, base, start + d * 0.25 + 0.75 * sag)
        && occupied(table, base, start + d * 0.75 + 0.75 * sag);
}
// Whether light goes from xi to xo inside the object (mesh::occupancy::joined_inside). A chord
// that leaves neither end's surface (xo − xi below xi's tangent plane and above xo's, as every
// pair of a convex object) is inside; leaving by less than ~3° is a face's round-off or its
// facets, not air (the box's faces). One that leaves either is tested (through_medium): where
// even an arc sagging into the object crosses air (an ear beside the other, across a torus's
// hole, a paw and the chest above it) light that stays in the medium has no short way, and the
// path tracer's light that exits once has none of it. (The straight chord alone was too strict:
// on a bumpy front-lit surface the chords between bumps graze the air, and the Skin1 bunny under
// a far point light lost 7% of its red.)
bool joined_inside(usamplerBuffer table, int base, Occupancy grid, vec3 xi, vec3 ni, vec3 xo, vec3 no) {
    vec3 d = xo - xi;
    float lean = 0.05 * length(d);
    if (dot(d, ni) <= lean && dot(d, no) >= -lean) return true;
    return through_medium(table, base, grid, xi, ni, xo, no);
}

// The ray-source term S'(x, w, r) of the directional dipole.
float dirpole_source(BssrdfChannel c, vec3 x, vec3 w, float r, vec3 no) {
    float s_r = c.sigma_tr * r;
    float one = 1.0 + s_r;
    float x_dot_w = dot(x, w);
    float phi = c.c_phi * (r * r / c.d + 3.0 * one * x_dot_w);
    float e = c.c_e * (3.0 * c.d * one * dot(w, no)
                       - (one + 3.0 * c.d * (3.0 * one + s_r * s_r) / (r * r) * x_dot_w) * dot(x, no));
    return c.n_over_4pi2 * exp(-s_r) / (r * r * r) * (phi - e);
}

// Light refracted into the medium: w12 = -(1/eta)(wi - (wi.ni)ni) - ni sqrt(1 - (1/eta)^2 (1 - (wi.ni)^2)).
vec3 refract_in(vec3 wi, vec3 ni, float eta) {
    float cos_i = dot(wi, ni);
    float k = max(1.0 - (1.0 - cos_i * cos_i) / (eta * eta), 0.0);
    return -(wi - cos_i * ni) / eta - ni * sqrt(k);
}

// What the directional dipole needs of a (xi, ni, wi; xo, no) query that does not depend on the
// channel's coefficients: computed once and shared by the three channels of a source.
struct DirpoleGeometry {
    vec3 x;       // xo - xi
    float r2;
    vec3 w12;     // refracted light direction
    float mu0;    // -no . w12
    vec3 ni_star; // normal of the modified tangent plane
    vec3 wv;      // virtual source direction
};

// The geometry for a refracted direction w12 given directly: a light's own (unit), or a merged
// record's irradiance-weighted mean of several (PointFlux in points.glsl; shorter than 1).
DirpoleGeometry dirpole_geometry_refracted(vec3 xi, vec3 ni, vec3 w12, vec3 xo, vec3 no) {
    DirpoleGeometry g;
    g.x = xo - xi;
    g.r2 = dot(g.x, g.x);
    g.w12 = w12;
    // Modified tangent plane: the part of ni normal to x; ni where x is zero or parallel to ni.
    vec3 perp = ni - g.x * (dot(g.x, ni) / max(g.r2, 1e-30));
    g.ni_star = (g.r2 > 0.0 && dot(perp, perp) > 1e-12) ? normalize(perp) : ni;
    g.mu0 = -dot(no, g.w12);
    g.wv = g.w12 - 2.0 * dot(g.w12, g.ni_star) * g.ni_star;
    return g;
}

// The same geometry for another refracted direction (the channel-independent parts kept).
DirpoleGeometry with_refracted(DirpoleGeometry g, vec3 w12, vec3 no) {
    g.w12 = w12;
    g.mu0 = -dot(no, w12);
    g.wv = w12 - 2.0 * dot(w12, g.ni_star) * g.ni_star;
    return g;
}

DirpoleGeometry dirpole_geometry(vec3 xi, vec3 ni, vec3 wi, vec3 xo, vec3 no, float eta) {
    return dirpole_geometry_refracted(xi, ni, refract_in(wi, ni, eta), xo, no);
}

// Real and virtual source terms of one channel; Sd = max(0, real - virtual).
void dirpole_channel_terms(BssrdfChannel c, DirpoleGeometry g, vec3 xi, vec3 xo, vec3 no,
                           out float real_term, out float virtual_term) {
    real_term = 0.0;
    virtual_term = 0.0;
    if (c.transports == 0.0) return;
    float dr2;
    if (g.mu0 > 0.0) {
        float along = dot(g.x, g.w12);
        float cos_beta = -sqrt(max(g.r2 - along * along, 0.0) / (g.r2 + c.de * c.de));
        dr2 = g.r2 + c.d * g.mu0 * (c.d * g.mu0 - 2.0 * c.de * cos_beta);
    } else {
        dr2 = g.r2 + c.back_lit_dr2;
    }
    float dr = sqrt(max(dr2, 1e-24 * c.d * c.d));

    // Virtual source, mirrored in the modified tangent plane.
    vec3 xv = xi + (2.0 * c.a_dirpole * c.de) * g.ni_star;
    vec3 xov = xo - xv;
    float dv = length(xov);

    real_term = dirpole_source(c, g.x, g.w12, dr, no);
    virtual_term = dirpole_source(c, xov, g.wv, dv, no);
}

float dirpole_channel_sd(BssrdfChannel c, DirpoleGeometry g, vec3 xi, vec3 xo, vec3 no) {
    float real_term, virtual_term;
    dirpole_channel_terms(c, g, xi, xo, no, real_term, virtual_term);
    float v = real_term - virtual_term;
    // Also maps NaN to 0: a comparison with NaN is false.
    return (v > 0.0 && v < 3.4e38) ? v : 0.0;
}

void dirpole_terms(BssrdfChannel c, vec3 xi, vec3 ni, vec3 wi, vec3 xo, vec3 no,
                   out float real_term, out float virtual_term) {
    dirpole_channel_terms(c, dirpole_geometry(xi, ni, wi, xo, no, c.eta), xi, xo, no, real_term, virtual_term);
}

float dirpole_sd(BssrdfChannel c, vec3 xi, vec3 ni, vec3 wi, vec3 xo, vec3 no) {
    return dirpole_channel_sd(c, dirpole_geometry(xi, ni, wi, xo, no, c.eta), xi, xo, no);
}

#endif
