// A bounding-volume hierarchy over triangles (corners in the mesh's float or double, node boxes
// in float rounded outward), for the exact nearest-triangle query of the
// point-to-surface search (design.md §11).
//
// Built top-down over the triangles sorted by the Morton codes of their box
// centres (rounded to float; cubic cells, 1024 along the centres' box's
// longest edge; ties by triangle index, so the order is one function of
// the mesh): a range splits where the highest bit in which its first and
// last codes differ changes (the two halves of the Morton cell they share),
// in the middle where the codes are equal (duplicate triangles) or for at
// most 2 * kLeafTriangles; leaves hold 1 to kLeafTriangles. Each level
// takes a code bit, so the depth stays below 30 + log2(n) + 2 (a guard
// splits in the middle before a depth of 64). The same nodes, boxes and
// triangle order on any number of threads. The build runs on the worker
// pool: the centres and codes in chunks, a parallel radix sort, the ranges
// of more than 4,096 triangles split level by level, the subtrees below
// them as tasks (counted, then built in place); then the corners, each
// triangle's written once to its place, and the boxes from the leaves up.
// (A median split along the longest axis, the build before session 31,
// took about twice the time in a one-shot call: 16.5 -> 8.1 ms for the
// bunny's 69,451 triangles on 2 cores, 28.6 -> 14.2 ms for the dragon's
// 871,414 on 16; the searches no slower.)
//
// The query visits the nearer child first and skips a box only when its
// distance exceeds the best distance so far by more than
// core::closestSlack: the triangle with the smallest measure (the smallest
// index on a tie) is never skipped, so the answer equals a brute force over
// every triangle. That holds for any tree shape: it only needs each node's
// box to contain the boxes of the triangles below it (min and max are exact,
// rounding to float goes outward, and the rounded box distance only shrinks
// as a box grows), and a tie
// between triangles is settled by their index, not by the order of the
// visit. A hint (where an earlier query ended) only sets where the search
// starts; the same argument holds from any start (nearest's comment).
//
// Layout for a later GPU path: the leaves' boxes hold the triangles' own
// (the procedural AABBs of a BLAS would be the same), and the measure is the
// shared rule (shaders/shared/rthdist_point_triangle.h).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/uninit_vector.hpp"
#include "rthdist/mesh.hpp"

namespace rthdist::cpu {

inline constexpr uint32_t kLeafTriangles = 4;
// An early break names the node this many levels above its leaf for the next
// query's hint (TriangleHint::node): a subtree of at most 8 leaves.
inline constexpr uint32_t kHintLevels = 3;

// One query's answer.
struct NearestTriangle {
    double distance2 = 0.0;  // |p - point|^2
    uint32_t triangle = UINT32_MAX;
    uint32_t position = UINT32_MAX;  // the triangle's place in the BVH's order (TriangleHint::position)
    uint32_t near = 0;  // an early break's: its leaf's ancestor kHintLevels up (TriangleHint::node)
    glm::dvec3 point{0.0};
    glm::dvec3 barycentric{0.0};
    bool dominated = false;  // stopped early: distance2 < stopBelow2 (not the nearest)
    uint64_t nodesVisited = 0;
    uint64_t trianglesTested = 0;
};

// Where an earlier query ended (TriangleBvh::nearest's hint).
struct TriangleHint {
    uint32_t position = UINT32_MAX;  // NearestTriangle::position; past the triangles: none
    uint32_t node = 0;               // NearestTriangle::near; 0 (the root) or past the nodes: none
};

class TriangleBvh {
public:
    // The mesh's triangles (indices checked by the caller, coordinates
    // finite), copied: in float for a float mesh (exactly its values), else in
    // double. threads: of the worker pool for the build
    // (core::resolveThreads: 0 = every hardware thread); the tree does not
    // depend on it.
    explicit TriangleBvh(const MeshView& mesh, int threads = 1);

    // The nearest triangle to p. slack: core::closestSlack of the largest
    // coordinate magnitude of p and the mesh. stopBelow2 > 0: return as soon
    // as a triangle measures below it (dominated; the early break of a
    // directed maximum), 0: never. hint: where an earlier query (the
    // previous one, when queries come in space order) ended: its triangle is
    // measured first and, for an early break, the subtree of its node next,
    // then the tree looking only at boxes within the stop; when one of them
    // ends the query below stopBelow2 there is no full descent, else what
    // they measured bounds it from the start. The answer does not
    // depend on the hint (the nearest is a minimum over every triangle, ties
    // to the smallest index), only the work does.
    [[nodiscard]] NearestTriangle nearest(const glm::dvec3& p, double slack, double stopBelow2 = 0.0,
                                          TriangleHint hint = {}) const;

    [[nodiscard]] size_t triangleCount() const { return m_original.size(); }
    [[nodiscard]] size_t nodeCount() const { return m_nodes.size(); }
    [[nodiscard]] size_t hostBytes() const;

    // Every field written by the build (no initializers: the arrays are
    // UninitVector, first touched by the build's workers).
    // 32 bytes: the box in float, rounded outward (it holds every triangle
    // below; a coordinate past float's range widens it to FLT_MAX or
    // infinity, still holding them), so the nodes take 57 % of the memory
    // of a box in double, which a one-shot call faults in fresh.
    struct Node {
        glm::vec3 lo,
            hi;          // leaf: the union of its triangles' boxes rounded outward; inner: of its children's
        uint32_t first;  // leaf: first triangle (BVH order); inner: left child (right = first + 1)
        uint32_t count;  // leaf: triangles; inner: 0
    };
    static_assert(sizeof(Node) == 32);
    // For tests and diagnostics: node 0 is the root; a node's children come
    // after it. triangleOrder()[i]: the triangle at BVH position i.
    [[nodiscard]] const core::UninitVector<Node>& nodes() const { return m_nodes; }
    [[nodiscard]] const core::UninitVector<uint32_t>& triangleOrder() const { return m_original; }

private:
    // UninitVector: no pass zeroes them first, and a kept Engine's next call
    // reuses their blocks (core/uninit_vector.hpp): 83 MB for 871k triangles
    // in double, 52 MB in float.
    core::UninitVector<Node> m_nodes;
    // The corners, 3 per triangle in BVH order: in float for a float mesh
    // (m_cornersF), else in double; the other array stays empty.
    core::UninitVector<glm::dvec3> m_corners;
    core::UninitVector<glm::vec3> m_cornersF;
    bool m_floatCorners = false;

    [[nodiscard]] glm::dvec3 cornerAt(size_t k) const {
        return m_floatCorners ? glm::dvec3(m_cornersF[k]) : m_corners[k];
    }
    template <class Corner>
    [[nodiscard]] NearestTriangle nearestIn(const Corner* corners, const glm::dvec3& p, double slack,
                                            double stopBelow2, TriangleHint hint) const;
    core::UninitVector<uint32_t> m_original;  // BVH order -> triangle index
    core::UninitVector<uint8_t> m_thin;       // BVH order -> core::thinTriangle of its corners
};

}  // namespace rthdist::cpu
