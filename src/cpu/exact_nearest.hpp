// Exact nearest neighbours in double for per-point output (design.md §10,
// "Per-point distances"): every backend searches float copies of the sets,
// so each query's nearest pair is the float search's, and its distance,
// recomputed in double from the caller's coordinates, lies within 2e of the
// exact nearest distance (e the frame's float error). Where e is large
// against the gaps between points (a far stray point stretching the frame
// over a millimetre cluster: e ~1.4 mm for a 3 km stray) that pair can be
// millimetres off. This pass makes every entry the exact one: each query's
// nearest target in double over ALL targets, the smallest index on a tie,
// found by a descent of a kd-tree over the targets in double that starts
// from the float pair's distance (so it visits little more than the leaves
// within that distance of the query).
//
// Exact means what the certificate means (core/certificate.hpp): the
// distance is core::exactDistance (sqrt(dx^2 + dy^2 + dz^2) in double of
// the caller's coordinates), minimal over every target; among targets at
// that distance, the smallest index.
//
// Threading: the tree is built on `threads` of the worker pool and read by
// any number of threads at once.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

#include "core/uninit_vector.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cpu {

class ExactPointTree {
public:
    // points: finite, non-empty, fewer than 2^32 (read during the build only).
    ExactPointTree(const PointView& points, int threads);

    // The nearest point to p (exactDistance, the smallest index on a tie)
    // and its distance. start: a point index whose exact distance from p is
    // startDistance (any index of the set works, a near one saves work):
    // its leaf is scanned first, then the other subtrees along the path
    // from the root to it, deepest first, each only where its box lies
    // within the best distance (the float search's pair usually is the
    // nearest, and its leaf's neighbours are the only boxes that close),
    // until the ball of the best distance lies inside the cell of the
    // path's subtree (the split planes above it): no point outside it can
    // be nearer.
    struct Nearest {
        uint32_t index = 0;
        double distance = 0.0;
    };
    [[nodiscard]] Nearest nearest(const glm::dvec3& p, uint32_t start, double startDistance) const;

    [[nodiscard]] size_t hostBytes() const;
    // Where point `index` sits in the tree order: queries taken in the order
    // of their starts' positions read the same leaves and boxes one after
    // another (inputs in no spatial order otherwise miss the cache on every
    // node: 10M random-order queries took ~2 s on 16 cores).
    [[nodiscard]] uint32_t positionOf(uint32_t index) const { return m_position[index]; }
    // Point `index` as the tree holds it (PointView::at's value), read in tree order.
    [[nodiscard]] const glm::dvec3& pointAt(uint32_t index) const { return m_items[m_position[index]].p; }

private:
    // Node n covers the points [first, first + count) of the tree order; an
    // inner node's children are n + 1 and n + 1 + (nodes of the left
    // subtree), the left holding the first count / 2 points.
    struct Node {
        glm::dvec3 lo, hi;  // the exact box of its points
        double split;       // inner: the left's points have p[axis] <= split, the right's >= split
        uint32_t first, count;
        uint32_t right;  // inner: the right child's node; leaf: 0
        uint32_t axis;   // inner: 0, 1 or 2
    };
    struct Item {
        glm::dvec3 p;    // the point, as PointView::at gives it
        uint32_t index;  // its input index
    };
    core::UninitVector<Node> m_nodes;
    core::UninitVector<Item> m_items;         // in tree order
    core::UninitVector<uint32_t> m_position;  // input index -> tree order
    // The best-first descent of subtree `root` from `best` (bound2 its bound).
    void descend(const glm::dvec3& p, uint32_t root, Nearest& best, double& bound2) const;
};

// Makes every entry of `perPoint` (queries q against targets t, the
// caller's coordinates) exact: each query's nearest target in double over
// all of t, its distance as core::exactDistance, the smallest index on a
// tie. perPoint.nearest must hold a target index per query (the float
// search's, any index being correct, a near one fast); perPoint.distance is
// filled when it is not empty (it may be: nearest-only calls). Returns the
// entries that changed.
uint64_t makePerPointExact(PerPoint& perPoint, const PointView& q, const PointView& t, int threads);

}  // namespace rthdist::cpu
