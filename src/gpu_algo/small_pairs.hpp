// computeBatch's small pairs on a GPU backend: every direction of every pair
// of a batch scanned exactly, query by target, in one submission
// (batch_nearest.comp, batch_witness.comp). For sets of a few thousand points
// the RT path's fixed cost (a cull, a self-check and per-radius submissions
// per pair, one pair after another) is far above the scan's, which is the
// brute force of DESIGN §4's sample with the early break of §3:
//   1. seed: RTHDIST_WG sample queries per direction scan all targets; the
//      largest of their exact nearest distances is the first lower bound of h;
//   2. scan: every query scans the targets (a spread order, RTHDIST_WG at a
//      time) until one is at most as far as the running maximum (it cannot
//      raise h; the maximum has its witness already) or the targets end (its
//      nearest distance is exact and raises the maximum, with its input
//      index);
//   3. witnesses: the maximum's query and its nearest target per direction.
// Per-point calls skip the seed and the early break: every query's nearest
// target comes back.
//
// Precision: the sets' searched floats (the prepared sets' own records) in
// the pair's frame (powers of two: exact); squared distances in float as in
// the RT path; the caller recomputes witnesses and per-point distances in
// double from the inputs. Each witness is checked against the device's
// maximum (self_check.hpp), and every index the device returns against its
// set's size, before the host reads a point with it.
//
// Threading: one caller at a time (the Workspace's).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gpu_algo/point_index.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

// One pair of a batch: two sets prepared from host arrays, and the powers of
// two that bring each set's searched points into the pair's frame.
struct SmallPair {
    const DeviceSet* a = nullptr;
    const DeviceSet* b = nullptr;
    float aScale = 1.0f;
    float bScale = 1.0f;
};

class SmallPairScan {
public:
    explicit SmallPairScan(Workspace& ws);

    // Whether a direction of `queries` x `targets` is scanned whole: the
    // product at most 2^28 on a GPU, 2^20 on a CPU device (lavapipe: its
    // scan of 2,000-10,000-point pairs took 3x the RT path's time). The
    // environment variable RTHDIST_SMALL_PAIR_WORK replaces the limit
    // (benchmarks of both paths; 0: none is scanned whole).
    [[nodiscard]] bool takes(uint64_t queries, uint64_t targets) const;

    // Every pair's witnesses (input indices) and, with perPointDistances,
    // nearest indices, in `results` (one per pair, filled from `blank`);
    // distances and points are left to the caller (core::restoreOriginal).
    // An entry of `failed` names a pair whose result broke the self-check.
    struct Outcome {
        std::vector<HausdorffResult> results;
        std::vector<std::string> failed;  // "" where the pair passed
    };
    [[nodiscard]] Outcome run(std::span<const SmallPair> pairs, const CallOptions& options,
                              const HausdorffResult& blank);

private:
    struct Layout;  // the directions' records and chunks, their offsets
    [[nodiscard]] Layout layOut(std::span<const SmallPair> pairs, bool directedOnly, bool perPoint);
    void record(VkCommandBuffer cmd, const Layout& layout, bool perPoint);
    // Pair i's result from the read-back witnesses (and per-point indices).
    [[nodiscard]] std::string finishPair(const SmallPair& pair, size_t first, const Layout& layout,
                                         bool perPoint, HausdorffResult& out) const;

    Workspace& m_ws;
    uint64_t m_maxWork;
};

}  // namespace rthdist::gpu_algo
