// rthdist._rthdist: the compiled half of the `rthdist` Python package
// (python/rthdist/__init__.py is the public face; docs/python.md the guide).
// One file per concept: errors (Error -> exceptions), points (NumPy ->
// PointView), result (HausdorffResult), engine (hausdorff, Engine), io
// (loaders, device list), masks (segmentation masks: volumes, MaskEngine),
// surface (point to surface, surface to surface, the evaluation summary).
#include <pybind11/pybind11.h>

#include "engine.hpp"
#include "errors.hpp"
#include "io.hpp"
#include "masks.hpp"
#include "result.hpp"
#include "rthdist/rthdist.hpp"
#include "surface.hpp"

PYBIND11_MODULE(_rthdist, m) {
    m.doc() = "rthdist: exact Hausdorff distance between 3-D point sets (compiled core)";
    m.attr("__version__") = rthdist::versionString();
    rthdist::python::bindErrors(m);
    rthdist::python::bindResult(m);
    rthdist::python::bindEngine(m);
    rthdist::python::bindIo(m);
    rthdist::python::bindMasks(m);
    rthdist::python::bindSurface(m);
}
