// Per-point entries of the GPU route (api/surface_gpu.cpp; design.md §11,
// "Per-point distances"): the float rule, which the device's search applies,
// measures a sliver (a triangle whose width w has w^2 ~ u_f L D, L its
// longest edge, D the query's distance) anywhere along its length, so an
// entry taken from the device's triangle could lie far above the exact
// distance where a sliver is the nearest. Those triangles are measured on
// the host instead.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>

#include "rthdist/surface.hpp"

namespace rthdist::api {

// entries: every query's entry after the proof (certifySurface with
// EveryQueryBound::perPoint: the device's triangle measured in double, the
// witness's exact, entries.tolerance set); corners: the device's float
// corners in the search frame of scale `scale` (3 per triangle); hausdorff:
// the proven h. Flags every triangle the float rule may measure more than
// 2^-17 of the frame off for a query within h + tolerance of it, and gives
// each query whose entry a flagged triangle can beat (nearer in double, or
// as near with a smaller index) that triangle's entry: found through a
// 128^3 grid of the flagged triangles' cells (the queries whose entry
// reaches one), then the CPU backend's BVH search over them alone. The worker
// pool on `threads`. Returns how many triangles were flagged.
[[nodiscard]] uint64_t measureSlivers(const PointView& points, const MeshView& surface,
                                      std::span<const glm::vec3> corners, double scale, double hausdorff,
                                      double magnitude, int threads, SurfacePerPoint& entries);

}  // namespace rthdist::api
