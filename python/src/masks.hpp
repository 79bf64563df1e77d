// rthdist Python module — segmentation masks (include/rthdist/masks.hpp): label
// volumes from NumPy arrays (_MaskVolume: the labels copied once, i fastest,
// with their voxel-to-world affine) and _MaskEngine (the masks' Engine and,
// on a GPU backend, its boundary pass, kept between calls). A comparison
// returns one dict per (label, convention) row with the keys and values of
// a `rthdist-masks --json` row (tools/cli/masks/masks_main.cpp): NaN and
// infinities as None, empty masks as a status with the convention's value as
// text. python/rthdist/_masks.py is the public face (arrays, nibabel images,
// MaskResult).
//
// Calls release the GIL while volumes are converted and compared; an engine
// serializes its calls behind a mutex. Ctrl-C is checked between rows (a
// single comparison is not interrupted: MaskOptions has no cancel flag).
#pragma once

#include <pybind11/pybind11.h>

namespace rthdist::python {

void bindMasks(pybind11::module_& m);

}  // namespace rthdist::python
