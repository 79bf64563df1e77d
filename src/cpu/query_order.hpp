// The order in which a search visits its queries (cpu/surface_search.cpp):
// a Morton order of their positions, so that the queries of one thread's
// chunk lie near each other and descend the same nodes of the tree, read
// from cache. Scans and samples often come in no spatial order: on 2 cores
// the point-to-surface search of 1M samples of dragon_vrip_res2 against
// res3's 47,794 triangles took 500 ms in input order and 250 ms in Morton
// order (docs/bench/surfaces, session 22). The order decides no value:
// each query's answer is its own, and the search's maximum and witness
// are order-free (cpu/surface_search.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "rthdist/point_view.hpp"

namespace rthdist::cpu {

// From this many queries the order is worth its sort (~10-20 ns a query).
inline constexpr uint64_t kSpatialOrderFrom = uint64_t(1) << 12;
// Past this many queries a search that stops early (the directed maximum:
// a query stops at the first triangle below the running maximum) keeps
// input order: reading the points out of order then costs what the tree's
// locality saves (an H200's 16 cores, the scale row of docs/bench/surfaces
// session 22: 1M samples 43 -> 30 ms in Morton order, 10M 371-392 ->
// 390-419 ms), while a per-point search (every query to its nearest) gains
// at both sizes (108 -> 76 ms, 1081-1138 -> 774-790 ms).
inline constexpr uint64_t kSpatialOrderEarlyBreakUpTo = uint64_t(1) << 22;

// The queries' indices in Morton order of their cells (10 bits an axis over
// their box), ties by index; empty (input order) below kSpatialOrderFrom
// queries, from 2^32 (the sort's 32-bit payload), or where the input is in
// space order already (more than half of 64 runs of 32 consecutive queries
// span at most 2 (32 / n)^(1/3) of the set's extent: a mesh's vertices, a
// scan's lines, a sorted set; sorting them cost ~20 ms of 1M on 2 cores for
// nothing). The worker pool on
// `threads` for the keys and the radix sort: the same order on any count.
[[nodiscard]] std::vector<uint32_t> spatialOrder(const PointView& points, int threads);

}  // namespace rthdist::cpu
