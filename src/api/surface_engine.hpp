// Engine::hausdorffToSurface (rthdist.hpp): a point-to-surface call on the
// backend an Engine keeps (api/backend.hpp), routed by planSurfaceRoute
// from the Engine's requested backend: the CPU backend's search (over the
// Engine's kept tree when the mesh is the last call's), or the device
// search of api/surface_gpu.hpp on the kept device.
#pragma once

#include "api/backend.hpp"
#include "api/surface_gpu.hpp"
#include "cpu/kept_surface_tree.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::api {

// engine: the Engine's options (its requested backend and threads). kept:
// the Engine's CPU-backend tree, reused by the CPU route for the same mesh;
// keptGpu: the GPU route's last mesh and framed corners (api/surface_gpu.hpp).
// spare: a recycled result's per-point arrays (Engine::recycle), taken by a
// per-point call on either route (left as they are by the others).
[[nodiscard]] Result<SurfaceResult> surfaceOnEngine(ComputeBackend& backend, const EngineOptions& engine,
                                                    cpu::KeptSurfaceTree& kept, KeptGpuSurface& keptGpu,
                                                    const PointView& points, const MeshView& surface,
                                                    const SurfaceCallOptions& call, SurfacePerPoint& spare);

}  // namespace rthdist::api
