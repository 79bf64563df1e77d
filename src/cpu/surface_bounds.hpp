// The CPU backend's surface-to-surface refinement (design.md §12): certified
// bounds on H between two triangle surfaces by splitting triangles into
// patches until each patch's upper bound (convexity of the distance to one
// triangle, after Tang, Lee & Kim 2009, "Interactive Hausdorff distance
// computation for general polygonal models", and the 1-Lipschitz bound) is
// within the tolerance of the best lower bound. Each round is one batch of
// exact nearest-triangle queries on a TriangleBvh (the point-to-surface
// search of design.md §11), run on the worker pool.
#pragma once

#include "rthdist/surface.hpp"

namespace rthdist::cpu {

// a and b checked by the caller (api/surface_bounds.cpp) and given in the
// work frame (the caller shifts them and the witnesses back). tolerance:
// absolute, resolved, at least 4 slack; slack: core::closestSlack of the
// largest |coordinate| of both in that frame. Fills every field of the
// result but origin, tolerance and the timings of the whole call.
[[nodiscard]] Result<SurfaceBoundsResult> surfaceBounds(const MeshView& a, const MeshView& b,
                                                        double tolerance, double slack,
                                                        const SurfaceBoundsOptions& options);

}  // namespace rthdist::cpu
