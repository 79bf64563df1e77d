#include "cpu/exact_nearest.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/certificate.hpp"
#include "core/parallel.hpp"
#include "cpu/key_sort.hpp"

namespace rthdist::cpu {
namespace {

constexpr uint32_t kLeafPoints = 8;
// Ranges at least this large are split one level at a time, a level's
// nodes on the worker pool, until there are four a worker; smaller ones
// are whole subtrees of one thread (~0.5 ms of work each at 2^12).
constexpr uint32_t kParallelPoints = uint32_t(1) << 12;
// A level of fewer ranges than workers splits each range of at least this
// many points on every worker (parallelSelect): the box, then the median
// by a sample's two brackets, a parallel three-way scatter and the
// selection inside the middle bucket only; smaller ones by std::nth_element.
constexpr uint32_t kParallelSelectPoints = uint32_t(1) << 16;
// The sample of parallelSelect (evenly spaced items) and its brackets'
// distance from the median in sample ranks: the middle bucket holds about
// 2 x 48 / 4096 of the range (~2.3 %); a median outside it (a sample far
// from the range's distribution) falls back to std::nth_element.
constexpr size_t kSelectSample = 4096;
constexpr size_t kSelectBracket = 48;
constexpr size_t kQueryChunk = 1024;
constexpr size_t kPrefetch = 16;

// Nodes of a subtree over n points (a leaf up to kLeafPoints, else the
// node and its halves' subtrees, the left holding n / 2): at each depth the
// sizes are k or k + 1, so the distinct sizes are few (~2 log2 n).
class NodeCounts {
public:
    explicit NodeCounts(uint32_t n) {
        std::vector<uint32_t> sizes{n};
        for (size_t i = 0; i < sizes.size(); ++i) {
            const uint32_t s = sizes[i];
            if (s <= kLeafPoints) continue;
            for (const uint32_t half : {s / 2, s - s / 2})
                if (std::find(sizes.begin(), sizes.end(), half) == sizes.end()) sizes.push_back(half);
        }
        std::sort(sizes.begin(), sizes.end());
        for (const uint32_t s : sizes) {
            const uint64_t c = s <= kLeafPoints ? 1 : 1 + of(s / 2) + of(s - s / 2);
            m_table.emplace_back(s, c);
        }
    }
    [[nodiscard]] uint64_t of(uint32_t n) const {
        const auto it = std::lower_bound(m_table.begin(), m_table.end(), std::make_pair(n, uint64_t(0)));
        if (it == m_table.end() || it->first != n) throw std::logic_error("a subtree size not counted");
        return it->second;
    }

private:
    std::vector<std::pair<uint32_t, uint64_t>> m_table;  // (size, nodes), ascending
};

double boxDistance2(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
    // Each gap rounds monotonically, as do its square and the sum, so this
    // never exceeds the computed squared distance to a point of the box.
    const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return d.x * d.x + d.y * d.y + d.z * d.z;
}

}  // namespace

ExactPointTree::ExactPointTree(const PointView& points, int threads) {
    const size_t n = points.count;
    if (n == 0 || n > UINT32_MAX) throw std::invalid_argument("ExactPointTree: 1 to 2^32 - 1 points");
    m_items.resize(n);
    core::parallelChunks(n, core::balancedChunk(n, threads), threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) m_items[i] = Item{points.at(i), uint32_t(i)};
    });
    const NodeCounts counts{uint32_t(n)};
    m_nodes.resize(counts.of(uint32_t(n)));
    const int workers = core::resolveThreads(threads, n / kParallelPoints + 1);
    // Node `at` over [first, first + count): its exact box, then (inner) the
    // median of its longest axis between its halves; returns the halves
    // (count 0: a leaf). `wide`: the box and the median on every worker
    // (parallelSelect), for the few large ranges of the top levels.
    struct Range {
        uint32_t at, first, count;
    };
    core::UninitVector<Item> scratch;  // parallelSelect's buckets, allocated at its first use
    const auto boxOf = [&](const Item* items, uint32_t count, bool wide, glm::dvec3& lo, glm::dvec3& hi) {
        lo = hi = items[0].p;
        if (!wide) {
            for (uint32_t i = 1; i < count; ++i) {
                lo = glm::min(lo, items[i].p);
                hi = glm::max(hi, items[i].p);
            }
            return;
        }
        const size_t chunk = (count + 63) / 64;
        std::array<glm::dvec3, 64> los, his;
        los.fill(lo);
        his.fill(hi);
        core::parallelChunks(count, chunk, workers, [&](size_t begin, size_t end, int) {
            glm::dvec3 l = items[begin].p, h = l;
            for (size_t i = begin + 1; i < end; ++i) {
                l = glm::min(l, items[i].p);
                h = glm::max(h, items[i].p);
            }
            los[begin / chunk] = l;
            his[begin / chunk] = h;
        });
        for (size_t c = 0; c < 64; ++c) {
            lo = glm::min(lo, los[c]);
            hi = glm::max(hi, his[c]);
        }
    };
    // items[half] becomes the item of rank `half` by p[axis], none before it
    // larger and none after it smaller (std::nth_element's contract), on
    // every worker: the items below a sample's lower bracket, between the
    // brackets and above the upper one scattered apart in parallel (each
    // chunk's items in order), then nth_element within the middle only.
    const auto parallelSelect = [&](Item* items, uint32_t count, uint32_t half, int axis) {
        const auto less = [axis](const Item& x, const Item& y) { return x.p[axis] < y.p[axis]; };
        std::vector<double> sample(kSelectSample);
        for (size_t k = 0; k < kSelectSample; ++k)
            sample[k] = items[size_t(count) * k / kSelectSample].p[axis];
        std::sort(sample.begin(), sample.end());
        const size_t mid = size_t(uint64_t(kSelectSample) * half / count);
        const double low = sample[mid > kSelectBracket ? mid - kSelectBracket : 0];
        const double high = sample[std::min(kSelectSample - 1, mid + kSelectBracket)];
        constexpr size_t kChunks = 256;
        const size_t chunk = (count + kChunks - 1) / kChunks;
        std::vector<std::array<uint32_t, 3>> bucket(kChunks, {0u, 0u, 0u});  // below, between, above
        const auto which = [&](const Item& it) { return it.p[axis] < low ? 0 : (it.p[axis] > high ? 2 : 1); };
        core::parallelChunks(count, chunk, workers, [&](size_t begin, size_t end, int) {
            std::array<uint32_t, 3>& c = bucket[begin / chunk];
            for (size_t i = begin; i < end; ++i) ++c[size_t(which(items[i]))];
        });
        uint64_t total[3] = {0, 0, 0};
        for (const auto& c : bucket)
            for (int b = 0; b < 3; ++b) total[b] += c[size_t(b)];
        if (!(total[0] <= half && half < total[0] + total[1])) {
            std::nth_element(items, items + half, items + count, less);
            return;
        }
        if (scratch.empty()) scratch.resize(n);
        Item* const to = scratch.data() + (items - m_items.data());
        std::vector<std::array<uint64_t, 3>> at(kChunks);
        uint64_t next[3] = {0, total[0], total[0] + total[1]};
        for (size_t c = 0; c < kChunks; ++c)
            for (int b = 0; b < 3; ++b) {
                at[c][size_t(b)] = next[b];
                next[b] += bucket[c][size_t(b)];
            }
        core::parallelChunks(count, chunk, workers, [&](size_t begin, size_t end, int) {
            std::array<uint64_t, 3> put = at[begin / chunk];
            for (size_t i = begin; i < end; ++i) to[put[size_t(which(items[i]))]++] = items[i];
        });
        std::nth_element(to + total[0], to + half, to + total[0] + total[1], less);
        core::parallelChunks(count, chunk, workers, [&](size_t begin, size_t end, int) {
            std::copy(to + begin, to + end, items + begin);
        });
    };
    const auto split = [&](const Range& r, bool wide) -> std::array<Range, 2> {
        Item* const items = m_items.data() + r.first;
        glm::dvec3 lo, hi;
        boxOf(items, r.count, wide, lo, hi);
        Node& node = m_nodes[r.at];
        node.lo = lo;
        node.hi = hi;
        node.first = r.first;
        node.count = r.count;
        node.right = 0;
        node.split = 0.0;
        node.axis = 0;
        if (lo == hi) {
            // Copies of one point: every query meets them at one distance, so
            // only the smallest index can answer; the leaf keeps it alone (the
            // subtree's other node slots stay unused). Without this a query
            // beside a million copies would visit each one.
            Item* smallest = std::min_element(items, items + r.count,
                                              [](const Item& x, const Item& y) { return x.index < y.index; });
            std::swap(*smallest, items[0]);
            node.count = 1;
            return {};
        }
        if (r.count <= kLeafPoints) return {};
        const glm::dvec3 e = hi - lo;
        const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        const uint32_t half = r.count / 2;
        if (wide)
            parallelSelect(items, r.count, half, axis);
        else
            std::nth_element(items, items + half, items + r.count,
                             [axis](const Item& x, const Item& y) { return x.p[axis] < y.p[axis]; });
        node.split = items[half].p[axis];
        node.axis = uint32_t(axis);
        node.right = uint32_t(r.at + 1 + counts.of(half));
        return {Range{r.at + 1, r.first, half}, Range{node.right, r.first + half, r.count - half}};
    };
    const auto subtree = [&](const auto& self, const Range& r) -> void {
        for (const Range& c : split(r, false))
            if (c.count > 0) self(self, c);
    };
    // The top levels one level at a time: while a level has fewer ranges
    // than workers, each large range on every worker in turn; then a
    // level's ranges in parallel, one a task; then the subtrees below as
    // parallel tasks, each depth first on one thread.
    std::vector<Range> level{Range{0, 0, uint32_t(n)}};
    while (!level.empty() && level.size() < 4 * size_t(workers) && level.front().count >= kParallelPoints) {
        std::vector<std::array<Range, 2>> halves(level.size());
        if (workers > 1 && level.size() < size_t(workers) && level.front().count >= kParallelSelectPoints) {
            for (size_t i = 0; i < level.size(); ++i) halves[i] = split(level[i], true);
        } else {
            core::parallelChunks(level.size(), 1, workers, [&](size_t begin, size_t end, int) {
                for (size_t i = begin; i < end; ++i) halves[i] = split(level[i], false);
            });
        }
        std::vector<Range> next;
        for (const auto& h : halves)
            for (const Range& c : h)
                if (c.count > 0) next.push_back(c);
        level = std::move(next);
    }
    core::parallelChunks(level.size(), 1, workers, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) subtree(subtree, level[i]);
    });
    m_position.resize(n);
    core::parallelChunks(n, core::balancedChunk(n, threads), threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) m_position[m_items[i].index] = uint32_t(i);
    });
}

namespace {

// A target at the best distance may have a larger squared distance whose
// square root rounds to the same value: the bound keeps a margin of 2^-48
// relative above the best's square (sqrt rounds within 2^-52).
double boundOf(double distance) { return distance * distance * (1.0 + 0x1p-48); }

}  // namespace

void ExactPointTree::descend(const glm::dvec3& p, uint32_t root, Nearest& best, double& bound2) const {
    struct Entry {
        uint32_t node;
        double distance2;
    };
    std::array<Entry, 72> stack;  // depth <= 33: at most one waiting entry per level
    size_t top = 0;
    stack[top++] = {root, boxDistance2(p, m_nodes[root].lo, m_nodes[root].hi)};
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.distance2 > bound2) continue;
        const Node& node = m_nodes[e.node];
        if (node.right == 0) {
            for (uint32_t i = node.first; i < node.first + node.count; ++i) {
                const glm::dvec3 d = p - m_items[i].p;  // as core::exactDistance
                const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
                if (d2 > bound2) continue;
                const double dist = std::sqrt(d2);
                const uint32_t index = m_items[i].index;
                if (dist < best.distance || (dist == best.distance && index < best.index)) {
                    best = {index, dist};
                    bound2 = boundOf(dist);
                }
            }
            continue;
        }
        const uint32_t l = e.node + 1, r = node.right;
        const double dl = boxDistance2(p, m_nodes[l].lo, m_nodes[l].hi);
        const double dr = boxDistance2(p, m_nodes[r].lo, m_nodes[r].hi);
        // The nearer child on top, visited first.
        const bool leftFirst = dl <= dr;
        const Entry nearE{leftFirst ? l : r, leftFirst ? dl : dr};
        const Entry farE{leftFirst ? r : l, leftFirst ? dr : dl};
        if (farE.distance2 <= bound2) stack[top++] = farE;
        if (nearE.distance2 <= bound2) stack[top++] = nearE;
    }
}

ExactPointTree::Nearest ExactPointTree::nearest(const glm::dvec3& p, uint32_t start,
                                                double startDistance) const {
    Nearest best{start, startDistance};
    double bound2 = boundOf(best.distance);
    // The path to the start's leaf: each step's other child, and the cell
    // (the split planes so far) of the child taken.
    const uint32_t at = m_position[start];
    struct Step {
        uint32_t other;
        glm::dvec3 lo, hi;  // the cell of the child on the path
    };
    std::array<Step, 40> path;  // depth <= 33
    size_t depth = 0;
    uint32_t node = 0;
    glm::dvec3 lo(-std::numeric_limits<double>::infinity()), hi(std::numeric_limits<double>::infinity());
    while (m_nodes[node].right != 0) {
        const Node& n = m_nodes[node];
        const bool goRight = at >= m_nodes[n.right].first;
        if (goRight)
            lo[int(n.axis)] = std::max(lo[int(n.axis)], n.split);
        else
            hi[int(n.axis)] = std::min(hi[int(n.axis)], n.split);
        path[depth++] = {goRight ? node + 1 : n.right, lo, hi};
        node = goRight ? n.right : node + 1;
    }
    descend(p, node, best, bound2);
    // Climbing: a point outside the path's subtree at this depth lies on or
    // past a face of its cell; a face whose rounded gap from p squares above
    // the bound puts every such point's rounded distance above it too (the
    // gap, its square and the sum round monotonically), so once every face
    // does, nothing above can answer.
    while (depth > 0) {
        const Step& s = path[--depth];
        bool inside = true;
        for (int a = 0; a < 3 && inside; ++a) {
            const double below = p[a] - s.lo[a], above = s.hi[a] - p[a];
            inside = below > 0.0 && above > 0.0 && below * below > bound2 && above * above > bound2;
        }
        if (inside) break;
        descend(p, s.other, best, bound2);
    }
    return best;
}

size_t ExactPointTree::hostBytes() const {
    return m_nodes.capacity() * sizeof(Node) + m_items.capacity() * sizeof(Item) +
           m_position.capacity() * sizeof(uint32_t);
}

namespace {

// Whether most consecutive queries start within 64 tree positions of each
// other (4,096 evenly spaced pairs looked at).
bool inSpaceOrder(const std::vector<uint32_t>& starts, const ExactPointTree& tree) {
    const size_t n = starts.size();
    if (n < 2) return true;
    const size_t samples = std::min<size_t>(4096, n - 1), step = (n - 1) / samples;
    size_t near = 0;
    for (size_t s = 0; s < samples; ++s) {
        const size_t i = 1 + s * step;
        const int64_t d = int64_t(tree.positionOf(starts[i])) - int64_t(tree.positionOf(starts[i - 1]));
        if (d > -64 && d < 64) ++near;
    }
    return 2 * near >= samples;
}

}  // namespace

uint64_t makePerPointExact(PerPoint& perPoint, const PointView& q, const PointView& t, int threads) {
    if (perPoint.nearest.empty() || t.count == 0) return 0;
    if (perPoint.nearest.size() != q.count)
        throw std::logic_error("makePerPointExact: one nearest index per query");
    const ExactPointTree tree(t, threads);
    const bool distances = !perPoint.distance.empty();
    // Queries whose starts follow each other in the tree (inputs in space
    // order: scans) go in input order, which reads the queries and writes
    // their entries in sequence; others by their starts' tree positions, 8
    // to a key (cpu/key_sort.hpp's radix sort of (key << 32 | query)),
    // which reads the tree in sequence instead (2 cores: the Dragon's
    // scan-ordered queries 47 -> 40 ms in input order, 1M shuffled shell
    // points 226 -> 462 ms in it).
    const size_t nq = q.count;
    std::vector<uint64_t> order;  // empty: input order
    if (!inSpaceOrder(perPoint.nearest, tree)) {
        order.resize(nq);
        core::parallelChunks(nq, core::balancedChunk(nq, threads), threads,
                             [&](size_t begin, size_t end, int) {
                                 for (size_t i = begin; i < end; ++i)
                                     order[i] = uint64_t(tree.positionOf(perPoint.nearest[i]) / 8) << 32 | i;
                             });
        radixSortKeys(order, std::bit_width(t.count / 8), threads);
    }
    std::atomic<uint64_t> changed{0};
    const auto* queryBytes = static_cast<const char*>(q.data);
    core::parallelChunks(nq, kQueryChunk, threads, [&](size_t begin, size_t end, int) {
        uint64_t mine = 0;
        for (size_t k = begin; k < end; ++k) {
            // In the starts' order the queries' coordinates and entries are
            // read at random: each asked for kPrefetch queries ahead.
            if (!order.empty() && k + kPrefetch < end) {
                const size_t j = order[k + kPrefetch] & 0xffffffffu;
                __builtin_prefetch(queryBytes + j * q.strideBytes);
                __builtin_prefetch(&perPoint.nearest[j], 1);
                if (distances) __builtin_prefetch(&perPoint.distance[j], 1);
            }
            const auto i = uint32_t(order.empty() ? k : order[k] & 0xffffffffu);
            const glm::dvec3 p = q.at(i);
            const uint32_t start = perPoint.nearest[i];
            const ExactPointTree::Nearest n =
                tree.nearest(p, start, core::exactDistance(p, tree.pointAt(start)));
            if (n.index != start) {
                perPoint.nearest[i] = n.index;
                ++mine;
            }
            if (distances) perPoint.distance[i] = n.distance;
        }
        changed.fetch_add(mine, std::memory_order_relaxed);
    });
    return changed.load();
}

}  // namespace rthdist::cpu
