#include "gpu_algo/surface_tree.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

#include "core/float_box.hpp"
#include "core/morton_split.hpp"
#include "core/parallel.hpp"
#include "rthdist_morton.h"

namespace rthdist::gpu_algo {

namespace {

namespace sh = rthdist::shared;

constexpr size_t kChunk = size_t(1) << 15;
constexpr uint32_t kTaskTriangles = uint32_t(1) << 13;  // a subtree built depth first by one worker
constexpr uint32_t kMortonBits = 30;                    // 10 per axis
constexpr uint32_t kRadixBits = 10;                     // three passes over the codes
constexpr uint32_t kBuckets = uint32_t(1) << kRadixBits;

using Box = core::FloatBox;

Box triangleBox(std::span<const glm::vec3> corners, size_t t) {
    Box b;
    for (size_t k = 0; k < 3; ++k) b.add(corners[3 * t + k]);
    return b;
}

glm::vec3 centreOf(const Box& b) { return 0.5f * (b.lo + b.hi); }

Box boxOf(const sh::Cell& c) { return {{c.lo.x, c.lo.y, c.lo.z}, {c.hi.x, c.hi.y, c.hi.z}}; }

sh::Cell cellOf(const Box& b, uint32_t first, uint32_t count) {
    return {{b.lo.x, b.lo.y, b.lo.z}, first, {b.hi.x, b.hi.y, b.hi.z}, count};
}

// Stable LSD radix sort of (codes, items) by the codes' kMortonBits low
// bits. Each chunk of the input scatters to the places the prefix over
// (digit, chunk) gives it, so the result is the serial stable sort's
// whatever the threads.
void radixSort(std::vector<uint32_t>& codes, std::vector<uint32_t>& items, int threads) {
    const size_t n = codes.size();
    const size_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<uint32_t> codesOut(n), itemsOut(n), offsets(chunks * kBuckets);
    for (uint32_t shift = 0; shift < kMortonBits; shift += kRadixBits) {
        std::fill(offsets.begin(), offsets.end(), 0u);
        core::parallelChunks(n, kChunk, threads, [&](size_t begin, size_t end, int) {
            uint32_t* count = offsets.data() + begin / kChunk * kBuckets;
            for (size_t i = begin; i < end; ++i) ++count[(codes[i] >> shift) & (kBuckets - 1)];
        });
        uint32_t sum = 0;
        for (uint32_t digit = 0; digit < kBuckets; ++digit) {
            for (size_t chunk = 0; chunk < chunks; ++chunk) {
                uint32_t& slot = offsets[chunk * kBuckets + digit];
                const uint32_t count = slot;
                slot = sum;
                sum += count;
            }
        }
        core::parallelChunks(n, kChunk, threads, [&](size_t begin, size_t end, int) {
            uint32_t* next = offsets.data() + begin / kChunk * kBuckets;
            for (size_t i = begin; i < end; ++i) {
                const uint32_t at = next[(codes[i] >> shift) & (kBuckets - 1)]++;
                codesOut[at] = codes[i];
                itemsOut[at] = items[i];
            }
        });
        codes.swap(codesOut);
        items.swap(itemsOut);
    }
}

// Where the sorted positions [first, end) at `depth` (the root's 1) split
// (core/morton_split.hpp): the middle for at most twice kSurfaceTreeLeaf
// (two leaves, not an uneven split's three or four: 12 % fewer nodes on
// dragon_vrip_res3, the descent's visits level in a model of it), and the
// depth within kSurfaceTreeMaxLevels (levelsBelow(2^30) = 28).
uint32_t splitAt(const std::vector<uint32_t>& codes, uint32_t first, uint32_t end, uint32_t depth) {
    return core::mortonSplitAt(codes.data(), first, end, depth, kSurfaceTreeLeaf, kSurfaceTreeMaxLevels);
}

// A task's subtree, depth first, into the tree's nodes: its root at a
// node of the levels above, the others from `next` on (counted by
// core::mortonTaskOffsets), an inner node's two children adjacent, a
// leaf's first its sorted position.
struct Subtree {
    const std::vector<uint32_t>& codes;
    const std::vector<uint32_t>& order;
    std::span<const glm::vec3> corners;
    uint32_t deepest = 0;  // the deepest node's depth

    Box build(std::vector<sh::Cell>& nodes, size_t& next, size_t at, uint32_t first, uint32_t end,
              uint32_t depth) {
        deepest = std::max(deepest, depth);
        const uint32_t split = splitAt(codes, first, end, depth);
        Box box;
        if (split == 0u) {
            for (uint32_t i = first; i < end; ++i) box.add(triangleBox(corners, order[i]));
            nodes[at] = cellOf(box, first, end - first);
            return box;
        }
        const size_t child = next;
        next += 2;
        box = build(nodes, next, child, first, split, depth + 1);
        box.add(build(nodes, next, child + 1, split, end, depth + 1));
        nodes[at] = cellOf(box, uint32_t(child), 0u);
        return box;
    }
};

}  // namespace

SurfaceTree buildSurfaceTree(std::span<const glm::vec3> corners, int threads) {
    const size_t triangles = corners.size() / 3;
    if (triangles == 0 || corners.size() % 3 != 0 || triangles >= (size_t(1) << 30))
        throw std::length_error("the surface tree takes 1 to 2^30 - 1 triangles");
    // The passes over chunks of kChunk triangles take at most a worker a
    // chunk; the subtrees' passes below take one a task (the bunny's 69,451
    // triangles: 3 chunks, 9 tasks).
    const int taskThreads = threads;
    threads = core::resolveThreads(threads, triangles / kChunk + 1);

    // The box of the triangles' box centres, per chunk, then joined in chunk order.
    const size_t chunks = (triangles + kChunk - 1) / kChunk;
    std::vector<Box> centres(chunks);
    core::parallelChunks(triangles, kChunk, threads, [&](size_t begin, size_t end, int) {
        Box b;
        for (size_t t = begin; t < end; ++t) b.add(centreOf(triangleBox(corners, t)));
        centres[begin / kChunk] = b;
    });
    Box all;
    for (const Box& b : centres) all.add(b);
    // 1024 cells per axis over it (in double: one value per centre, whatever the threads).
    double lo[3], scale[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = double(all.lo[k]);
        const double extent = double(all.hi[k]) - lo[k];
        scale[k] = extent > 0.0 ? 1024.0 / extent : 0.0;
    }
    std::vector<uint32_t> codes(triangles), order(triangles);
    core::parallelChunks(triangles, kChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t t = begin; t < end; ++t) {
            const glm::vec3 c = centreOf(triangleBox(corners, t));
            uint32_t cell[3];
            for (int k = 0; k < 3; ++k)
                cell[k] = uint32_t(std::min(1023.0, std::floor((double(c[k]) - lo[k]) * scale[k])));
            codes[t] = sh::mortonEncode(cell[0], cell[1], cell[2]);
            order[t] = uint32_t(t);
        }
    });
    radixSort(codes, order, threads);  // stable: ties keep the triangles' order

    // Top down: a range of more than kSurfaceTreeLeaf sorted triangles
    // splits where its codes' highest differing bit changes (the two halves
    // of the Morton cell they share), or in the middle where its codes are
    // all equal or where the depth left could not hold an uneven split
    // (splitAt). The ranges of more than kTaskTriangles split here, a level
    // at a time (core::mortonTopLevels); each smaller one is a task, its
    // subtree built depth first on the worker pool into the nodes after the
    // levels', in the tasks' order (so the tree does not depend on the
    // threads).
    SurfaceTree tree;
    const core::MortonTop levels = core::mortonTopLevels(codes.data(), uint32_t(triangles), kTaskTriangles,
                                                         kSurfaceTreeLeaf, kSurfaceTreeMaxLevels);
    const std::vector<core::MortonTop::Range>& tasks = levels.tasks;
    // Each task's nodes below its root counted, then built in place.
    const std::vector<size_t> offset =
        core::mortonTaskOffsets(codes.data(), levels, kSurfaceTreeLeaf, kSurfaceTreeMaxLevels, taskThreads);
    tree.nodes.resize(offset.back());
    for (const core::MortonTop::Inner& in : levels.inner)
        tree.nodes[in.at] = cellOf(Box{}, uint32_t(in.child), 0u);
    std::vector<uint32_t> deepest(tasks.size(), 0u);
    core::parallelChunks(tasks.size(), 1, taskThreads, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k) {
            Subtree part{codes, order, corners};
            size_t next = offset[k];
            part.build(tree.nodes, next, tasks[k].at, tasks[k].first, tasks[k].end, tasks[k].depth);
            deepest[k] = part.deepest;
        }
    });
    for (auto in = levels.inner.rbegin(); in != levels.inner.rend(); ++in) {
        sh::Cell& n = tree.nodes[in->at];
        Box box = boxOf(tree.nodes[n.first]);
        box.add(boxOf(tree.nodes[n.first + 1]));
        n = cellOf(box, n.first, 0u);
    }
    for (const uint32_t d : deepest) tree.levels = std::max(tree.levels, d);
    if (tree.levels > kSurfaceTreeMaxLevels) throw std::logic_error("the surface tree's depth guard failed");
    tree.order = std::move(order);
    return tree;
}

}  // namespace rthdist::gpu_algo
