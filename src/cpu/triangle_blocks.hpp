// Boxes of runs of consecutive triangles, for the witness check's brute
// force (cpu/surface_search.cpp) over a mesh an Engine keeps
// (cpu/kept_surface_tree.hpp): the check skips a whole run whose box lies
// past its bound instead of reading each of its triangles.
//
// Run b holds triangles [b * kTriangles, (b + 1) * kTriangles) (the last may
// hold fewer); its box is the smallest and largest corner coordinates of
// those triangles, in double (exact: a min and a max of the same values the
// check reads). Every triangle's own box lies inside its run's, so the
// rounded point-to-box distance of the run (core::boxDistance2: the
// differences, the maxima, the squares and the sum are each monotone under
// rounding) is at most that of any of its triangles: a run the check skips
// holds no triangle it would have measured, and the check's answer is the
// same with or without the runs (tests/cpu/triangle_blocks_test.cpp).
//
// Independent of the BVH it checks: built from the mesh directly, in input
// order.
// Threading: built on `threads` threads of the worker pool, then read-only.
// Memory: 48 bytes a run (under 1 byte a triangle).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <vector>

#include "rthdist/mesh.hpp"

namespace rthdist::cpu {

class TriangleBlocks {
public:
    static constexpr size_t kTriangles = 64;  // triangles of a run

    TriangleBlocks() = default;
    // The runs of `surface` (checked by the caller: indices in range).
    TriangleBlocks(const MeshView& surface, int threads);

    [[nodiscard]] size_t count() const { return m_boxes.size(); }
    [[nodiscard]] const glm::dvec3& lo(size_t run) const { return m_boxes[run].lo; }
    [[nodiscard]] const glm::dvec3& hi(size_t run) const { return m_boxes[run].hi; }

private:
    struct Box {
        glm::dvec3 lo, hi;
    };
    std::vector<Box> m_boxes;
};

}  // namespace rthdist::cpu
