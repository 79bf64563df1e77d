#include "cpu/exact_nearest.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/certificate.hpp"
#include "core/parallel.hpp"

namespace rthdist::cpu {
namespace {

constexpr uint32_t kLeafPoints = 8;
// Ranges at least this large split their children on two threads.
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
    // median of its longest axis between its halves, then the halves.
    const auto build = [&](const auto& self, uint32_t at, uint32_t first, uint32_t count) -> void {
        Item* const items = m_items.data() + first;
        glm::dvec3 lo = items[0].p, hi = lo;
        for (uint32_t i = 1; i < count; ++i) {
            lo = glm::min(lo, items[i].p);
            hi = glm::max(hi, items[i].p);
        }
        Node& node = m_nodes[at];
        node.lo = lo;
        node.hi = hi;
        node.first = first;
        node.count = count;
        node.right = 0;
        if (count <= kLeafPoints) return;
        const glm::dvec3 e = hi - lo;
        const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
        const uint32_t half = count / 2;
        std::nth_element(items, items + half, items + count,
                         [axis](const Item& x, const Item& y) { return x.p[axis] < y.p[axis]; });
        const uint32_t left = at + 1;
        const auto right = uint32_t(at + 1 + counts.of(half));
        node.right = right;
        if (count >= kParallelPoints && threads != 1) {
            core::parallelChunks(2, 1, 2, [&](size_t begin, size_t end, int) {
                for (size_t c = begin; c < end; ++c) {
                    if (c == 0)
                        self(self, left, first, half);
                    else
                        self(self, right, first + half, count - half);
                }
            });
        } else {
            self(self, left, first, half);
            self(self, right, first + half, count - half);
        }
    };
    build(build, 0, 0, uint32_t(n));
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
    // The path to the start's leaf, each step's other child kept.
    const uint32_t at = m_position[start];
    std::array<uint32_t, 40> others;  // depth <= 33
    size_t depth = 0;
    uint32_t node = 0;
    while (m_nodes[node].right != 0) {
        const uint32_t right = m_nodes[node].right;
        const bool goRight = at >= m_nodes[right].first;
        others[depth++] = goRight ? node + 1 : right;
        node = goRight ? right : node + 1;
    }
    descend(p, node, best, bound2);
    while (depth > 0) descend(p, others[--depth], best, bound2);
    return best;
}

size_t ExactPointTree::hostBytes() const {
    return m_nodes.capacity() * sizeof(Node) + m_items.capacity() * sizeof(Item) +
           m_position.capacity() * sizeof(uint32_t);
}

uint64_t makePerPointExact(PerPoint& perPoint, const PointView& q, const PointView& t, int threads) {
    if (perPoint.nearest.empty() || t.count == 0) return 0;
    if (perPoint.nearest.size() != q.count)
        throw std::logic_error("makePerPointExact: one nearest index per query");
    const ExactPointTree tree(t, threads);
    const bool distances = !perPoint.distance.empty();
    std::atomic<uint64_t> changed{0};
    core::parallelChunks(q.count, kQueryChunk, threads, [&](size_t begin, size_t end, int) {
        uint64_t mine = 0;
        for (size_t i = begin; i < end; ++i) {
            const glm::dvec3 p = q.at(i);
            const uint32_t start = perPoint.nearest[i];
            const ExactPointTree::Nearest n = tree.nearest(p, start, core::exactDistance(p, t.at(start)));
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
