#include "cpu/adaptive_order.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <limits>

#include "algo/index_space.hpp"
#include "cpu/parallel.hpp"
#include "cpu/target_index.hpp"

namespace rthdist::cpu {
namespace {

constexpr uint32_t kRefineCells = 1024;      // cells per axis of a refinement key (10 bits)
constexpr uint32_t kParallelRun = 1u << 16;  // runs this long are refined with all threads
constexpr uint64_t kIndexMask = 0xffffffffull;
constexpr float kInf = std::numeric_limits<float>::infinity();

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

struct Box {
    glm::vec3 lo{kInf}, hi{-kInf};
    void add(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void add(const Box& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
};

class Refiner {
public:
    Refiner(std::vector<uint64_t>& keyed, std::span<const glm::vec3> points, double scale)
        : m_keyed(keyed), m_points(points), m_scale(scale) {}

    // Orders one run by the key over its tight box; its sub-runs that need
    // refining go to `children`, an all-identical run to `identical`.
    // threads > 1 only for long runs (keys and box in parallel, radix sort).
    void refine(const Run& run, int threads, std::vector<Run>& children,
                std::vector<IdenticalRun>& identical) {
        const uint32_t count = run.end - run.first;
        const bool wide = threads > 1 && count >= kParallelRun;
        const std::span<uint64_t> values(m_keyed.data() + run.first, count);
        const Box box = boxOf(values, wide ? threads : 1);
        if (box.lo == box.hi) {
            identical.push_back({run.first, run.end});
            return;
        }
        if (run.depth >= kMaxRefineDepth) return;
        const glm::vec3 ext = box.hi - box.lo;
        const double cellSize = double(std::max({ext.x, ext.y, ext.z})) / double(kRefineCells);
        const glm::dvec3 origin(box.lo);
        auto keyOf = [&](uint64_t v) {
            const glm::dvec3 p(scaled(m_points[uint32_t(v)], m_scale));
            const uint32_t key = algo::mortonEncode(algo::cellCoord(p.x, origin.x, cellSize, kRefineCells),
                                                    algo::cellCoord(p.y, origin.y, cellSize, kRefineCells),
                                                    algo::cellCoord(p.z, origin.z, cellSize, kRefineCells));
            return (uint64_t(key) << 32) | (v & kIndexMask);
        };
        const uint64_t runKey = values[0] & ~kIndexMask;
        if (wide) {
            std::vector<uint64_t> sorted(count);
            parallelChunks(count, 1 << 14, threads, [&](size_t begin, size_t end, int) {
                for (size_t i = begin; i < end; ++i) sorted[i] = keyOf(values[i]);
            });
            radixSortKeys(sorted, 30, threads);  // stable: ties keep the run's ascending index order
            collectRuns(sorted, run.first, run.depth + 1, children);
            parallelChunks(count, 1 << 14, threads, [&](size_t begin, size_t end, int) {
                for (size_t i = begin; i < end; ++i) values[i] = runKey | (sorted[i] & kIndexMask);
            });
        } else {
            for (uint64_t& v : values) v = keyOf(v);
            std::sort(values.begin(), values.end());  // (key, index): ties by ascending index
            collectRuns(values, run.first, run.depth + 1, children);
            for (uint64_t& v : values) v = runKey | (v & kIndexMask);
        }
    }

private:
    Box boxOf(std::span<const uint64_t> values, int threads) const {
        std::vector<Box> partial(size_t(resolveThreads(threads)));
        parallelChunks(values.size(), 1 << 14, threads, [&](size_t begin, size_t end, int w) {
            Box b;
            for (size_t i = begin; i < end; ++i) b.add(scaled(m_points[uint32_t(values[i])], m_scale));
            partial[size_t(w)].add(b);
        });
        Box all;
        for (const Box& b : partial) all.add(b);
        return all;
    }

    std::vector<uint64_t>& m_keyed;
    std::span<const glm::vec3> m_points;
    double m_scale;
};

}  // namespace

void refineOrder(std::vector<uint64_t>& keyed, std::span<const glm::vec3> points, double scale, int threads,
                 std::vector<IdenticalRun>* identicalOut) {
    std::vector<Run> pending;
    collectRuns(keyed, 0, 0, pending);
    if (pending.empty()) {
        if (identicalOut != nullptr) identicalOut->clear();
        return;
    }
    threads = resolveThreads(threads);
    Refiner refiner(keyed, points, scale);
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
