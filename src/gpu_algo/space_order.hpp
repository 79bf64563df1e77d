// Whether a set's points lie in space order (IndexBuild::setGrid sets
// PointIndex::spaceOrder from it), so that the index build's keys and
// scatter passes take them spread over each warp (common.glsl spreadItem):
// points in space order (the out-of-core pieces' gathered points) send a
// warp's 32 atomics to a few lines of the dense key table (on an H200 a
// torus piece of 80M points: keys 7.7 -> 2.6 ms, scatter 10.1 -> 5.3 ms
// spread; docs/bench/scale session 20), while points in no order read
// spread cost more (the torus's 400M in input order: keys 5.9 -> 14.5 ms).
// Contract: of 64 runs of 32 consecutive points strided over the set, more
// than half have their grid cells' Morton keys (core::cellCoord,
// mortonEncode) within 2^-8 of the key range; false below 2048 points and
// below minPoints (default kMinSpaceOrderPoints: the keys pass of a smaller set takes ~0.1 ms on a
// GPU, below the ~50 us this look costs on the host). A
// heuristic of speed only: either order gives the same cells (the order of
// points within a cell, left to the atomics in both, is read by nothing).
// Threading: pure, any thread. Cost: 2048 points read (~50 us).
#pragma once

#include <glm/vec3.hpp>

#include <span>

#include "core/index_space.hpp"

namespace rthdist::gpu_algo {

inline constexpr size_t kMinSpaceOrderPoints = size_t(1) << 20;

// `minPoints`: a smaller set is not looked at (tests lower it).
[[nodiscard]] bool inSpaceOrder(std::span<const glm::vec3> pts, const core::GridSpec& grid,
                                size_t minPoints = kMinSpaceOrderPoints);

}  // namespace rthdist::gpu_algo
