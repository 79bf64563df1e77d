// rthdist — the surface input type: a read-only view of a triangle mesh,
// its vertices as a PointView (float or double, any stride: point_view.hpp)
// and three 32-bit vertex indices per triangle, read where they are.
//
// Triangle t has the vertices indices[3t], indices[3t + 1], indices[3t + 2].
// Every index must be below vertices.count (an index out of range is
// kInvalidArgument naming the triangle); indices.size() must be a multiple
// of 3. Degenerate triangles (repeated vertices, collinear vertices, zero
// area) and duplicate triangles are allowed: a degenerate triangle is the
// union of its edges (design.md §11). Vertices that no triangle uses are
// not part of the surface. The view must stay valid for the call that
// reads it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "rthdist/point_view.hpp"

namespace rthdist {

struct MeshView {
    PointView vertices;
    std::span<const uint32_t> indices;  // 3 per triangle

    [[nodiscard]] size_t triangleCount() const { return indices.size() / 3; }
    // Vertex k (0, 1, 2) of triangle t, in double.
    [[nodiscard]] glm::dvec3 corner(size_t t, int k) const { return vertices.at(indices[3 * t + size_t(k)]); }
};

}  // namespace rthdist
