// Engine::hausdorffToSurface (rthdist.hpp): a point-to-surface call on the
// backend an Engine keeps (api/backend.hpp), routed by planSurfaceRoute
// from the Engine's requested backend: the CPU backend's search, or the
// device search of api/surface_gpu.hpp on the kept device.
#pragma once

#include "api/backend.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::api {

// engine: the Engine's options (its requested backend and threads).
[[nodiscard]] Result<SurfaceResult> surfaceOnEngine(ComputeBackend& backend, const EngineOptions& engine,
                                                    const PointView& points, const MeshView& surface,
                                                    const SurfaceCallOptions& call);

}  // namespace rthdist::api
