// rthdist Python module — the loaders (rthdist/io.hpp) and the device list.
#pragma once

#include <pybind11/pybind11.h>

namespace rthdist::python {

// _load(path, las_classes) -> (N, 3) float32 or float64 array in the file's
// precision, owning the loader's vector (no copy); list_devices().
void bindIo(pybind11::module_& m);

}  // namespace rthdist::python
