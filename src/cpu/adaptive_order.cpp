#include "cpu/adaptive_order.hpp"

#include <glm/common.hpp>

#include <algorithm>

#include "core/float_box.hpp"
#include "core/index_space.hpp"
#include "core/parallel.hpp"
#include "cpu/key_sort.hpp"

namespace rthdist::cpu {

using core::parallelChunks;
using core::resolveThreads;
namespace {

constexpr uint32_t kRefineCells = 1024;      // cells per axis of a refinement key (10 bits)
constexpr uint32_t kParallelRun = 1u << 16;  // runs this long are refined with all threads
constexpr uint64_t kIndexMask = 0xffffffffull;

struct Run {
    uint32_t first = 0, end = 0;
    int depth = 0;
};

// Runs of equal keys (bits 32..63) longer than kRefineRun in values, as
// positions offset by `base`.
void collectRuns(std::span<const uint64_t> values, uint32_t base, int depth, std::vector<Run>& out) {
    const uint32_t n = uint32_t(values.size());
    for (uint32_t i = 0; i < n;) {
        const uint64_t key = values[i] >> 32;
        uint32_t j = i + 1;
        while (j < n && (values[j] >> 32) == key) ++j;
        if (j - i > kRefineRun) out.push_back({base + i, base + j, depth});
        i = j;
    }
}

// collectRuns over all of `values` with `threads` workers: each takes the
// runs that start in its chunk (one may end past the chunk). A run starting
// at i is longer than kRefineRun exactly when the entry kRefineRun further
// on has the same key (the keys ascend), and scanning from a run start, the
// first i where that holds is a run start (an earlier entry of the same run
// would have matched first): a test that almost never branches, instead of
// one end of run per entry.
std::vector<Run> collectRunsInParallel(std::span<const uint64_t> values, int threads) {
    std::vector<std::vector<Run>> found(size_t(resolveThreads(threads)));
    const size_t n = values.size();
    auto keyAt = [values](size_t i) { return values[i] >> 32; };
    parallelChunks(n, 1 << 18, threads, [&](size_t begin, size_t end, int w) {
        size_t i = begin;
        while (i < end && i > 0 && keyAt(i) == keyAt(i - 1)) ++i;  // the previous chunk's run
        for (; i < end && i + kRefineRun < n; ++i) {
            if (keyAt(i + kRefineRun) != keyAt(i)) continue;
            size_t j = i + kRefineRun + 1;
            while (j < n && keyAt(j) == keyAt(i)) ++j;
            found[size_t(w)].push_back({uint32_t(i), uint32_t(j), 0});
            i = j - 1;
        }
    });
    std::vector<Run> all;
    for (const std::vector<Run>& f : found) all.insert(all.end(), f.begin(), f.end());
    return all;
}

using Box = core::FloatBox;

// The run's entries before it is permuted: input index and coordinates.
struct RunCopy {
    std::vector<uint32_t> index;
    std::vector<float> x, y, z;
};

class Refiner {
public:
    explicit Refiner(OrderedPoints& order) : m_order(order) {}

    // Orders one run by the key over its tight box; its sub-runs that need
    // refining go to `children`, an all-identical run to `identical`.
    // threads > 1 only for long runs (keys, box and moves in parallel, radix sort).
    void refine(const Run& run, int threads, std::vector<Run>& children,
                std::vector<IdenticalRun>& identical) {
        const uint32_t count = run.end - run.first;
        const int workers = threads > 1 && count >= kParallelRun ? threads : 1;
        const Box box = boxOf(run, workers);
        if (box.lo == box.hi) {
            identical.push_back({run.first, run.end});
            return;
        }
        if (run.depth >= kMaxRefineDepth) return;
        const glm::vec3 ext = box.hi - box.lo;
        const double cellSize = double(std::max({ext.x, ext.y, ext.z})) / double(kRefineCells);
        const glm::dvec3 origin(box.lo);
        // (key << 32 | position in the run): positions ascend with the input
        // index inside a run, so sorting these sorts by (key, index).
        std::vector<uint64_t> sorted(count);
        parallelChunks(count, 1 << 14, workers, [&](size_t begin, size_t end, int) {
            for (size_t j = begin; j < end; ++j) {
                const size_t i = run.first + j;
                const glm::dvec3 p(m_order.x[i], m_order.y[i], m_order.z[i]);
                const uint32_t key =
                    core::mortonEncode(core::cellCoord(p.x, origin.x, cellSize, kRefineCells),
                                       core::cellCoord(p.y, origin.y, cellSize, kRefineCells),
                                       core::cellCoord(p.z, origin.z, cellSize, kRefineCells));
                sorted[j] = (uint64_t(key) << 32) | j;
            }
        });
        if (workers > 1) {
            radixSortKeys(sorted, 30, workers);
        } else {
            std::sort(sorted.begin(), sorted.end());
        }
        collectRuns(sorted, run.first, run.depth + 1, children);
        permute(run, sorted, workers);
    }

private:
    Box boxOf(const Run& run, int threads) const {
        std::vector<Box> partial(size_t(resolveThreads(threads)));
        parallelChunks(run.end - run.first, 1 << 14, threads, [&](size_t begin, size_t end, int w) {
            Box b;
            for (size_t i = run.first + begin; i < run.first + end; ++i) {
                b.add(glm::vec3(m_order.x[i], m_order.y[i], m_order.z[i]));
            }
            partial[size_t(w)].add(b);
        });
        Box all;
        for (const Box& b : partial) all.add(b);
        return all;
    }

    // Moves the run's entries into the order of `sorted` (positions in the
    // run); the keys stay the run's key.
    void permute(const Run& run, std::span<const uint64_t> sorted, int threads) {
        const uint32_t count = run.end - run.first;
        const uint64_t runKey = m_order.keyed[run.first] & ~kIndexMask;
        RunCopy old;
        old.index.resize(count), old.x.resize(count), old.y.resize(count), old.z.resize(count);
        parallelChunks(count, 1 << 14, threads, [&](size_t begin, size_t end, int) {
            for (size_t j = begin; j < end; ++j) {
                const size_t i = run.first + j;
                old.index[j] = uint32_t(m_order.keyed[i]);
                old.x[j] = m_order.x[i], old.y[j] = m_order.y[i], old.z[j] = m_order.z[i];
            }
        });
        parallelChunks(count, 1 << 14, threads, [&](size_t begin, size_t end, int) {
            for (size_t j = begin; j < end; ++j) {
                const size_t i = run.first + j;
                const uint32_t from = uint32_t(sorted[j] & kIndexMask);
                m_order.keyed[i] = runKey | old.index[from];
                m_order.x[i] = old.x[from], m_order.y[i] = old.y[from], m_order.z[i] = old.z[from];
            }
        });
    }

    OrderedPoints& m_order;
};

}  // namespace

void refineOrder(OrderedPoints& order, int threads, std::vector<IdenticalRun>* identicalOut) {
    std::vector<Run> pending = collectRunsInParallel(order.keyed, threads);
    if (pending.empty()) {
        if (identicalOut != nullptr) identicalOut->clear();
        return;
    }
    threads = resolveThreads(threads);
    Refiner refiner(order);
    std::vector<IdenticalRun> identical;
    // Long runs one at a time with every thread (their long sub-runs come
    // back on the list), then the short ones in parallel, each to its end.
    std::vector<Run> shortRuns;
    while (!pending.empty()) {
        const Run run = pending.back();
        pending.pop_back();
        if (run.end - run.first < kParallelRun || threads == 1) {
            shortRuns.push_back(run);
            continue;
        }
        refiner.refine(run, threads, pending, identical);
    }
    std::vector<std::vector<IdenticalRun>> found(static_cast<size_t>(threads));
    parallelChunks(shortRuns.size(), 1, threads, [&](size_t begin, size_t end, int w) {
        std::vector<Run> stack;
        for (size_t s = begin; s < end; ++s) {
            stack.push_back(shortRuns[s]);
            while (!stack.empty()) {
                const Run run = stack.back();
                stack.pop_back();
                refiner.refine(run, 1, stack, found[size_t(w)]);
            }
        }
    });
    for (const std::vector<IdenticalRun>& f : found) identical.insert(identical.end(), f.begin(), f.end());
    if (identicalOut != nullptr) {
        std::sort(identical.begin(), identical.end(),
                  [](const IdenticalRun& a, const IdenticalRun& b) { return a.first < b.first; });
        *identicalOut = std::move(identical);
    }
}

}  // namespace rthdist::cpu
