#include "gpu_algo/surface_tree.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/float_box.hpp"
#include "core/parallel.hpp"
#include "rthdist_morton.h"

namespace rthdist::gpu_algo {

namespace {

namespace sh = rthdist::shared;

constexpr size_t kChunk = size_t(1) << 15;
constexpr uint32_t kMortonBits = 30;  // 10 per axis
constexpr uint32_t kRadixBits = 10;   // three passes over the codes
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

}  // namespace

SurfaceTree buildSurfaceTree(std::span<const glm::vec3> corners, int threads) {
    const size_t triangles = corners.size() / 3;
    if (triangles == 0 || corners.size() % 3 != 0 || triangles >= (size_t(1) << 30))
        throw std::length_error("the surface tree takes 1 to 2^30 - 1 triangles");
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

    // The levels' sizes, leaves first; laid out root first.
    std::vector<size_t> sizes{(triangles + kSurfaceTreeLeaf - 1) / kSurfaceTreeLeaf};
    while (sizes.back() > 1) sizes.push_back((sizes.back() + 1) / 2);
    if (sizes.size() > kSurfaceTreeMaxLevels) throw std::length_error("the surface tree is too deep");
    std::vector<size_t> offset(sizes.size(), 0);
    for (size_t k = sizes.size() - 1; k-- > 0;) offset[k] = offset[k + 1] + sizes[k + 1];

    SurfaceTree tree;
    tree.levels = uint32_t(sizes.size());
    tree.nodes.resize(offset[0] + sizes[0]);
    core::parallelChunks(sizes[0], kChunk / kSurfaceTreeLeaf, threads, [&](size_t begin, size_t end, int) {
        for (size_t leaf = begin; leaf < end; ++leaf) {
            const size_t first = leaf * kSurfaceTreeLeaf;
            const size_t count = std::min<size_t>(kSurfaceTreeLeaf, triangles - first);
            Box b;
            for (size_t i = first; i < first + count; ++i) b.add(triangleBox(corners, order[i]));
            tree.nodes[offset[0] + leaf] = cellOf(b, uint32_t(first), uint32_t(count));
        }
    });
    for (size_t k = 1; k < sizes.size(); ++k) {
        core::parallelChunks(sizes[k], kChunk, threads, [&](size_t begin, size_t end, int) {
            for (size_t j = begin; j < end; ++j) {
                const size_t left = offset[k - 1] + 2 * j;
                sh::Cell& node = tree.nodes[offset[k] + j];
                if (2 * j + 1 == sizes[k - 1]) {
                    node = tree.nodes[left];  // the lone last node, carried up as it is
                    continue;
                }
                Box b = boxOf(tree.nodes[left]);
                b.add(boxOf(tree.nodes[left + 1]));
                node = cellOf(b, uint32_t(left), 0u);
            }
        });
    }
    tree.order = std::move(order);
    return tree;
}

}  // namespace rthdist::gpu_algo
