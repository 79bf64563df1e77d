#include "cpu/kept_surface_tree.hpp"

#include <atomic>
#include <cstring>

#include "core/parallel.hpp"

namespace rthdist::cpu {
namespace {

constexpr size_t kChunk = size_t(1) << 16;

}  // namespace

bool KeptSurfaceTree::holds(const MeshView& surface, int threads) const {
    if (!m_tree || surface.vertices.count != m_vertices.size() || surface.indices.size() != m_indices.size())
        return false;
    std::atomic<bool> differ{false};
    core::parallelChunks(m_vertices.size(), kChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end && !differ.load(std::memory_order_relaxed); ++i) {
            const glm::dvec3 v = surface.vertices.at(i);
            if (std::memcmp(&v, &m_vertices[i], sizeof v) != 0) differ.store(true, std::memory_order_relaxed);
        }
    });
    if (differ.load()) return false;
    core::parallelChunks(m_indices.size(), kChunk, threads, [&](size_t begin, size_t end, int) {
        if (std::memcmp(surface.indices.data() + begin, m_indices.data() + begin,
                        (end - begin) * sizeof(uint32_t)))
            differ.store(true, std::memory_order_relaxed);
    });
    return !differ.load();
}

const TriangleBvh& KeptSurfaceTree::keep(const MeshView& surface, const core::SetSummary& summary,
                                         int threads) {
    m_tree.reset();  // its memory back before the next one is built
    m_blocks = TriangleBlocks();
    m_vertices.resize(surface.vertices.count);
    core::parallelChunks(m_vertices.size(), kChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) m_vertices[i] = surface.vertices.at(i);
    });
    m_indices.assign(surface.indices.begin(), surface.indices.end());
    m_tree.emplace(surface, threads);
    m_blocks = TriangleBlocks(surface, threads);
    m_summary = summary;
    return *m_tree;
}

}  // namespace rthdist::cpu
