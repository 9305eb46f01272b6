// The BSSRDF's sources as the shade pass (shade.frag) and the far-field pass (far_field.comp)
// evaluate them, so that both compute the same sum: points and nodes of the tree, every light
// merged into one record per source (PointFlux, NodeFlux), through the model fixed per pipeline.
// The including shader declares, before including this file: the specialisation constants MODEL
// and ONE_LIGHT, `object_params` (ObjectParams), and the texel buffers `nodes`, `points`,
// `node_flux`, `point_flux`, `point_spread` and `dipole_table`; and calls begin_sources() once per
// pixel before any source.
#ifndef SOURCES_GLSL
#define SOURCES_GLSL
#include "common.glsl"
vec4 dipole_header; // its texel 0, read once per pixel
vec4 slab_header; // the Monte Carlo table's slab header (L in mm, scales), read once per pixel (0 for the other models)
Occupancy object_inside; // the grid of the object's inside (its corner's w 0: none), read once per pixel
// The Monte Carlo table's curvature rows at the pixel's mean curvature (curvature_rows), smoothed
// over the longest diffusion length: the exit's distribution, the light across, and the near
// field's tangent plane read it. Each source is read at its pair's own curvature (pair_curvature).
vec4 pixel_curvature_rows;
float pixel_curvature_mm = 0.0;
// Where the object is a thin sheet under the pixel (an ear), the Monte Carlo table's half-space
// gives back light that a sheet lets out of its far face: each pair is read times the slab's lit
// face over the half-space's (slab_reflected_ratio) at the sheet's thickness under the pixel
// (thickness_below), weighed by thin_weight (set by begin_thickness; 0: none).
vec4 thin_rows = vec4(0.0);
float thin_weight = 0.0;
float thin_mm = 0.0; // the sheet's thickness

// The curvature of the surface between a source (xi, ni) and the pixel (xo, no) along the way
// from one to the other (mirrors physics::curvature_profile::pair_curvature): κ = (no − ni)·d/|d|²,
// d = xo − xi in mm; on a sphere of radius R exactly 1/R for every pair, 0 between points of one
// plane, negative in a cavity. The light between two points bends with the surface along their
// way, not across it: a cylinder's exits around its bend are a ball's of its radius, along its
// axis the half-space's (examples/cylinder_walk), so each pair is read as on the ball of its own
// curvature. (The pixel's mean curvature read every pair of the pixel alike: a box's faces, flat,
// lost the light that turns its edges, 0.53 of the path tracer in green.)
// The light of the object's sources, by luminance: x from beyond a chord R√2 of the pair's ball
// (rκ ≥ √2: the far hemisphere of a ball, none on a plane), y all of it. It leaves nearer the
// normal (curvature_exit's far rows), weighed by x/y per pixel.
// And the light's sin²θi where it entered, by luminance (Σ luminance·sin²θi, Σ luminance): the
// exit's rows are read at its mean (curvature_exit). The far-field pass's sources are taken at
// the mean of the rest (its samples carry the far share only).
vec2 far_light = vec2(0.0);
vec2 entry_incidence = vec2(0.0);
void count_far(float r_kappa, vec3 contribution, float sin2_i) {
    float luminance = dot(contribution, LUMINANCE);
    far_light += vec2(r_kappa >= 1.41421356 ? luminance : 0.0, luminance);
    entry_incidence += vec2(luminance * sin2_i, luminance);
}
// sin²θi of light from `toward` (the direction toward it, unit or a mean) at a source of normal ni.
float entry_sin2(vec3 toward, vec3 ni) {
    float along = dot(toward, ni);
    return clamp(dot(toward, toward) - along * along, 0.0, 1.0);
}

float pair_curvature(vec3 d, vec3 ni, vec3 no) {
    float r2 = dot(d, d);
    return r2 > 0.0 ? dot(no - ni, d) / r2 : pixel_curvature_mm;
}

// The curvature a source of the object at (xi, ni) is read at from the pixel (xo, no): its
// pair's. The near field's tangent plane stands for the surface around the pixel and takes the
// pixel's (pixel_curvature_mm).
float source_curvature(vec3 xi, vec3 ni, vec3 xo, vec3 no) {
    return pair_curvature((xo - xi) * object_params.mm_per_unit, ni, no);
}

// The same for a node's sigma point at xi = c + offset: it stands for points of the surface
// around c, whose normals turn with it, but lies in c's tangent plane with the node's one normal.
// Paired with that normal, its curvature moved against its distance, so r·κ (where the ratio is
// read) stayed the centre's for both sigma points (green +0.8% on the 10 mm Skin1 sphere against
// brute force over the same points). Its normal is turned as the surface turns around the pixel
// (its mean curvature κ: n + κ·offset, a ball's); on a flat face (κ = 0) it stays the node's,
// exact there (paired from c instead, the slab's edges lost 0.6% in green).
float sigma_point_curvature(vec3 xi, vec3 ni, vec3 offset, vec3 xo, vec3 no) {
    vec3 turned = ni + (pixel_curvature_mm * object_params.mm_per_unit) * offset;
    return source_curvature(xi, dot(turned, turned) > 0.0 ? normalize(turned) : ni, xo, no);
}

// Which way the Monte Carlo table's light leaves the pixel (McProfile::exit_tilt): the eye's
// direction along the pixel's surface, wo − (wo·no)no (|exit_along| = sin θo; 0: no tilt), and
// the pixel's normal, set per pixel (shade.frag) or per far-field sample (far_field.comp).
vec3 exit_along = vec3(0.0);
vec3 exit_normal = vec3(0.0, 0.0, 1.0);

// The Monte Carlo table's multiple scattering at xo from a source at (xi, ni) lit from the mean
// directions `toward[c]` (per channel, toward the lights, per unit power): Sp(r) times the
// azimuthal harmonics of the light's lean, 1 + b x + b₂(2x² − s²) + b₃(4x³ − 3xs²) ≥ 0
// (McProfile::lean: sin θt cos φ, sin²θt cos 2φ and sin³θt cos 3φ written in m), x = m·d̂ and
// s² = |m|², m = −(toward's part along the surface)/η the refracted direction's part along it
// (|m| = sin θt for one light, shorter where lights differ) and d̂ the direction to xo along
// xi's surface (so m·d̂ = −toward·d̂/η), times the
// curvature ratio at curvature `kappa` (1/mm); r = |d|, d = xo − xi in mm. Times the exit's tilt
// toward the eye, 1 + c(r) ωt·â + g(r) ωt·m (ωt = exit_along, â the way along the pixel's
// surface away from the source): light leaves leaning away from where it entered, and near an
// oblique entry back toward its light. Without it a front-lit 10 mm Skin1 ball's rim was 1.2-1.3x
// the exact walk's radiance toward the eye, and a back-lit one's 0.6-0.8x (tests/exit_tilt.rs).
vec3 mc_sd(vec3 d, vec3 ni, float kappa, vec3 toward[3]) {
    float r = length(d);
    vec3 tangential = d - dot(d, ni) * ni;
    float len = length(tangential);
    float eta = object_params.channels[0].eta;
    float scale = len > 0.0 ? -1.0 / (eta * len) : 0.0;
    vec3 lean = scale * vec3(dot(toward[0], tangential), dot(toward[1], tangential), dot(toward[2], tangential));
    // |m|² per channel (0 where the pair has no direction along the surface: no harmonic).
    vec3 m2 = len > 0.0 ? vec3(dot(toward[0], toward[0]) - dot(toward[0], ni) * dot(toward[0], ni),
                               dot(toward[1], toward[1]) - dot(toward[1], ni) * dot(toward[1], ni),
                               dot(toward[2], toward[2]) - dot(toward[2], ni) * dot(toward[2], ni)) / (eta * eta)
                        : vec3(0.0);
    vec3 b, b2, b3, c, g, a;
    vec3 sd = sd_table_azimuth(dipole_table, dipole_header, r, b);
    bool tilted = exit_along != vec3(0.0);
    exit_terms(dipole_table, pixel_curvature_rows.w, r, tilted, c, g, b2, b3, a);
    vec3 tilt = vec3(1.0);
    if (tilted) {
        vec3 away = d - dot(d, exit_normal) * exit_normal;
        float away_len = length(away);
        float radial = away_len > 0.0 ? dot(exit_along, away) / away_len : 0.0;
        // ωt·m per channel (m = −(toward − (toward·ni)ni)/η; ωt lies in the pixel's plane).
        vec3 ahead = (-1.0 / eta) * vec3(dot(exit_along, toward[0] - dot(toward[0], ni) * ni),
                                         dot(exit_along, toward[1] - dot(toward[1], ni) * ni),
                                         dot(exit_along, toward[2] - dot(toward[2], ni) * ni));
        tilt = max(vec3(1.0) + c * radial + g * ahead, vec3(0.0));
    }
    // The radial change with incidence (1 + a sin²θt) times the harmonics (McProfile::lean).
    vec3 harmonics = (vec3(1.0) + a * m2)
                   * (vec3(1.0) + b * lean + b2 * (2.0 * lean * lean - m2) + b3 * (4.0 * lean * lean - 3.0 * m2) * lean);
    // Every source within the sheet, bent or not (light that goes along a thin sheet leaks out of
    // both its faces however the sheet bends: weighed by ni·no instead, the Marble bunny's ears
    // stayed 1.16x the path tracer's one-exit route), none from deeper behind the pixel's tangent
    // plane than twice the sheet's thickness: that light comes through a thicker body (the
    // bunny's chest above its shadowed paw, which the sheet's ratio drew black).
    float depth = dot(d, exit_normal);
    float along_face = thin_weight > 0.0 ? thin_weight * (1.0 - smoothstep(thin_mm, 2.0 * thin_mm, depth)) : 0.0;
    vec3 thin = along_face > 0.0 ? mix(vec3(1.0), slab_reflected_ratio(dipole_table, thin_rows, r), along_face)
                                 : vec3(1.0);
    return sd * max(harmonics, vec3(0.0)) * tilt * thin
        * curvature_ratio(dipole_table, curvature_rows_at(pixel_curvature_rows.w, kappa), r, (eta * eta) * m2);
}

// Points nearer than this many diffusion lengths (1/σtr) of the farthest-reaching channel are
// evaluated in sigma directions (PointSpread).
const float SIGMA_DIRECTIONS_REACH = 2.0;

// The Monte Carlo table's light across the object (physics::slab_profile): a source whose
// normal faces away from the pixel's (w = −ni·no > 0) and lies behind the pixel's tangent plane
// is read as across a flat slab of thickness t = (xo − xi)·no, at lateral distance ρ, in
// S = (1 − w) Sp(r) + w T(ρ; t): this returns (1 − w) times the half-space's `sd` and adds
// w T · `power_mm` to across_sum, and its luminance-weighted thickness to across_thickness and
// sin²θt of the light refracted in at xi (`sin2_t`, per channel) to across_incidence (the exit
// factor h_T and the change of what a slab lets through with incidence are read once per
// pixel at their means, main()).
vec3 across_sum = vec3(0.0);
vec2 across_thickness = vec2(0.0); // Σ t·luminance, Σ luminance
vec3 across_incidence = vec3(0.0); // Σ sin²θt·luminance per channel
vec3 across(vec3 xi, vec3 ni, vec3 xo, vec3 no, vec3 sd, vec3 power_mm, vec3 sin2_t) {
    float w = -dot(ni, no);
    if (w <= 0.0) return sd;
    float s = object_params.mm_per_unit;
    vec3 d = (xo - xi) * s;
    float t = dot(d, no);
    if (t <= 0.0) return sd;
    float rho = length(d - t * no);
    // Across a ball the measured sphere's transport (the curvature ratio) holds: a pair across
    // a sphere of radius R is at least R deep (κt ≥ 1). Across a sheet thinner than half its
    // radius of curvature (κt ≤ 1/2: an ear, a lens's rim) the slab's holds, and between the
    // two they blend. (Blending from κt = 0, a thin 16 × 8 × 2.4 mm Skin1 lens's rim read a
    // ball of its rim's radius and came out 1.29x the path tracer in red.)
    w = min(w, 1.0) * (1.0 - clamp(2.0 * pixel_curvature_mm * t - 1.0, 0.0, 1.0));
    vec3 through = w * slab_transmission(dipole_table, slab_header, rho, t) * power_mm;
    across_sum += through;
    float luminance = dot(through, LUMINANCE);
    across_thickness += vec2(t * luminance, luminance);
    across_incidence += sin2_t * luminance;
    return (1.0 - w) * sd;
}

// sin²θt per channel of light from the mean directions `toward[c]` refracted in at a source of
// normal ni: |toward's part along the surface|²/η² (shorter where the lights' directions differ).
vec3 refracted_sin2(vec3 toward[3], vec3 ni) {
    float eta = object_params.channels[0].eta;
    return vec3(entry_sin2(toward[0], ni), entry_sin2(toward[1], ni), entry_sin2(toward[2], ni)) / (eta * eta);
}

// Whether light goes from xi to xo inside the object (bssrdf.glsl `joined_inside`, the Monte
// Carlo table only).
bool joined_inside(vec3 xi, vec3 ni, vec3 xo, vec3 no) {
    return joined_inside(dipole_table, OCCUPANCY_BASE, object_inside, xi, ni, xo, no);
}

vec3 source(vec3 xi, vec3 ni, vec3 wi, vec3 power, vec3 xo, vec3 no) {
    float s = object_params.mm_per_unit;
    vec3 sd;
    // Written out, not looped: loop iterations count against llvmpipe's budget (see main).
    if (MODEL == MODEL_DIRECTIONAL) {
        // The geometry once for all three channels (they share eta).
        vec3 xi_mm = xi * s, xo_mm = xo * s;
        DirpoleGeometry g = dirpole_geometry(xi_mm, ni, wi, xo_mm, no, object_params.channels[0].eta);
        sd = vec3(dirpole_channel_sd(object_params.channels[0], g, xi_mm, xo_mm, no),
                  dirpole_channel_sd(object_params.channels[1], g, xi_mm, xo_mm, no),
                  dirpole_channel_sd(object_params.channels[2], g, xi_mm, xo_mm, no));
    } else if (MODEL == MODEL_MC) {
        if (!joined_inside(xi, ni, xo, no)) return vec3(0.0);
        vec3 toward[3] = vec3[](wi, wi, wi);
        vec3 d = (xo - xi) * s;
        float kappa = pair_curvature(d, ni, no);
        sd = across(xi, ni, xo, no, mc_sd(d, ni, kappa, toward), power * (s * s), refracted_sin2(toward, ni));
        count_far(length(d) * kappa, sd * power * (s * s), entry_sin2(wi, ni));
    } else {
        sd = dipole_sd_table(dipole_table, dipole_header, length(xo - xi) * s);
    }
    return sd * power * (s * s); // power is irradiance × scene-unit area: to mm²
}

// Every light's flux from xi at once: `power` (irradiance × scene-unit area) per channel, and
// `incident` (PointFlux's sums times the area): the power-weighted sum of the refracted
// directions, at the source's normal ni, is -(Σωi - (Σωi·ni)ni)/η - ni Σcos θt.
// `dw` moves every channel's mean refracted direction (a sigma direction, see PointSpread).
vec3 merged_source(vec3 xi, vec3 ni, vec3 power, vec4 incident[3], vec3 dw, vec3 xo, vec3 no, float kappa,
                  bool across_object) {
    float s = object_params.mm_per_unit;
    vec3 sd;
    if (MODEL == MODEL_DIRECTIONAL) {
        // The geometry once; per channel only its mean refracted direction (equal for lights of
        // one colour, different under an environment).
        vec3 xi_mm = xi * s, xo_mm = xo * s;
        float inv_eta = 1.0 / object_params.channels[0].eta;
        vec3 w[3];
        for (uint c = 0u; c < 3u; ++c) {
            vec3 t = incident[c].xyz - dot(incident[c].xyz, ni) * ni;
            w[c] = power[c] > 0.0 ? (-t * inv_eta - ni * incident[c].w) / power[c] + dw : vec3(0.0);
        }
        DirpoleGeometry g = dirpole_geometry_refracted(xi_mm, ni, w[0], xo_mm, no);
        sd.x = dirpole_channel_sd(object_params.channels[0], g, xi_mm, xo_mm, no);
        sd.y = dirpole_channel_sd(object_params.channels[1], with_refracted(g, w[1], no), xi_mm, xo_mm, no);
        sd.z = dirpole_channel_sd(object_params.channels[2], with_refracted(g, w[2], no), xi_mm, xo_mm, no);
    } else if (MODEL == MODEL_MC) {
        if (across_object && !joined_inside(xi, ni, xo, no)) return vec3(0.0);
        // Each channel's mean direction toward its lights: Σ E ωi / Σ E (the merged record's).
        vec3 toward[3];
        for (uint c = 0u; c < 3u; ++c) toward[c] = power[c] > 0.0 ? incident[c].xyz / power[c] : vec3(0.0);
        vec3 d = (xo - xi) * s;
        sd = mc_sd(d, ni, kappa, toward);
        if (across_object) {
            sd = across(xi, ni, xo, no, sd, power * (s * s), refracted_sin2(toward, ni));
            count_far(length(d) * kappa, sd * power * (s * s), entry_sin2(toward[1], ni));
        }
    } else {
        sd = dipole_sd_table(dipole_table, dipole_header, length(xo - xi) * s);
    }
    return sd * power * (s * s); // power is irradiance × scene-unit area: to mm²
}

// Point `index` as a merged source: its position, power and flux (times its area).
void point_source(uint index, out vec3 xi, out vec3 power, out vec4 incident[3], out float area) {
    vec4 position_area = texel_float(points, index * POINT_TEXELS);
    xi = position_area.xyz;
    area = position_area.w;
    power = texel_float(points, index * POINT_TEXELS + 2u).xyz * position_area.w;
    for (uint c = 0u; c < 3u; ++c) incident[c] = texel_float(point_flux, index * POINT_FLUX_TEXELS + c) * position_area.w;
}

// Point `index` evaluated on its own (the near field): its mean refracted directions, or, where
// the lights' directions spread (PointSpread), four sigma directions of a quarter power each.
// Returns the evaluations made.
// `spread_from`: the place whose distance from xi decides whether the spread shows (xo, or for the
// far field of a tile its centre, so that every pixel of the tile takes the same choice).
vec3 point_evaluated(uint index, vec3 xi, vec3 ni, vec3 power, vec4 incident[3], vec3 xo, vec3 no, vec3 spread_from,
                     out uint made) {
    vec3 a0 = texel_float(point_spread, index * POINT_SPREAD_TEXELS).xyz;
    vec3 a1 = texel_float(point_spread, index * POINT_SPREAD_TEXELS + 1u).xyz;
    // Beyond two diffusion lengths of the farthest-reaching channel the source's curvature in ω12
    // no longer shows (measured: the sigma directions changed nothing there).
    float reach = SIGMA_DIRECTIONS_REACH / min(min(object_params.channels[0].sigma_tr, object_params.channels[1].sigma_tr),
                                               object_params.channels[2].sigma_tr);
    bool near = length(spread_from - xi) * object_params.mm_per_unit < reach;
    // The table models' Sd is radial: the sigma directions would sum to the one evaluation.
    if (MODEL != MODEL_DIRECTIONAL || ONE_LIGHT || (a0 == vec3(0.0) && a1 == vec3(0.0)) || !near) {
        made = 1u;
        return merged_source(xi, ni, power, incident, vec3(0.0), xo, no, source_curvature(xi, ni, xo, no), true);
    }
    made = 4u;
    vec3 q = 0.25 * power;
    vec4 iq[3];
    for (uint c = 0u; c < 3u; ++c) iq[c] = 0.25 * incident[c];
    float kappa = source_curvature(xi, ni, xo, no);
    return merged_source(xi, ni, q, iq, a0, xo, no, kappa, true) + merged_source(xi, ni, q, iq, -a0, xo, no, kappa, true)
         + merged_source(xi, ni, q, iq, a1, xo, no, kappa, true) + merged_source(xi, ni, q, iq, -a1, xo, no, kappa, true);
}

// The two sources of node `index` used whole: sigma points center ± offset, each with half the
// power. A node used whole is not one source at its power centre c: Sd is convex in distance, so that
// underestimates it (1-1.5% on a slab). Two sigma points c ± s(u + t), s² = spread²/2 per axis of
// the node's tangent plane (u toward xo, t across), match the points' mean and second moments, so
// Sd's curvature along u and t is taken into account to second order.
// `area`: half the node's (an unlit node's sigma points are both at its centre).
void node_sigma(uint index, vec3 ni, vec3 xo, out vec3 center, out vec3 offset, out vec3 power, out vec4 incident[3],
                out float area) {
    uint record = index * NODE_FLUX_TEXELS;
    vec4 power_area = texel_float(nodes, index * NODE_TEXELS);
    power = 0.5 * power_area.xyz;
    area = 0.5 * power_area.w;
    for (uint c = 0u; c < 3u; ++c) incident[c] = 0.5 * texel_float(node_flux, record + c);
    vec4 center_spread = texel_float(node_flux, record + 3u);
    center = center_spread.xyz;
    vec3 towards_xo = xo - center;
    vec3 u = towards_xo - ni * dot(towards_xo, ni);
    u = dot(u, u) > 0.0 ? normalize(u) : normalize(cross(ni, abs(ni.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    offset = sqrt(0.5 * center_spread.w) * (u + cross(ni, u));
}

// The object's thickness (mm) under xo along −no: the distance to where the inside grid's cell
// centres (the un-grown grid) are outside again, in steps of half the smallest cell (then
// refined on the interpolated field, inside_field), after at
// most two cells of air at the start (the surface cuts xo's own cell). None inside within those
// two cells (a sheet thinner than the grid resolves), past THICKEST_STEPS, or no grid (an open
// mesh): 0, no sheet.
const float THICKEST_STEPS = 256.0;
// The cell centres' bits (the un-grown grid) interpolated trilinearly at `at` (in cells).
float inside_field(vec3 at) {
    vec3 p = at - 0.5, c = floor(p), f = p - c;
    float sum = 0.0;
    for (int k = 0; k < 8; ++k) {
        vec3 o = vec3(float(k & 1), float((k >> 1) & 1), float(k >> 2));
        vec3 w = mix(vec3(1.0) - f, f, o);
        sum += centre_occupied(dipole_table, OCCUPANCY_BASE, c + o + 0.5) ? w.x * w.y * w.z : 0.0;
    }
    return sum;
}
float thickness_below(vec3 xo, vec3 no) {
    if (object_inside.corner.w == 0.0) return 0.0;
    vec3 cell = object_inside.cell;
    float step_units = 0.5 * min(cell.x, min(cell.y, cell.z));
    vec3 start = (xo - object_inside.corner.xyz) / cell, d = -no * step_units / cell;
    float first = 0.0, last = 0.0;
    for (float i = 1.0; i <= THICKEST_STEPS; i += 1.0) {
        bool inside = centre_occupied(dipole_table, OCCUPANCY_BASE, start + d * i);
        if (inside) {
            if (first == 0.0) first = i;
            last = i;
        } else if (first > 0.0 || i >= 4.0) {
            break;
        }
    }
    if (first == 0.0 || last >= THICKEST_STEPS) return 0.0;
    // Where the far face is: the cells' bits alone move it a step at a time, and the sheet's
    // ratio with it, which mottled an ear seen at a slant. The centres' bits interpolated
    // trilinearly are a field that changes smoothly; its level ½ between the steps around
    // the last inside one, by bisection.
    float lo = last - 1.0, hi = last + 1.0;
    for (int k = 0; k < 5; ++k) {
        float mid = 0.5 * (lo + hi);
        if (inside_field(start + d * mid) >= 0.5) lo = mid;
        else hi = mid;
    }
    return 0.5 * (lo + hi) * step_units * object_params.mm_per_unit;
}

// Sets the pixel's sheet (thin_rows, thin_weight) for the Monte Carlo table: the slab's lit face
// holds where the object under the pixel is thinner than half its radius of curvature (κt ≤ 1/2),
// the measured balls' transport (the curvature ratio, whose balls are 2R thick) where κt ≥ 1,
// blended between, as the light across is (`across`).
void begin_thickness(vec3 xo, vec3 no) {
    thin_weight = 0.0;
    if (MODEL != MODEL_MC) return;
    float t = thickness_below(xo, no);
    thin_mm = t;
    thin_rows = slab_reflected_rows(slab_header, t);
    if (thin_rows.w == 0.0) return;
    thin_weight = 1.0 - clamp(2.0 * pixel_curvature_mm * t - 1.0, 0.0, 1.0);
}

// The per-pixel state of the sources above, from the pixel's normal and mean curvature (the
// G-buffer's normal texel: xyz the normal, w the curvature in 1 / scene units).
void begin_sources(vec4 normal_curvature) {
    dipole_header = dipole_table_header(dipole_table);
    slab_header = MODEL == MODEL_MC ? slab_header_of(dipole_table) : vec4(0.0);
    object_inside = MODEL == MODEL_MC ? occupancy_header(dipole_table, OCCUPANCY_BASE) : Occupancy(vec4(0.0), vec3(1.0));
    if (MODEL == MODEL_MC) pixel_curvature_mm = normal_curvature.w / object_params.mm_per_unit;
    pixel_curvature_rows = MODEL == MODEL_MC ? curvature_rows(dipole_table, pixel_curvature_mm)
                                             : vec4(-1.0, 0.0, 0.0, 0.0);
    thin_weight = 0.0;
}
#endif
