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
// every triangle would. Counts the queries it searched.
#include "common.glsl"
#include "rthdist_surface_search.h"
layout(local_size_x = RTHDIST_WG) in;
layout(push_constant) uniform Push { SurfaceTailPush pc; };
#define RTHDIST_SURFACE_VISIT_CORNERS_ONLY
#include "surface_visit.glsl"

void main() {
    uint qi = gl_GlobalInvocationID.x;
    if (qi >= pc.numQueries) return;
    uint64_t best = u64At(pc.best, qi).v;
    if (packedDist2(best) <= pc.settled2) return;
    atomicAdd(uintAt(pc.counts, 0u).v, 1u);
    vec3 q = vec4At(pc.queries, qi).v.xyz;

    uint stackNode[RTHDIST_SURFACE_TAIL_STACK];
    float stackDist2[RTHDIST_SURFACE_TAIL_STACK];
    uint top = 0u;
    Cell node = cellAt(pc.nodes, 0u).v;
    float d2 = boxDist2(q, node.lo, node.hi);
    while (true) {
        if (!(d2 > packedDist2(best))) {
            if (node.count != 0u) {
                for (uint i = 0u; i < node.count; ++i) {
                    uint p = 3u * (node.first + i);
                    uvec4 a = uvec4At(pc.leafCorners, p).v;
                    uvec4 b = uvec4At(pc.leafCorners, p + 1u).v;
                    uvec4 c = uvec4At(pc.leafCorners, p + 2u).v;
                    visitCorners(q, a.w, uintBitsToFloat(a.xyz), uintBitsToFloat(b.xyz), uintBitsToFloat(c.xyz),
                                 best);
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
        if (d2 > packedDist2(best)) continue;  // skipped without reading the node
        node = cellAt(pc.nodes, stackNode[top]).v;
    }
    u64At(pc.best, qi).v = best;
}
