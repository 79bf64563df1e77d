// An Engine's CPU-backend BVH kept between point-to-surface calls
// (Engine::hausdorffToSurface on the CPU backend, design.md §11): the next
// call against the same mesh reuses it instead of building it again. "The
// same" is decided exactly, never by a hash: a copy of the last mesh's
// vertex values (in double, bit for bit) and triangle indices is compared
// with the call's, so a kept tree is only ever searched for the triangles
// it was built over, and every result is the one-shot call's (==).
//
// Threading: one call at a time (an Engine's contract); the comparison and
// the build run on `threads` threads of the worker pool.
// Memory: the tree (TriangleBvh::hostBytes), its runs (under a byte a
// triangle) and the copy, 24 bytes a vertex and 12 a triangle, until a
// different mesh replaces them or the Engine is destroyed.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>
#include <vector>

#include "cpu/triangle_blocks.hpp"
#include "cpu/triangle_bvh.hpp"
#include "rthdist/mesh.hpp"

namespace rthdist::cpu {

class KeptSurfaceTree {
public:
    // The tree over `surface` (checked by the caller): the kept one when the
    // mesh equals the last one's (kept = true), else one built now and kept.
    [[nodiscard]] const TriangleBvh& treeFor(const MeshView& surface, int threads, bool& kept);
    // The same mesh's runs (cpu/triangle_blocks.hpp), for the witness check:
    // built with the tree, valid while it is.
    [[nodiscard]] const TriangleBlocks& blocks() const { return m_blocks; }

private:
    [[nodiscard]] bool sameMesh(const MeshView& surface, int threads) const;

    std::vector<glm::dvec3> m_vertices;  // the kept tree's mesh, bit for bit
    std::vector<uint32_t> m_indices;
    std::optional<TriangleBvh> m_tree;
    TriangleBlocks m_blocks;
};

}  // namespace rthdist::cpu
