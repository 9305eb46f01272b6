#version 460
// Subsurface scattering per pixel, in a full-screen pass over the G-buffer of the surface pass.
// The pixel's sources come from its tile's list (tile_cut.comp): nodes used whole for the whole
// tile (two sigma points) and points evaluated singly, the same list for every pixel of the tile.
// A tile whose list did not fit walks from the root per pixel instead (a node far and small
// enough from xo, area / distance² < epsilon and xo outside its box, is used whole, else its
// children are visited). Every source carries all the lights at once
// (PointFlux, NodeFlux: per channel the power and the power-weighted refracted direction), so the
// cost does not grow with the number of lights; brute force instead sums over every (point,
// light) pair exactly, the reference the merged records are measured against.
// Lo(xo, wo) = Ft(eta, wo) · Σ over sources Sd(xi, ω12; xo, no) · power, power = E·A (mm²), plus
// the surface's own reflection from each light: a microfacet lobe, shadowed by the same shadow
// maps. Which nodes are used whole does not depend on the lights.
#include "common.glsl"
#include "shade_constants.glsl"
#include "points.glsl"
#include "shading_params.glsl"
#define LIGHTS_BINDING 4
#define SHADOW_MAP_BINDING 5
#include "lights.glsl"
#include "microfacet.glsl"
#include "tile_lists.glsl"
#include "far_field.glsl"

// The model, fixed per pipeline: llvmpipe runs both sides of a branch for every SIMD group, so a
// model chosen at run time would cost both models' arithmetic (measured: the classical dipole
// took 2.4x longer beside the directional one's dead code).
// The pipelines use the module compiled with SHADE_MODEL defined (build.rs, one per model): a
// module with every model's code took lavapipe 120-150 ms to make a pipeline of, against a
// frame's 50 ms at 8x8 pixels.
#ifdef SHADE_MODEL
const uint MODEL = SHADE_MODEL;
#else
layout(constant_id = 0) const uint MODEL = 0u; // 0 directional dipole, 1 classical dipole, 2 beam diffusion, 3 Monte Carlo table (1-3: table)
#endif
// Whether the near field is split off (see near_field()), fixed per pipeline for the same reason:
// a frame without it pays nothing for its code.
layout(constant_id = 1) const bool NEAR_FIELD = false;
// One light: no point's lights spread, so point_evaluated() needs no sigma directions (llvmpipe
// would run their four evaluations for every point, masked off or not).
layout(constant_id = 2) const bool ONE_LIGHT = false;

layout(location = 0) out vec4 radiance;

// A uniform buffer: llvmpipe loads its members once per SIMD group (storage buffers per lane).
layout(std140, binding = 0) uniform Object { ObjectParams object_params; };
// The tree's records as texels (see points.glsl): TreeNode, SurfacePoint (sorted).
layout(binding = 1) uniform usamplerBuffer nodes;
layout(binding = 2) uniform usamplerBuffer points;
// Work per pixel for --profile: sums and maxima of nodes visited and points evaluated.
// Sd evaluations: calls of source(), each for three channels (a node used whole is two per light).
// One record per translucent object, indexed by the object shaded.
struct WorkCounters { uint pixels; uint node_sum; uint node_max; uint point_sum; uint point_max; uint evaluation_sum; };
layout(std430, binding = 3) buffer Work { WorkCounters objects[]; } work;
// Light records as texels: PointLight (sorted, brute force only), NodeFlux.
layout(binding = 6) uniform usamplerBuffer point_lights;
layout(binding = 7) uniform usamplerBuffer node_flux;
// The surface pass's G-buffer: world position (w = 1 where covered) and interpolated normal.
layout(binding = 8, rgba32f) uniform readonly image2D surface_position;
layout(binding = 9, rgba32f) uniform readonly image2D surface_normal;
// The tile-cut pass's lists (see tile_lists.glsl): a header texel per tile, entries 4 per texel.
layout(binding = 10) uniform usamplerBuffer tile_headers;
layout(binding = 11) uniform usamplerBuffer tile_entries;
// The model's Sd per channel, tabulated (bssrdf.glsl): the classical dipole's or beam diffusion's.
layout(binding = 12) uniform usamplerBuffer dipole_table;
layout(std140, binding = 13) uniform Frame { FrameParams frame_params; };
// PointFlux and PointSpread (sorted) as texels.
layout(binding = 14) uniform usamplerBuffer point_flux;
layout(binding = 15) uniform usamplerBuffer point_spread;
// The same shadow map's depth, unfiltered: how far light travels inside (single scattering).
layout(binding = 16) uniform sampler2DArray shadow_depth;
// The G-buffer's texture: a translucent pixel's scatter weight (1 where the object has no
// texture; gpu_world::SurfaceTexture).
layout(binding = 17, rgba32f) uniform readonly image2D surface_albedo;
// The far-field pass's sixteen sums per 8x8 tile (far_field.comp), as texels.
layout(binding = 18) uniform usamplerBuffer far_field;
// The mesh's normal at each shadow-map texel (shadow.frag; encode_oct), read with texelFetch.
layout(binding = 19) uniform usampler2DArray shadow_normals;
#include "sources.glsl"

const uint STACK_SIZE = 96u;
// Stack entries: a point or node index (below 2^24, with LEAF_BIT for points) and the number of
// its next evaluation plus one (a node's second sigma point).
const uint EVALUATION_SHIFT = 24u;
const uint EVALUATION_MASK = 0x1fu;
// Steps of the walk (tests of nodes and points, and evaluations) before it stops opening nodes:
// llvmpipe's loop budget.
const uint MAX_STEPS = 32768u;

// The near field (see near_field()): the pixel's own irradiance and flux, merged over the lights
// (set in main when the frame splits it off; own_lit false where the pixel is unlit).
// The pixel's scatter weight: the points' irradiance carries theirs (the source's), the sum is
// multiplied by the pixel's (the exit's), so a texture weighs each pair by the geometric mean.
vec3 own_weight = vec3(1.0);
vec3 own_irradiance;
vec4 own_incident[3];
bool own_lit = false;
// The control variate's sum, −Σ v_i Sd_i A_i under the variate's light (near_correction()), and
// Σ v_i f_i, the sources' own contributions weighted by the same v_i (near_blend in main).
vec3 near_sum = vec3(0.0);
vec3 near_sources = vec3(0.0);
// Sources whose normal turns further than this from the pixel's (ni·no below it: the far side
// of a sheet thinner than the near field's reach) are no part of the pixel's tangent plane,
// unfolded or not, and stay out of the control variate.
const float NEAR_UNFOLD_MIN_COS = -0.9;

// The near field's weight 1 − w(r) of a place xi seen from xo: 1 within near_start_mm, falling
// smoothly (smoothstep) to 0 at near_end_mm (ObjectParams).
float near_weight(vec3 xi, vec3 xo) {
    return 1.0 - smoothstep(object_params.near_start_mm, object_params.near_end_mm, length(xo - xi) * object_params.mm_per_unit);
}


// Where the surface between xo and a source xi bends, the source is put where the surface
// unfolded into xo's tangent plane would carry it: xi turned about the line where the two
// tangent planes (xo, no) and (xi, ni) meet, by the angle that takes ni to no. Across a box's
// edge that is exact (the folded face lies flat beside the pixel's), on a smooth surface the
// turn brings xi onto the plane at nearly its distance along the surface, so the points' sum of
// the control variate estimates the tangent-plane integral near_field() computes. Taking xi as it
// lies instead, the folded face (nearer in 3D than unfolded) made that sum 15% too large on a
// box's edge, and the variate had to fade out there, leaving the edge's pixels the plain sum's
// noise (up to 25% of the image's mean on the slab at 48²).
vec3 unfolded(vec3 xi, vec3 ni, vec3 xo, vec3 no) {
    vec3 v = xi - xo;
    vec3 axis = cross(ni, no);
    float sin_t = length(axis);
    // Planes nearly parallel: their line is far away and the turn a shift onto the plane.
    if (sin_t < 1e-3) return xi - dot(v, no) * no;
    axis /= sin_t;
    float cos_t = dot(ni, no);
    // The line's point nearest xo: on xo's plane (·no = 0) and xi's (·ni = ni·v), across axis.
    vec3 across = cross(no, axis); // in xo's plane, perpendicular to the line
    vec3 p = xo + across * (dot(ni, v) / dot(ni, across));
    vec3 u = xi - p;
    // Rodrigues' rotation by the angle from ni to no about axis.
    vec3 turned = u * cos_t + cross(axis, u) * sin_t + axis * (dot(axis, u) * (1.0 - cos_t));
    return p + turned;
}

// The near field's control variate at a source of `area` (scene units²) at xi, ni, whether lit
// or not: −(1 − w) times that area, unfolded into the pixel's tangent plane (unfolded()), lit
// by the pixel's own irradiance and lights (see near_field()); `made` counts the evaluations.
// Adds to near_sum; returns v, the source's weight in it (0 beyond reach).
float near_correction(vec3 xi, vec3 ni, float area, vec3 xo, vec3 no, inout uint made) {
    // An unlit pixel has no variate: a SIMD group or warp of unlit pixels (the dark side of a
    // back-lit object, most of the default image) skips it whole.
    if (!NEAR_FIELD || !own_lit || dot(ni, no) < NEAR_UNFOLD_MIN_COS) return 0.0;
    vec3 x = unfolded(xi, ni, xo, no);
    // A fold carries a source no nearer than it lies (the way through the fold is no shorter
    // than the straight line), so an unfolded place nearer than the source itself is no fold:
    // a far source whose tangent plane meets the pixel's near the pixel, turned onto the pixel.
    // Such a source (a node's sigma point across the object, 7-19 mm away on the bunny) made
    // 75-99% of the points' estimate at every negative pixel, 7-140x the integral it estimates.
    // It is weighed at its own distance, which leaves it out.
    float v = min(near_weight(x, xo), near_weight(xi, xo));
    if (v <= 0.0) return 0.0;
    ++made;
    vec4 flux[3];
    for (uint c = 0u; c < 3u; ++c) flux[c] = own_incident[c] * (v * area);
    // At the pixel's normal, as the plane integral has it: the pixel's lights refracted at ni
    // would make a different function (near a terminator, lights below ni's horizon).
    near_sum -= merged_source(x, no, own_irradiance * (v * area), flux, vec3(0.0), xo, no, pixel_curvature_mm, false);
    return v;
}

// The near field. The few points nearest a pixel sample the BSSRDF's peak at r → 0 badly (the
// default spacing leaves a few percent of noise per pixel, and a moiré of the sample pattern on
// flat parts), so the sum over sources near xo uses a control variate: the pixel's own
// irradiance E(xo) (every light's, merged into one PointFlux-style record at xo exactly as the
// irradiance pass does per point: light_irradiance() in lights.glsl) as if it lit the whole
// tangent plane,
//   Lo = Σ_i Sd_i E_i A_i − E(xo) Σ_i (1 − w_i) Sd_i(xo's lights) A_i + E(xo) ∫(1 − w) Sd dA,
// with 1 − w (near_weight()) falling smoothly from 1 within one point spacing to 0 at four. The
// middle sum (near_correction(), every source within reach, lit or not) is what the points make
// of the last term, so the two cancel but for the points' error in it: what remains sampled is
// Sd · (E_i − E(xo)), which vanishes at the peak where E is smooth, and is the plain point sum
// where it is not (shadow edges, terminators), so brute force's expectation is kept everywhere.
// Where the points oversample the peak (their estimate Σ v_i Sd_i A_i above the integral G), the
// variate alone can make a pixel negative wherever E_i < E(xo) (a shadow's or terminator's
// edge); there main() blends it (γ) toward Σ (1 − v_i) f_i + E(xo) G, the peak taken from the
// pixel's own irradiance alone, which has the same expectation where E is smooth and only
// non-negative coefficients (see near_blend in main).
// The integral is a fixed quadrature over the disk (this function). Radially: Gauss–Legendre on
// [0, start] in t, r = scale · sinh t (r dr = scale² sinh t cosh t dt: smooth where Sd peaks
// over ~D, and where Sd ~ 1/r for beam diffusion's single scattering), and on [start, end],
// where 1 − w falls smoothly to 0. Angularly (the directional dipole only; the tables are
// radial): NEAR_ANGLES angles on the half circle from the lights' mean tangential direction,
// each standing for its mirror image too (the source is symmetric about the plane of the normal
// and the refracted light). The quadrature's error against a fine f64 grid: within 0.015%
// (Skin1, light at 0-80°). Returns the evaluations made (`made`).
const float NEAR_INNER_X[6] = float[](0.033765243, 0.169395307, 0.380690407, 0.619309593, 0.830604693, 0.966234757);
const float NEAR_INNER_W[6] = float[](0.085662246, 0.180380787, 0.233956967, 0.233956967, 0.180380787, 0.085662246);
const float NEAR_OUTER_X[4] = float[](0.069431844, 0.330009478, 0.669990522, 0.930568156);
const float NEAR_OUTER_W[4] = float[](0.173927423, 0.326072577, 0.326072577, 0.173927423);
const uint NEAR_ANGLES = 4u;
const uint NEAR_ANGLES_MC = 8u;
// The pixel's own irradiance and flux (own_irradiance, own_incident, own_lit).
void own_light(vec3 xo, vec3 no) {
    own_irradiance = vec3(0.0);
    own_incident[0] = own_incident[1] = own_incident[2] = vec4(0.0);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        vec3 toward;
        vec3 e = light_irradiance(light_of(k), xo, no, toward);
        if (e == vec3(0.0)) continue;
        vec4 term = flux_term(toward, no);
        // As the irradiance pass weighs each point's (1 but for the Monte Carlo table, and its
        // scatter weight).
        e *= table_incidence_factor(dipole_table, term.w) * own_weight;
        for (uint c = 0u; c < 3u; ++c) own_incident[c] += e[c] * term;
        own_irradiance += e;
    }
    own_lit = own_irradiance != vec3(0.0);
}

vec3 near_field(vec3 xo, vec3 no, out uint made) {
    made = 0u;
    if (!own_lit) return vec3(0.0);
    vec3 e = own_irradiance;
    vec4 incident[3] = own_incident;
    vec3 toward_mean = incident[0].xyz * 0.2126 + incident[1].xyz * 0.7152 + incident[2].xyz * 0.0722;
    float s = object_params.mm_per_unit;
    float start = object_params.near_start_mm, end = object_params.near_end_mm, scale = object_params.near_scale_mm;
    // The tangent frame: t1 along the lights' mean direction projected onto the plane.
    vec3 tangential = toward_mean - dot(toward_mean, no) * no;
    vec3 t1 = dot(tangential, tangential) > 1e-12 * dot(toward_mean, toward_mean)
        ? normalize(tangential)
        : normalize(cross(no, abs(no.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    vec3 t2 = cross(no, t1);
    // The directional dipole: NEAR_ANGLES angles on the half circle, each standing for its
    // mirror image. The Monte Carlo table: its lean (harmonics up to the third) times the exit's
    // tilt toward the eye (1 + c cos(φ − φe) + ...), whose product has harmonics up to the
    // fourth and no mirror symmetry (the eye's way along the surface is any): NEAR_ANGLES_MC
    // angles evenly over the whole circle, exact for harmonics up to the seventh. (Four, exact to
    // the third, were enough for the lean's first harmonic alone; with the third the
    // convergence test's sphere was 0.81% from the reference in blue, 0.56% with eight. One
    // angle at φ = π/2 with the product's mean left the clamp at zero out where the eye grazes.)
    uint angles = MODEL == MODEL_MC ? NEAR_ANGLES_MC : NEAR_ANGLES;
    float arc = MODEL == MODEL_DIRECTIONAL ? 3.14159265359 : 6.28318530718;
    float t_end = asinh(start / scale);
    vec3 sum = vec3(0.0);
    for (uint j = 0u; j < 10u; ++j) {
        // r and its weight r dr (1 − w included), in mm and mm².
        float r, weight;
        if (j < 6u) {
            float t = t_end * NEAR_INNER_X[j];
            r = scale * sinh(t);
            weight = r * scale * cosh(t) * t_end * NEAR_INNER_W[j];
        } else {
            r = start + (end - start) * NEAR_OUTER_X[j - 6u];
            weight = r * (end - start) * NEAR_OUTER_W[j - 6u] * (1.0 - smoothstep(start, end, r));
        }
        // Each angle stands for 2π / angles of the circle; in scene units² for merged_source.
        float area = weight * (6.28318530718 / float(angles)) / (s * s);
        vec4 flux[3];
        for (uint c = 0u; c < 3u; ++c) flux[c] = incident[c] * area;
        for (uint a = 0u; a < angles; ++a) {
            float phi = (float(a) + 0.5) * (arc / float(angles));
            vec3 xi = xo + (r / s) * (cos(phi) * t1 + sin(phi) * t2);
            sum += merged_source(xi, no, e * area, flux, vec3(0.0), xo, no, pixel_curvature_mm, false);
        }
        made += angles;
    }
    return sum;
}

// One light's record of one point (brute force): record = point · light_count + light.
vec3 point_light_source(uint record, uint light_count, vec3 xo, vec3 no) {
    uvec4 l = texel(point_lights, record);
    vec3 irradiance = uintBitsToFloat(l.xyz);
    if (irradiance == vec3(0.0)) return vec3(0.0);
    uint point = record / light_count;
    vec4 position_area = texel_float(points, point * POINT_TEXELS);
    vec3 normal = texel_float(points, point * POINT_TEXELS + 1u).xyz;
    return source(position_area.xyz, normal, decode_oct(l.w), irradiance * position_area.w, xo, no);
}


// Whether the box [lo, hi] (scene units) reaches within the near field's end of xo.
bool within_near_reach(vec3 xo, vec3 lo, vec3 hi) {
    vec3 d = max(max(lo - xo, xo - hi), vec3(0.0)) * object_params.mm_per_unit;
    return dot(d, d) < object_params.near_end_mm * object_params.near_end_mm;
}

uint tile_entry(uint i) { return texel(tile_entries, i >> 2)[i & 3u]; }

// Σ over lights of f_spec(wi, wo) · E · cos θi · visibility.
vec3 specular(vec3 xo, vec3 no, vec3 wo) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        vec3 toward;
        uint layer;
        vec3 incident = light_at(light_of(k), xo, toward, layer);
        float f_cos = microfacet_reflect_cos(no, toward, wo, frame_params.roughness, object_params.channels[0].eta);
        if (f_cos <= 0.0) continue;
        sum += f_cos * incident * shadow_visibility(layer, xo, no);
    }
    return sum;
}

// The pixel's own angle of incidence, from its own flux (own_light): the refracted cosine of its
// lights weighted by the luminance of what each brings in; 1 (normal incidence) where none
// reaches it. The Monte Carlo table's exit factor is read there.
float own_cos_t() {
    float weight = dot(LUMINANCE, own_irradiance);
    float sum = dot(LUMINANCE, vec3(own_incident[0].w, own_incident[1].w, own_incident[2].w));
    return weight > 0.0 ? sum / weight : 1.0;
}

// Samples of the refracted view ray for single scattering (the first at the pixel): spaced as
// s_k = reach · (k/N)², reach = SS_REACH mean free paths of the most translucent channel.
const uint SS_SAMPLES = 24u;
const float SS_REACH = 10.0;

// ∫ e^{−σ g} over an interval of length `len` along which the path g ≥ 0 runs linearly from g0 to
// g1, per channel: len (e^{−σ g0} − e^{−σ g1}) / (σ (g1 − g0)), by its series where f32 would
// cancel. Both exponentials are at most 1, so no slope overflows it.
vec3 interval_integral(vec3 sigma, float g0, float g1, float len) {
    g0 = max(g0, 0.0);
    g1 = max(g1, 0.0);
    vec3 a = sigma * (g1 - g0);
    vec3 e0 = exp(-sigma * g0);
    vec3 series = e0 * (vec3(1.0) - 0.5 * a + a * a / 6.0);
    vec3 closed = (e0 - exp(-sigma * g1)) / mix(vec3(1.0), a, notEqual(a, vec3(0.0)));
    return len * mix(series, closed, step(vec3(1e-3), abs(a)));
}

// The mesh's normal where the light meets it at the texel corner `corner` (in texels), and its
// mean curvature there (1/scene unit): the texel's at +u, +v from it (shadow.frag: interpolated
// from the vertex normals, the shading normal a path tracer refracts at; the mean of the four
// around the corner measured the same and cost 1.1x more). The entry took the facets' normal
// from the depths' differences before: the default Skin1 bunny's single scattering was 0.69 0.73
// 0.75 of the path tracer's with it, 0.80 0.82 0.82 with this (README, "The default bunny").
vec3 mesh_normal_at(vec2 corner, uint layer, out float curvature) {
    ivec2 size = textureSize(shadow_normals, 0).xy;
    ivec2 texel = clamp(ivec2(corner), ivec2(0), size - 1);
    uvec2 normal_curvature = texelFetch(shadow_normals, ivec3(texel, int(layer)), 0).rg;
    curvature = uintBitsToFloat(normal_curvature.y);
    return decode_oct(normal_curvature.x);
}

// The surface the shadow map sees at `uv` (the corner of texels nearest it, unprojected by
// `unproject`: the mean of the four texels' points around it, one gather) and the mesh's normal
// and mean curvature there. False where they do not span a surface (beyond the map, a
// silhouette seen from the light).
bool entry_surface(vec2 uv, uint layer, mat4 unproject, out vec3 point, out vec3 normal, out float curvature) {
    vec2 size = vec2(textureSize(shadow_depth, 0).xy);
    point = vec3(0.0);
    normal = vec3(0.0, 0.0, 1.0);
    curvature = 0.0;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return false;
    // The corner: gather takes the 2×2 texels around it (floor(uv·size − 0.5) is half a texel
    // from any rounding of an integer).
    vec2 corner = round(uv * size);
    vec4 d = textureGather(shadow_depth, vec3(corner / size, float(layer)));
    if (any(greaterThanEqual(d, vec4(1.0)))) return false;
    // Gather's order: x (−u, +v), y (+u, +v), z (+u, −v), w (−u, −v).
    vec2 h = 0.5 / size;
    vec2 ndc_lo = (corner / size - h) * 2.0 - 1.0, ndc_hi = (corner / size + h) * 2.0 - 1.0;
    vec4 q0 = unproject * vec4(ndc_lo.x, ndc_hi.y, d.x, 1.0);
    vec4 q1 = unproject * vec4(ndc_hi.x, ndc_hi.y, d.y, 1.0);
    vec4 q2 = unproject * vec4(ndc_hi.x, ndc_lo.y, d.z, 1.0);
    vec4 q3 = unproject * vec4(ndc_lo.x, ndc_lo.y, d.w, 1.0);
    point = 0.25 * (q0.xyz / q0.w + q1.xyz / q1.w + q2.xyz / q2.w + q3.xyz / q3.w);
    normal = mesh_normal_at(corner, layer, curvature);
    return true;
}

// How far the shadow pass's slope-scaled depth bias (1.5 texels of depth slope, texels
// normal_offset / 2 wide) moved the surface the map sees away from the light, along it:
// about 0.75 normal_offset · tan θl, with tan θl held at `max_tan`.
float shadow_bias_distance(float cos_l, float max_tan) {
    float tan_l = min(sqrt(max(1.0 - cos_l * cos_l, 0.0)) / max(cos_l, 1e-3), max_tan);
    return 0.75 * light_set.normal_offset * tan_l;
}

// Where light toward `toward` that reaches x inside entered (SS_ENTRY_STEPS refinements): from
// the surface the map sees straight toward the light (y, normal n), the light refracted through
// y's tangent plane reaches x from the point y* = x − t·h/cos θt of that plane (h: x's depth
// below it), exactly so on a flat surface; y* is taken back to the surface the map sees there,
// and again (four steps: at points of a ball that refracted light reaches, two end a median 0.6%
// of the way from the exact entry, four 0.03%). On a curved surface that follows the refracted light to where it really enters:
// past a terminator (light grazing the surface beyond it), the straight line toward the light
// crosses the lit side far away, where light enters at a steep angle that its tangent plane
// would carry to x but the real, curving surface does not. Returns h (scene units, ≥ 0), the
// cosine at the entry, how far x lies from the light refracted there (`miss`, scene units:
// where no refracted light reaches x, in the shadow a curved surface casts inside itself beyond a
// terminator, the steps find no entry and it stays large) and the mesh's mean curvature at the
// entry (1/scene unit); false where the map sees no surface.
const int SS_ENTRY_STEPS = 4;
bool light_entry(vec3 x, vec2 uv, uint layer, mat4 unproject, vec3 toward, float eta, out float h, out float cos_l,
                 out float miss, out float curvature) {
    vec3 y, n;
    h = 0.0;
    cos_l = 0.0;
    miss = 0.0;
    if (!entry_surface(uv, layer, unproject, y, n, curvature)) return false;
    vec3 entry, t;
    for (int step = 0; step <= SS_ENTRY_STEPS; ++step) {
        cos_l = clamp(dot(n, toward), 0.0, 1.0);
        entry = y + toward * shadow_bias_distance(cos_l, 1e30); // the shadow pass's bias taken back
        h = max(dot(entry - x, n), 0.0);
        float cos_t = sqrt(max(1.0 - (1.0 - cos_l * cos_l) / (eta * eta), 0.0));
        t = -(toward - cos_l * n) / eta - n * cos_t; // the refracted direction, inward
        if (step == SS_ENTRY_STEPS || cos_t <= 1e-4 || cos_l <= 0.0) break;
        vec3 plane_entry = x - t * (h / cos_t);
        vec4 clip = layer_matrix(layer) * vec4(plane_entry, 1.0);
        vec3 y2, n2;
        float curvature2;
        if (!entry_surface(clip.xy / clip.w * 0.5 + 0.5, layer, unproject, y2, n2, curvature2)) break;
        y = y2;
        n = n2;
        curvature = curvature2;
    }
    // How far x lies from the light refracted at the last entry.
    vec3 v = x - entry;
    miss = length(v - dot(v, t) * t);
    return true;
}

// How a curved entry focuses the refracted beam: a parallel beam through a surface of curvature
// κ (a ball's 1/R; the mesh's mean curvature at the entry, smoothed over a diffusion length: an
// ear curves two ways, not as a ball, but its shape operator there measured no better at a
// scale clean of speckles, README "The default bunny") converges with refracting
// power P = (η cos θt − cos θi)·κ, toward its sagittal focus η/P and tangential focus
// η cos²θt/P along the ray (Coddington's equations); at a distance l along it the beam's cross
// section has shrunk by (1 − l P/η)(1 − l P/(η cos²θt)), and its flux per unit area grown by
// the inverse. A 10 mm Ketchup ball lit from behind: its red single scattering, light that
// crosses the ball, was 0.59 of the path tracer's without it. Past a focus the beam widens
// again (the absolute value); at one, its flux per unit area, infinite for a delta light, is
// held at 10x per direction (a 5° sun widens a focus 3–20 mm away to 0.2–1.4 mm).
float lens_gain(float l_mm, float cos_i, float cos_t, float eta, float kappa_mm) {
    float p = (eta * cos_t - cos_i) * kappa_mm / eta;
    float sagittal = max(abs(1.0 - l_mm * p), 0.1);
    float tangential = max(abs(1.0 - l_mm * p / max(cos_t * cos_t, 1e-4)), 0.1);
    return 1.0 / (sagittal * tangential);
}

// Single scattering, the Monte Carlo table's (Jensen et al. 2001 §3; with its table's similarity
// relation: σ's, σ't and an isotropic phase function). Along the refracted view ray
// x(s) = xo + s·ωo' inside, light from each light scatters once toward the eye:
//   Lo = Ft(θo)/η² · Σ_l E_l cos θl Ft(θl)/cos θtl · σs'/(4π) ∫ e^{−σ't (s + s_l(s))} ds,
// s_l the light's refracted path inside, from where it entered (light_entry: through the
// shadow map, exact on a flat half-space and slab; the tangent plane alone was 1.3-5.7x too
// bright beyond a Ketchup sphere's terminator), no light where refracted light does not reach
// x, and the beam's focusing by a curved entry (lens_gain). Against the path tracer's light
// scattered once (tests/ground_truth.rs): 10 mm spheres front-lit 1.01-1.02, back-lit
// 0.94-0.97, the default Skin1 bunny 0.84-0.85. 1/η²: radiance leaving a denser medium. Between samples s + s_l is taken linear,
// so each interval's integral is exact there, and the beam's mean of its ends; samples the shadow map puts outside the object (nearer the light than its surface)
// scatter nothing, and an interval with one such end counts up to where the depth differences
// at its ends say the ray crosses the surface.
vec3 single_scattering(vec3 xo, vec3 no, vec3 wo) {
    float mm = object_params.mm_per_unit;
    float eta = object_params.channels[0].eta;
    vec3 sigma_s = vec3(object_params.channels[0].sigma_s_reduced, object_params.channels[1].sigma_s_reduced,
                        object_params.channels[2].sigma_s_reduced);
    vec3 sigma_t = vec3(object_params.channels[0].sigma_t_reduced, object_params.channels[1].sigma_t_reduced,
                        object_params.channels[2].sigma_t_reduced);
    float slowest = min(min(sigma_t.x > 0.0 ? sigma_t.x : 1e30, sigma_t.y > 0.0 ? sigma_t.y : 1e30),
                        sigma_t.z > 0.0 ? sigma_t.z : 1e30);
    if (slowest >= 1e30 || sigma_s == vec3(0.0)) return vec3(0.0);
    float cos_o = max(dot(no, wo), 0.0);
    if (cos_o <= 0.0) return vec3(0.0);
    vec3 inward = refract_in(wo, no, eta);
    float reach = SS_REACH / slowest;
    float near_band = 2.0 * light_set.normal_offset * mm;
    // A per-pixel fraction in [0, 1) (an integer hash of the pixel, the same every frame).
    uvec2 q = uvec2(gl_FragCoord.xy);
    uint h = q.x * 1973u + q.y * 9277u + 26699u;
    h = (h ^ (h >> 16)) * 0x7feb352du;
    h = (h ^ (h >> 15)) * 0x846ca68bu;
    float jitter = float((h ^ (h >> 16)) >> 8) / 16777216.0;
    vec3 sum = vec3(0.0);
    for (uint l = 0u; l < light_set.light_count; ++l) {
        GpuLight light = light_of(l);
        uint cached_layer = 0xffffffffu;
        mat4 unproject = mat4(1.0);
        vec3 along = vec3(0.0); // the interval integrals of e^{−σ't g}
        float g_prev = 0.0, s_prev = 0.0, d_prev = 0.0, slope_prev = 1.0;
        bool inside_prev = false;
        vec3 beam = vec3(0.0), beam_prev = vec3(0.0);
        // The shadow pass's slope-scaled depth bias put the surface the map sees deeper than it
        // is: by about 0.75 normal_offset · tan θl along the light (light_entry puts the entry
        // back by as much). In this layer's depth, at the last entry found: where the ray leaves
        // through the lit surface, that band counted as outside (a 2 mm Skin1 slab lit from
        // behind at 60°: single scattering 0.95 of its closed form, the lost band its brightest).
        float depth_bias = 0.0;
        uint bias_layer = 0xffffffffu;
        for (uint k = 0u; k <= SS_SAMPLES; ++k) {
            // Past the pixel itself, the samples shift by a fraction of a step per pixel: where a
            // shadow inside the object (a part of it between the ray and the light) starts
            // between samples, fixed samples draw its edge as contour lines across the image.
            float t = k == 0u ? 0.0 : (float(k) - 1.0 + jitter) / float(SS_SAMPLES - 1u);
            float s = reach * t * t; // mm
            vec3 x = xo + inward * (s / mm);
            vec3 toward;
            uint layer;
            vec3 incident = light_at(light, x, toward, layer);
            vec4 clip = layer_matrix(layer) * vec4(x, 1.0);
            vec3 ndc = clip.xyz / clip.w;
            vec2 uv = ndc.xy * 0.5 + 0.5;
            float depth = texture(shadow_depth, vec3(uv, float(layer))).r;
            // Beyond the map or nearer the light than the surface it sees: outside the object.
            // Within a few shadow texels of the pixel (the band its depth's rounding and bias
            // blur) the ray is inside whatever the depth says.
            bool near = s < near_band;
            bool in_map = all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0))) && depth < 1.0;
            // How far behind the surface (in depth), < 0 in front of it; where the map sees no
            // surface, unknown (-1e30).
            float d = in_map ? ndc.z - depth + (layer == bias_layer ? depth_bias : 0.0) : -1e30;
            bool inside = in_map && (near || d > 0.0);
            float g = s;
            if (inside) {
                if (layer != cached_layer) {
                    unproject = inverse(layer_matrix(layer));
                    cached_layer = layer;
                }
                float h, cos_l, miss, entry_curvature;
                bool entered = light_entry(x, uv, layer, unproject, toward, eta, h, cos_l, miss, entry_curvature);
                // The beam focuses by the curvature where the light enters (the pixel's where the
                // map sees no entry): at the base of the bunny's ear the pixel is concave where
                // the entry, on the ear's back, is convex; there the pixel's gave single
                // scattering 0.80 0.82 0.82 of the path tracer's, the entry's 0.84 0.85 0.84.
                float lens_curvature_mm = entered ? entry_curvature / mm : pixel_curvature_mm;
                if (!entered) {
                    // No surface around it in the map (its edge): the pixel's own, straight.
                    vec4 p = unproject * vec4(ndc.xy, depth, 1.0);
                    cos_l = abs(dot(no, toward));
                    h = max(dot(p.xyz / p.w - x, toward), 0.0) * cos_l;
                } else {
                    // The bias at this entry (its slope held at tan θl ≤ 8: the band a few
                    // texels, not the whole way to a grazing surface), for this sample's depth
                    // difference and the next ones'.
                    vec4 lifted = layer_matrix(layer) * vec4(x + toward * shadow_bias_distance(cos_l, 8.0), 1.0);
                    float bias = ndc.z - lifted.z / lifted.w;
                    d += bias - (layer == bias_layer ? depth_bias : 0.0);
                    depth_bias = bias;
                    bias_layer = layer;
                }
                float cos_t = sqrt(max(1.0 - (1.0 - cos_l * cos_l) / (eta * eta), 0.0));
                // Beyond the critical angle (η < 1) no light enters there.
                bool enters = cos_t > 1e-4;
                g = s + h * mm / (enters ? cos_t : 1.0);
                // Refracted light that reaches x enters where the steps end (miss within a few
                // shadow texels, or 2% of its way inside); none where they end far from any.
                // Measured on a ball (exact entries against the steps, 2,100 random points):
                // where an entry exists the steps end a median 0.03% of the way from it, 90%
                // within 1%; where none does, 0.1% of them nearer than 2%, 1% nearer than 2.4%.
                // (A tenth, as before, lit a band past the shadow a ball casts inside itself,
                // where the beam focuses: 1.3x Ketchup's green with lens_gain.)
                float tolerance = max(light_set.normal_offset, 0.02 * h / max(cos_t, 1e-3));
                float reached = 1.0 - smoothstep(tolerance, 2.0 * tolerance, miss);
                // The beam's flux inside per unit area across it (its irradiance at normal incidence outside).
                beam = enters ? reached * incident * cos_l * fresnel_transmittance(eta, cos_l) / cos_t : vec3(0.0);
                if (enters) beam *= lens_gain(h * mm / cos_t, cos_l, cos_t, eta, lens_curvature_mm);
            }
            float ds = s - s_prev;
            if (k > 0u && inside && inside_prev) {
                // The beam changes along the interval (focusing, the edge of a shadow): the
                // mean of its ends (the end alone took whole intervals into light that only
                // their end saw: 1.4x Ketchup's green single scattering with the lens gain).
                along += interval_integral(sigma_t, g_prev, g, ds) * (0.5 * (beam + beam_prev));
                slope_prev = (g - g_prev) / ds; // d(s + s_l)/ds over the interval
            } else if (k > 0u && (inside || inside_prev)) {
                // The ray leaves (or enters) the object within the interval: where, from the depth
                // differences at its ends, linear between them (the middle if one is unknown), so
                // that the sum does not jump as the object's thickness passes a sample.
                bool known = d_prev > -1e29 && d > -1e29 && d_prev != d;
                float f = known ? clamp(d_prev / (d_prev - d), 0.0, 1.0) : 0.5;
                if (inside_prev) {
                    float len = f * ds;
                    along += interval_integral(sigma_t, g_prev, g_prev + slope_prev * len, len) * beam;
                } else {
                    along += exp(-sigma_t * g) * (1.0 - f) * ds * beam;
                }
            }
            d_prev = near ? max(d, 1e-7) : d;
            g_prev = g;
            s_prev = s;
            inside_prev = inside;
            beam_prev = beam;
        }
        sum += along;
    }
    float ft_o = fresnel_transmittance(eta, cos_o);
    return ft_o / (eta * eta) * sigma_s * (1.0 / (4.0 * 3.14159265358979323846)) * sum;
}

// Every binding stays in every model's module (a branch no frame takes: no list tile is 0 pixels
// a side), so that they share one pipeline layout and one list of resources.
void keep_every_binding() {
    uint any = texel(nodes, 0u).x + texel(points, 0u).x + work.objects[0].pixels + light_set.light_count
        + texel(point_lights, 0u).x + texel(node_flux, 0u).x + texel(tile_headers, 0u).x + texel(tile_entries, 0u).x
        + texel(dipole_table, 0u).x + texel(point_flux, 0u).x + texel(point_spread, 0u).x + texel(far_field, 0u).x
        + frame_params.brute_force + object_params.point_count;
    vec4 images = imageLoad(surface_position, ivec2(0)) + imageLoad(surface_normal, ivec2(0))
        + imageLoad(surface_albedo, ivec2(0)) + texture(shadow_depth, vec3(0.0))
        + vec4(texelFetch(shadow_normals, ivec3(0), 0))
        + vec4(shadow_visibility(0u, vec3(0.0), vec3(0.0, 0.0, 1.0)));
    radiance = images + vec4(float(any));
}

void main() {
    if (pc.point_range.w == 0u) {
        keep_every_binding();
        return;
    }
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 surface = imageLoad(surface_position, pixel);
    // No surface: the background pass drew it.
    if (surface.w == 0.0) discard;
    // Another object's pixel: its own draw shades it.
    if (surface.w != float(pc.point_range.z + 1u)) discard;
    vec3 xo = surface.xyz;
    vec4 normal_curvature = imageLoad(surface_normal, pixel);
    vec3 no = normalize(normal_curvature.xyz);
    own_weight = imageLoad(surface_albedo, pixel).rgb;
    begin_sources(normal_curvature);
    begin_thickness(xo, no);
    vec3 wo = normalize(pc.eye.xyz - xo);
    if (MODEL == MODEL_MC) {
        exit_along = wo - dot(wo, no) * no;
        exit_normal = no;
    }
    vec3 sum = vec3(0.0);
    uint visits = 0u;
    uint evaluated = 0u;
    uint evaluations = 0u;
    uint light_count = light_set.light_count;
    if (NEAR_FIELD) own_light(xo, no);
    if (frame_params.brute_force != 0u || object_params.node_count == 0u) {
        // One draw per range of (point, light) records, added by blending: llvmpipe (lavapipe)
        // silently ends a shader invocation's loops after ~65k iterations in total, so no draw
        // may loop longer.
        uint end = min(pc.point_range.x + pc.point_range.y, object_params.point_count * light_count);
        uint corrections = 0u;
        for (uint r = pc.point_range.x; r < end; ++r) {
            sum += point_light_source(r, light_count, xo, no);
            // The near field's control variate, once per point (with --near-field on).
            if (r % light_count == 0u) {
                uint point = r / light_count;
                vec4 position_area = texel_float(points, point * POINT_TEXELS);
                vec3 ni = texel_float(points, point * POINT_TEXELS + 1u).xyz;
                near_correction(position_area.xyz, ni, position_area.w, xo, no, corrections);
            }
        }
        evaluated = end > pc.point_range.x ? end - pc.point_range.x : 0u;
        evaluations = evaluated + corrections;
    } else {
        // The tile's list (tile_cut.comp): every lane of the tile runs the same evaluations in
        // the same order, one loop iteration each, so the lanes of a SIMD group or warp stay
        // together and load the same records.
        uint list_tile = pc.point_range.w;
        uint tiles_across = (uint(imageSize(surface_position).x) + list_tile - 1u) / list_tile;
        uint tile_index = (uint(pixel.y) / list_tile) * tiles_across + uint(pixel.x) / list_tile;
        uvec4 tile = texel(tile_headers, tile_index);
        uint entry = tile.x;
        uint point_count = tile.y & 0xffffu, near_count = tile.y >> 16;
        // A list built without the near field (no pixel of the tile lit, as tile_cut.comp found
        // with the same lights and shadow maps): no variate, the plain sum, as the cut has it.
        if (tile.w != NEAR_FIELD_TILE && tile.w != WALK_FROM_ROOT) own_lit = false;
        // The points within the near field's reach of the tile, with its control variate.
        for (uint e = 0u; e < near_count; ++e) {
            uint index = tile_entry(entry + e);
            vec3 xi, power;
            vec4 incident[3];
            float area;
            point_source(index, xi, power, incident, area);
            vec3 ni = texel_float(points, index * POINT_TEXELS + 1u).xyz;
            // Unlit points are listed only within the near field's reach, for its control variate.
            float v = near_correction(xi, ni, area, xo, no, evaluations);
            if (power == vec3(0.0)) continue;
            uint made;
            vec3 f = point_evaluated(index, xi, ni, power, incident, xo, no, xo, made);
            sum += f;
            near_sources += v * f;
            evaluations += made;
        }
        // The rest, beyond its reach: no pixel of the tile pays for the variate's code there.
        for (uint e = near_count; e < point_count; ++e) {
            uint index = tile_entry(entry + e);
            vec3 xi, power;
            vec4 incident[3];
            float area;
            point_source(index, xi, power, incident, area);
            if (power == vec3(0.0)) continue;
            vec3 ni = texel_float(points, index * POINT_TEXELS + 1u).xyz;
            uint made;
            sum += point_evaluated(index, xi, ni, power, incident, xo, no, xo, made);
            evaluations += made;
        }
        evaluated += point_count;
        entry += point_count;
        // Both sigma points of a node in one iteration: its records are loaded once.
        for (uint e = 0u; e < tile.z; ++e) {
            uint index = tile_entry(entry + e);
            vec3 ni = decode_oct(texel(nodes, index * NODE_TEXELS + 3u).x);
            vec3 center, offset, power;
            vec4 incident[3];
            float area;
            node_sigma(index, ni, xo, center, offset, power, incident, area);
            // Never within the near field's reach of the tile: the tile cut opens such nodes, so
            // no node pays for the control variate's unfolding (llvmpipe would run it for every
            // node, reach or not).
            if (power == vec3(0.0)) continue;
            evaluations += 2u;
            sum += merged_source(center + offset, ni, power, incident, vec3(0.0), xo, no,
                                 sigma_point_curvature(center + offset, ni, offset, xo, no), true)
                 + merged_source(center - offset, ni, power, incident, vec3(0.0), xo, no,
                                 sigma_point_curvature(center - offset, ni, -offset, xo, no), true);
        }
        visits += tile.z;
        // The tile's far sources (none where the tile has no far field: its sums are 0), summed
        // at sixteen of its pixels by the far-field pass and interpolated here.
        if (frame_params.far_field != 0u && list_tile == FAR_FIELD_TILE) {
            ivec2 at = pixel % int(FAR_FIELD_TILE);
            vec4 wu = far_weights(float(at.x)), wv = far_weights(float(at.y));
            for (uint k = 0u; k < FAR_FIELD_SAMPLES; ++k) {
                vec4 far = (wu[k % 4u] * wv[k / 4u]) * texel_float(far_field, tile_index * FAR_FIELD_SAMPLES + k);
                sum += far.xyz;
                far_light += vec2(far.w, dot(far.xyz, LUMINANCE));
            }
        }

        // A tile whose list did not fit this frame: each pixel walks the tree from the root with
        // its own stack. Points are pushed like nodes, so that each step evaluates at most
        // one source at one place in the code: the lanes of a SIMD group (llvmpipe) or warp (GPU)
        // that evaluate in a step do it together, whether their source is a node or a point.
        // Stack entries are a point or node and, in bits 24-28, which of its evaluations is
        // next: 0 for a fresh entry (test it first), e + 1 for evaluation e. A source's
        // evaluations (one for a point, two sigma points for a node) are steps of this one
        // loop, each pushing the next.
        if (tile.w == WALK_FROM_ROOT) {
            uint steps = evaluations;
            uint stack[STACK_SIZE];
            uint top = 0u;
            stack[top++] = 0u;
            while (top > 0u) {
                uint item_entry = stack[--top];
                ++steps;
                uint next = (item_entry >> EVALUATION_SHIFT) & EVALUATION_MASK;
                uint item = item_entry & ~(EVALUATION_MASK << EVALUATION_SHIFT);
                bool is_point = (item & LEAF_BIT) != 0u;
                uint index = item & ~LEAF_BIT;
                vec3 ni;
                if (is_point) {
                    ni = texel_float(points, index * POINT_TEXELS + 1u).xyz;
                    if (next == 0u) {
                        ++evaluated;
                        // Unlit: only the near field's control variate needs it.
                        if (texel_float(points, index * POINT_TEXELS + 2u).xyz == vec3(0.0)
                            && !(NEAR_FIELD && near_weight(texel_float(points, index * POINT_TEXELS).xyz, xo) > 0.0))
                            continue;
                    }
                } else {
                    // A continuation needs only the node's normal: the rest is loaded on its first visit.
                    ni = decode_oct(texel(nodes, index * NODE_TEXELS + 3u).x);
                    if (next == 0u) {
                        vec4 power_area = texel_float(nodes, index * NODE_TEXELS);
                        uvec4 center_left = texel(nodes, index * NODE_TEXELS + 1u);
                        uvec4 box_right = texel(nodes, index * NODE_TEXELS + 2u);
                        ++visits;
                        vec3 lo, hi;
                        unpack_box(box_right.xyz, lo, hi);
                        // Unlit: only the near field's control variate needs it, within its reach.
                        if (power_area.xyz == vec3(0.0) && !(NEAR_FIELD && within_near_reach(xo, lo, hi))) continue;
                        vec3 d = uintBitsToFloat(center_left.xyz) - xo;
                        // A node within the near field's reach is opened down to its points (only
                        // points enter the control variate).
                        bool inside = all(greaterThanEqual(xo, lo)) && all(lessThanEqual(xo, hi))
                            || (NEAR_FIELD && within_near_reach(xo, lo, hi));
                        // A full stack or a spent step budget (see above) ends the descent: the
                        // node is then used whole, an approximation rather than a silently
                        // truncated sum.
                        bool must_stop = top + 2u > STACK_SIZE || steps > MAX_STEPS;
                        if (inside || power_area.w >= frame_params.epsilon * dot(d, d)) {
                            if (!must_stop) {
                                stack[top++] = center_left.w;
                                stack[top++] = box_right.w;
                                continue;
                            }
                        }
                    }
                }
                uint evaluation = next == 0u ? 0u : next - 1u;
                // A node's second sigma point, after this one (it took this entry's place).
                if (!is_point && evaluation == 0u) stack[top++] = item | (2u << EVALUATION_SHIFT);
                vec3 xi, offset, power;
                vec4 incident[3];
                float area;
                if (is_point) {
                    point_source(index, xi, power, incident, area);
                } else {
                    node_sigma(index, ni, xo, xi, offset, power, incident, area);
                    xi += evaluation != 0u ? -offset : offset;
                }
                if (is_point) {
                    float v = near_correction(xi, ni, area, xo, no, evaluations);
                    if (power == vec3(0.0)) continue;
                    uint made;
                    vec3 f = point_evaluated(index, xi, ni, power, incident, xo, no, xo, made);
                    evaluations += made;
                    sum += f;
                    near_sources += v * f;
                } else {
                    // Beyond the near field's reach (opened above when within it; a spent
                    // budget may stop that, and the node is then used whole without its share).
                    if (power == vec3(0.0)) continue;
                    ++evaluations;
                    float kappa = sigma_point_curvature(xi, ni, evaluation != 0u ? -offset : offset, xo, no);
                    sum += merged_source(xi, ni, power, incident, vec3(0.0), xo, no, kappa, true);
                }
            }
        }
    }
    // The near field, once: by the first of several brute-force draws.
    if (NEAR_FIELD) {
        uint made = 0u;
        vec3 integral = pc.point_range.x == 0u ? near_field(xo, no, made) : vec3(0.0);
        evaluations += made;
        // near_blend: the blend γ per channel between the control variate (γ = 0) and taking the peak from
        // the pixel's own irradiance alone (γ = 1), see near_field(): the least γ that keeps the
        // pixel's own-irradiance coefficient G − (1 − γ) Σg non-negative, so no pixel can be
        // negative whatever its lights. Both ends expect the same where E is smooth; γ > 0 only
        // where the points oversample the peak (Σg > G: a point a small fraction of a spacing
        // from the pixel), which is exactly where the variate alone went negative at a shadow's
        // or terminator's edge. It is a ratio of two sums under the same light: the geometry's
        // alone but for the directional dipole's mean direction, so the image stays linear in
        // the lights but where a pixel is lit by some lights and not others (an unlit pixel has
        // no variate and γ = 0: measured 16 lights against 8 + 8 in tests/image_quality.rs).
        // Brute force's draws each see part of the points, so it keeps γ = 0.
        bool tree = frame_params.brute_force == 0u && object_params.node_count != 0u;
        vec3 points_estimate = -near_sum;
        vec3 blend = vec3(0.0);
        for (uint c = 0u; c < 3u; ++c) {
            if (tree && points_estimate[c] > integral[c]) blend[c] = 1.0 - integral[c] / points_estimate[c];
        }
        sum -= blend * near_sources;
        sum += integral - (1.0 - blend) * points_estimate;
    }
    // Helper invocations' atomics have no effect (Vulkan spec), so only real pixels count.
    if (frame_params.count_work != 0u) {
        // Brute-force draws after the first add their points only.
        bool brute_force = frame_params.brute_force != 0u || object_params.node_count == 0u;
        if (pc.point_range.x == 0u) {
            atomicAdd(work.objects[pc.point_range.z].pixels, 1u);
            atomicAdd(work.objects[pc.point_range.z].node_sum, visits);
            atomicMax(work.objects[pc.point_range.z].node_max, visits);
            // A brute-force pixel's points span several draws: its maximum is all of them (the
            // measured sum over the draws checks it).
            atomicMax(work.objects[pc.point_range.z].point_max, brute_force ? object_params.point_count * light_count : evaluated);
        }
        atomicAdd(work.objects[pc.point_range.z].point_sum, evaluated);
        atomicAdd(work.objects[pc.point_range.z].evaluation_sum, evaluations);
    }
    float cos_o = max(dot(no, wo), 0.0);
    // The exit's half of the texture's weight (the sources' half is in their irradiance).
    sum *= own_weight;
    across_sum *= own_weight;
    vec3 lo = fresnel_transmittance(object_params.channels[0].eta, cos_o) * sum;
    // The Monte Carlo table's exit distribution (the others' lobe is Ft alone).
    if (MODEL == MODEL_MC) {
        // The pixel's own flux: already there where the near field needed it.
        if (!NEAR_FIELD) own_light(xo, no);
        // On a curved surface the exit's distribution is the ball's (curvature_exit: less
        // grazing light leaves a ball than a half-space).
        // and light from a ball's far side leaves it nearer the normal (far_light).
        float far = far_light.y > 0.0 ? clamp(far_light.x / far_light.y, 0.0, 1.0) : 0.0;
        // Read at the mean incidence of the light it carries (entry_incidence).
        float sin2_i = entry_incidence.y > 0.0 ? clamp(entry_incidence.x / entry_incidence.y, 0.0, 1.0) : 0.0;
        lo *= table_exit_factor(dipole_table, own_cos_t(), cos_o)
            * curvature_exit(dipole_table, pixel_curvature_rows, cos_o, far, sin2_i);
        if (across_thickness.y > 0.0) {
            float t = across_thickness.x / across_thickness.y;
            vec3 sin2_t = across_incidence / across_thickness.y;
            lo += fresnel_transmittance(object_params.channels[0].eta, cos_o) * across_sum
                * slab_exit_factor(dipole_table, slab_header, t, cos_o)
                * slab_oblique_factor(dipole_table, slab_header, t, sin2_t, object_params.channels[0].eta);
        } else {
            lo += fresnel_transmittance(object_params.channels[0].eta, cos_o) * across_sum;
        }
        // Single scattering, once (by the first of several brute-force draws, as the lobe).
        // Single scattering is the pixel's own: its whole weight (the albedo's ratio).
        if (frame_params.scattering == 1u) lo = vec3(0.0);
        if (pc.point_range.x == 0u && frame_params.scattering != 2u)
            lo += own_weight * own_weight * single_scattering(xo, no, wo);
    }
    // The lobe is added once: by the first of several brute-force draws.
    if (frame_params.specular != 0u && pc.point_range.x == 0u) lo += specular(xo, no, wo);
    radiance = vec4(lo, 1.0);
}
