#version 460
// Karras (HPG 2012) binary radix tree over the sorted 63-bit keys: one thread per internal node
// finds its key range and split from the keys alone, so all N − 1 nodes are built in parallel.
// Equal keys are told apart by their index, as Karras suggests.
#include "points.glsl"
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Keys { uvec2 keys[]; };
layout(std430, binding = 1) writeonly buffer Nodes { TreeNode nodes[]; };
layout(std430, binding = 2) writeonly buffer NodeParents { uint node_parent[]; };
layout(std430, binding = 3) writeonly buffer PointParents { uint point_parent[]; };
layout(std430, binding = 4) writeonly buffer Arrivals { uint arrivals[]; };
layout(push_constant) uniform TreeConstants { uint point_count; } pc;

const uint NONE = 0xffffffffu;

int clz32(uint x) { return 31 - findMSB(x); } // findMSB(0) = -1 gives 32

// Length of the common prefix of keys i and j (−1 outside the array).
int delta(int i, int j) {
    if (j < 0 || j >= int(pc.point_count)) return -1;
    uvec2 a = keys[i], b = keys[j];
    if (a == b) return 64 + clz32(uint(i) ^ uint(j));
    uvec2 x = a ^ b;
    return x.y != 0u ? clz32(x.y) : 32 + clz32(x.x);
}

void main() {
    int i = int(gl_GlobalInvocationID.x);
    int n = int(pc.point_count);
    if (i >= n - 1) return;
    if (i == 0) node_parent[0] = NONE;
    arrivals[i] = 0u;

    int d = (delta(i, i + 1) - delta(i, i - 1)) >= 0 ? 1 : -1;
    int delta_min = delta(i, i - d);
    int l_max = 2;
    while (delta(i, i + l_max * d) > delta_min) l_max *= 2;
    int l = 0;
    for (int t = l_max / 2; t >= 1; t /= 2) {
        if (delta(i, i + (l + t) * d) > delta_min) l += t;
    }
    int j = i + l * d;
    int delta_node = delta(i, j);
    int s = 0;
    for (int t = (l + 1) / 2; ; t = (t + 1) / 2) {
        if (delta(i, i + (s + t) * d) > delta_node) s += t;
        if (t == 1) break;
    }
    int split = i + s * d + min(d, 0);
    int first = min(i, j), last = max(i, j);

    uint left = first == split ? (uint(split) | LEAF_BIT) : uint(split);
    uint right = last == split + 1 ? (uint(split + 1) | LEAF_BIT) : uint(split + 1);
    if ((left & LEAF_BIT) != 0u) point_parent[split] = uint(i); else node_parent[split] = uint(i);
    if ((right & LEAF_BIT) != 0u) point_parent[split + 1] = uint(i); else node_parent[split + 1] = uint(i);

    nodes[i].left = left;
    nodes[i].right = right;
    nodes[i].first_point = uint(first);
    nodes[i].point_count = uint(last - first + 1);
}
