#include "cpu/triangle_blocks.hpp"

#include <glm/common.hpp>

#include <algorithm>

#include "core/parallel.hpp"

namespace rthdist::cpu {

TriangleBlocks::TriangleBlocks(const MeshView& surface, int threads) {
    const size_t triangles = surface.triangleCount();
    m_boxes.resize((triangles + kTriangles - 1) / kTriangles);
    core::parallelChunks(m_boxes.size(), core::balancedChunk(m_boxes.size(), threads, 64), threads,
                         [&](size_t begin, size_t end, int) {
                             for (size_t run = begin; run < end; ++run) {
                                 const size_t first = run * kTriangles;
                                 const size_t last = std::min(triangles, first + kTriangles);
                                 glm::dvec3 lo = surface.corner(first, 0), hi = lo;
                                 for (size_t t = first; t < last; ++t) {
                                     for (int k = 0; k < 3; ++k) {
                                         const glm::dvec3 c = surface.corner(t, k);
                                         lo = glm::min(lo, c);
                                         hi = glm::max(hi, c);
                                     }
                                 }
                                 m_boxes[run] = {lo, hi};
                             }
                         });
}

}  // namespace rthdist::cpu
