#include "cpu/target_index.hpp"

#include <algorithm>
#include <cassert>
#include <limits>

#include "core/parallel.hpp"
#include "cpu/adaptive_order.hpp"

namespace rthdist::cpu {

using core::parallelChunks;
using core::resolveThreads;
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// core::boundsOf with `threads` workers (min and max are exact in any order).
core::Bounds boundsOf(std::span<const glm::vec3> points, int threads) {
    std::vector<glm::vec3> lo(size_t(resolveThreads(threads)), points[0]), hi = lo;
    parallelChunks(points.size(), 1 << 16, threads, [&](size_t begin, size_t end, int w) {
        glm::vec3 l = lo[size_t(w)], h = hi[size_t(w)];
        for (size_t i = begin; i < end; ++i) {
            l = glm::min(l, points[i]);
            h = glm::max(h, points[i]);
        }
        lo[size_t(w)] = l, hi[size_t(w)] = h;
    });
    core::Bounds b{glm::dvec3(lo[0]), glm::dvec3(hi[0])};
    for (size_t w = 1; w < lo.size(); ++w) {
        b.lo = glm::min(b.lo, glm::dvec3(lo[w]));
        b.hi = glm::max(b.hi, glm::dvec3(hi[w]));
    }
    return b;
}

// Cells of the sorted targets (runs of equal coarseKey(i), i < m: their
// first positions and keys into `index`, cell starts found in parallel
// chunks) and buckets (each cell cut into pieces of at most kBucketSize):
// bucketFirst gets every bucket's first position then m, cellBucket every
// cell's first bucket then the bucket count.
template <class CoarseKey>
void buildCells(size_t m, CoarseKey coarseKey, int threads, TargetIndex& index,
                std::vector<uint32_t>& bucketFirst, std::vector<uint32_t>& cellBucket) {
    constexpr size_t kChunk = size_t(1) << 16;
    std::vector<std::vector<uint32_t>> starts((m + kChunk - 1) / kChunk);
    parallelChunks(m, kChunk, threads, [&](size_t begin, size_t end, int) {
        std::vector<uint32_t>& s = starts[begin / kChunk];
        for (size_t i = begin; i < end; ++i) {
            if (i == 0 || coarseKey(i) != coarseKey(i - 1)) s.push_back(uint32_t(i));
        }
    });
    for (const std::vector<uint32_t>& s : starts)
        index.cellFirst.insert(index.cellFirst.end(), s.begin(), s.end());
    index.cellFirst.push_back(uint32_t(m));
    const size_t cells = index.cellFirst.size() - 1;
    index.cellKey.resize(cells);
    cellBucket.assign(cells + 1, 0);
    for (size_t c = 0; c < cells; ++c) {
        index.cellKey[c] = coarseKey(index.cellFirst[c]);
        const uint32_t size = index.cellFirst[c + 1] - index.cellFirst[c];
        cellBucket[c + 1] = cellBucket[c] + (size + kBucketSize - 1) / kBucketSize;
    }
    bucketFirst.resize(size_t(cellBucket[cells]) + 1);
    parallelChunks(cells, 4096, threads, [&](size_t begin, size_t end, int) {
        for (size_t c = begin; c < end; ++c) {
            uint32_t b = cellBucket[c];
            for (uint32_t i = index.cellFirst[c]; i < index.cellFirst[c + 1]; i += kBucketSize)
                bucketFirst[b++] = i;
        }
    });
    bucketFirst.back() = uint32_t(m);
}

// Positions of the order that the index stores: every one but the copies
// after the first of an all-identical run (the smallest input index among
// the copies: the one the tie rule reports anyway). Empty when every
// position is stored.
class StoredPositions {
public:
    explicit StoredPositions(const SetOrder& order) : m_count(order.keyed.size()) {
        if (order.identical.empty()) return;
        m_kept.reserve(m_count);
        size_t next = 0;
        for (size_t i = 0; i < m_count; ++i) {
            const IdenticalRun* run = next < order.identical.size() ? &order.identical[next] : nullptr;
            if (run != nullptr && i > run->first && i < run->end) {
                if (i + 1 == run->end) ++next;
                continue;
            }
            m_kept.push_back(uint32_t(i));
        }
    }
    [[nodiscard]] bool all() const { return m_kept.empty(); }
    [[nodiscard]] size_t size() const { return all() ? m_count : m_kept.size(); }
    // Position in the order of stored target i.
    [[nodiscard]] size_t operator[](size_t i) const { return all() ? i : size_t(m_kept[i]); }

private:
    size_t m_count;
    std::vector<uint32_t> m_kept;
};

// The stored targets' input indices and coordinates, each padded with kPad
// entries (sized without a fill: the copies are the first touch, in parallel).
void storeTargets(const SetOrder& order, const StoredPositions& stored, int threads, TargetIndex& index) {
    const size_t m = stored.size();
    index.original.resize(m + kPad);
    std::fill(index.original.begin() + ptrdiff_t(m), index.original.end(),
              std::numeric_limits<uint32_t>::max());
    index.bucketOf.resize(m);
    parallelChunks(m, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) index.original[i] = uint32_t(order.keyed[stored[i]]);
    });
    if (stored.all()) {  // the order's arrays as they are (padded by orderSet)
        index.x = order.x, index.y = order.y, index.z = order.z;
        return;
    }
    UninitVector<float>* to[3] = {&index.keptX, &index.keptY, &index.keptZ};
    const UninitVector<float>* from[3] = {&order.x, &order.y, &order.z};
    for (int a = 0; a < 3; ++a) {
        to[a]->resize(m + kPad);
        std::fill(to[a]->begin() + ptrdiff_t(m), to[a]->end(), kInf);
        parallelChunks(m, 1 << 16, threads, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) (*to[a])[i] = (*from[a])[stored[i]];
        });
    }
    index.x = index.keptX, index.y = index.keptY, index.z = index.keptZ;
}

// Level 0 of the BVH: tight bucket boxes; every stored target's bucket.
void buildLeaves(std::vector<uint32_t> bucketFirst, int threads, TargetIndex& index) {
    const uint32_t buckets = uint32_t(bucketFirst.size() - 1);
    index.levels.emplace_back();
    BoxLevel& leaves = index.levels.back();
    leaves.resize(buckets, threads);
    parallelChunks(buckets, 4096, threads, [&](size_t begin, size_t end, int) {
        for (size_t b = begin; b < end; ++b) {
            glm::vec3 lo(kInf), hi(-kInf);
            for (uint32_t j = bucketFirst[b]; j < bucketFirst[b + 1]; ++j) {
                const glm::vec3 p(index.x[j], index.y[j], index.z[j]);
                lo = glm::min(lo, p);
                hi = glm::max(hi, p);
                index.bucketOf[j] = uint32_t(b);
            }
            leaves.set(uint32_t(b), lo, hi);
        }
    });
    index.bucketFirst = std::move(bucketFirst);
}

// Tight cell boxes: the union of the cell's buckets (cellBucket as buildCells).
void buildCellBoxes(const std::vector<uint32_t>& cellBucket, int threads, TargetIndex& index) {
    const BoxLevel& leaves = index.levels[0];
    const uint32_t cells = index.cellCount();
    index.cellLo.resize(cells);
    index.cellHi.resize(cells);
    parallelChunks(cells, 4096, threads, [&](size_t begin, size_t end, int) {
        for (size_t c = begin; c < end; ++c) {
            glm::vec3 lo(kInf), hi(-kInf);
            for (uint32_t b = cellBucket[c]; b < cellBucket[c + 1]; ++b) {
                lo = glm::min(lo, leaves.lo(b));
                hi = glm::max(hi, leaves.hi(b));
            }
            index.cellLo[c] = lo;
            index.cellHi[c] = hi;
        }
    });
}

// Upper levels: node j covers children kFanout*j .. kFanout*j + 7. At least
// one level above the leaves so the search always starts at an inner node.
void buildUpperLevels(int threads, TargetIndex& index) {
    do {
        const BoxLevel& child = index.levels.back();
        const uint32_t parents = (child.count + kFanout - 1) / kFanout;
        BoxLevel level;
        level.resize(parents, threads);
        parallelChunks(parents, 4096, threads, [&](size_t begin, size_t end, int) {
            for (size_t j = begin; j < end; ++j) {
                glm::vec3 lo(kInf), hi(-kInf);
                for (uint32_t c = uint32_t(j) * kFanout; c < (uint32_t(j) + 1) * kFanout;
                     ++c) {  // padding is empty
                    lo = glm::min(lo, child.lo(c));
                    hi = glm::max(hi, child.hi(c));
                }
                level.set(uint32_t(j), lo, hi);
            }
        });
        index.levels.push_back(std::move(level));
    } while (index.levels.back().count > 1);
}

}  // namespace

void BoxLevel::resize(uint32_t n, int threads) {
    count = n;
    const size_t blocks = (size_t(n) + kFanout - 1) / kFanout;
    boxes.resize(blocks * kBlock);  // every entry written below
    // On `threads` threads, the first touch of fresh pages among them: one
    // thread filled the 12.6M leaves of a 100M-point torus (300 MB) in
    // 500-1,100 ms on 2 cores.
    parallelChunks(blocks, 4096, threads, [&](size_t begin, size_t end, int) {
        for (size_t g = begin; g < end; ++g) {
            std::fill_n(boxes.begin() + ptrdiff_t(g * kBlock), 3 * kFanout, kInf);
            std::fill_n(boxes.begin() + ptrdiff_t(g * kBlock + 3 * kFanout), 3 * kFanout, -kInf);
        }
    });
}

SetOrder orderSet(std::span<const glm::vec3> points, double scale, int bits, int threads) {
    SetOrder order;
    const size_t n = points.size();

    // Grid over the scaled points; the bit count is scale invariant.
    const core::Bounds raw = boundsOf(points, threads);
    if (bits <= 0) bits = core::chooseBits(points, raw);
    order.bounds = core::Bounds{raw.lo * scale, raw.hi * scale};
    order.grid = core::makeGrid(order.bounds, bits);
    order.fineBits = std::min(order.grid.bits + 2, 10);
    const int extra = order.fineBits - order.grid.bits;
    // A fine cell is the grid cell split 2^extra times per axis. The fine cell
    // size differs from the grid's by a power of two, so (p - o) / s scales
    // exactly and fine >> extra equals core::cellCoord of the grid (clamping
    // included): the grid's cells are contiguous runs of the fine order.
    core::GridSpec fine = order.grid;
    fine.bits = order.fineBits;
    fine.cellsPerAxis = 1u << fine.bits;
    fine.cellSize = order.grid.cellSize / double(1u << extra);

    // Fine keys in input order, then the points sorted by them (moved with
    // their keys: no gather afterwards), then overfull fine cells ordered by
    // their own boxes.
    UninitVector<uint32_t> keys(n);  // every entry written below
    parallelChunks(n, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const glm::vec3 p = scaled(points[i], scale);
            keys[i] = core::cellKey(glm::dvec3(p), fine);
        }
    });
    OrderedPoints sorted = sortPointsByKey(keys, 3 * order.fineBits, points, scale, threads, kPad);
    refineOrder(sorted, threads, &order.identical);
    order.keyed = std::move(sorted.keyed);
    order.x = std::move(sorted.x);
    order.y = std::move(sorted.y);
    order.z = std::move(sorted.z);
    return order;
}

TargetIndex buildTargetIndex(double scale, const SetOrder& order, int threads) {
    TargetIndex index;
    index.scale = scale;
    index.grid = order.grid;
    index.fineBits = order.fineBits;
    // The stored targets, cells (runs of the coarse key) and buckets (pieces
    // of a cell); the stored positions are freed before the boxes are built.
    std::vector<uint32_t> bucketFirst, cellBucket;
    {
        const StoredPositions stored(order);
        index.collapsed = order.keyed.size() - stored.size();
        storeTargets(order, stored, threads, index);
        const int coarseShift = 32 + 3 * (order.fineBits - order.grid.bits);
        buildCells(
            stored.size(), [&](size_t i) { return uint32_t(order.keyed[stored[i]] >> coarseShift); }, threads,
            index, bucketFirst, cellBucket);
    }
    buildLeaves(std::move(bucketFirst), threads, index);
    buildCellBoxes(cellBucket, threads, index);
    buildUpperLevels(threads, index);
    return index;
}

}  // namespace rthdist::cpu
