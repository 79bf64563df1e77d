#version 460
#extension GL_GOOGLE_include_directive : require
// The point-to-surface search's tail (design.md §11), plain compute on both
// device paths: every query the radii left open (its best farther than the
// last radius, or none) descends the float BVH of the triangles
// (gpu_algo/surface_tree.hpp) nearest-first from the best the rays found:
// a node whose box lies farther than the best is skipped (a NaN best, none
// yet, compares false: visited), an inner node's nearer child is taken
// first and the other kept on the stack, and each triangle of a leaf
// reached is measured by the rays' own test (surface_visit.glsl) on the
// tree's copy of its corners, a leaf's in consecutive records. A node's
// box holds its triangles' float boxes, so the skip is surface_visit's box
// test of each of its triangles lifted: the descent keeps what a visit of
// every triangle would. Counts the queries it searched (one atomic a
// workgroup).
//
// Lanes: 2^laneBits threads of one workgroup share a query (few queries
// keep more of the device busy so). Lane l starts at the node its bits
// choose level by level for the top laneBits levels (bit k: the right
// child at level k), so the lanes' subtrees cover the tree once (a leaf
// above that depth goes to the lane whose remaining bits are 0), and each
// descends its own subtree nearest-first. The lanes of a query share the
// smallest distance any of them found (s_best, a float's bits: distances
// are not negative, so their bits order as the floats), which prunes each
// lane's descent as its own best would; each lane lowers the query's
// packed best with atomicMin at its end. Every triangle whose distance can
// equal the final best lies under no pruned node (the shared bound is never
// below it), so the packed minimum (the smaller distance, then the smaller
// triangle) is what one thread's descent finds, whatever the lanes.
#include "common.glsl"
#include "rthdist_surface_search.h"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SurfaceTailPush pc; };
#define RTHDIST_SURFACE_VISIT_CORNERS_ONLY
#include "surface_visit.glsl"

shared uint s_best[RTHDIST_WG];  // per query of the group: the smallest distance's bits its lanes found
shared uint s_open;              // the group's queries that descend

void main() {
    const uint lane = gl_GlobalInvocationID.x & ((1u << pc.laneBits) - 1u);
    const uint qi = gl_GlobalInvocationID.x >> pc.laneBits;
    const uint slot = gl_LocalInvocationID.x >> pc.laneBits;
    const uint64_t start = qi < pc.numQueries ? u64At(pc.best, qi).v : ~uint64_t(0);
    const bool open = qi < pc.numQueries && !(packedDist2(start) <= pc.settled2);
    // The group's open queries counted in workgroup memory, then added to
    // the count once (one atomic a group, not a query: tens of thousands
    // on one address had queued at the device's cache).
    if (gl_LocalInvocationID.x == 0u) s_open = 0u;
    if (lane == 0u) s_best[slot] = uint(start >> 32);
    barrier();
    if (open && lane == 0u) atomicAdd(s_open, 1u);
    barrier();
    if (gl_LocalInvocationID.x == 0u && s_open != 0u) atomicAdd(uintAt(pc.counts, 0u).v, s_open);
    if (!open) return;
    vec3 q = vec4At(pc.queries, qi).v.xyz;
    uint64_t best = start;

    // The lane's subtree: its bits choose the child at each of the top levels.
    Cell node = cellAt(pc.nodes, 0u).v;
    uint level = 0u;
    for (; level < pc.laneBits && node.count == 0u; ++level)
        node = cellAt(pc.nodes, node.first + ((lane >> level) & 1u)).v;
    if ((lane >> level) != 0u && node.count != 0u) return;  // a leaf above the lanes' depth: another lane's

    uint stackNode[RTHDIST_SURFACE_TAIL_STACK];
    float stackDist2[RTHDIST_SURFACE_TAIL_STACK];
    uint top = 0u;
    float d2 = boxDist2(q, node.lo, node.hi);
    // The bound a node is pruned by: the lane's best or the query's lanes' (a
    // stale read is larger: it prunes less, never more).
    float bound = uintBitsToFloat(min(uint(best >> 32), s_best[slot]));
    if (pc.laneBits == 0u) bound = packedDist2(best);
    while (true) {
        if (!(d2 > bound)) {
            if (node.count != 0u) {
                for (uint i = 0u; i < node.count; ++i) {
                    uint p = 3u * (node.first + i);
                    uvec4 a = uvec4At(pc.leafCorners, p).v;
                    uvec4 b = uvec4At(pc.leafCorners, p + 1u).v;
                    uvec4 c = uvec4At(pc.leafCorners, p + 2u).v;
                    visitCorners(q, a.w, uintBitsToFloat(a.xyz), uintBitsToFloat(b.xyz), uintBitsToFloat(c.xyz),
                                 best);
                }
                if (pc.laneBits != 0u) {
                    const uint mine = uint(best >> 32);
                    if (mine < s_best[slot]) atomicMin(s_best[slot], mine);
                    bound = uintBitsToFloat(min(mine, s_best[slot]));
                } else {
                    bound = packedDist2(best);
                }
            } else {
                Cell left = cellAt(pc.nodes, node.first).v;
                Cell right = cellAt(pc.nodes, node.first + 1u).v;
                float dl = boxDist2(q, left.lo, left.hi);
                float dr = boxDist2(q, right.lo, right.hi);
                // The nearer child now (the left on a tie), the other later:
                // at most one entry per level below the root (the host's limit).
                bool rightFirst = dr < dl;
                stackNode[top] = rightFirst ? node.first : node.first + 1u;
                stackDist2[top] = rightFirst ? dl : dr;
                ++top;
                node = rightFirst ? right : left;
                d2 = rightFirst ? dr : dl;
                continue;
            }
        }
        if (top == 0u) break;
        --top;
        d2 = stackDist2[top];
        if (pc.laneBits != 0u) bound = uintBitsToFloat(min(uint(best >> 32), s_best[slot]));
        if (d2 > bound) continue;  // skipped without reading the node
        node = cellAt(pc.nodes, stackNode[top]).v;
    }
    if (pc.laneBits == 0u)
        u64At(pc.best, qi).v = best;
    else if (best < start)
        atomicMin(u64At(pc.best, qi).v, best);
}
