// Voxel index lists built one z slice at a time on all threads and joined in
// slice order: ascending voxel indices when each slice's list ascends (the
// boundary, difference and selection passes of boundary.cpp and
// selection_bits.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/parallel.hpp"

namespace rthdist::masks::detail {

// fn(z, out) for every slice z in [0, slices), each with its own list (one
// slice per work item, any thread); the lists joined in slice order.
template <class Fn>
std::vector<uint64_t> perSlice(int64_t slices, int threads, Fn&& fn) {
    std::vector<std::vector<uint64_t>> lists(size_t(std::max<int64_t>(slices, 0)));
    core::parallelChunks(lists.size(), 1, threads, [&](size_t zb, size_t ze, int) {
        for (size_t z = zb; z < ze; ++z) fn(int64_t(z), lists[z]);
    });
    size_t total = 0;
    for (const auto& l : lists) total += l.size();
    std::vector<uint64_t> out;
    out.reserve(total);
    for (auto& l : lists) {
        out.insert(out.end(), l.begin(), l.end());
        std::vector<uint64_t>().swap(l);
    }
    return out;
}

}  // namespace rthdist::masks::detail
