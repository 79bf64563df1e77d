// Exact Hausdorff distance on the CPU (Backend::kCpu).
//
// Each set is ordered once per call (adaptive Morton order, cpu/adaptive_order:
// a uniform grid's Morton order in which every overfull cell is ordered again
// over its own tight box, so the order follows the points at any density);
// that order is the layout of its index and the order in which it is queried.
// Algorithm per direction h(Q, T) (see cpu_hausdorff.cpp for the proofs):
//   1. Index T: the shared RT-HDIST grid (Kim, Lee, Kim 2025), cells' points
//      contiguous with tight boxes, cut into buckets of 8 under an implicit
//      8-wide BVH over the adaptive order (an LBVH with bounded leaves: its
//      depth follows the points, not the bounding box); runs of identical
//      targets stored once.
//   2. Lower bound M: exact NN of a strided sample of Q, and the largest
//      distance from a query to BV(T) (no witness, so it is lowered by 1e-5
//      relative before use and can never hide the maximizing query).
//   3. Queries in their adaptive order, chunks pulled by std::threads: a query
//      dies when a point strictly closer than M is found in the previous
//      query's nearest bucket, its own grid cell (only when that cell holds at
//      most 64 targets), or the 64 buckets around the previous query's nearest
//      (early break, Taha & Hanbury 2015); survivors run a best-first-ordered
//      BVH search that still breaks as soon as a point closer than M appears,
//      else ends with the exact nearest neighbour and raises M. No query scans
//      more than a bounded number of points before the BVH takes over; a
//      nearest distance of 0 ends a query at once; a copy of the previous
//      query is skipped.
//   4. The winning pair is recomputed in double.
// With Options::perPointDistances, steps 2 and 3 become one pass that finds
// every query's exact nearest neighbour (the same seeds and BVH search, never
// breaking early); its distances are recomputed in double per pair, and the
// witness is the query with the largest of them (smallest index among ties).
// Progress: Options::progress is called from the calling thread at stage
// boundaries and about every percent of the search.
//
// Contract: a and b non-empty, all coordinates finite (the caller checks).
// Precision: squared distances are float differences of the raw float
//   coordinates (no origin shift, so coordinates near 1e7 stay exact), and
//   boxes are pruned only when farther than the best point by more than a
//   relative 1e-5, so the search is exact in float; the reported distances
//   are recomputed in double from the witness pairs. Inputs whose magnitudes
//   would overflow or underflow squared floats are scaled by a power of two
//   (exact).
// Threading: options.threads workers (0 = all hardware threads); the result
//   does not depend on the thread count (ties: smallest query index, then
//   smallest target index among equal nonzero float distances; at distance 0
//   the target is a copy of the query point, the first one the search meets).
// Timings: index = both sets' orders + target index + query keys, cull = lower bound,
//   search = the pass over all queries (neighbourhood kill and BVH search),
//   refine = witness recomputation.
#pragma once

#include <glm/vec3.hpp>

#include <memory>
#include <mutex>
#include <span>

#include "core/per_point_floor.hpp"
#include "cpu/adaptive_order.hpp"
#include "cpu/target_index.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cpu {

// A set ordered once (its query order and the layout of its index) and, on
// first use as a target, indexed; `points` (float, before `scale`) must
// outlive it. targetIndex() builds the index once, thread-safely.
class CpuSet {
public:
    std::span<const glm::vec3> points;
    double scale = 1.0;
    SetOrder order;

    [[nodiscard]] const TargetIndex& targetIndex(int threads) const;
    // Host memory of its order and (once built) index.
    [[nodiscard]] uint64_t hostBytes() const;

private:
    mutable std::once_flag m_indexOnce;
    mutable TargetIndex m_index;
};

// Orders `points` (exact power-of-two `scale`, core::exactScale; bits 0 =
// from the data) with `threads` workers (0 = all).
[[nodiscard]] std::shared_ptr<CpuSet> prepareCpuSet(std::span<const glm::vec3> points, double scale, int bits,
                                                    int threads);

// H (or h) of two prepared sets of one scale. `floor` (with per-point
// output): queries below it may stop there (core/per_point_floor.hpp).
[[nodiscard]] Result<HausdorffResult> cpuHausdorff(const CpuSet& a, const CpuSet& b,
                                                   const CallOptions& options, int threads,
                                                   const core::PerPointFloor& floor = {});

// One-shot: both sets prepared for this call at `scale`, the exact power of
// two of the pair's frame (core::exactScale of the largest coordinate
// magnitude of both; the Engine decides it once per call).
[[nodiscard]] Result<HausdorffResult> cpuHausdorff(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                   double scale, const Options& options,
                                                   const core::PerPointFloor& floor = {});

// One-shot at the scale of the shared rule over both sets (core::exactScale
// of their largest magnitude, a pass over the points).
[[nodiscard]] Result<HausdorffResult> cpuHausdorff(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                   const Options& options);

}  // namespace rthdist::cpu
