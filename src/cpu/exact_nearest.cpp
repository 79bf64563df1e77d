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
// nodes on the worker pool; smaller ones are whole subtrees of one thread.
constexpr uint32_t kParallelPoints = uint32_t(1) << 16;
constexpr size_t kQueryChunk = 1024;

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
    // Node `at` over [first, first + count): its exact box, then (inner) the
    // median of its longest axis between its halves; returns the halves
    // (count 0: a leaf).
    struct Range {
        uint32_t at, first, count;
    };
    const auto split = [&](const Range& r) -> std::array<Range, 2> {
        Item* const items = m_items.data() + r.first;
        glm::dvec3 lo = items[0].p, hi = lo;
        for (uint32_t i = 1; i < r.count; ++i) {
            lo = glm::min(lo, items[i].p);
            hi = glm::max(hi, items[i].p);
        }
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
        std::nth_element(items, items + half, items + r.count,
                         [axis](const Item& x, const Item& y) { return x.p[axis] < y.p[axis]; });
        node.split = items[half].p[axis];
        node.axis = uint32_t(axis);
        node.right = uint32_t(r.at + 1 + counts.of(half));
        return {Range{r.at + 1, r.first, half}, Range{node.right, r.first + half, r.count - half}};
    };
    const auto subtree = [&](const auto& self, const Range& r) -> void {
        for (const Range& c : split(r))
            if (c.count > 0) self(self, c);
    };
    // The top levels one level at a time, a level's nodes in parallel (the
    // root's selection alone on one thread); then the subtrees below as
    // parallel tasks, each depth first on one thread.
    const int workers = core::resolveThreads(threads, n / kParallelPoints + 1);
    std::vector<Range> level{Range{0, 0, uint32_t(n)}};
    while (!level.empty() && level.size() < 4 * size_t(workers) && level.front().count >= kParallelPoints) {
        std::vector<std::array<Range, 2>> halves(level.size());
        core::parallelChunks(level.size(), 1, workers, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) halves[i] = split(level[i]);
        });
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
    core::parallelChunks(nq, kQueryChunk, threads, [&](size_t begin, size_t end, int) {
        uint64_t mine = 0;
        for (size_t k = begin; k < end; ++k) {
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
