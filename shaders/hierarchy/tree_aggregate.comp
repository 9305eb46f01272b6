#version 460
// Threads hand node summaries to each other through memory: the Vulkan memory model's
// acquire/release atomics make that visible (plain `coherent` + memoryBarrierBuffer lost updates
// on lavapipe).
#extension GL_KHR_memory_scope_semantics : require
// Bottom-up summaries: one thread per point climbs toward the root; at each node the first thread
// to arrive stops and the second, which knows both children are done, sums them. Sums are always
// left + right, so the result does not depend on which thread arrives second.
// A node's geometry (area, area-weighted centre, bounds) does not depend on the lights; its
// normal is its sources': power-weighted where it is lit (area-weighted where not). A node
// across a box's edge, lit on one face, took the mean of both faces' normals, so its refracted
// light and the directional dipole's planes were the unlit face's half-way: the slab's unlit
// face came out 2-4% too bright in red at ε = 0.2. Its NodeFlux sums its points' merged light
// records (PointFlux), one record whatever the number of lights.
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Sorted { SurfacePoint points[]; };
layout(std430, binding = 1) queuefamilycoherent buffer Nodes { TreeNode nodes[]; };
layout(std430, binding = 2) readonly buffer NodeParents { uint node_parent[]; };
layout(std430, binding = 3) readonly buffer PointParents { uint point_parent[]; };
layout(std430, binding = 4) queuefamilycoherent buffer Arrivals { uint arrivals[]; };
layout(std430, binding = 5) readonly buffer SortedPointFluxes { PointFlux point_flux[]; };
layout(std430, binding = 6) queuefamilycoherent buffer NodeFluxes { NodeFlux node_flux[]; };
layout(push_constant) uniform TreeConstants { uint point_count; } pc;

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

NodeFlux flux_of_child(uint child) {
    if ((child & LEAF_BIT) != 0u) {
        uint i = child & ~LEAF_BIT;
        PointFlux p = point_flux[i];
        float area = points[i].area;
        return NodeFlux(vec4[3](p.incident[0] * area, p.incident[1] * area, p.incident[2] * area),
                        points[i].position, 0.0);
    }
    return node_flux[child];
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
        vec3 normal_sum = wa + wb > 0.0 ? a.normal * wa + b.normal * wb : a.normal * a.area + b.normal * b.area;
        vec3 light_sum = a.light * wa + b.light * wb;
        nodes[node].power = a.power + b.power;
        nodes[node].area = a.area + b.area;
        nodes[node].center = center;
        nodes[node].normal_oct = encode_oct(dot(normal_sum, normal_sum) > 0.0 ? normalize(normal_sum) : vec3(0.0, 0.0, 1.0));
        nodes[node].light_oct = dot(light_sum, light_sum) > 0.0 ? encode_oct(normalize(light_sum)) : 0u;
        nodes[node].box_half = pack_box(min(a.lo, b.lo), max(a.hi, b.hi));
        NodeFlux fa = flux_of_child(left), fb = flux_of_child(right);
        NodeFlux merged;
        for (uint c = 0u; c < 3u; ++c) merged.incident[c] = fa.incident[c] + fb.incident[c];
        if (wa + wb > 0.0) {
            merged.power_center = (fa.power_center * wa + fb.power_center * wb) / (wa + wb);
            // Parallel axes: each child's spread about its own centre plus its offset.
            merged.spread2 = (wa * (fa.spread2 + dot(squared(fa.power_center - merged.power_center), vec3(1.0)))
                            + wb * (fb.spread2 + dot(squared(fb.power_center - merged.power_center), vec3(1.0))))
                           / (wa + wb);
        } else {
            merged.power_center = center;
            merged.spread2 = 0.0;
        }
        node_flux[node] = merged;
        node = node_parent[node];
    }
}
