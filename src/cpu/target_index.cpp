#include "cpu/target_index.hpp"

#include <algorithm>
#include <cassert>
#include <limits>

#include "cpu/adaptive_order.hpp"
#include "cpu/parallel.hpp"

namespace rthdist::cpu {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

void BoxLevel::resize(uint32_t n) {
    count = n;
    const size_t blocks = (size_t(n) + kFanout - 1) / kFanout;
    boxes.assign(blocks * kBlock, kInf);
    for (size_t g = 0; g < blocks; ++g) {
        std::fill_n(boxes.begin() + ptrdiff_t(g * kBlock + 3 * kFanout), 3 * kFanout, -kInf);
    }
}

void radixSortKeys(std::vector<uint64_t>& values, int keyBits, int threads) {
    constexpr int kDigit = 12;  // 16 KiB of counts (8-bit digits measured slower)
    constexpr uint32_t kDigits = 1u << kDigit;
    constexpr size_t kMinPerPart = 1 << 16;
    const size_t n = values.size();
    // Parts: contiguous ranges counted and scattered independently; a digit's
    // slots are handed out in part order, so every pass stays stable.
    const size_t parts = std::clamp<size_t>(n / kMinPerPart, 1, size_t(resolveThreads(threads)) * 2);
    const size_t partSize = (n + parts - 1) / parts;
    std::vector<uint64_t> scratch(n);
    std::vector<uint32_t> histogram(parts * kDigits);
    for (int shift = 32; shift < 32 + keyBits; shift += kDigit) {
        std::fill(histogram.begin(), histogram.end(), 0u);
        auto digit = [shift](uint64_t v) { return uint32_t(v >> shift) & (kDigits - 1); };
        parallelChunks(parts, 1, threads, [&](size_t p, size_t, int) {
            uint32_t* h = &histogram[p * kDigits];
            for (size_t i = p * partSize; i < std::min(n, (p + 1) * partSize); ++i) ++h[digit(values[i])];
        });
        uint32_t sum = 0;
        bool oneDigit = false;  // every value has the same digit: the pass is the identity
        for (uint32_t d = 0; d < kDigits; ++d) {
            const uint32_t before = sum;
            for (size_t p = 0; p < parts; ++p) {
                const uint32_t c = histogram[p * kDigits + d];
                histogram[p * kDigits + d] = sum;
                sum += c;
            }
            oneDigit = oneDigit || sum - before == n;
        }
        if (oneDigit) continue;
        parallelChunks(parts, 1, threads, [&](size_t p, size_t, int) {
            uint32_t* h = &histogram[p * kDigits];
            for (size_t i = p * partSize; i < std::min(n, (p + 1) * partSize); ++i) {
                scratch[h[digit(values[i])]++] = values[i];
            }
        });
        values.swap(scratch);
    }
}

SetOrder orderSet(std::span<const glm::vec3> points, double scale, int bits, int threads) {
    SetOrder order;
    const size_t n = points.size();

    // Grid over the scaled points; the bit count is scale invariant.
    const algo::Bounds raw = algo::boundsOf(points);
    if (bits <= 0) bits = algo::chooseBits(points, raw);
    order.bounds = algo::Bounds{raw.lo * scale, raw.hi * scale};
    order.grid = algo::makeGrid(order.bounds, bits);
    order.fineBits = std::min(order.grid.bits + 2, 10);
    const int extra = order.fineBits - order.grid.bits;
    // A fine cell is the grid cell split 2^extra times per axis. The fine cell
    // size differs from the grid's by a power of two, so (p - o) / s scales
    // exactly and fine >> extra equals algo::cellCoord of the grid (clamping
    // included): the grid's cells are contiguous runs of the fine order.
    algo::GridSpec fine = order.grid;
    fine.bits = order.fineBits;
    fine.cellsPerAxis = 1u << fine.bits;
    fine.cellSize = order.grid.cellSize / double(1u << extra);

    std::vector<uint64_t>& keyed = order.keyed;
    keyed.resize(n);
    parallelChunks(n, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const glm::vec3 p = scaled(points[i], scale);
            const uint32_t key =
                algo::mortonEncode(algo::cellCoord(p.x, fine.origin.x, fine.cellSize, fine.cellsPerAxis),
                                   algo::cellCoord(p.y, fine.origin.y, fine.cellSize, fine.cellsPerAxis),
                                   algo::cellCoord(p.z, fine.origin.z, fine.cellSize, fine.cellsPerAxis));
            keyed[i] = (uint64_t(key) << 32) | uint64_t(i);
        }
    });
    radixSortKeys(keyed, 3 * order.fineBits, threads);
    // Overfull fine cells ordered by their own boxes.
    refineOrder(keyed, points, scale, threads, &order.identical);
    // The one gather of the set's coordinates into its order.
    order.x.resize(n);
    order.y.resize(n);
    order.z.resize(n);
    parallelChunks(n, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const glm::vec3 p = scaled(points[uint32_t(keyed[i])], scale);
            order.x[i] = p.x;
            order.y[i] = p.y;
            order.z[i] = p.z;
        }
    });
    return order;
}

TargetIndex buildTargetIndex(double scale, const SetOrder& order, int threads) {
    TargetIndex index;
    index.scale = scale;
    index.grid = order.grid;
    index.fineBits = order.fineBits;
    const int extra = order.fineBits - order.grid.bits;
    const size_t n = order.keyed.size();

    // All-identical runs collapsed to their first point (the smallest input
    // index among the copies: the one the tie rule reports anyway).
    std::vector<uint32_t> kept;  // positions of the order that are stored (when some are not)
    if (!order.identical.empty()) {
        kept.reserve(n);
        size_t next = 0;
        for (size_t i = 0; i < n; ++i) {
            const IdenticalRun* run = next < order.identical.size() ? &order.identical[next] : nullptr;
            if (run != nullptr && i > run->first && i < run->end) {
                if (i + 1 == run->end) ++next;
                continue;
            }
            kept.push_back(uint32_t(i));
        }
    }
    const size_t m = kept.empty() ? n : kept.size();
    auto positionOf = [&kept](size_t i) { return kept.empty() ? i : size_t(kept[i]); };
    index.collapsed = n - m;

    index.x.resize(m + kPad, kInf);
    index.y.resize(m + kPad, kInf);
    index.z.resize(m + kPad, kInf);
    index.original.resize(m + kPad, std::numeric_limits<uint32_t>::max());
    index.bucketOf.resize(m);
    parallelChunks(m, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const size_t at = positionOf(i);
            index.x[i] = order.x[at];
            index.y[i] = order.y[at];
            index.z[i] = order.z[at];
            index.original[i] = uint32_t(order.keyed[at]);
        }
    });

    // Cells (runs of the coarse key) and buckets (pieces of a cell).
    const int coarseShift = 32 + 3 * extra;
    std::vector<uint32_t> bucketFirst;
    for (size_t i = 0; i < m;) {
        const uint32_t key = uint32_t(order.keyed[positionOf(i)] >> coarseShift);
        size_t end = i + 1;
        while (end < m && uint32_t(order.keyed[positionOf(end)] >> coarseShift) == key) ++end;
        index.cellKey.push_back(key);
        index.cellFirst.push_back(uint32_t(i));
        for (size_t b = i; b < end; b += kBucketSize) bucketFirst.push_back(uint32_t(b));
        i = end;
    }
    index.cellFirst.push_back(uint32_t(m));
    bucketFirst.push_back(uint32_t(m));
    std::vector<uint32_t>().swap(kept);

    // Level 0: tight bucket boxes.
    const uint32_t buckets = uint32_t(bucketFirst.size() - 1);
    index.levels.emplace_back();
    BoxLevel& leaves = index.levels.back();
    leaves.resize(buckets);
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

    // Tight cell boxes: the union of the cell's buckets.
    const uint32_t cells = index.cellCount();
    index.cellLo.resize(cells);
    index.cellHi.resize(cells);
    for (uint32_t c = 0, b = 0; c < cells; ++c) {
        glm::vec3 lo(kInf), hi(-kInf);
        for (; b < buckets && index.bucketFirst[b] < index.cellFirst[c + 1]; ++b) {
            lo = glm::min(lo, leaves.lo(b));
            hi = glm::max(hi, leaves.hi(b));
        }
        index.cellLo[c] = lo;
        index.cellHi[c] = hi;
    }

    // Upper levels: node j covers children kFanout*j .. kFanout*j + 7. At least
    // one level above the leaves so the search always starts at an inner node.
    do {
        const BoxLevel& child = index.levels.back();
        const uint32_t parents = (child.count + kFanout - 1) / kFanout;
        BoxLevel level;
        level.resize(parents);
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
    return index;
}

}  // namespace rthdist::cpu
