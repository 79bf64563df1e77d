// Route::kSurfaceGpu (api/route_planner.hpp): a point set against a
// triangle surface on a GPU backend (design.md §11, "The GPU backends").
// Both inputs are shifted by the centre of their union's box, scaled by a
// power of two (|coordinate| <= 1) and rounded to float; the backend's
// device search (gpu_algo/surface_search.hpp) gives each query a nearest
// triangle; api/surface_certify.hpp proves the directed maximum from the
// caller's coordinates in double.
#pragma once

#include "core/input_frame.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::api {

// Inputs checked by the caller (api/surface.cpp); a, b: their summaries;
// magnitude: the largest |coordinate| over both.
[[nodiscard]] Result<SurfaceResult> surfaceOnGpu(const PointView& points, const MeshView& surface,
                                                 const core::SetSummary& a, const core::SetSummary& b,
                                                 double magnitude, const SurfaceOptions& options);

}  // namespace rthdist::api
