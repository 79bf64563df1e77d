// The CPU backend's surface-to-surface refinement (design.md §12): certified
// bounds on H between two triangle surfaces by splitting triangles into
// patches until each patch's upper bound (convexity of the distance to one
// triangle, after Tang, Lee & Kim 2009, "Interactive Hausdorff distance
// computation for general polygonal models", and the 1-Lipschitz bound) is
// within the tolerance of the best lower bound. Each round is one batch of
// nearest-triangle queries per direction (cpu/sample_search.hpp): the CPU
// backend's exact BVH search, or a GPU backend's float search whose
// distances are upper bounds and whose batch maximum is proven on the host
// (api/surface_pair_gpu.hpp); the refinement itself runs on the worker pool.
#pragma once

#include "cpu/sample_search.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::cpu {

// a and b checked by the caller (api/surface_bounds.cpp) and given in the
// work frame (the caller shifts them and the witnesses back). tolerance:
// absolute, resolved, at least 4 slack; slack: core::closestSlack of the
// largest |coordinate| of both in that frame. aToB searches b's triangles,
// bToA a's (unused, may be null, with options.directedOnly). lower is the
// largest proven batch maximum (exact), upper the patches' bounds from the
// samples' distances (upper bounds): both certified whichever search runs;
// a search whose distances exceed the exact ones by more than the tolerance
// less 2 slack may not settle (the depth and query limits then end it with
// an error). Fills every field of the result but origin, tolerance,
// backend, device, buildMs and the timings of the whole call.
[[nodiscard]] Result<SurfaceBoundsResult> surfaceBounds(const MeshView& a, const MeshView& b,
                                                        double tolerance, double slack,
                                                        const SurfaceBoundsOptions& options,
                                                        SampleSearch& aToB, SampleSearch* bToA);

}  // namespace rthdist::cpu
