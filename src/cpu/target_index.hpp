// Target index of the CPU backend: the shared RT-HDIST grid (core/index_space,
// Kim, Lee, Kim 2025, Sec. 4.1) with every occupied cell's points contiguous
// and a tight box per cell, plus an implicit 8-wide bounding-volume hierarchy
// over sub-cell buckets for exact nearest-neighbour search with early break
// (Taha & Hanbury 2015).
//
// Layout: targets are sorted by a fine Morton key (2 bits per axis finer than
// the grid, at most 10), so each grid cell is a contiguous run and, inside a
// cell, points follow the Morton curve. A run of more than kRefineRun equal
// fine keys (a dense cluster in a box stretched by a stray point, a heavy
// tail) is ordered again by a Morton key over its own tight box, recursively
// (cpu/adaptive_order.hpp), so the order follows the points at every density:
// consecutive points are spatial neighbours and the boxes built over them are
// tight whatever the bounding box. Each cell is cut into buckets of at most
// kBucketSize consecutive points (a bucket never crosses a cell); buckets are
// the BVH leaves, and groups of 8 consecutive nodes (adaptive Morton order)
// form the next level: an LBVH with bounded leaves, O(log n) levels. A run of
// identical points longer than kRefineRun is stored once (its first point,
// the smallest input index among the copies), so heavy duplication costs no
// per-copy work in any search. Coordinates live in SoA float arrays padded
// with +inf so that the 8-wide scans may read past a bucket's end (extra
// lanes are real targets or +inf, never wrong).
//
// Why a search over it is exact (design.md §3 restated for this structure):
// every stored target lies in the bucket that holds its sorted position, every
// bucket's box is the float min/max of its points, and every node's box the
// min/max of its children's, so the float distance from a query to a node's
// box never exceeds the float distance to any target below it (rounding is
// monotone; cpu_hausdorff.cpp computes both with the same operations). A
// search that skips only nodes farther than its best point therefore skips no
// closer target. The targets dropped by the collapse have a stored copy with
// the same float coordinates and a smaller input index, so the minimum over
// the stored targets equals the minimum over all of them, and so does the
// smallest index among the nearest. The order itself (sort, refinement) moves
// points between buckets but never loses one: the refinement only permutes
// runs, the collapse only drops copies.
//
// Precision: coordinates are the input floats times a power-of-two `scale`
// (exact; 1 unless the magnitudes would overflow or underflow squared floats).
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

#include "core/index_space.hpp"
#include "core/uninit_vector.hpp"
#include "cpu/adaptive_order.hpp"

namespace rthdist::cpu {

using core::scaled;
using core::UninitVector;

inline constexpr uint32_t kBucketSize = 8;  // points per BVH leaf (at most)
inline constexpr uint32_t kFanout = 8;      // children per BVH node
inline constexpr uint32_t kPad = 8;         // +inf entries after every SoA array

// Boxes of one BVH level, in blocks of kFanout (the children of one parent
// node): block g holds loX, loY, loZ, hiX, hiY, hiZ of boxes 8g .. 8g + 7,
// eight floats each, so one node's children are 192 contiguous bytes (three
// cache lines) for the 8-wide distance test. The last block is padded with
// empty boxes (lo = +inf, hi = -inf: infinitely far from every point).
struct BoxLevel {
    static constexpr uint32_t kBlock = 6 * kFanout;  // floats per block
    core::UninitVector<float> boxes;  // kept between calls (uninit_vector.hpp), written by resize
    uint32_t count = 0;               // real boxes

    void resize(uint32_t n, int threads = 1);  // n empty boxes, written on `threads` threads (0: all)
    void set(uint32_t j, const glm::vec3& lo, const glm::vec3& hi) {
        float* b = &boxes[size_t(j / kFanout) * kBlock + j % kFanout];
        b[0] = lo.x, b[8] = lo.y, b[16] = lo.z, b[24] = hi.x, b[32] = hi.y, b[40] = hi.z;
    }
    [[nodiscard]] glm::vec3 lo(uint32_t j) const {
        const float* b = &boxes[size_t(j / kFanout) * kBlock + j % kFanout];
        return {b[0], b[8], b[16]};
    }
    [[nodiscard]] glm::vec3 hi(uint32_t j) const {
        const float* b = &boxes[size_t(j / kFanout) * kBlock + j % kFanout];
        return {b[24], b[32], b[40]};
    }
    // The block of node `node`'s children (boxes kFanout * node ..).
    [[nodiscard]] const float* block(uint32_t node) const { return &boxes[size_t(node) * kBlock]; }
};

struct TargetIndex {
    core::GridSpec grid;   // over the scaled targets
    int fineBits = 1;      // bits of the sort key per axis (grid.bits + 2, <= 10)
    double scale = 1.0;    // core::exactScale
    size_t collapsed = 0;  // copies of identical points not stored (targets - stored)

    // Sorted targets (scaled), each padded with kPad entries of +inf: views of
    // the set order's own arrays (SetOrder::x, y, z carry the same padding)
    // when no copy was collapsed, else of kept*. So an index must not outlive
    // the SetOrder it was built from; it is move-only (the views follow a move).
    std::span<const float> x, y, z;
    UninitVector<float> keptX, keptY, keptZ;  // the stored targets, only when some were collapsed
    UninitVector<uint32_t> original;          // sorted position -> input index (of the first copy)
    UninitVector<uint32_t> bucketOf;          // sorted position -> bucket

    // Occupied cells, ascending Morton key (grid.bits per axis).
    core::UninitVector<uint32_t> cellKey;
    core::UninitVector<uint32_t> cellFirst;        // cellCount + 1 offsets into the sorted points
    core::UninitVector<glm::vec3> cellLo, cellHi;  // tight boxes of the cells' points

    // Buckets and the BVH: levels[0] holds the buckets, levels.back() one root.
    std::vector<uint32_t> bucketFirst;  // bucketCount + 1 offsets
    std::vector<BoxLevel> levels;

    TargetIndex() = default;
    TargetIndex(TargetIndex&&) = default;
    TargetIndex& operator=(TargetIndex&&) = default;
    TargetIndex(const TargetIndex&) = delete;
    TargetIndex& operator=(const TargetIndex&) = delete;

    [[nodiscard]] uint32_t cellCount() const { return uint32_t(cellKey.size()); }
    [[nodiscard]] uint32_t bucketCount() const { return levels.empty() ? 0 : levels[0].count; }
    [[nodiscard]] uint32_t size() const { return uint32_t(x.size() - kPad); }  // stored targets
};

// A set's adaptive Morton order: the layout of its target index and, the
// same order, the order in which it is queried (neighbours consecutive, copies
// adjacent, ties in input order). Computed once per set and call.
struct SetOrder {
    core::Bounds bounds;                  // of the scaled points
    core::GridSpec grid;                  // over them
    int fineBits = 1;                     // bits of the sort key per axis (grid.bits + 2, <= 10)
    UninitVector<uint64_t> keyed;         // (fine key << 32 | input index), every point, in order
    UninitVector<float> x, y, z;          // the scaled coordinates in that order, then kPad of +inf
    std::vector<IdenticalRun> identical;  // all-identical runs of that order (refineOrder)
};

// Orders `points` (non-empty, finite) scaled by `scale`: the fine Morton key
// over the grid, then refineOrder. bits <= 0 picks the grid's bit count with
// core::chooseBits.
[[nodiscard]] SetOrder orderSet(std::span<const glm::vec3> points, double scale, int bits, int threads);

// Builds the index over a set in its order (orderSet of the set and scale).
[[nodiscard]] TargetIndex buildTargetIndex(double scale, const SetOrder& order, int threads);

}  // namespace rthdist::cpu
