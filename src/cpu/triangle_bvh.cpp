#include "cpu/triangle_bvh.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "core/float_box.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"

namespace rthdist::cpu {
namespace {

// A node's float box, read in double.
double boxDistance2(const glm::dvec3& p, const glm::vec3& lo, const glm::vec3& hi) {
    return core::boxDistance2(p, glm::dvec3(lo), glm::dvec3(hi));
}

// The nearest float at or below v (FLT_MAX for v past it) and at or above.
float floatAtOrBelow(double v) {
    const float f = float(v);
    return double(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float floatAtOrAbove(double v) {
    const float f = float(v);
    return double(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
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

// The box of build items' centres (min and max are exact: the same box
// whatever the order the items are added in).
core::FloatBox boundsOf(const BuildItem* items, uint32_t count) {
    core::FloatBox b;
    for (uint32_t i = 0; i < count; ++i) b.add(items[i].centre);
    return b;
}

// A node's split: the first `half` items (by CentreBefore along the axis)
// go left, the rest right; the halves' centre boxes; `moved`: the halves
// were written to the other buffer (else reordered in place).
struct Split {
    uint32_t half = 0;
    core::FloatBox left, right;
    bool moved = false;
};

// Items a split takes on several threads (from this many), in chunks of
// kSplitChunk: fixed chunks, so the items land where one thread puts them.
// (From 2^16 in chunks of 2^14 before session 11: the levels below the root
// of a 50-200k-triangle mesh, a few nodes of 2^14-2^16 items, then ran one
// thread a node; H200, 16 cores, one-shot builds: the bunny 3.0-3.6 ->
// 2.3-2.6 ms, the dragon's res2 7.2-7.6 -> 6.2-6.4, level on 2 cores.)
constexpr uint32_t kParallelSplit = uint32_t(1) << 14;
constexpr uint32_t kSplitChunk = uint32_t(1) << 12;
constexpr uint32_t kMaxBins = 256;
using Histogram = std::array<uint32_t, kMaxBins>;

// Splits src[0, count) at count / 2 along Axis. A large range is cut by a
// histogram of its centres over the node's [lo, hi] along the axis (about
// 16 items a bin, at most kMaxBins; a bin is a non-decreasing function of
// the centre, so every item of a lower bin is smaller than every item of a
// higher one): one pass writes the items below the median's bin, the bin's,
// and those above into dst (three cursors, no branch on the item), adding
// each to its half's box, and only the median's bin is ordered by
// nth_element. Two passes a level, each read once (perf: the selection was
// most of the build). A small or flat range is selected in place. From
// kParallelSplit items and with threads > 1 both passes run on the worker
// pool in fixed chunks: each chunk's histogram, then each chunk's first
// place in each part from them, so every item lands where one thread's
// stable pass puts it and the tree is the same on any thread count.
template <int Axis>
Split splitAlong(BuildItem* src, BuildItem* dst, uint32_t count, const core::FloatBox& bounds, int threads) {
    constexpr uint32_t kSmallRange = 128;
    Split s;
    s.half = count / 2;
    const float lo = bounds.lo[Axis];
    const float width = bounds.hi[Axis] - lo;
    if (count <= kSmallRange || !(width > 0.0f) || !std::isfinite(width)) {
        std::nth_element(src, src + s.half, src + count, CentreBefore<Axis>{});
        s.left = boundsOf(src, s.half);
        s.right = boundsOf(src + s.half, count - s.half);
        return s;
    }
    const uint32_t bins = std::min(kMaxBins, count / 16);
    const float toBin = float(bins) / width;
    const auto binOf = [&](const BuildItem& item) {
        const float b = (item.centre[Axis] - lo) * toBin;
        return b < float(bins - 1) ? uint32_t(b) : bins - 1;  // b >= 0: lo is the minimum
    };
    const auto countBins = [&](Histogram& h, size_t begin, size_t end) {
        for (size_t i = begin; i < end; ++i) ++h[binOf(src[i])];
    };
    uint32_t median = 0, below = 0;
    const auto findMedian = [&](const Histogram& histogram) {
        while (below + histogram[median] <= s.half) below += histogram[median++];
    };
    // One pass writes each item to its part through three cursors (no branch
    // on the item) and grows its half's centre box.
    const auto scatter = [&](std::array<uint32_t, 3> at, std::array<core::FloatBox, 3>& side, size_t begin,
                             size_t end) {
        for (size_t i = begin; i < end; ++i) {
            const BuildItem item = src[i];
            const uint32_t bin = binOf(item);
            const uint32_t k = uint32_t(bin >= median) + uint32_t(bin > median);
            dst[at[k]++] = item;
            side[k].add(item.centre);
        }
    };
    uint32_t inMedian = 0;
    if (threads <= 1 || count < kParallelSplit) {
        Histogram histogram{};
        countBins(histogram, 0, count);
        findMedian(histogram);
        inMedian = histogram[median];
        std::array<core::FloatBox, 3> side;  // below, the median's bin (unused), above
        scatter({0, below, below + inMedian}, side, 0, count);
        s.left = side[0];
        s.right = side[2];
    } else {
        const uint32_t chunks = (count + kSplitChunk - 1) / kSplitChunk;
        std::vector<Histogram> local(chunks);
        core::parallelChunks(count, kSplitChunk, threads, [&](size_t begin, size_t end, int) {
            Histogram& h = local[begin / kSplitChunk];
            h.fill(0);
            countBins(h, begin, end);
        });
        Histogram histogram{};
        for (const Histogram& h : local)
            for (uint32_t b = 0; b < bins; ++b) histogram[b] += h[b];
        findMedian(histogram);
        inMedian = histogram[median];
        // Each chunk's first place in each part: below, the median's bin, above.
        std::vector<std::array<uint32_t, 3>> first(chunks);
        std::array<uint32_t, 3> cursor{0, below, below + inMedian};
        for (uint32_t c = 0; c < chunks; ++c) {
            first[c] = cursor;
            uint32_t under = 0;
            for (uint32_t b = 0; b < median; ++b) under += local[c][b];
            const uint32_t size = std::min(kSplitChunk, count - c * kSplitChunk);
            cursor[0] += under;
            cursor[1] += local[c][median];
            cursor[2] += size - under - local[c][median];
        }
        std::vector<std::array<core::FloatBox, 3>> sides(chunks);
        core::parallelChunks(count, kSplitChunk, threads, [&](size_t begin, size_t end, int) {
            scatter(first[begin / kSplitChunk], sides[begin / kSplitChunk], begin, end);
        });
        for (const std::array<core::FloatBox, 3>& side : sides) {
            s.left.add(side[0]);
            s.right.add(side[2]);
        }
    }
    std::nth_element(dst + below, dst + s.half, dst + below + inMedian, CentreBefore<Axis>{});
    s.left.add(boundsOf(dst + below, s.half - below));
    s.right.add(boundsOf(dst + s.half, below + inMedian - s.half));
    s.moved = true;
    return s;
}

// Splits at count / 2 along the longest axis of the centres' spread. The
// order is strict and total, so the halves depend only on the set of items,
// never on their order or on the thread.
Split splitAtMedian(BuildItem* src, BuildItem* dst, uint32_t count, const core::FloatBox& bounds,
                    int threads) {
    const glm::dvec3 spread = glm::dvec3(bounds.hi) - glm::dvec3(bounds.lo);
    const int axis = spread.x >= spread.y && spread.x >= spread.z ? 0 : (spread.y >= spread.z ? 1 : 2);
    switch (axis) {
        case 0: return splitAlong<0>(src, dst, count, bounds, threads);
        case 1: return splitAlong<1>(src, dst, count, bounds, threads);
        default: return splitAlong<2>(src, dst, count, bounds, threads);
    }
}

// One node still to build: node `at` over the items [first, first + count)
// of buffer `buffer`, whose centres lie in `bounds`; its descendants at
// [base, base + descendantCount(count)).
struct PendingNode {
    uint32_t at = 0;
    uint32_t first = 0;
    uint32_t count = 0;
    uint32_t base = 0;
    core::FloatBox bounds;
    uint32_t buffer = 0;
};

}  // namespace

// The build in three passes: the splits (which triangles each leaf holds),
// then every triangle's corners written once, in input order, to its place
// in BVH order (a scattered write instead of a random read through the
// index array), then the boxes from the leaves up.
TriangleBvh::TriangleBvh(const MeshView& mesh, int threads) {
    const auto n = uint32_t(mesh.triangleCount());
    threads = core::resolveThreads(threads, n / kSubtreeTriangles);
    m_nodes.resize(1 + size_t(descendantCount(n)));
    // Float corners for a float mesh (its coordinates, exactly: the rule
    // reads them as doubles), half the memory of double ones.
    m_floatCorners = mesh.vertices.scalar == Scalar::kFloat32;
    if (m_floatCorners)
        m_cornersF.resize(3 * size_t(n));
    else
        m_corners.resize(3 * size_t(n));
    m_original.resize(n);
    m_thin.resize(n);
    if (n == 0) {
        m_nodes[0] = Node{glm::vec3(std::numeric_limits<float>::infinity()),
                          glm::vec3(-std::numeric_limits<float>::infinity()), 0, 0};
        return;
    }
    // Two buffers of build items (a level's splits read one and write the
    // other) in the corners' memory, 32 of its 36 (float) or 72 (double)
    // bytes a triangle: the items are spent before the corners pass writes
    // there. Fresh memory is what a one-shot build pays most for on a VM
    // (~2.3 ms a MiB on first touch, docs/bench/surfaces session 10), and no
    // block of its own is faulted in.
    static_assert(2 * sizeof(BuildItem) <= 3 * sizeof(glm::vec3) && alignof(BuildItem) <= alignof(glm::vec3));
    BuildItem* const items = m_floatCorners ? reinterpret_cast<BuildItem*>(m_cornersF.data())
                                            : reinterpret_cast<BuildItem*>(m_corners.data());
    BuildItem* const buffers[2] = {items, items + n};
    const size_t chunks = (size_t(n) + kSubtreeTriangles - 1) / kSubtreeTriangles;
    std::vector<core::FloatBox> chunkBounds(chunks);
    core::parallelChunks(n, kSubtreeTriangles, threads, [&](size_t begin, size_t end, int) {
        core::FloatBox b;
        for (size_t t = begin; t < end; ++t) {
            const glm::dvec3 c0 = mesh.corner(t, 0), c1 = mesh.corner(t, 1), c2 = mesh.corner(t, 2);
            items[t] = {glm::vec3((glm::min(glm::min(c0, c1), c2) + glm::max(glm::max(c0, c1), c2)) * 0.5),
                        uint32_t(t)};
            b.add(items[t].centre);
        }
        chunkBounds[begin / kSubtreeTriangles] = b;
    });
    PendingNode root{0, 0, n, 1, {}, 0};
    for (const core::FloatBox& b : chunkBounds) root.bounds.add(b);

    core::UninitVector<uint32_t> placeOf(n);  // triangle -> its BVH position
    // A leaf: its triangles' BVH order (their corners and box come later).
    const auto makeLeaf = [&](const PendingNode& p) {
        const BuildItem* from = buffers[p.buffer];
        for (uint32_t i = p.first; i < p.first + p.count; ++i) {
            const uint32_t t = from[i].triangle;
            m_original[i] = t;
            placeOf[t] = i;
        }
        m_nodes[p.at].first = p.first;
        m_nodes[p.at].count = p.count;
    };
    // Node p becomes inner; its children are the first two of its
    // descendants, then the left's descendants, then the right's.
    const auto split = [&](const PendingNode& p, int splitThreads) {
        const Split s = splitAtMedian(buffers[p.buffer] + p.first, buffers[1 - p.buffer] + p.first, p.count,
                                      p.bounds, splitThreads);
        m_nodes[p.at].first = p.base;
        m_nodes[p.at].count = 0;
        const uint32_t buffer = s.moved ? 1 - p.buffer : p.buffer;
        return std::array<PendingNode, 2>{PendingNode{p.base, p.first, s.half, p.base + 2, s.left, buffer},
                                          PendingNode{p.base + 1, p.first + s.half, p.count - s.half,
                                                      p.base + 2 + descendantCount(s.half), s.right, buffer}};
    };
    // A whole subtree's splits on this thread, depth first.
    const auto splitSubtree = [&](const PendingNode& top) {
        const auto recurse = [&](const auto& self, const PendingNode& p) -> void {
            if (p.count <= kLeafTriangles) {
                makeLeaf(p);
                return;
            }
            for (const PendingNode& c : split(p, 1)) self(self, c);
        };
        recurse(recurse, top);
    };

    // The top levels one level at a time, the nodes of a level in parallel;
    // then the subtrees below them as parallel tasks.
    std::vector<PendingNode> level{root};
    std::vector<uint32_t> topInner;  // parents before their children
    while (threads > 1 && level.size() < kSubtreesPerThread * size_t(threads) &&
           level.front().count > kSubtreeTriangles) {
        // A level of fewer nodes than threads shares them out: each node's
        // split on threads / nodes of them (the root's on all).
        std::vector<std::array<PendingNode, 2>> halves(level.size());
        const int each = std::max(1, threads / int(level.size()));
        core::parallelChunks(level.size(), 1, threads, [&](size_t begin, size_t end, int) {
            for (size_t i = begin; i < end; ++i) halves[i] = split(level[i], each);
        });
        std::vector<PendingNode> next;
        next.reserve(2 * level.size());
        for (size_t i = 0; i < level.size(); ++i) {
            topInner.push_back(level[i].at);
            next.insert(next.end(), halves[i].begin(), halves[i].end());
        }
        level = std::move(next);
    }
    core::parallelChunks(level.size(), 1, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) splitSubtree(level[i]);
    });

    // The corners, each triangle's in input order to its BVH place, and
    // whether it is thin (core::thinTriangle).
    core::parallelChunks(n, kSubtreeTriangles, threads, [&](size_t begin, size_t end, int) {
        for (size_t t = begin; t < end; ++t) {
            const size_t at = 3 * size_t(placeOf[t]);
            const glm::dvec3 c[3] = {mesh.corner(t, 0), mesh.corner(t, 1), mesh.corner(t, 2)};
            for (int k = 0; k < 3; ++k) {
                if (m_floatCorners)
                    m_cornersF[at + size_t(k)] = glm::vec3(c[k]);  // exact: a float's value
                else
                    m_corners[at + size_t(k)] = c[k];
            }
            m_thin[placeOf[t]] = core::thinTriangle(c[0], c[1], c[2]) ? 1 : 0;
        }
    });

    // The boxes: a node's children come after it, so each subtree's nodes in
    // reverse order meet the children first; then the top levels.
    const auto boxOf = [&](uint32_t at) {
        Node& node = m_nodes[at];
        if (node.count > 0) {
            const size_t first = 3 * size_t(node.first);
            glm::dvec3 lo = cornerAt(first), hi = lo;
            for (uint32_t k = 1; k < 3 * node.count; ++k) {
                lo = glm::min(lo, cornerAt(first + k));
                hi = glm::max(hi, cornerAt(first + k));
            }
            node.lo = glm::vec3(floatAtOrBelow(lo.x), floatAtOrBelow(lo.y), floatAtOrBelow(lo.z));
            node.hi = glm::vec3(floatAtOrAbove(hi.x), floatAtOrAbove(hi.y), floatAtOrAbove(hi.z));
            return;
        }
        const Node& l = m_nodes[node.first];
        const Node& r = m_nodes[node.first + 1];
        node.lo = glm::min(l.lo, r.lo);
        node.hi = glm::max(l.hi, r.hi);
    };
    core::parallelChunks(level.size(), 1, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const PendingNode& p = level[i];
            for (uint32_t at = p.base + descendantCount(p.count); at-- > p.base;) boxOf(at);
            boxOf(p.at);
        }
    });
    for (auto it = topInner.rbegin(); it != topInner.rend(); ++it) boxOf(*it);
}

NearestTriangle TriangleBvh::nearest(const glm::dvec3& p, double slack, double stopBelow2,
                                     TriangleHint hint) const {
    return m_floatCorners ? nearestIn(m_cornersF.data(), p, slack, stopBelow2, hint)
                          : nearestIn(m_corners.data(), p, slack, stopBelow2, hint);
}

template <class Corner>
NearestTriangle TriangleBvh::nearestIn(const Corner* corners, const glm::dvec3& p, double slack,
                                       double stopBelow2, TriangleHint hint) const {
    NearestTriangle best;
    best.distance2 = std::numeric_limits<double>::infinity();
    double bound2 = best.distance2;
    // While looking for an early break only: boxes past the stop are
    // skipped too (they hold no triangle that ends the query).
    double limit2 = best.distance2;
    auto cut = [&] { return std::min(bound2, limit2); };
    // Triangle i (BVH order) against the best so far; true when it ends the
    // query (below stopBelow2).
    auto test = [&](uint32_t i) {
        const Corner* c = &corners[3 * size_t(i)];
        const glm::dvec3 a(c[0]), b(c[1]), cc(c[2]);
        // The triangle's own box, as its node's (which holds it) is pruned:
        // past the bound it holds neither the nearest nor a tie.
        if (core::boxDistance2(p, glm::min(glm::min(a, b), cc), glm::max(glm::max(a, b), cc)) > cut())
            return false;
        const core::TriangleClosest r = core::closestOnTriangle(p, a, b, cc, m_thin[i] != 0);
        ++best.trianglesTested;
        const uint32_t t = m_original[i];
        if (r.distance2 < best.distance2 || (r.distance2 == best.distance2 && t < best.triangle)) {
            best.distance2 = r.distance2;
            best.triangle = t;
            best.position = i;
            best.point = r.point;
            best.barycentric = r.barycentric;
            bound2 = pruneBound2(best.distance2, slack);
            if (best.distance2 < stopBelow2) {
                best.dominated = true;
                return true;
            }
        }
        return false;
    };
    // Depth first from `from`, the nearer child first, pruning past the
    // bound; the path's nodes by depth, so that a query ended at a leaf
    // names its ancestor kHintLevels up (TriangleHint::node) for the next.
    // Balanced tree: depth <= log2(2^32) + 2, at most one entry per level waits.
    struct Entry {
        uint32_t node, depth;
        double distance2;
    };
    std::array<Entry, 80> stack;
    std::array<uint32_t, 80> path;
    auto descend = [&](uint32_t from) {
        size_t top = 0;
        stack[top++] = {from, 0, boxDistance2(p, m_nodes[from].lo, m_nodes[from].hi)};
        ++best.nodesVisited;
        while (top > 0) {
            const Entry e = stack[--top];
            if (e.distance2 > cut()) continue;
            path[e.depth] = e.node;
            const Node& node = m_nodes[e.node];
            if (node.count > 0) {
                for (uint32_t i = node.first; i < node.first + node.count; ++i) {
                    if (!test(i)) continue;
                    best.near = path[e.depth >= kHintLevels ? e.depth - kHintLevels : 0];
                    return true;
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
            const Entry nearE{leftFirst ? node.first : node.first + 1, e.depth + 1, leftFirst ? dl : dr};
            const Entry farE{leftFirst ? node.first + 1 : node.first, e.depth + 1, leftFirst ? dr : dl};
            const double bound = cut();
            if (farE.distance2 <= bound) stack[top++] = farE;
            if (nearE.distance2 <= bound) stack[top++] = nearE;
        }
        return false;
    };
    // The hint's triangle, then for an early break its subtree and the tree
    // looking only within the stop, then the tree: each triangle met is a
    // real measure, so the best so far; the last descent prunes past it and
    // meets every triangle it could not rule out (kept, or a nearer one, or
    // a tie of a smaller index: the same test), so the answer is the one
    // that descent alone would give.
    if (hint.position < m_original.size() && test(hint.position)) {
        best.near = hint.node;
        return best;
    }
    if (stopBelow2 > 0.0) {
        limit2 = pruneBound2(stopBelow2, slack);
        if (hint.node != 0 && hint.node < m_nodes.size() && descend(hint.node)) {
            best.near = hint.node;  // its ancestor within the subtree: the same node again
            return best;
        }
        if (descend(0)) return best;
        limit2 = std::numeric_limits<double>::infinity();
    }
    descend(0);
    return best;
}

size_t TriangleBvh::hostBytes() const {
    return m_nodes.capacity() * sizeof(Node) + m_corners.capacity() * sizeof(glm::dvec3) +
           m_cornersF.capacity() * sizeof(glm::vec3) + m_original.capacity() * sizeof(uint32_t) +
           m_thin.capacity();
}

}  // namespace rthdist::cpu
