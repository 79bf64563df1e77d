// The top-down split of a range of items sorted by Morton code, shared by
// the two triangle trees (cpu/triangle_bvh, the CPU backend's; and
// gpu_algo/surface_tree, the GPU tail's descent).
//
// A range of more than `leaf` items splits where the highest bit in which
// its first and last codes differ changes (the two halves of the Morton
// cell they share; a split at the count's median instead cuts a Z-curve
// segment's jumps into boxes that span far blobs: docs/bench/surfaces,
// sessions 8 and 30), in the middle where it holds at most 2 * leaf (two
// leaves), where its codes are all equal (duplicates), or where an uneven
// split could leave a node deeper than `maxLevels` (a range of n at depth d
// with d + levelsBelow(n) <= maxLevels keeps that after either split; the
// root's depth is 1). Each uneven split takes a code bit, so with 30-bit
// codes the depth stays below 31 + levelsBelow(n): the guard decides only
// where maxLevels is below that (the GPU tree's 32), and holds whatever
// the codes.
//
// Keys: uint32_t codes, or uint64_t (code << 32 | payload), ascending.
// Header only, pure: any thread (mortonTaskOffsets on the worker pool).
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "core/parallel.hpp"

namespace rthdist::core {

// Levels a balanced split of `count` items needs below a node: leaves of up
// to `leaf`, halves of ceil(count / 2).
[[nodiscard]] constexpr uint32_t levelsBelow(size_t count, uint32_t leaf) {
    uint32_t levels = 0;
    for (size_t leaves = (count + leaf - 1) / leaf; leaves > 1; leaves = (leaves + 1) / 2) ++levels;
    return levels;
}

// Where the sorted positions [first, end) at `depth` split (above): 0 for a
// leaf (at most `leaf` items), else the first position of the right half.
template <class Key>
[[nodiscard]] uint32_t mortonSplitAt(const Key* keys, uint32_t first, uint32_t end, uint32_t depth,
                                     uint32_t leaf, uint32_t maxLevels) {
    static_assert(std::is_same_v<Key, uint32_t> || std::is_same_v<Key, uint64_t>);
    constexpr int kShift = sizeof(Key) == 8 ? 32 : 0;
    const uint32_t count = end - first;
    if (count <= leaf) return 0u;
    const uint32_t middle = first + count / 2;
    const auto a = uint32_t(keys[first] >> kShift), z = uint32_t(keys[end - 1] >> kShift);
    if (count <= 2 * leaf || a == z || depth + 1 + levelsBelow(count, leaf) > maxLevels) return middle;
    const uint32_t bit = uint32_t(1) << (31 - std::countl_zero(a ^ z));
    const Key upper = Key(z & ~(bit - 1u)) << kShift;  // the least code with that bit set (z's bits above it)
    return uint32_t(std::lower_bound(keys + first, keys + end, upper) - keys);
}

// The levels above a tree's tasks: from the root's range [0, count) (node
// 0, depth 1), the ranges of more than taskItems split a level at a time
// (mortonSplitAt), each split node's two children the next two nodes; the
// smaller ranges are the tasks, whose subtrees the caller builds below the
// top levels' nodes.
struct MortonTop {
    struct Range {
        size_t at;  // the range's node
        uint32_t first, end, depth;
    };
    struct Inner {
        size_t at, child;  // node `at` split; its children are child and child + 1
    };
    std::vector<Range> tasks;  // in position order
    std::vector<Inner> inner;  // parents before children
    size_t nodes = 1;          // the top levels' nodes, tasks' roots included
};

template <class Key>
[[nodiscard]] MortonTop mortonTopLevels(const Key* keys, uint32_t count, uint32_t taskItems, uint32_t leaf,
                                        uint32_t maxLevels) {
    MortonTop top;
    std::vector<MortonTop::Range> open{{0, 0u, count, 1u}};
    for (size_t i = 0; i < open.size(); ++i) {
        const MortonTop::Range r = open[i];
        if (r.end - r.first <= taskItems) {
            top.tasks.push_back(r);
            continue;
        }
        const uint32_t split = mortonSplitAt(keys, r.first, r.end, r.depth, leaf, maxLevels);
        top.inner.push_back({r.at, top.nodes});
        open.push_back({top.nodes, r.first, split, r.depth + 1});
        open.push_back({top.nodes + 1, split, r.end, r.depth + 1});
        top.nodes += 2;
    }
    return top;
}

// The nodes below a range's node in the tree the split rule builds (two
// for each split, down to the leaves).
template <class Key>
[[nodiscard]] size_t mortonNodesBelow(const Key* keys, uint32_t first, uint32_t end, uint32_t depth,
                                      uint32_t leaf, uint32_t maxLevels) {
    const uint32_t split = mortonSplitAt(keys, first, end, depth, leaf, maxLevels);
    if (split == 0u) return 0;
    return 2 + mortonNodesBelow(keys, first, split, depth + 1, leaf, maxLevels) +
           mortonNodesBelow(keys, split, end, depth + 1, leaf, maxLevels);
}

// Where each task's nodes below its root go when they follow the top
// levels' nodes in the tasks' order: task k's from offsets[k], the tree's
// node count offsets.back(). Counted a task at a time on `threads`
// workers (0: all), so that each subtree can then be built in place.
template <class Key>
[[nodiscard]] std::vector<size_t> mortonTaskOffsets(const Key* keys, const MortonTop& top, uint32_t leaf,
                                                    uint32_t maxLevels, int threads) {
    const std::vector<MortonTop::Range>& tasks = top.tasks;
    std::vector<size_t> offsets(tasks.size() + 1, 0);
    parallelChunks(tasks.size(), 1, threads, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k)
            offsets[k + 1] =
                mortonNodesBelow(keys, tasks[k].first, tasks[k].end, tasks[k].depth, leaf, maxLevels);
    });
    offsets[0] = top.nodes;
    for (size_t k = 0; k < tasks.size(); ++k) offsets[k + 1] += offsets[k];
    return offsets;
}

}  // namespace rthdist::core
