#include "core/kept_mesh.hpp"

#include <atomic>
#include <cstring>

#include "core/parallel.hpp"

namespace rthdist::core {
namespace {

// Vertices and indices a chunk of the worker pool: small enough that the
// bunny's 35,947 vertices spread over 9 threads (one pass of ~4 ns a vertex:
// the view's read in double and the comparison).
constexpr size_t kVertexChunk = size_t(1) << 12;
constexpr size_t kIndexChunk = size_t(1) << 15;

}  // namespace

bool KeptMesh::holds(const MeshView& surface, int threads) const {
    if (!m_kept || surface.vertices.count != m_vertices.size() || surface.indices.size() != m_indices.size())
        return false;
    std::atomic<bool> differ{false};
    parallelChunks(m_vertices.size(), kVertexChunk, threads, [&](size_t begin, size_t end, int) {
        if (differ.load(std::memory_order_relaxed)) return;
        bool same = true;
        for (size_t i = begin; i < end; ++i) {
            const glm::dvec3 v = surface.vertices.at(i);
            same = same && std::memcmp(&v, &m_vertices[i], sizeof v) == 0;
        }
        if (!same) differ.store(true, std::memory_order_relaxed);
    });
    if (differ.load()) return false;
    parallelChunks(m_indices.size(), kIndexChunk, threads, [&](size_t begin, size_t end, int) {
        if (std::memcmp(surface.indices.data() + begin, m_indices.data() + begin,
                        (end - begin) * sizeof(uint32_t)))
            differ.store(true, std::memory_order_relaxed);
    });
    return !differ.load();
}

void KeptMesh::keep(const MeshView& surface, const SetSummary& summary, int threads) {
    m_vertices.resize(surface.vertices.count);
    parallelChunks(m_vertices.size(), kVertexChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) m_vertices[i] = surface.vertices.at(i);
    });
    m_indices.assign(surface.indices.begin(), surface.indices.end());
    m_summary = summary;
    m_kept = true;
}

}  // namespace rthdist::core
