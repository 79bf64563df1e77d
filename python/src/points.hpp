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

#include <cstddef>
#include <memory>

#include "rthdist/point_view.hpp"

namespace rthdist::python {

// The view of `array` (valid while the array lives); `name` is for messages.
[[nodiscard]] PointView viewOf(const pybind11::array& array, const char* name);

// The points of a view copied into memory of the call's own (packed x, y, z
// in the view's precision), taken before the library reads them: the GIL is
// released during a call, and another Python thread that writes into the
// array meanwhile (NaN, inf, any value) changes neither the points the
// library checked nor those it searches (docs/python.md, "Threads"). Made
// without the GIL: the caller keeps the array alive.
class PointCopy {
public:
    explicit PointCopy(const PointView& view);
    [[nodiscard]] const PointView& view() const { return m_view; }

private:
    std::unique_ptr<std::byte[]> m_bytes;  // not zeroed first: every byte is copied
    PointView m_view;
};

}  // namespace rthdist::python
