// rthdist Python module — triangle surfaces: point to surface
// (hausdorffToSurface), surface to surface (surfaceHausdorff: certified
// bounds) and the reconstruction-evaluation summary (rthdist/eval.hpp).
// Vertices are (V, 3) float32/float64 arrays read in place as points are
// (points.hpp); faces are (F, 3) int32, int64 or uint32 arrays (C order),
// each index checked in [0, V) before the call (ValueError naming the face).
// The GIL is released during the search; points, vertices and faces are
// copied first (points.hpp, "Threads"). Results are dicts with the CLI's
// JSON keys.
#pragma once

#include <pybind11/pybind11.h>

namespace rthdist::python {

void bindSurface(pybind11::module_& m);

}  // namespace rthdist::python
