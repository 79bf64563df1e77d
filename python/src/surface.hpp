// rthdist Python module — triangle surfaces: point to surface
// (hausdorffToSurface), surface to surface (surfaceHausdorff: certified
// bounds) and the reconstruction-evaluation summary (rthdist/eval.hpp);
// Engine.hausdorff_to_surface (engine.cpp) uses the two helpers below.
// Vertices are (V, 3) float32/float64 arrays read in place as points are
// (points.hpp); faces are (F, 3) int32, int64 or uint32 arrays (C order),
// each index checked in [0, V) before the call (ValueError naming the face).
// The GIL is released during the search; points, vertices and faces are
// copied first (points.hpp, "Threads"). Results are dicts with the CLI's
// JSON keys.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <vector>

#include "rthdist/surface.hpp"

namespace rthdist::python {

void bindSurface(pybind11::module_& m);

// Shared with the Engine's binding (engine.cpp, Engine.hausdorff_to_surface):
// the faces of an (F, 3) array as checked 32-bit indices, and a result as
// the Python dict (with perPoint, its arrays moved into read-only NumPy
// arrays).
[[nodiscard]] std::vector<uint32_t> facesOf(const pybind11::array& faces, size_t vertices, const char* name);
[[nodiscard]] pybind11::dict surfaceResultDict(SurfaceResult&& r, bool perPoint);

}  // namespace rthdist::python
