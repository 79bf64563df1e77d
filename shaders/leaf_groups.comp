#version 460
#extension GL_GOOGLE_include_directive : require
// After the leaf split and leaf_first.comp: the leaves of every crowded grid
// cell in groups of at most groupLeaves consecutive leaves, each with the
// union of its leaves' boxes (issue 33). The neighbourhood pass tests a
// group's box before its leaves', so a cell of thousands of leaves costs a
// few dozen box tests and the leaves of the groups near the query, not a test
// per leaf. One thread per leaf in each mode (LeafGroupPush):
// 0: head flags (a crowded cell's leaves l0, l0 + G, l0 + 2G, ...);
// 1: the groups, each written by its head (its index: the scanned flag);
// 2: firsts[key] = the first group of each crowded cell, written by the cell's
//    first leaf (modes 0 and 1 read firsts as leafFirst, so 2 comes last).
// The union of boxes is formed with min and max, which are exact: a group's
// box holds each of its leaves' boxes.
#include "common.glsl"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { LeafGroupPush pc; };

uint leafKey(uint l) { return uintAt(pc.sortedKeys, cellAt(pc.leaves, l).v.first).v; }

bool crowded(uint key) {
    uint end = uintAt(pc.dense, key).v;
    uint start = key == 0u ? 0u : uintAt(pc.dense, key - 1u).v;
    return end - start > pc.crowded;
}

void main() {
    uint l = gl_GlobalInvocationID.x;
    if (l >= pc.numLeaves) return;
    uint key = leafKey(l);
    if (pc.mode == 2u) {
        if (crowded(key) && (l == 0u || leafKey(l - 1u) != key)) uintAt(pc.firsts, key).v = uintAt(pc.flags, l).v;
        return;
    }
    bool head = crowded(key) && (l - uintAt(pc.firsts, key).v) % pc.groupLeaves == 0u;
    if (pc.mode == 0u) {
        uintAt(pc.flags, l).v = head ? 1u : 0u;
        return;
    }
    if (!head) return;
    Cell leaf = cellAt(pc.leaves, l).v;
    LeafGroup g;
    g.lo = leaf.lo;
    g.hi = leaf.hi;
    g.firstLeaf = l;
    uint next = l + 1u;
    uint stop = l + min(pc.groupLeaves, pc.numLeaves - l);
    for (; next < stop && leafKey(next) == key; ++next) {
        Cell c = cellAt(pc.leaves, next).v;
        g.lo = min(g.lo, c.lo);
        g.hi = max(g.hi, c.hi);
    }
    bool last = next == pc.numLeaves || leafKey(next) != key;
    g.leaves = (next - l) | (last ? RTHDIST_GROUP_LAST : 0u);
    groupAt(pc.groups, uintAt(pc.flags, l).v).v = g;
}
