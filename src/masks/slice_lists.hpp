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
// slice per work item, any thread); the lists joined in slice order into an
// `Out` (a std::vector, or a core::UninitVector, which the join's threads
// touch first instead of one thread zeroing it: 0.5 ms of a noisy mask's
// 376k boundary voxels on an H100 host), each list copied to its place and
// freed by the thread that copies it. A slice's list grows in a vector of
// the thread's own and moves into place when done: growing it in place, next
// to the neighbouring slices' vectors that other threads were filling, shared
// their cache lines on every append (0.65 ms per volume on the H100
// machine's 16 threads, no faster than 2).
template <class Out = std::vector<uint64_t>, class Fn>
Out perSlice(int64_t slices, int threads, Fn&& fn) {
    std::vector<std::vector<uint64_t>> lists(size_t(std::max<int64_t>(slices, 0)));
    core::parallelChunks(lists.size(), 1, threads, [&](size_t zb, size_t ze, int) {
        for (size_t z = zb; z < ze; ++z) {
            std::vector<uint64_t> own;
            fn(int64_t(z), own);
            lists[z] = std::move(own);
        }
    });
    std::vector<size_t> at(lists.size() + 1, 0);
    for (size_t z = 0; z < lists.size(); ++z) at[z + 1] = at[z] + lists[z].size();
    Out out;
    out.resize(at.back());
    core::parallelChunks(lists.size(), 1, threads, [&](size_t zb, size_t ze, int) {
        for (size_t z = zb; z < ze; ++z) {
            std::copy(lists[z].begin(), lists[z].end(), out.begin() + ptrdiff_t(at[z]));
            std::vector<uint64_t>().swap(lists[z]);
        }
    });
    return out;
}

}  // namespace rthdist::masks::detail
