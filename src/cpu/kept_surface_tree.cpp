#include "cpu/kept_surface_tree.hpp"

namespace rthdist::cpu {

bool KeptSurfaceTree::holds(const MeshView& surface, int threads) const {
    return m_tree.has_value() && m_mesh.holds(surface, threads);
}

const TriangleBvh& KeptSurfaceTree::keep(const MeshView& surface, const core::SetSummary& summary,
                                         int threads) {
    m_tree.reset();  // its memory back before the next one is built
    m_blocks = TriangleBlocks();
    m_mesh.keep(surface, summary, threads);
    m_tree.emplace(surface, threads);
    m_blocks = TriangleBlocks(surface, threads);
    return *m_tree;
}

}  // namespace rthdist::cpu
