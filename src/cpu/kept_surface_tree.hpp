// An Engine's CPU-backend BVH kept between point-to-surface calls
// (Engine::hausdorffToSurface on the CPU backend, design.md §11): the next
// call against the same mesh reuses it instead of building it again. "The
// same" is decided exactly, never by a hash (core/kept_mesh.hpp: a copy of
// the last mesh's vertex values, in double, bit for bit, and triangle
// indices compared with the call's), so a kept tree is only ever searched for the triangles
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

#include "core/input_frame.hpp"
#include "core/kept_mesh.hpp"
#include "cpu/triangle_blocks.hpp"
#include "cpu/triangle_bvh.hpp"
#include "rthdist/mesh.hpp"

namespace rthdist::cpu {

class KeptSurfaceTree {
public:
    // Whether a tree is kept for a mesh equal to `surface` (its shape checked
    // by the caller: the view readable), bit for bit: one pass over it.
    [[nodiscard]] bool holds(const MeshView& surface, int threads) const;
    // Builds and keeps the tree over `surface` (checked by the caller: every
    // index in range, every coordinate finite), replacing any kept one;
    // `summary`: its vertices' checked summary, kept beside it.
    const TriangleBvh& keep(const MeshView& surface, const core::SetSummary& summary, int threads);

    // The kept tree and, built with it, the mesh's runs (cpu/triangle_blocks.hpp,
    // for the witness check) and its vertices' summary as checked when kept:
    // valid while holds() of the mesh searched.
    [[nodiscard]] const TriangleBvh& tree() const { return *m_tree; }
    [[nodiscard]] const TriangleBlocks& blocks() const { return m_blocks; }
    [[nodiscard]] const core::SetSummary& summary() const { return m_mesh.summary(); }

private:
    core::KeptMesh m_mesh;  // the kept tree's mesh, bit for bit
    std::optional<TriangleBvh> m_tree;
    TriangleBlocks m_blocks;
};

}  // namespace rthdist::cpu
