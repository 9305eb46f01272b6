#version 460
// Threads hand node summaries to each other through memory: the Vulkan memory model's
// acquire/release atomics make that visible (plain `coherent` + memoryBarrierBuffer lost updates
// on lavapipe).
#extension GL_KHR_memory_scope_semantics : require
// Bottom-up summaries: one thread per point climbs toward the root; at each node the first thread
// to arrive stops and the second, which knows both children are done, sums them. Sums are always
// left + right, so the result does not depend on which thread arrives second.
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Sorted { SurfacePoint points[]; };
layout(std430, binding = 1) queuefamilycoherent buffer Nodes { TreeNode nodes[]; };
layout(std430, binding = 2) readonly buffer NodeParents { uint node_parent[]; };
layout(std430, binding = 3) readonly buffer PointParents { uint point_parent[]; };
layout(std430, binding = 4) queuefamilycoherent buffer Arrivals { uint arrivals[]; };
layout(push_constant) uniform TreeConstants { uint point_count; } pc;

const uint NONE = 0xffffffffu;

struct Summary { vec3 power; float area; vec3 power_center; vec3 normal; vec3 light; vec3 lo; vec3 hi; };

Summary of_child(uint child) {
    Summary s;
    if ((child & LEAF_BIT) != 0u) {
        SurfacePoint p = points[child & ~LEAF_BIT];
        s.power = p.irradiance * p.area;
        s.area = p.area;
        s.power_center = p.position;
        s.normal = p.normal;
        s.light = p.light_dir;
        s.lo = p.position;
        s.hi = p.position;
    } else {
        TreeNode node = nodes[child];
        s.power = node.power;
        s.area = node.area;
        s.power_center = node.power_center;
        s.normal = decode_oct(node.normal_oct);
        s.light = node.light_oct == 0u ? vec3(0.0) : decode_oct(node.light_oct);
        unpack_box(node.box_half, s.lo, s.hi);
    }
    return s;
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

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
        Summary a = of_child(nodes[node].left);
        Summary b = of_child(nodes[node].right);
        float wa = luminance(a.power), wb = luminance(b.power);
        vec3 power_center = (wa + wb) > 0.0 ? (a.power_center * wa + b.power_center * wb) / (wa + wb)
                                        : (a.power_center * a.area + b.power_center * b.area) / (a.area + b.area);
        vec3 normal_sum = a.normal * a.area + b.normal * b.area;
        vec3 light_sum = a.light * wa + b.light * wb;
        nodes[node].power = a.power + b.power;
        nodes[node].area = a.area + b.area;
        nodes[node].power_center = power_center;
        nodes[node].normal_oct = encode_oct(dot(normal_sum, normal_sum) > 0.0 ? normalize(normal_sum) : vec3(0.0, 0.0, 1.0));
        nodes[node].light_oct = dot(light_sum, light_sum) > 0.0 ? encode_oct(normalize(light_sum)) : 0u;
        nodes[node].box_half = pack_box(min(a.lo, b.lo), max(a.hi, b.hi));
        node = node_parent[node];
    }
}
