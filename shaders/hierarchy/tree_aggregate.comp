#version 460
// Threads hand node summaries to each other through memory: the Vulkan memory model's
// acquire/release atomics make that visible (plain `coherent` + memoryBarrierBuffer lost updates
// on lavapipe).
#extension GL_KHR_memory_scope_semantics : require
// Bottom-up summaries: one thread per point climbs toward the root; at each node the first thread
// to arrive stops and the second, which knows both children are done, sums them. Sums are always
// left + right, so the result does not depend on which thread arrives second.
// A node's geometry (area, area-weighted centre, normal, bounds) does not depend on the lights;
// each light gets its own NodeLight (power, power centre and spread, direction), so that what a
// node contributes is a sum over lights of terms that each depend on one light only.
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Sorted { SurfacePoint points[]; };
layout(std430, binding = 1) queuefamilycoherent buffer Nodes { TreeNode nodes[]; };
layout(std430, binding = 2) readonly buffer NodeParents { uint node_parent[]; };
layout(std430, binding = 3) readonly buffer PointParents { uint point_parent[]; };
layout(std430, binding = 4) queuefamilycoherent buffer Arrivals { uint arrivals[]; };
layout(std430, binding = 5) readonly buffer SortedPointLights { PointLight point_lights[]; };
layout(std430, binding = 6) queuefamilycoherent buffer NodeLights { NodeLight node_lights[]; };
layout(push_constant) uniform TreeConstants { uint point_count; uint light_count; } pc;

const uint NONE = 0xffffffffu;

struct Summary { vec3 power; float area; vec3 center; vec3 normal; vec3 light; vec3 lo; vec3 hi; };

Summary of_child(uint child) {
    Summary s;
    if ((child & LEAF_BIT) != 0u) {
        SurfacePoint p = points[child & ~LEAF_BIT];
        s.power = p.irradiance * p.area;
        s.area = p.area;
        s.center = p.position;
        s.normal = p.normal;
        s.light = p.light_dir;
        s.lo = p.position;
        s.hi = p.position;
    } else {
        TreeNode node = nodes[child];
        s.power = node.power;
        s.area = node.area;
        s.center = node.center;
        s.normal = decode_oct(node.normal_oct);
        s.light = node.light_oct == 0u ? vec3(0.0) : decode_oct(node.light_oct);
        unpack_box(node.box_half, s.lo, s.hi);
    }
    return s;
}

struct LightSummary { vec3 power; vec3 toward; vec3 power_center; float spread2; };

LightSummary light_of_child(uint child, uint k) {
    LightSummary s;
    if ((child & LEAF_BIT) != 0u) {
        uint i = child & ~LEAF_BIT;
        PointLight l = point_lights[i * pc.light_count + k];
        s.power = l.irradiance * points[i].area;
        s.toward = decode_oct(l.toward_oct);
        s.power_center = points[i].position;
        s.spread2 = 0.0;
    } else {
        NodeLight l = node_lights[child * pc.light_count + k];
        s.power = l.power;
        s.toward = decode_oct(l.toward_oct);
        s.power_center = l.power_center;
        s.spread2 = l.spread2;
    }
    return s;
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

vec3 squared(vec3 v) { return v * v; }

void main() {
    uint j = gl_GlobalInvocationID.x;
    if (j >= pc.point_count) return;
    uint node = point_parent[j];
    while (node != NONE) {
        // Release: our writes to the child's summary become available to the sibling's thread;
        // acquire: the sibling's summary becomes visible to us.
        uint earlier = atomicAdd(arrivals[node], 1u, gl_ScopeQueueFamily, gl_StorageSemanticsBuffer,
                                 gl_SemanticsAcquireRelease | gl_SemanticsMakeAvailable | gl_SemanticsMakeVisible);
        if (earlier == 0u) break;
        uint left = nodes[node].left, right = nodes[node].right;
        Summary a = of_child(left);
        Summary b = of_child(right);
        float wa = luminance(a.power), wb = luminance(b.power);
        vec3 center = (a.center * a.area + b.center * b.area) / (a.area + b.area);
        vec3 normal_sum = a.normal * a.area + b.normal * b.area;
        vec3 light_sum = a.light * wa + b.light * wb;
        nodes[node].power = a.power + b.power;
        nodes[node].area = a.area + b.area;
        nodes[node].center = center;
        nodes[node].normal_oct = encode_oct(dot(normal_sum, normal_sum) > 0.0 ? normalize(normal_sum) : vec3(0.0, 0.0, 1.0));
        nodes[node].light_oct = dot(light_sum, light_sum) > 0.0 ? encode_oct(normalize(light_sum)) : 0u;
        nodes[node].box_half = pack_box(min(a.lo, b.lo), max(a.hi, b.hi));
        for (uint k = 0u; k < pc.light_count; ++k) {
            LightSummary la = light_of_child(left, k), lb = light_of_child(right, k);
            float pa = luminance(la.power), pb = luminance(lb.power);
            NodeLight merged;
            merged.power = la.power + lb.power;
            if (pa + pb > 0.0) {
                merged.power_center = (la.power_center * pa + lb.power_center * pb) / (pa + pb);
                // Parallel axes: each child's spread about its own centre plus its offset.
                merged.spread2 = (pa * (la.spread2 + dot(squared(la.power_center - merged.power_center), vec3(1.0)))
                                + pb * (lb.spread2 + dot(squared(lb.power_center - merged.power_center), vec3(1.0))))
                               / (pa + pb);
                vec3 toward = la.toward * pa + lb.toward * pb;
                merged.toward_oct = encode_oct(dot(toward, toward) > 0.0 ? normalize(toward) : vec3(0.0, 0.0, 1.0));
            } else {
                merged.power_center = center;
                merged.spread2 = 0.0;
                merged.toward_oct = encode_oct(vec3(0.0, 0.0, 1.0));
            }
            node_lights[node * pc.light_count + k] = merged;
        }
        node = node_parent[node];
    }
}
