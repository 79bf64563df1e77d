// rthdist Python module — HausdorffResult for Python: the value and its
// witnesses, timings and counters as dicts, per-point distances and nearest
// indices as read-only NumPy arrays (no copy: they share the result's
// memory), and the statistics of rthdist/stats.hpp (the CLI's definitions).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <mutex>
#include <vector>

#include "rthdist/rthdist.hpp"

namespace rthdist::python {

struct PyResult {
    HausdorffResult result;
    // The inputs, kept for statistics normalized by their bounding boxes
    // (per_point only; None otherwise).
    pybind11::object a, b;
    // Sorted per-point distances, built on first use of a percentile.
    std::vector<double> sortedA, sortedB, sortedPooled;
    bool sorted = false;
};

void bindResult(pybind11::module_& m);

}  // namespace rthdist::python
