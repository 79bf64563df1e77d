// A bounding-volume hierarchy over triangles, in double, for the exact
// nearest-triangle query of the point-to-surface search (design.md §11).
//
// Built top-down by median splits of the triangles' box centres along the
// longest axis of their spread (leaves of at most kLeafTriangles), so the
// tree is balanced (depth <= log2(n) + 2) whatever the input, duplicate and
// degenerate triangles included. The query visits the nearer child first
// and skips a box only when its distance exceeds the best distance so far by
// more than core::closestSlack: the triangle with the smallest measure (the
// smallest index on a tie) is never skipped, so the answer equals a brute
// force over every triangle.
//
// Layout for a later GPU path: the boxes are the triangles' own (the
// procedural AABBs of a BLAS would be the same), and the measure is the
// shared rule (shaders/shared/rthdist_point_triangle.h).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rthdist/mesh.hpp"

namespace rthdist::cpu {

inline constexpr uint32_t kLeafTriangles = 4;

// One query's answer.
struct NearestTriangle {
    double distance2 = 0.0;  // |p - point|^2
    uint32_t triangle = UINT32_MAX;
    glm::dvec3 point{0.0};
    glm::dvec3 barycentric{0.0};
    bool dominated = false;  // stopped early: distance2 < stopBelow2 (not the nearest)
    uint64_t nodesVisited = 0;
    uint64_t trianglesTested = 0;
};

class TriangleBvh {
public:
    // The mesh's triangles (indices checked by the caller), copied in double.
    explicit TriangleBvh(const MeshView& mesh);

    // The nearest triangle to p. slack: core::closestSlack of the largest
    // coordinate magnitude of p and the mesh. stopBelow2 > 0: return as soon
    // as a triangle measures below it (dominated; the early break of a
    // directed maximum), 0: never.
    [[nodiscard]] NearestTriangle nearest(const glm::dvec3& p, double slack, double stopBelow2 = 0.0) const;

    [[nodiscard]] size_t triangleCount() const { return m_original.size(); }
    [[nodiscard]] size_t nodeCount() const { return m_nodes.size(); }
    [[nodiscard]] size_t hostBytes() const;

private:
    struct Node {
        glm::dvec3 lo{0.0}, hi{0.0};
        uint32_t first = 0;  // leaf: first triangle (BVH order); inner: left child (right = first + 1)
        uint32_t count = 0;  // leaf: triangles; inner: 0
    };

    void build(const std::vector<glm::dvec3>& lo, const std::vector<glm::dvec3>& hi,
               const std::vector<glm::dvec3>& centre);

    std::vector<Node> m_nodes;
    std::vector<glm::dvec3> m_corners;  // 3 per triangle, in BVH order
    std::vector<uint32_t> m_original;   // BVH order -> triangle index
};

}  // namespace rthdist::cpu
