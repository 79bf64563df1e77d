// The options of every engine call of compareMasks: each query's exact
// nearest point (per-point, nearest only: the masks recompute each
// distance in double from the voxels), one direction or both. Set per call, so any
// Engine serves (its own call defaults are not used). Internal to rthdist_masks.
#pragma once

#include "rthdist/options.hpp"

namespace rthdist::masks::detail {

[[nodiscard]] inline CallOptions perPointCall(bool directedOnly) {
    CallOptions call;
    call.perPointDistances = true;
    call.perPointNearestOnly = true;  // the distances are recomputed from the voxels
    call.directedOnly = directedOnly;
    return call;
}

}  // namespace rthdist::masks::detail
