// A copy of a mesh, bit for bit, kept between an Engine's point-to-surface
// calls to tell exactly whether the next call's mesh is the same one (never
// by a hash): its vertex values in double and its triangle indices, with
// the summary of its vertices as checked when it was kept. The CPU route
// keeps its BVH beside it (cpu/kept_surface_tree.hpp), the GPU route its
// framed corners and its BVH (api/surface_gpu.hpp's KeptGpuSurface).
//
// Threading: one call at a time (an Engine's contract); the comparison and
// the copy run on `threads` threads of the worker pool.
// Memory: 24 bytes a vertex and 12 a triangle, until another mesh replaces
// them.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

#include "core/input_frame.hpp"
#include "rthdist/mesh.hpp"

namespace rthdist::core {

class KeptMesh {
public:
    // Whether a mesh is kept and equals `surface` (its shape checked by the
    // caller: the view readable), every vertex value and index bit for bit:
    // one pass over it.
    [[nodiscard]] bool holds(const MeshView& surface, int threads) const;
    // Copies `surface` (checked by the caller: every index in range, every
    // coordinate finite) and `summary`, its vertices' checked summary,
    // replacing any kept mesh.
    void keep(const MeshView& surface, const SetSummary& summary, int threads);
    // The kept mesh's summary: valid while holds() of the mesh searched.
    [[nodiscard]] const SetSummary& summary() const { return m_summary; }

private:
    bool m_kept = false;
    std::vector<glm::dvec3> m_vertices;
    std::vector<uint32_t> m_indices;
    SetSummary m_summary;
};

}  // namespace rthdist::core
