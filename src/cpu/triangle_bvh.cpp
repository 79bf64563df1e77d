#include "cpu/triangle_bvh.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <utility>

#include "core/float_box.hpp"
#include "core/morton_split.hpp"
#include "core/parallel.hpp"
#include "core/point_triangle.hpp"
#include "cpu/key_sort.hpp"
#include "rthdist_morton.h"

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

// Subtrees of at most this many triangles are built whole by one task.
constexpr uint32_t kSubtreeTriangles = 4096;
// The deepest node's depth (the root's 1): nearestIn's stack and path hold 80.
constexpr uint32_t kMaxLevels = 64;
constexpr int kMortonBits = 30;  // 10 per axis

// Where the sorted positions [first, end) at `depth` split (core/morton_split.hpp).
uint32_t splitAt(const uint64_t* keyed, uint32_t first, uint32_t end, uint32_t depth) {
    return core::mortonSplitAt(keyed, first, end, depth, kLeafTriangles, kMaxLevels);
}

// A task's subtree, depth first, into the nodes: its root at a node the
// levels above made, the others from `next` on (core::mortonTaskOffsets
// counted them), an inner node's two children adjacent (first, first + 1)
// and after it; a leaf's first is its sorted position. Boxes come later.
struct Subtree {
    const uint64_t* keyed;
    TriangleBvh::Node* nodes;
    uint32_t deepest = 0;

    void build(size_t& next, size_t at, uint32_t first, uint32_t end, uint32_t depth) {
        deepest = std::max(deepest, depth);
        const uint32_t split = splitAt(keyed, first, end, depth);
        if (split == 0u) {
            nodes[at].first = first;
            nodes[at].count = end - first;
            return;
        }
        const auto child = uint32_t(next);
        next += 2;
        nodes[at].first = child;
        nodes[at].count = 0;
        build(next, child, first, split, depth + 1);
        build(next, child + 1, split, end, depth + 1);
    }
};

}  // namespace

// The build in four passes: the triangles sorted by the Morton codes of
// their box centres, the splits (which triangles each leaf holds), then
// every triangle's corners written once, in input order, to its place in
// BVH order (a scattered write instead of a random read through the index
// array), then the boxes from the leaves up.
TriangleBvh::TriangleBvh(const MeshView& mesh, int threads) {
    const auto n = uint32_t(mesh.triangleCount());
    const int taskThreads = threads;
    threads = core::resolveThreads(threads, n / kSubtreeTriangles);
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
        m_nodes.resize(1);
        m_nodes[0] = Node{glm::vec3(std::numeric_limits<float>::infinity()),
                          glm::vec3(-std::numeric_limits<float>::infinity()), 0, 0};
        return;
    }
    // The sort's two buffers of (code << 32 | triangle) in the corners'
    // memory, 16 of its 36 (float) or 72 (double) bytes a triangle: they
    // are spent before the corners pass writes there. Fresh memory is what
    // a one-shot build pays most for on a VM (~2.3 ms a MiB on first touch,
    // docs/bench/surfaces session 10), and no block of its own is faulted in.
    static_assert(2 * sizeof(uint64_t) <= 3 * sizeof(glm::vec3) && alignof(uint64_t) <= alignof(glm::dvec3));
    auto* const words = m_floatCorners ? reinterpret_cast<uint64_t*>(m_cornersF.data())
                                       : reinterpret_cast<uint64_t*>(m_corners.data());
    // (glm::vec3 itself is 4-aligned, but an UninitVector block is at least
    // 16-aligned: operator new or a mapping; checked here.)
    if (reinterpret_cast<uintptr_t>(words) % alignof(uint64_t) != 0)
        throw std::logic_error("the triangle BVH's corner block is not 8-aligned");
    const std::span<uint64_t> keys(words, n), scratch(words + n, n);

    // The centres (each triangle's box's, in double, rounded to float) and
    // their box, per chunk, joined in chunk order.
    const auto centreOf = [&](size_t t) {
        const glm::dvec3 c0 = mesh.corner(t, 0), c1 = mesh.corner(t, 1), c2 = mesh.corner(t, 2);
        return glm::vec3((glm::min(glm::min(c0, c1), c2) + glm::max(glm::max(c0, c1), c2)) * 0.5);
    };
    const size_t chunks = (size_t(n) + kSubtreeTriangles - 1) / kSubtreeTriangles;
    std::vector<core::FloatBox> chunkBounds(chunks);
    core::parallelChunks(n, kSubtreeTriangles, threads, [&](size_t begin, size_t end, int) {
        core::FloatBox b;
        for (size_t t = begin; t < end; ++t) b.add(centreOf(t));
        chunkBounds[begin / kSubtreeTriangles] = b;
    });
    core::FloatBox all;
    for (const core::FloatBox& b : chunkBounds) all.add(b);
    // Cubic cells, 1024 along the centres' box's longest edge (in double: one
    // value per centre, whatever the threads): per-axis cells would give a
    // thin axis as many bits as a long one and split along it first.
    double lo[3], extent = 0.0;
    for (int k = 0; k < 3; ++k) {
        lo[k] = double(all.lo[k]);
        extent = std::max(extent, double(all.hi[k]) - lo[k]);
    }
    const double scale = extent > 0.0 && std::isfinite(extent) ? 1024.0 / extent : 0.0;
    core::parallelChunks(n, kSubtreeTriangles, threads, [&](size_t begin, size_t end, int) {
        for (size_t t = begin; t < end; ++t) {
            const glm::vec3 c = centreOf(t);
            uint32_t cell[3];
            for (int k = 0; k < 3; ++k) {
                const double at = std::floor((double(c[k]) - lo[k]) * scale);
                cell[k] = at > 0.0 ? uint32_t(std::min(1023.0, at)) : 0u;
            }
            keys[t] = (uint64_t(shared::mortonEncode(cell[0], cell[1], cell[2])) << 32) | t;
        }
    });
    // Ascending code, ties by triangle index.
    const uint64_t* keyed = radixSortKeys(keys, scratch, kMortonBits, threads) ? scratch.data() : keys.data();

    // Top down (splitAt): the ranges of more than kSubtreeTriangles split
    // here, a level at a time (core::mortonTopLevels); each smaller one is
    // a task, its subtree counted, then built depth first on the worker pool
    // into the nodes after the levels', in the tasks' order (so the tree
    // does not depend on the threads).
    const core::MortonTop levels =
        core::mortonTopLevels(keyed, n, kSubtreeTriangles, kLeafTriangles, kMaxLevels);
    const std::vector<core::MortonTop::Range>& tasks = levels.tasks;
    const std::vector<size_t> offset =
        core::mortonTaskOffsets(keyed, levels, kLeafTriangles, kMaxLevels, taskThreads);
    m_nodes.resize(offset.back());
    for (const core::MortonTop::Inner& in : levels.inner) {
        m_nodes[in.at].first = uint32_t(in.child);
        m_nodes[in.at].count = 0;
    }
    core::UninitVector<uint32_t> placeOf(n);  // triangle -> its BVH position
    std::vector<uint32_t> deepest(tasks.size(), 0u);
    core::parallelChunks(tasks.size(), 1, taskThreads, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k) {
            Subtree part{keyed, m_nodes.data()};
            size_t next = offset[k];
            part.build(next, tasks[k].at, tasks[k].first, tasks[k].end, tasks[k].depth);
            deepest[k] = part.deepest;
            for (uint32_t i = tasks[k].first; i < tasks[k].end; ++i) {
                const auto t = uint32_t(keyed[i]);
                m_original[i] = t;
                placeOf[t] = i;
            }
        }
    });
    if (*std::max_element(deepest.begin(), deepest.end()) > kMaxLevels)
        throw std::logic_error("the triangle BVH's depth guard failed");

    // The corners, each triangle's in input order to its BVH place (the
    // sort's buffers are spent), and whether it is thin (core::thinTriangle).
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

    // The boxes: a node's children come after it, so each task's nodes in
    // reverse order meet the children first, then its root; then the top
    // levels.
    const auto boxOf = [&](size_t at) {
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
    core::parallelChunks(tasks.size(), 1, taskThreads, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k) {
            for (size_t at = offset[k + 1]; at-- > offset[k];) boxOf(at);
            boxOf(tasks[k].at);
        }
    });
    for (auto it = levels.inner.rbegin(); it != levels.inner.rend(); ++it) boxOf(it->at);
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
    // The build keeps every node within kMaxLevels (64) levels, and at most
    // one entry per level waits: 80 entries hold any descent.
    static_assert(kMaxLevels < 80);
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
