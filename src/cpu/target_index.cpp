#include "cpu/target_index.hpp"

#include <algorithm>
#include <cassert>
#include <limits>

#include "cpu/adaptive_order.hpp"
#include "cpu/parallel.hpp"

namespace rthdist::cpu {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

void padLevel(BoxLevel& level) {
    const size_t padded = (size_t(level.count) + kFanout - 1) / kFanout * kFanout;
    for (std::vector<float>* v : {&level.loX, &level.loY, &level.loZ}) v->resize(padded, kInf);
    for (std::vector<float>* v : {&level.hiX, &level.hiY, &level.hiZ}) v->resize(padded, -kInf);
}

void resizeLevel(BoxLevel& level, uint32_t count) {
    level.count = count;
    for (std::vector<float>* v : {&level.loX, &level.loY, &level.loZ, &level.hiX, &level.hiY, &level.hiZ}) {
        v->assign(count, 0.0f);
    }
}

}  // namespace

void radixSortKeys(std::vector<uint64_t>& values, int keyBits) {
    constexpr int kDigit = 12;  // 16 KiB of counts (8-bit digits measured slower)
    constexpr uint32_t kMask = (1u << kDigit) - 1;
    std::vector<uint64_t> scratch(values.size());
    std::vector<uint32_t> histogram(size_t(1) << kDigit);
    for (int shift = 32; shift < 32 + keyBits; shift += kDigit) {
        std::fill(histogram.begin(), histogram.end(), 0u);
        for (uint64_t v : values) ++histogram[(v >> shift) & kMask];
        uint32_t sum = 0;
        for (uint32_t& h : histogram) {
            const uint32_t c = h;
            h = sum;
            sum += c;
        }
        for (uint64_t v : values) scratch[histogram[(v >> shift) & kMask]++] = v;
        values.swap(scratch);
    }
}

TargetIndex buildTargetIndex(std::span<const glm::vec3> targets, double scale, int bits, int threads) {
    TargetIndex index;
    index.scale = scale;
    const size_t n = targets.size();

    // Grid over the scaled targets; the bit count is scale invariant.
    const algo::Bounds raw = algo::boundsOf(targets);
    if (bits <= 0) bits = algo::chooseBits(targets, raw);
    algo::Bounds scaledBounds{raw.lo * scale, raw.hi * scale};
    index.grid = algo::makeGrid(scaledBounds, bits);
    index.fineBits = std::min(index.grid.bits + 2, 10);
    const int extra = index.fineBits - index.grid.bits;
    // A fine cell is the grid cell split 2^extra times per axis. The fine cell
    // size differs from the grid's by a power of two, so (p - o) / s scales
    // exactly and fine >> extra equals algo::cellCoord of the grid (clamping
    // included): the grid's cells are contiguous runs of the fine order.
    algo::GridSpec fine = index.grid;
    fine.bits = index.fineBits;
    fine.cellsPerAxis = 1u << fine.bits;
    fine.cellSize = index.grid.cellSize / double(1u << extra);

    std::vector<uint64_t> keyed(n);
    parallelChunks(n, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const glm::vec3 p = scaled(targets[i], scale);
            const uint32_t key =
                algo::mortonEncode(algo::cellCoord(p.x, fine.origin.x, fine.cellSize, fine.cellsPerAxis),
                                   algo::cellCoord(p.y, fine.origin.y, fine.cellSize, fine.cellsPerAxis),
                                   algo::cellCoord(p.z, fine.origin.z, fine.cellSize, fine.cellsPerAxis));
            keyed[i] = (uint64_t(key) << 32) | uint64_t(i);
        }
    });
    radixSortKeys(keyed, 3 * index.fineBits);
    // Overfull fine cells ordered by their own boxes, and all-identical runs
    // collapsed to their first point (the smallest input index among the
    // copies: the one the tie rule reports anyway).
    std::vector<IdenticalRun> identical;
    refineOrder(keyed, targets, scale, threads, &identical);
    if (!identical.empty()) {
        size_t kept = 0, next = 0;
        for (size_t i = 0; i < n; ++i) {
            if (next < identical.size() && i > identical[next].first && i < identical[next].end) {
                if (i + 1 == identical[next].end) ++next;
                continue;
            }
            keyed[kept++] = keyed[i];
        }
        keyed.resize(kept);
    }
    const size_t m = keyed.size();
    index.collapsed = n - m;

    index.x.resize(m + kPad, kInf);
    index.y.resize(m + kPad, kInf);
    index.z.resize(m + kPad, kInf);
    index.original.resize(m + kPad, std::numeric_limits<uint32_t>::max());
    index.bucketOf.resize(m);
    parallelChunks(m, 1 << 16, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const uint32_t src = uint32_t(keyed[i]);
            const glm::vec3 p = scaled(targets[src], scale);
            index.x[i] = p.x;
            index.y[i] = p.y;
            index.z[i] = p.z;
            index.original[i] = src;
        }
    });

    // Cells (runs of the coarse key) and buckets (pieces of a cell).
    const int coarseShift = 32 + 3 * extra;
    std::vector<uint32_t> bucketFirst;
    for (size_t i = 0; i < m;) {
        const uint32_t key = uint32_t(keyed[i] >> coarseShift);
        size_t end = i + 1;
        while (end < m && uint32_t(keyed[end] >> coarseShift) == key) ++end;
        index.cellKey.push_back(key);
        index.cellFirst.push_back(uint32_t(i));
        for (size_t b = i; b < end; b += kBucketSize) bucketFirst.push_back(uint32_t(b));
        i = end;
    }
    index.cellFirst.push_back(uint32_t(m));
    bucketFirst.push_back(uint32_t(m));
    std::vector<uint64_t>().swap(keyed);

    // Level 0: tight bucket boxes.
    const uint32_t buckets = uint32_t(bucketFirst.size() - 1);
    index.levels.emplace_back();
    BoxLevel& leaves = index.levels.back();
    resizeLevel(leaves, buckets);
    parallelChunks(buckets, 4096, threads, [&](size_t begin, size_t end, int) {
        for (size_t b = begin; b < end; ++b) {
            float lx = kInf, ly = kInf, lz = kInf, hx = -kInf, hy = -kInf, hz = -kInf;
            for (uint32_t j = bucketFirst[b]; j < bucketFirst[b + 1]; ++j) {
                lx = std::min(lx, index.x[j]);
                ly = std::min(ly, index.y[j]);
                lz = std::min(lz, index.z[j]);
                hx = std::max(hx, index.x[j]);
                hy = std::max(hy, index.y[j]);
                hz = std::max(hz, index.z[j]);
                index.bucketOf[j] = uint32_t(b);
            }
            leaves.loX[b] = lx;
            leaves.loY[b] = ly;
            leaves.loZ[b] = lz;
            leaves.hiX[b] = hx;
            leaves.hiY[b] = hy;
            leaves.hiZ[b] = hz;
        }
    });
    padLevel(leaves);
    index.bucketFirst = std::move(bucketFirst);

    // Tight cell boxes: the union of the cell's buckets.
    const uint32_t cells = index.cellCount();
    index.cellLo.resize(cells);
    index.cellHi.resize(cells);
    for (uint32_t c = 0, b = 0; c < cells; ++c) {
        glm::vec3 lo(kInf), hi(-kInf);
        for (; b < buckets && index.bucketFirst[b] < index.cellFirst[c + 1]; ++b) {
            lo = glm::min(lo, glm::vec3(leaves.loX[b], leaves.loY[b], leaves.loZ[b]));
            hi = glm::max(hi, glm::vec3(leaves.hiX[b], leaves.hiY[b], leaves.hiZ[b]));
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
        resizeLevel(level, parents);
        for (uint32_t j = 0; j < parents; ++j) {
            float lx = kInf, ly = kInf, lz = kInf, hx = -kInf, hy = -kInf, hz = -kInf;
            for (uint32_t c = j * kFanout; c < (j + 1) * kFanout; ++c) {  // padding is empty
                lx = std::min(lx, child.loX[c]);
                ly = std::min(ly, child.loY[c]);
                lz = std::min(lz, child.loZ[c]);
                hx = std::max(hx, child.hiX[c]);
                hy = std::max(hy, child.hiY[c]);
                hz = std::max(hz, child.hiZ[c]);
            }
            level.loX[j] = lx;
            level.loY[j] = ly;
            level.loZ[j] = lz;
            level.hiX[j] = hx;
            level.hiY[j] = hy;
            level.hiZ[j] = hz;
        }
        padLevel(level);
        index.levels.push_back(std::move(level));
    } while (index.levels.back().count > 1);
    return index;
}

}  // namespace rthdist::cpu
