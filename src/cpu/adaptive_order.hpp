// Adaptive Morton order of the CPU backend: a uniform grid's Morton order in
// which every overfull cell is ordered again by a Morton key over its own
// points' tight box, recursively (an implicit sparse octree whose depth
// follows the points, as in the LBVH of Karras 2012, "Maximizing parallelism
// in the construction of BVHs, octrees, and k-d trees", where the key
// resolution is fixed instead). It is what keeps the BVH over a dense
// cluster in a huge bounding box tight: a cluster of 200k points inside one
// grid cell of a box stretched by a stray point would otherwise be one run in
// input order, cut into buckets with random, overlapping boxes.
//
// Rules: a run of equal keys longer than kRefineRun whose points are not all
// identical is sorted by the 30-bit Morton key (10 bits per axis) of its
// points over its tight box (cubic, longest side / 1024; cell coordinates
// as core::cellCoord, clamped); the runs of equal keys that this gives are
// refined the same way. The box of a refined run has at least two distinct
// keys along its longest axis (its min point is in cell 0, its max point in
// cell 1023), so every round splits the run, and a sub-run's extent is at
// most 1/1024 of its parent's (plus double rounding): float coordinates stop
// refining after about 19 rounds (2^190 spans every ratio of two float
// extents the scaling rule allows); kMaxRefineDepth caps it anyway (past the
// cap a run stays in input order: still correct, only slower to search).
// Ties (equal keys at every level) keep ascending input index, so the order
// is deterministic and independent of the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "cpu/key_sort.hpp"

namespace rthdist::cpu {

inline constexpr uint32_t kRefineRun = 64;  // runs longer than this are refined
inline constexpr int kMaxRefineDepth = 24;  // refinement rounds (never reached by float data)

// Positions [first, end) of the sorted order whose points are all identical
// (a refined run of zero extent, longer than kRefineRun).
struct IdenticalRun {
    uint32_t first = 0;
    uint32_t end = 0;
};

// `order` holds points sorted by key, ties by ascending input index (what
// sortPointsByKey gives); its coordinates are the scaled ones, from which
// boxes and keys are taken. Reorders every run of equal keys in place as
// described above (keyed values and coordinates together); the keys
// themselves are left as they were (each run is only permuted). When
// `identical` is given, it receives the identical runs, ascending.
void refineOrder(OrderedPoints& order, int threads, std::vector<IdenticalRun>* identical = nullptr);

}  // namespace rthdist::cpu
