// computeBatch's small pairs on a GPU backend: every direction of every pair
// of a batch scanned exactly, query by target, in one submission
// (batch_nearest.comp, batch_witness.comp). For sets of a few thousand points
// the RT path's fixed cost (a cull, a self-check and per-radius submissions
// per pair, one pair after another) is far above the scan's, which is the
// brute force of design.md §4's sample with the early break of §3:
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

#include "core/certificate.hpp"
#include "core/scan_limits.hpp"

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "gpu_algo/point_index.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

// One side of a pair as the scan reads it: vec4 records on the device (xyz,
// w = input index bits; any order) and the power of two that brings them into
// the pair's frame; the same points by input index on the host with the power
// of two that brings those there (the self-check's); its index's size for the
// counters (0 for a set that has none).
struct ScanSet {
    VkDeviceAddress records = 0;
    float scale = 1.0f;
    std::span<const glm::vec3> points;
    double pointsScale = 1.0;
    int bits = 0;
    uint64_t cells = 0;
    double inputScale = 1.0;  // searched units (points * pointsScale) per unit of the caller's input
};

// A prepared set (its cell-sorted records) as a scan's side.
[[nodiscard]] ScanSet scanSetOf(const DeviceSet& set, double scale);

struct SmallPair {
    ScanSet a, b;
};

class SmallPairScan {
public:
    explicit SmallPairScan(Workspace& ws);

    // Whether a direction of `queries` x `targets` is scanned whole: each at
    // most 2^22 points and the product at most 2^28 on a GPU, 2^20 on a CPU
    // device (lavapipe: its scan of 2,000-10,000-point pairs took 3x the RT
    // path's time). Tuning::smallPairWork (RTHDIST_SMALL_PAIR_WORK)
    // replaces the product's limit (benchmarks of both paths; 0: none is
    // scanned whole).
    [[nodiscard]] bool takes(uint64_t queries, uint64_t targets) const {
        return m_limits.takes(queries, targets);
    }
    [[nodiscard]] const core::ScanLimits& limits() const { return m_limits; }

    // Every pair's witnesses (input indices) and, with perPointDistances,
    // nearest indices, in `results` (one per pair, filled from `blank`); the
    // pairs in one submission per 2^24 queries (their scratch stays bounded);
    // distances and points are left to the caller (core::restoreOriginal).
    // An entry of `failed` names a pair whose result broke the self-check.
    struct Outcome {
        std::vector<HausdorffResult> results;
        std::vector<std::string> failed;  // "" where the pair passed
    };
    [[nodiscard]] Outcome run(std::span<const SmallPair> pairs, const CallOptions& options,
                              const HausdorffResult& blank);
    // One pair of host arrays (float, before the power of two `scale`): the
    // records staged by the host and copied to the device in the scan's own
    // submission (upload times in the result's timings).
    [[nodiscard]] Outcome runHostArrays(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                        double scale, const CallOptions& options,
                                        const HausdorffResult& blank);

private:
    struct Layout;  // the directions' records and chunks, their offsets
    [[nodiscard]] Layout layOut(std::span<const SmallPair> pairs, bool directedOnly, bool perPoint);
    void record(VkCommandBuffer cmd, const Layout& layout, bool perPoint);
    // Records, submits and waits; then every pair's result.
    [[nodiscard]] Outcome submit(std::span<const SmallPair> pairs, const Layout& layout,
                                 const CallOptions& options, const HausdorffResult& blank,
                                 const std::function<void(VkCommandBuffer)>& before);
    // Pair i's result from the read-back witnesses (and per-point indices).
    [[nodiscard]] std::string finishPair(const SmallPair& pair, size_t first, const Layout& layout,
                                         bool perPoint, HausdorffResult& out) const;
    // One direction's band for the certificate, from every query's nearest
    // (or killing) target and the float maximum.
    [[nodiscard]] static core::DirectionBand bandOf(const ScanSet& q, const ScanSet& t,
                                                    const uint32_t* nearest, float maxD2);

    Workspace& m_ws;
    core::ScanLimits m_limits;
};

}  // namespace rthdist::gpu_algo
