// The two directions of a voxel comparison (every convention but deepmind)
// and the numbers made from them, shared by compareMasks (compare.cpp) and
// the prepared reference's comparisons (prepared_reference.cpp), so a
// prepared reference reports what the one-shot call reports. Internal to
// rthdist_masks.
//
// A direction X -> Y: X's points (voxels) sent to the engine as queries,
// Y's as targets, both in ONE float search frame (VoxelMetric: the first
// volume's, A's, for both directions), every distance then recomputed in
// double from the voxel pair (voxel_metric.hpp), zeros (X's voxels inside Y,
// itk) added without a search.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "core/stopwatch.hpp"
#include "core/uninit_vector.hpp"
#include "masks/voxel_metric.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::masks::detail {

using core::Clock;
using core::msSince;

struct Direction {
    core::UninitVector<double> distances;  // all of X's distances, in no particular order (zeros included)
    DirectedMask out;
    double sum = 0.0;
    double least = 0.0;  // the smallest of `distances` (out.hd the greatest): their range for the percentiles
    // The distances within `countedAt` (directionOf counts them at the
    // tolerance it is given; directionNumbers recounts at another).
    uint64_t withinTolerance = 0;
    double countedAt = -1.0;
    // directionNumbers: out.surfaceOverlap and out.percentiles filled.
    bool numbered = false;
};

// The connectivity convention c measures boundaries with (`requested`: MaskOptions::connectivity).
[[nodiscard]] int connectivityOf(Convention c, int requested);

// compareMasks's checks of the options (connectivity, percentiles, tolerance).
[[nodiscard]] std::optional<Error> checkOptions(const MaskOptions& options);

// Adds one call's stage timings and its total to `sum`.
void addTimings(Timings& sum, const Timings& t);

// X's side of an engine call: `queries` (X's voxels sent, in the call's
// order), `nearest` the engine's per-point output (indices into `targets`),
// plus `zeros` more of X's voxels at distance 0 that were not sent. Distances
// in `metric`, witness points on X's grid `v`; the mean, points and the
// distances within `tolerance` (>= 0) filled.
[[nodiscard]] Result<Direction> directionOf(const Volume& v, const VoxelMetric& metric,
                                            std::span<const uint64_t> queries,
                                            std::span<const uint32_t> nearest,
                                            std::span<const uint64_t> targets, uint64_t zeros,
                                            double tolerance, int threads);

// A direction's own numbers under `options` (none for itk, whose surface
// overlap and HD-p are not defined): the fraction of its distances within
// the tolerance (counted again unless directionOf counted at it) and its
// HD-p of the convention, per percentile asked for. `d.distances` is
// reordered (selection).
void directionNumbers(const MaskOptions& options, Direction& d);

// One side of a boundary comparison: X's grid, X's voxels (the engine's
// queries) and Y's (its targets).
struct Side {
    const Volume* grid = nullptr;
    std::span<const uint64_t> queries, targets;
};

// Runs the engine's call over both sides' points (A's queries first) with the call options given.
using PairCall = std::function<Result<HausdorffResult>(const CallOptions& call)>;

// Both directions of one engine call (`call`, on `engine`; its result
// recycled), each with its distances and numbers (directionNumbers) computed
// as soon as the engine hands its nearest points back
// (CallOptions::perPointReady): on a GPU backend the first one while the
// device searches the other. `timed` gains the engine's timings and the
// whole as distanceMs.
[[nodiscard]] Result<std::array<Direction, 2>> directionsOfOneCall(Engine& engine, const PairCall& call,
                                                                   const VoxelMetric& metric,
                                                                   const std::array<Side, 2>& sides,
                                                                   const MaskOptions& options,
                                                                   MaskResult& timed);

// The engine's per-point search of float query points against one target
// set it already holds (or is given with the call).
using NearestCall = std::function<Result<HausdorffResult>(std::span<const glm::vec3> queries)>;

// A one-shot call against `targets` (voxels, put in `metric`'s frame at each
// call; `timed.extractMs` gains that); the arguments must outlive it.
[[nodiscard]] NearestCall oneShotCall(Engine& engine, const VoxelMetric& metric,
                                      std::span<const uint64_t> targets, int threads, MaskResult& timed);

// One direction of itk: `queries` (X's voxels outside Y), `zeros` more of
// X's voxels at distance 0 (zeroWitness: one of them), `targets` (Y's
// boundary voxels, searched by `nearest`); X's grid `v`. `timed` gains the
// extraction, distance and engine times.
[[nodiscard]] Result<Direction> directed(const VoxelMetric& metric, const Volume& v,
                                         std::span<const uint64_t> queries, uint64_t zeros,
                                         uint64_t zeroWitness, std::span<const uint64_t> targets,
                                         const NearestCall& nearest, int threads, MaskResult& timed);

// The empty status and the convention's values (emptyValues) for masks with
// na and nb points (one of them 0; r.convention set): NaN in every number,
// both sides' points.
void setEmpty(uint64_t na, uint64_t nb, const std::vector<double>& percentiles, MaskResult& r);

// The largest distance counted within options.tolerance: the tolerance, or
// for monai with monaiFloat32 the largest double d with float(d) <=
// float(tolerance) (MONAI compares float32 distances with the threshold
// rounded to float32).
[[nodiscard]] double toleranceLimit(const MaskOptions& options);

// HD, ASSD, MSD, surface overlaps and Dice and (but for itk) the HD-p of
// options.convention from both directions (numbered here unless they are),
// moved into r.aToB and r.bToA.
void combine(const MaskOptions& options, Direction& ab, Direction& ba, MaskResult& r);

}  // namespace rthdist::masks::detail
