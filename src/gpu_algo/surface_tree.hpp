// The float BVH of the framed triangles for the point-to-surface search's
// tail (surface_tail.comp; design.md §11): the queries the radii leave open
// descend it nearest-first on the device. Built on the host from the float
// corners the search already has (3 per triangle, search frame):
//   - the Morton code (10 bits per axis) of each triangle's box centre over
//     the box of the centres, sorted with the triangle index breaking ties
//     (so the tree is one function of the corners, whatever the threads);
//   - then, top down, a range of more than kSurfaceTreeLeaf sorted
//     triangles splits where the highest bit in which its first and last
//     codes differ changes (so a node is the triangles of one Morton cell's
//     half: its box holds that part of space and little else), in the
//     middle where the codes are all equal or where an uneven split could
//     pass kSurfaceTreeMaxLevels, or where it holds at most twice
//     kSurfaceTreeLeaf; a range of at most kSurfaceTreeLeaf is a leaf.
// Layout: the nodes of more than 2^13 triangles a level at a time from the
// root, then each smaller node's subtree depth first (on the worker pool),
// in the order of those nodes; the same tree whatever the threads.
// Nodes are shared::Cell {lo, first, hi, count}: a leaf has count = its
// triangles (1..kSurfaceTreeLeaf) and first = its first position in the
// sorted order (`order` maps a position to its triangle); an inner node has
// count = 0 and its two children at first (left) and first + 1 (right),
// absolute indices into `nodes`; nodes[0] is the root. Every box is the
// exact min/max of the FLOAT corners below it, so that a node's box holds
// the box surface_visit.glsl tests for each of its triangles: pruning the
// node when its boxDist2 exceeds the best is that test of each triangle
// lifted (float rounding is monotone), and the descent finds what a visit
// of every triangle would.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

#include "rthdist_surface_search.h"

namespace rthdist::gpu_algo {

inline constexpr uint32_t kSurfaceTreeLeaf = 4;
// The descent's stack (surface_tail.comp) holds at most one node per level
// below the root. 2^30 triangles make at most 2^28 leaves: 29 levels.
inline constexpr uint32_t kSurfaceTreeMaxLevels = RTHDIST_SURFACE_TAIL_STACK;

struct SurfaceTree {
    std::vector<shared::Cell> nodes;  // nodes[0]: the root
    std::vector<uint32_t> order;      // sorted position -> triangle
    uint32_t levels = 0;              // the deepest node's depth, the root's 1 (1: the root is a leaf)
};

// corners: a, b, c of every triangle (3 per triangle, at least one
// triangle, fewer than 2^30); threads: for core::parallelChunks (0: all).
[[nodiscard]] SurfaceTree buildSurfaceTree(std::span<const glm::vec3> corners, int threads);

}  // namespace rthdist::gpu_algo
