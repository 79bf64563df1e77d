// rthdist Python module — NumPy arrays as PointViews, without a copy.
//
// rthdist/_points.py turns what users pass (array-likes, tensors, objects
// with .points/.vertices) into a NumPy array this accepts: 2-D (N, k >= 3),
// float32 or float64, x, y, z adjacent in a row (column stride = one
// element) and rows a positive multiple of the element size apart (C order,
// a row slice, columns 0..2 of a wider C array). Anything else is a
// ValueError here rather than a wrong read.
#pragma once

#include <pybind11/numpy.h>

#include "rthdist/point_view.hpp"

namespace rthdist::python {

// The view of `array` (valid while the array lives); `name` is for messages.
[[nodiscard]] PointView viewOf(const pybind11::array& array, const char* name);

}  // namespace rthdist::python
