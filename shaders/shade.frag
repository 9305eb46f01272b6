#version 460
// Subsurface scattering per pixel: walks the Jensen–Buhler tree from the root with an explicit
// stack; a node far and small enough (area / distance² from its area centre < epsilon, and xo
// outside its box) is used whole: one source per light at that light's power centre; otherwise
// its children are visited; points are evaluated singly, one source per light.
// Lo(xo, wo) = Ft(eta, wo) · Σ over sources and lights Sd(xi, wi_k; xo, no) · power_k, power = E·A
// (mm²), plus the surface's own reflection from each light: a microfacet lobe, shadowed by the
// same shadow maps. Which nodes are used whole does not depend on the lights, and each term
// depends on one light only, so renders of several lights are the sums of each alone.
#include "common.glsl"
#include "shade_constants.glsl"
#include "points.glsl"
#include "subsurface_params.glsl"
#include "lights.glsl"
#include "microfacet.glsl"

// Depth test before shading: the shader writes the work counters, and without this a driver may
// run it for every layer of the mesh and test depth after (llvmpipe did: a 64x64 sphere counted
// 6144 shaded pixels, its back faces walked the tree too).
layout(early_fragment_tests) in;

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;
layout(location = 0) out vec4 radiance;

layout(std430, binding = 0) readonly buffer Params { SubsurfaceParams params; };
layout(std430, binding = 1) readonly buffer Nodes { TreeNode nodes[]; };
layout(std430, binding = 2) readonly buffer Sorted { SurfacePoint points[]; };
// Work per pixel for --profile: sums and maxima of nodes visited and points evaluated.
// Sd evaluations: calls of source(), each for three channels (a node used whole is two per light).
layout(std430, binding = 3) buffer WorkCounters { uint pixels; uint node_sum; uint node_max; uint point_sum; uint point_max; uint evaluation_sum; } work;
layout(std430, binding = 4) readonly buffer Lights { LightSet light_set; mat4 layer_matrices[]; };
layout(binding = 5) uniform sampler2DArrayShadow shadow_map;
layout(std430, binding = 6) readonly buffer SortedPointLights { PointLight point_lights[]; };
layout(std430, binding = 7) readonly buffer NodeLights { NodeLight node_lights[]; };

const uint STACK_SIZE = 96u;
// Stack entries: a point or node index (below 2^24, with LEAF_BIT for points) and the number of
// its next evaluation plus one (2 · MAX_LIGHTS at most).
const uint EVALUATION_SHIFT = 24u;
const uint EVALUATION_MASK = 0x1fu;
// Steps of the walk (tests of nodes and points, and evaluations) before it stops opening nodes:
// llvmpipe's loop budget.
const uint MAX_STEPS = 32768u;

vec3 source(vec3 xi, vec3 ni, vec3 wi, vec3 power, vec3 xo, vec3 no) {
    float s = params.mm_per_unit;
    vec3 sd;
    // Written out, not looped: loop iterations count against llvmpipe's budget (see main).
    if (params.model == MODEL_DIRECTIONAL) {
        // The geometry once for all three channels (they share eta).
        vec3 xi_mm = xi * s, xo_mm = xo * s;
        DirpoleGeometry g = dirpole_geometry(xi_mm, ni, wi, xo_mm, no, params.channels[0].eta);
        sd = vec3(dirpole_channel_sd(params.channels[0], g, xi_mm, xo_mm, no),
                  dirpole_channel_sd(params.channels[1], g, xi_mm, xo_mm, no),
                  dirpole_channel_sd(params.channels[2], g, xi_mm, xo_mm, no));
    } else {
        float r = length(xo - xi) * s;
        sd = vec3(dipole_sd(params.channels[0], r), dipole_sd(params.channels[1], r), dipole_sd(params.channels[2], r));
    }
    return sd * power * (s * s); // power is irradiance × scene-unit area: to mm²
}

// One light's record of one point: record = point · light_count + light.
vec3 point_light_source(uint record, vec3 xo, vec3 no) {
    PointLight l = point_lights[record];
    if (l.irradiance == vec3(0.0)) return vec3(0.0);
    SurfacePoint p = points[record / light_set.light_count];
    return source(p.position, p.normal, decode_oct(l.toward_oct), l.irradiance * p.area, xo, no);
}

// Σ over lights of f_spec(wi, wo) · E · cos θi · visibility.
vec3 specular(vec3 xo, vec3 no, vec3 wo) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < light_set.light_count; ++k) {
        vec3 toward;
        uint layer;
        vec3 incident = light_at(light_set.lights[k], xo, toward, layer);
        float f_cos = microfacet_reflect_cos(no, toward, wo, params.roughness, params.channels[0].eta);
        if (f_cos <= 0.0) continue;
        vec4 clip = layer_matrices[layer] * vec4(xo + no * light_set.normal_offset, 1.0);
        vec3 ndc = clip.xyz / clip.w;
        float visibility = texture(shadow_map, vec4(ndc.xy * 0.5 + 0.5, float(layer), ndc.z));
        sum += f_cos * incident * visibility;
    }
    return sum;
}

void main() {
    vec3 xo = world_position;
    vec3 no = normalize(world_normal);
    vec3 wo = normalize(pc.eye.xyz - xo);
    vec3 sum = vec3(0.0);
    uint visits = 0u;
    uint evaluated = 0u;
    uint evaluations = 0u;
    uint light_count = light_set.light_count;
    if (params.brute_force != 0u || params.node_count == 0u) {
        // One draw per range of (point, light) records, added by blending: llvmpipe (lavapipe)
        // silently ends a shader invocation's loops after ~65k iterations in total, so no draw
        // may loop longer.
        uint end = min(pc.point_range.x + pc.point_range.y, params.point_count * light_count);
        for (uint r = pc.point_range.x; r < end; ++r) sum += point_light_source(r, xo, no);
        evaluated = end > pc.point_range.x ? end - pc.point_range.x : 0u;
        evaluations = evaluated;
    } else {
        // Points are pushed like nodes, so that each step evaluates at most one source at one
        // place in the code: the lanes of a SIMD group (llvmpipe) or warp (GPU) that evaluate in
        // a step do it together, whether their source is a node or a point.
        // Stack entries are a point or node and, in bits 24-28, which of its evaluations is
        // next: 0 for a fresh entry (test it first), e + 1 for evaluation e. A source's
        // evaluations (one per light for a point, two sigma points per light for a node) are
        // steps of this one loop, each pushing the next: lanes of a SIMD group or warp step
        // together, so those that evaluate do it at the same place, whatever their source.
        uint stack[STACK_SIZE];
        uint top = 0u;
        stack[top++] = 0u;
        uint steps = 0u;
        while (top > 0u) {
            uint entry = stack[--top];
            ++steps;
            uint next = (entry >> EVALUATION_SHIFT) & EVALUATION_MASK;
            uint item = entry & ~(EVALUATION_MASK << EVALUATION_SHIFT);
            bool is_point = (item & LEAF_BIT) != 0u;
            uint index = item & ~LEAF_BIT;
            vec3 ni;
            if (is_point) {
                ni = points[index].normal;
                if (next == 0u) {
                    ++evaluated;
                    if (points[index].irradiance == vec3(0.0)) continue;
                }
            } else {
                // A continuation needs only the node's normal: the rest is loaded on its first visit.
                ni = decode_oct(nodes[index].normal_oct);
                if (next == 0u) {
                    TreeNode node = nodes[index];
                    ++visits;
                    if (node.power == vec3(0.0)) continue;
                    vec3 lo, hi;
                    unpack_box(node.box_half, lo, hi);
                    vec3 d = node.center - xo;
                    bool inside = all(greaterThanEqual(xo, lo)) && all(lessThanEqual(xo, hi));
                    // A full stack or a spent step budget (see above) ends the descent: the node
                    // is then used whole, an approximation rather than a silently truncated sum.
                    bool must_stop = top + 2u > STACK_SIZE || steps > MAX_STEPS;
                    if (inside || node.area >= params.epsilon * dot(d, d)) {
                        if (!must_stop) {
                            stack[top++] = node.left;
                            stack[top++] = node.right;
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
            vec3 center, power, offset = vec3(0.0);
            uint toward_oct;
            if (is_point) {
                PointLight l = point_lights[index * light_count + k];
                center = points[index].position;
                power = l.irradiance * points[index].area;
                toward_oct = l.toward_oct;
            } else {
                // A node used whole is not one source at its power centre c: Sd is convex in
                // distance, so that underestimates it (1-1.5% on a slab). Two sigma points
                // c ± s(u + t), s² = spread²/2 per axis of the node's tangent plane (u toward xo,
                // t across), match the points' mean and second moments, so Sd's curvature along
                // u and t is taken into account to second order.
                NodeLight l = node_lights[index * light_count + k];
                center = l.power_center;
                power = 0.5 * l.power;
                toward_oct = l.toward_oct;
                vec3 towards_xo = xo - center;
                vec3 u = towards_xo - ni * dot(towards_xo, ni);
                u = dot(u, u) > 0.0 ? normalize(u) : normalize(cross(ni, abs(ni.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0)));
                offset = sqrt(0.5 * l.spread2) * (u + cross(ni, u));
                if ((evaluation & 1u) != 0u) offset = -offset;
            }
            if (power == vec3(0.0)) continue;
            ++evaluations;
            sum += source(center + offset, ni, decode_oct(toward_oct), power, xo, no);
        }
    }
    // Helper invocations' atomics have no effect (Vulkan spec), so only real pixels count.
    if (params.count_work != 0u) {
        // Brute-force draws after the first add their points only.
        bool brute_force = params.brute_force != 0u || params.node_count == 0u;
        if (pc.point_range.x == 0u) {
            atomicAdd(work.pixels, 1u);
            atomicAdd(work.node_sum, visits);
            atomicMax(work.node_max, visits);
            // A brute-force pixel's points span several draws: its maximum is all of them (the
            // measured sum over the draws checks it).
            atomicMax(work.point_max, brute_force ? params.point_count * light_count : evaluated);
        }
        atomicAdd(work.point_sum, evaluated);
        atomicAdd(work.evaluation_sum, evaluations);
    }
    float cos_o = max(dot(no, wo), 0.0);
    vec3 lo = fresnel_transmittance(params.channels[0].eta, cos_o) * sum;
    // The lobe is added once: by the first of several brute-force draws.
    if (params.specular != 0u && pc.point_range.x == 0u) lo += specular(xo, no, wo);
    radiance = vec4(lo, 1.0);
}
