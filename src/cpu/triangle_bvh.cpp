#include "cpu/triangle_bvh.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "core/parallel.hpp"
#include "core/point_triangle.hpp"

namespace rthdist::cpu {
namespace {

double boxDistance2(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

// The squared distance a box must exceed to be skipped: (best + slack)^2,
// infinite while nothing was measured.
double pruneBound2(double best2, double slack) {
    if (!std::isfinite(best2)) return std::numeric_limits<double>::infinity();
    const double bound = std::sqrt(best2) + slack;
    return bound * bound;
}

// What the build partitions: a triangle's box centre beside its index, so
// that the splits read memory in order.
// The centre in float (16 bytes an item: half the memory the splits move
// with a double centre; any order of the items gives a correct tree, and
// rounding only makes more ties, which the index breaks).
struct BuildItem {
    glm::vec3 centre;
    uint32_t triangle;
};
static_assert(sizeof(BuildItem) == 16);

// Subtrees of at most this many triangles are built whole by one task.
constexpr uint32_t kSubtreeTriangles = 4096;
// The top levels are split until there are this many subtrees per thread.
constexpr size_t kSubtreesPerThread = 8;

// The leaves of the median-split tree over `count` triangles. The nodes of
// one depth hold floor or ceil of count / 2^depth triangles: a level is two
// sizes (small and small + 1) and how many nodes have each.
uint64_t medianSplitLeaves(uint64_t count) {
    uint64_t small = count, nSmall = 1, nLarge = 0, leaves = 0;
    while (true) {
        if (small + 1 <= kLeafTriangles) return leaves + nSmall + nLarge;
        if (small <= kLeafTriangles) {  // small leaves beside large nodes split once more
            leaves += nSmall;
            nSmall = 0;
        }
        // small even: small -> 2 x small/2, small + 1 -> small/2 and small/2 + 1;
        // small odd: small -> small/2 and small/2 + 1, small + 1 -> 2 x (small/2 + 1).
        const bool even = small % 2 == 0;
        const uint64_t nextSmall = even ? 2 * nSmall + nLarge : nSmall;
        const uint64_t nextLarge = even ? nLarge : nSmall + 2 * nLarge;
        small /= 2;
        nSmall = nextSmall;
        nLarge = nextLarge;
    }
}

// The nodes below the root of a median-split subtree over `count` triangles.
uint32_t descendantCount(uint32_t count) { return uint32_t(2 * medianSplitLeaves(count) - 2); }

// The split order along one axis (a constant, so the comparison compiles
// to plain loads): centre, then triangle index.
template <int Axis>
struct CentreBefore {
    bool operator()(const BuildItem& x, const BuildItem& y) const {
        const float a = x.centre[Axis], b = y.centre[Axis];
        return a < b || (a == b && x.triangle < y.triangle);
    }
};

// Reorders items[0, count) so that the first `half` are the smaller by
// CentreBefore<Axis>. A large range is first cut by a histogram of its
// centres over [lo, hi] (about 16 items a bin, at most kMaxBins; a bin is a non-decreasing
// function of the centre, so every item of a lower bin is smaller than every
// item of a higher one): the items below the bin that holds position `half`
// go first, that bin's next, and only that bin is ordered by nth_element.
// Two passes and a small selection instead of introselect's passes over the
// whole range (perf: nth_element was 41 % of a 871k-triangle build).
template <int Axis>
void selectHalf(BuildItem* items, uint32_t count, uint32_t half, float lo, float hi) {
    constexpr uint32_t kSmallRange = 128;
    constexpr uint32_t kMaxBins = 256;
    const float width = hi - lo;
    if (count <= kSmallRange || !(width > 0.0f) || !std::isfinite(width)) {
        std::nth_element(items, items + half, items + count, CentreBefore<Axis>{});
        return;
    }
    // About 16 items a bin, at most kMaxBins.
    const uint32_t bins = std::min(kMaxBins, count / 16);
    const float toBin = float(bins) / width;
    const auto binOf = [&](const BuildItem& item) {
        const float b = (item.centre[Axis] - lo) * toBin;
        return b < float(bins - 1) ? uint32_t(b) : bins - 1;  // b >= 0: lo is the minimum
    };
    std::array<uint32_t, kMaxBins> histogram{};
    for (uint32_t i = 0; i < count; ++i) ++histogram[binOf(items[i])];
    uint32_t median = 0, below = 0;
    while (below + histogram[median] <= half) below += histogram[median++];
    BuildItem* const end = items + count;
    BuildItem* const from = std::partition(items, end, [&](const BuildItem& x) { return binOf(x) < median; });
    BuildItem* const to = std::partition(from, end, [&](const BuildItem& x) { return binOf(x) == median; });
    std::nth_element(from, items + half, to, CentreBefore<Axis>{});
}

// Reorders items[0, count) so that the first count / 2 are the smaller by
// (centre along the longest axis of the centres' spread, triangle index),
// and returns count / 2. The order is strict and total, so the halves
// depend only on the set of items, never on their order or on the thread.
uint32_t splitAtMedian(BuildItem* items, uint32_t count) {
    glm::vec3 cLo(std::numeric_limits<float>::infinity()), cHi(-cLo);
    for (uint32_t i = 0; i < count; ++i) {
        cLo = glm::min(cLo, items[i].centre);
        cHi = glm::max(cHi, items[i].centre);
    }
    const glm::dvec3 spread = glm::dvec3(cHi) - glm::dvec3(cLo);
    const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
    const uint32_t half = count / 2;
    switch (axis) {
        case 0: selectHalf<0>(items, count, half, cLo.x, cHi.x); break;
        case 1: selectHalf<1>(items, count, half, cLo.y, cHi.y); break;
        default: selectHalf<2>(items, count, half, cLo.z, cHi.z); break;
    }
    return half;
}

// One node still to build: node `at` over items [first, first + count),
// its descendants at [base, base + descendantCount(count)).
struct PendingNode {
    uint32_t at = 0;
    uint32_t first = 0;
    uint32_t count = 0;
    uint32_t base = 0;
};

}  // namespace

TriangleBvh::TriangleBvh(const MeshView& mesh, int threads) {
    const auto n = uint32_t(mesh.triangleCount());
    threads = core::resolveThreads(threads, n / kSubtreeTriangles);
    core::UninitVector<BuildItem> items(n);  // every item written below
    core::parallelChunks(n, kSubtreeTriangles, threads, [&](size_t begin, size_t end, int) {
        for (size_t t = begin; t < end; ++t) {
            const glm::dvec3 c0 = mesh.corner(t, 0), c1 = mesh.corner(t, 1), c2 = mesh.corner(t, 2);
            items[t] = {glm::vec3((glm::min(glm::min(c0, c1), c2) + glm::max(glm::max(c0, c1), c2)) * 0.5),
                        uint32_t(t)};
        }
    });
    m_nodes.resize(1 + size_t(descendantCount(n)));
    m_corners.resize(3 * size_t(n));
    m_original.resize(n);

    // A leaf's triangles in BVH order, their corners, and its box.
    const auto makeLeaf = [&](const PendingNode& p) {
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
        for (uint32_t i = p.first; i < p.first + p.count; ++i) {
            const uint32_t t = items[i].triangle;
            m_original[i] = t;
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 c = mesh.corner(t, k);
                m_corners[3 * size_t(i) + size_t(k)] = c;
                lo = glm::min(lo, c);
                hi = glm::max(hi, c);
            }
        }
        m_nodes[p.at] = Node{lo, hi, p.first, p.count};
    };
    // Node p.at becomes inner over [first, first + half) and the rest; its
    // children are the first two of its descendants, then the left's
    // descendants, then the right's.
    const auto children = [&](const PendingNode& p, uint32_t half) {
        m_nodes[p.at].first = p.base;
        m_nodes[p.at].count = 0;
        return std::array<PendingNode, 2>{
            PendingNode{p.base, p.first, half, p.base + 2},
            PendingNode{p.base + 1, p.first + half, p.count - half, p.base + 2 + descendantCount(half)}};
    };
    const auto unionOfChildren = [&](uint32_t at) {
        Node& node = m_nodes[at];
        const Node& l = m_nodes[node.first];
        const Node& r = m_nodes[node.first + 1];
        node.lo = glm::min(l.lo, r.lo);
        node.hi = glm::max(l.hi, r.hi);
    };
    // A whole subtree on this thread, depth first.
    const auto buildSubtree = [&](const PendingNode& root) {
        const auto recurse = [&](const auto& self, const PendingNode& p) -> void {
            if (p.count <= kLeafTriangles) {
                makeLeaf(p);
                return;
            }
            const std::array<PendingNode, 2> c = children(p, splitAtMedian(&items[p.first], p.count));
            self(self, c[0]);
            self(self, c[1]);
            unionOfChildren(p.at);
        };
        recurse(recurse, root);
    };

    // The top levels one level at a time, the nodes of a level in parallel;
    // then the subtrees below them as parallel tasks; then the boxes of the
    // top levels from the bottom up.
    std::vector<PendingNode> level{PendingNode{0, 0, n, 1}};
    std::vector<uint32_t> topInner;  // parents before their children
    while (threads > 1 && level.size() < kSubtreesPerThread * size_t(threads) &&
           level.front().count > kSubtreeTriangles) {
        std::vector<uint32_t> half(level.size());
        core::parallelChunks(level.size(), 1, threads, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i)
                half[i] = splitAtMedian(&items[level[i].first], level[i].count);
        });
        std::vector<PendingNode> next;
        next.reserve(2 * level.size());
        for (size_t i = 0; i < level.size(); ++i) {
            topInner.push_back(level[i].at);
            for (const PendingNode& c : children(level[i], half[i])) next.push_back(c);
        }
        level = std::move(next);
    }
    core::parallelChunks(level.size(), 1, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) buildSubtree(level[i]);
    });
    for (auto it = topInner.rbegin(); it != topInner.rend(); ++it) unionOfChildren(*it);
}

NearestTriangle TriangleBvh::nearest(const glm::dvec3& p, double slack, double stopBelow2) const {
    NearestTriangle best;
    best.distance2 = std::numeric_limits<double>::infinity();
    double bound2 = best.distance2;
    // Balanced tree: depth <= log2(2^32) + 2, at most one entry per level waits.
    struct Entry {
        uint32_t node;
        double distance2;
    };
    std::array<Entry, 80> stack;
    size_t top = 0;
    stack[top++] = {0, boxDistance2(p, m_nodes[0].lo, m_nodes[0].hi)};
    ++best.nodesVisited;
    while (top > 0) {
        const Entry e = stack[--top];
        if (e.distance2 > bound2) continue;
        const Node& node = m_nodes[e.node];
        if (node.count > 0) {
            for (uint32_t i = node.first; i < node.first + node.count; ++i) {
                const glm::dvec3* c = &m_corners[3 * size_t(i)];
                const core::TriangleClosest r = core::closestOnTriangle(p, c[0], c[1], c[2]);
                ++best.trianglesTested;
                const uint32_t t = m_original[i];
                if (r.distance2 < best.distance2 || (r.distance2 == best.distance2 && t < best.triangle)) {
                    best.distance2 = r.distance2;
                    best.triangle = t;
                    best.point = r.point;
                    best.barycentric = r.barycentric;
                    bound2 = pruneBound2(best.distance2, slack);
                    if (best.distance2 < stopBelow2) {
                        best.dominated = true;
                        return best;
                    }
                }
            }
            continue;
        }
        const Node& l = m_nodes[node.first];
        const Node& r = m_nodes[node.first + 1];
        const double dl = boxDistance2(p, l.lo, l.hi);
        const double dr = boxDistance2(p, r.lo, r.hi);
        best.nodesVisited += 2;
        // Nearer child on top of the stack, visited first.
        const bool leftFirst = dl <= dr;
        const Entry nearE{leftFirst ? node.first : node.first + 1, leftFirst ? dl : dr};
        const Entry farE{leftFirst ? node.first + 1 : node.first, leftFirst ? dr : dl};
        if (farE.distance2 <= bound2) stack[top++] = farE;
        if (nearE.distance2 <= bound2) stack[top++] = nearE;
    }
    return best;
}

size_t TriangleBvh::hostBytes() const {
    return m_nodes.capacity() * sizeof(Node) + m_corners.capacity() * sizeof(glm::dvec3) +
           m_original.capacity() * sizeof(uint32_t);
}

}  // namespace rthdist::cpu
