#version 460
// Subsurface scattering per pixel, in a full-screen pass over the G-buffer of the surface pass.
// The pixel's sources come from its tile's list (tile_cut.comp): nodes used whole for the whole
// tile (two sigma points per light), points evaluated singly (one source per light), and frontier
// nodes that this pixel walks on its own (a node far and small enough from xo, area / distance²
// < epsilon and xo outside its box, is used whole, else its children are visited). A tile whose
// list did not fit, and brute force, sum from the root or over every point instead.
// Lo(xo, wo) = Ft(eta, wo) · Σ over sources and lights Sd(xi, wi_k; xo, no) · power_k, power = E·A
// (mm²), plus the surface's own reflection from each light: a microfacet lobe, shadowed by the
// same shadow maps. Which nodes are used whole does not depend on the lights, and each term
// depends on one light only, so renders of several lights are the sums of each alone.
#include "common.glsl"
#include "shade_constants.glsl"
#include "points.glsl"
#include "shading_params.glsl"
#include "lights.glsl"
#include "microfacet.glsl"
#include "tile_lists.glsl"

// The model, fixed per pipeline: llvmpipe runs both sides of a branch for every SIMD group, so a
// model chosen at run time would cost both models' arithmetic (measured: the classical dipole
// took 2.4x longer beside the directional one's dead code).
layout(constant_id = 0) const uint MODEL = 0u; // 0 directional dipole, 1 classical dipole

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
layout(std430, binding = 4) readonly buffer Lights { LightSet light_set; mat4 layer_matrices[]; };
layout(binding = 5) uniform sampler2DArrayShadow shadow_map;
// Per-light records as texels: PointLight (sorted), NodeLight.
layout(binding = 6) uniform usamplerBuffer point_lights;
layout(binding = 7) uniform usamplerBuffer node_lights;
// The surface pass's G-buffer: world position (w = 1 where covered) and interpolated normal.
layout(binding = 8, rgba32f) uniform readonly image2D surface_position;
layout(binding = 9, rgba32f) uniform readonly image2D surface_normal;
// The tile-cut pass's lists (see tile_lists.glsl): a header texel per tile, entries 4 per texel.
layout(binding = 10) uniform usamplerBuffer tile_headers;
layout(binding = 11) uniform usamplerBuffer tile_entries;
// The classical dipole's Sd per channel, tabulated (bssrdf.glsl).
layout(binding = 12) uniform usamplerBuffer dipole_table;
layout(std140, binding = 13) uniform Frame { FrameParams frame_params; };
vec4 dipole_header; // its texel 0, read once per pixel

const uint STACK_SIZE = 96u;
// Stack entries: a point or node index (below 2^24, with LEAF_BIT for points) and the number of
// its next evaluation plus one (2 · MAX_LIGHTS at most).
const uint EVALUATION_SHIFT = 24u;
const uint EVALUATION_MASK = 0x1fu;
// Steps of the walk (tests of nodes and points, and evaluations) before it stops opening nodes:
// llvmpipe's loop budget.
const uint MAX_STEPS = 32768u;

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
    } else {
        sd = dipole_sd_table(dipole_table, dipole_header, length(xo - xi) * s);
    }
    return sd * power * (s * s); // power is irradiance × scene-unit area: to mm²
}

// One light's record of one point: record = point · light_count + light.
vec3 point_light_source(uint record, uint light_count, vec3 xo, vec3 no) {
    uvec4 l = texel(point_lights, record);
    vec3 irradiance = uintBitsToFloat(l.xyz);
    if (irradiance == vec3(0.0)) return vec3(0.0);
    uint point = record / light_count;
    vec4 position_area = texel_float(points, point * POINT_TEXELS);
    vec3 normal = texel_float(points, point * POINT_TEXELS + 1u).xyz;
    return source(position_area.xyz, normal, decode_oct(l.w), irradiance * position_area.w, xo, no);
}

// The parameters of one source: point `index` for light k.
void point_source(uint index, uint k, uint light_count, out vec3 xi, out vec3 power, out uint toward_oct) {
    uvec4 l = texel(point_lights, index * light_count + k);
    vec4 position_area = texel_float(points, index * POINT_TEXELS);
    xi = position_area.xyz;
    power = uintBitsToFloat(l.xyz) * position_area.w;
    toward_oct = l.w;
}

// The two sources of node `index` used whole for light k: sigma points center ± offset, each
// with half the power. A node used whole is not one source at its power centre c: Sd is convex in distance, so that
// underestimates it (1-1.5% on a slab). Two sigma points c ± s(u + t), s² = spread²/2 per axis of
// the node's tangent plane (u toward xo, t across), match the points' mean and second moments, so
// Sd's curvature along u and t is taken into account to second order.
void node_sigma(uint index, uint k, uint light_count, vec3 ni, vec3 xo, out vec3 center, out vec3 offset,
                out vec3 power, out uint toward_oct) {
    uint record = (index * light_count + k) * NODE_LIGHT_TEXELS;
    uvec4 power_toward = texel(node_lights, record);
    vec4 center_spread = texel_float(node_lights, record + 1u);
    center = center_spread.xyz;
    vec3 towards_xo = xo - center;
    vec3 u = towards_xo - ni * dot(towards_xo, ni);
    u = dot(u, u) > 0.0 ? normalize(u) : normalize(cross(ni, abs(ni.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
    offset = sqrt(0.5 * center_spread.w) * (u + cross(ni, u));
    power = 0.5 * uintBitsToFloat(power_toward.xyz);
    toward_oct = power_toward.w;
}

uint tile_entry(uint i) { return texel(tile_entries, i >> 2)[i & 3u]; }

// Σ over lights of f_spec(wi, wo) · E · cos θi · visibility.
vec3 specular(vec3 xo, vec3 no, vec3 wo) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        vec3 toward;
        uint layer;
        vec3 incident = light_at(light_set.lights[k], xo, toward, layer);
        float f_cos = microfacet_reflect_cos(no, toward, wo, frame_params.roughness, object_params.channels[0].eta);
        if (f_cos <= 0.0) continue;
        vec4 clip = layer_matrices[layer] * vec4(xo + no * light_set.normal_offset, 1.0);
        vec3 ndc = clip.xyz / clip.w;
        float visibility = texture(shadow_map, vec4(ndc.xy * 0.5 + 0.5, float(layer), ndc.z));
        sum += f_cos * incident * visibility;
    }
    return sum;
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    vec4 surface = imageLoad(surface_position, pixel);
    if (surface.w == 0.0) {
        // No surface: the background stays clear (and adds nothing to brute-force sums).
        radiance = vec4(0.0);
        return;
    }
    // Another object's pixel: its own draw shades it.
    if (surface.w != float(pc.point_range.z + 1u)) discard;
    vec3 xo = surface.xyz;
    vec3 no = normalize(imageLoad(surface_normal, pixel).xyz);
    dipole_header = dipole_table_header(dipole_table);
    vec3 wo = normalize(pc.eye.xyz - xo);
    vec3 sum = vec3(0.0);
    uint visits = 0u;
    uint evaluated = 0u;
    uint evaluations = 0u;
    uint light_count = light_set.light_count;
    if (frame_params.brute_force != 0u || object_params.node_count == 0u) {
        // One draw per range of (point, light) records, added by blending: llvmpipe (lavapipe)
        // silently ends a shader invocation's loops after ~65k iterations in total, so no draw
        // may loop longer.
        uint end = min(pc.point_range.x + pc.point_range.y, object_params.point_count * light_count);
        for (uint r = pc.point_range.x; r < end; ++r) sum += point_light_source(r, light_count, xo, no);
        evaluated = end > pc.point_range.x ? end - pc.point_range.x : 0u;
        evaluations = evaluated;
    } else {
        // The tile's list (tile_cut.comp): every lane of the tile runs the same evaluations in
        // the same order, one loop iteration each, so the lanes of a SIMD group or warp stay
        // together and load the same records.
        uint tiles_across = (uint(imageSize(surface_position).x) + TILE_SIZE - 1u) / TILE_SIZE;
        uvec4 tile = texel(tile_headers, (uint(pixel.y) / TILE_SIZE) * tiles_across + uint(pixel.x) / TILE_SIZE);
        uint entry = tile.x;
        for (uint e = 0u; e < tile.y * light_count; ++e) {
            uint index = tile_entry(entry + e / light_count);
            vec3 xi, power;
            uint toward_oct;
            point_source(index, e % light_count, light_count, xi, power, toward_oct);
            if (power == vec3(0.0)) continue;
            ++evaluations;
            vec3 ni = texel_float(points, index * POINT_TEXELS + 1u).xyz;
            sum += source(xi, ni, decode_oct(toward_oct), power, xo, no);
        }
        evaluated += tile.y;
        entry += tile.y;
        // Both sigma points of a (node, light) in one iteration: its records are loaded once.
        for (uint e = 0u; e < tile.z * light_count; ++e) {
            uint index = tile_entry(entry + e / light_count);
            vec3 ni = decode_oct(texel(nodes, index * NODE_TEXELS + 3u).x);
            vec3 center, offset, power;
            uint toward_oct;
            node_sigma(index, e % light_count, light_count, ni, xo, center, offset, power, toward_oct);
            if (power == vec3(0.0)) continue;
            evaluations += 2u;
            vec3 wi = decode_oct(toward_oct);
            sum += source(center + offset, ni, wi, power, xo, no) + source(center - offset, ni, wi, power, xo, no);
        }
        visits += tile.z;
        entry += tile.z;

        // Frontier nodes: each pixel walks them with its own stack, as the walk without tiles
        // did from the root. Points are pushed like nodes, so that each step evaluates at most
        // one source at one place in the code: the lanes of a SIMD group (llvmpipe) or warp (GPU)
        // that evaluate in a step do it together, whether their source is a node or a point.
        // Stack entries are a point or node and, in bits 24-28, which of its evaluations is
        // next: 0 for a fresh entry (test it first), e + 1 for evaluation e. A source's
        // evaluations (one per light for a point, two sigma points per light for a node) are
        // steps of this one loop, each pushing the next.
        bool from_root = tile.w == WALK_FROM_ROOT;
        uint frontier_count = from_root ? 1u : tile.w;
        uint steps = evaluations;
        for (uint f = 0u; f < frontier_count; ++f) {
            uint stack[STACK_SIZE];
            uint top = 0u;
            stack[top++] = from_root ? 0u : tile_entry(entry + f);
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
                        if (texel_float(points, index * POINT_TEXELS + 2u).xyz == vec3(0.0)) continue;
                    }
                } else {
                    // A continuation needs only the node's normal: the rest is loaded on its first visit.
                    ni = decode_oct(texel(nodes, index * NODE_TEXELS + 3u).x);
                    if (next == 0u) {
                        vec4 power_area = texel_float(nodes, index * NODE_TEXELS);
                        uvec4 center_left = texel(nodes, index * NODE_TEXELS + 1u);
                        uvec4 box_right = texel(nodes, index * NODE_TEXELS + 2u);
                        ++visits;
                        if (power_area.xyz == vec3(0.0)) continue;
                        vec3 lo, hi;
                        unpack_box(box_right.xyz, lo, hi);
                        vec3 d = uintBitsToFloat(center_left.xyz) - xo;
                        bool inside = all(greaterThanEqual(xo, lo)) && all(lessThanEqual(xo, hi));
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
                uint per_light = is_point ? 1u : 2u;
                // The rest of this source's evaluations, after this one (it took this entry's place).
                if (evaluation + 1u < per_light * light_count) stack[top++] = item | ((evaluation + 2u) << EVALUATION_SHIFT);
                uint k = evaluation / per_light;
                vec3 xi, power, offset;
                uint toward_oct;
                if (is_point) {
                    point_source(index, k, light_count, xi, power, toward_oct);
                } else {
                    node_sigma(index, k, light_count, ni, xo, xi, offset, power, toward_oct);
                    xi += (evaluation & 1u) != 0u ? -offset : offset;
                }
                if (power == vec3(0.0)) continue;
                ++evaluations;
                sum += source(xi, ni, decode_oct(toward_oct), power, xo, no);
            }
        }
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
    vec3 lo = fresnel_transmittance(object_params.channels[0].eta, cos_o) * sum;
    // The lobe is added once: by the first of several brute-force draws.
    if (frame_params.specular != 0u && pc.point_range.x == 0u) lo += specular(xo, no, wo);
    radiance = vec4(lo, 1.0);
}
