// The CPU backend's exact point-to-surface search (design.md §11): a
// TriangleBvh over the surface, every query's nearest triangle on the
// worker pool, the directed maximum with the early break of Taha & Hanbury
// (2015) against the running maximum (off with per-point output), and the
// witness query checked against every triangle.
#pragma once

#include "cpu/triangle_blocks.hpp"
#include "cpu/triangle_bvh.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::cpu {

// points and surface checked by the caller (api/surface.cpp): finite,
// non-empty, indices in range. magnitude: the largest |coordinate| over
// both (the pruning's slack, core::closestSlack).
[[nodiscard]] Result<SurfaceResult> surfaceSearch(const PointView& points, const MeshView& surface,
                                                  double magnitude, const SurfaceOptions& options);

// The per-point arrays sized for `count` points (new elements zeroed), each
// array on its own thread of the worker pool (a serial zeroing of 60 bytes
// a point was ~0.3 s of a 10M-point call on an H200's host); closest and
// barycentric stay empty where `points` is false
// (SurfaceCallOptions::perPointDistancesOnly), emptied if they held any.
// Arrays recycled from an earlier result (Engine::recycle) keep their
// blocks: the caller writes every element. Shared by both routes.
void sizePerPoint(SurfacePerPoint& perPoint, size_t count, bool points, int threads);

// The same search over a tree already built over `surface`'s triangles (an
// Engine's kept tree, cpu/kept_surface_tree.hpp); buildMs is left 0.
// `blocks` (may be null): the runs of the same mesh, for the witness check
// (the same answer, cpu/triangle_blocks.hpp). `spare` (may be null): arrays
// a per-point call's entries are written into (moved out of it).
[[nodiscard]] Result<SurfaceResult> surfaceSearch(const PointView& points, const MeshView& surface,
                                                  double magnitude, const SurfaceOptions& options,
                                                  const TriangleBvh& bvh,
                                                  const TriangleBlocks* blocks = nullptr,
                                                  SurfacePerPoint* spare = nullptr);

}  // namespace rthdist::cpu
