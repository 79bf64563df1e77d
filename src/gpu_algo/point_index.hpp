// A point set sorted into the cells of its own grid on the device (the index
// space of RT-HDIST, design.md §2), and the set a prepared call or a one-shot
// call holds: its index, the buffers it owns, the float points behind it.
// Data only; IndexBuild (index_build.hpp) fills them.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/index_space.hpp"
#include "gpu/buffer.hpp"
#include "gpu_algo/scratch.hpp"
#include "gpu_algo/set_points.hpp"
#include "rthdist_shared.h"

namespace rthdist::gpu {
class HostImport;
}

namespace rthdist::gpu_algo {

using gpu::Buffer;
namespace sh = rthdist::shared;

// Density-robust index (issue 17): a uniform grid over the bounding box puts a
// dense cluster into a few cells when a stray point stretches the box. A cell
// of more than kCrowdedCell points (not all one point) switches the index to
// leaves: crowded cells are cut into sub-cells of their own tight box until no
// leaf that can split holds more than kLeafMax points. The neighbourhood pass
// scans at most kCrowdedCell points of a cell (a larger one is split, or holds
// copies of one point, whose first copy stands for all), so no stage's
// work per query depends on how many points share a grid cell. (The Dragon's
// fullest cell holds 134 points; even data stays on the grid path.)
inline constexpr uint32_t kCrowdedCell = 512;
// A crowded cell's leaves in groups of at most this many consecutive leaves,
// each with the union of their boxes (leaf_groups.comp): the neighbourhood
// pass tests a group's box before its leaves' (issue 33: the crowded sphere's
// cells hold up to ~1,700 leaves; one test per leaf kept 10.7 % of its
// queries out of the pass).
inline constexpr uint32_t kLeafGroupLeaves = 32;
// The neighbourhood pass makes at most this many box tests (leaf groups and
// leaves) in one crowded cell; past them the cell contributes what it
// scanned and the query is left to the rays.
inline constexpr uint32_t kCullCellTests = 1024;
inline constexpr uint32_t kLeafMax = RTHDIST_LEAF_MAX;
// Each round narrows a leaf >= 2x per axis; past it: bigger leaves.
inline constexpr int kMaxSplitRounds = 12;
// Points per host work item (the host's copies and bounds).
inline constexpr size_t kHostChunk = size_t(1) << 16;
// A set of more points is not staged whole in host-visible memory (a
// pinned buffer of 16 bytes a point, allocated per call): its bounds come
// from one read on the host and its points go up through one reused host
// buffer of kUploadChunkPoints packed points (12 bytes each), in chunks of
// half of it: the host writes one half while the device copies the other
// into a chunk-sized device buffer and makes records of it
// (IndexBuild::uploadChunked).
inline constexpr size_t kChunkedUploadPoints = size_t(1) << 23;
inline constexpr size_t kUploadChunkPoints = size_t(1) << 23;

struct PointIndex;

// The device memory of a set's index: its own (a prepared set, exact
// sizes) or the workspace's for set A or B (one-shot sets, reused and grown
// by the next call).
struct SetBuffers {
    Buffer sorted, sortedKeys, dense, cells;
    Buffer sorted2, sortedKeys2, leaves0, leaves1;  // the leaf split's ping-pong
    Buffer groupFirst;                              // a split index's first leaf group per grid key
    Buffer leafGroups;                              // and its leaf groups (LeafGroup)
    struct Level {
        Buffer cells, fineFirst;
    };
    std::deque<Level> levels;  // search level j at [j - 1] (deque: stable addresses)

    // Device bytes held.
    [[nodiscard]] uint64_t bytes() const;
    // Drops the buffers `ix` does not use (after a leaf split).
    void releaseUnused(const PointIndex& ix);
};

struct PointIndex {
    uint32_t n = 0;
    core::GridSpec grid;
    core::Bounds bounds;
    Buffer* sorted = nullptr;      // vec4: xyz, w = original index bits (cell order)
    Buffer* dense = nullptr;       // uint per key: end of the key's cell
    Buffer* groupFirst = nullptr;  // split: uint per key, the first leaf group of a crowded cell
    Buffer* groups = nullptr;      // split: LeafGroup per group of a crowded cell's leaves
    // A large set staged by the host: its points, still on the host, which
    // buildIndexes uploads in chunks (empty: staged whole, or ingested).
    std::span<const glm::vec3> hostSource;
    int hostSourceBits = 0;   // its bit count as asked (<= 0: chosen once its bounds are known)
    Buffer* cells = nullptr;  // Cell per occupied cell
    uint32_t numCells = 0;
    uint64_t cellCapacity = 0;                // room of `cells` at the build: min(n, keys)
    Buffer* sortedKeys = nullptr;             // fine key per sorted point (builds coarser levels)
    std::string name;                         // "A", "B" or "set#N": names its buffers and its messages
    BuildScratch* scratch = nullptr;          // its build's scratch (the workspace's for A or B)
    const gpu::HostImport* source = nullptr;  // ingest: the caller's array imported in place, if it could be
    // Where its buffers live: the workspace's (one-shot sets, reused by the
    // next call, with room to grow) or a prepared set's own (owned: exact sizes).
    SetBuffers* store = nullptr;
    bool owned = false;
    // Leaves: `cells` are sub-cells of crowded grid cells (still contiguous
    // runs inside their grid cells), searched directly while the radius is
    // small; minEdge is the narrowest split sub-cell's edge (first radius).
    bool split = false;
    double minEdge = 0.0;
    // Its points lie in space order (the index build's keys and scatter
    // passes then take them spread; IndexBuild::setGrid decides).
    bool spaceOrder = false;
    // Search cells by level j >= 1 (edge s * 2^j), built on first use.
    struct Level {
        Buffer* cells = nullptr;
        Buffer* fineFirst = nullptr;  // uint per cell: its first level-0 cell
        uint32_t count = 0;
    };
    std::vector<Level> levels;
};

// A set indexed on the device (DeviceSet in gpu_hausdorff.hpp): its index,
// the buffers it owns (prepared) and the float points the device holds.
struct DeviceSet {
    DeviceSet() = default;
    DeviceSet(const DeviceSet&) = delete;  // ix.store may point to `own`
    DeviceSet& operator=(const DeviceSet&) = delete;

    SetBuffers own;  // a prepared set's buffers (empty for one-shot sets)
    PointIndex ix;

    // Names the set and says where its build's scratch and its index's
    // buffers live: the workspace's `shared` ones (a one-shot set) or, with
    // shared null, its own (owned: a prepared set, exact sizes).
    void place(std::string name, BuildScratch& scratch, SetBuffers* shared) {
        ix.name = std::move(name);
        ix.scratch = &scratch;
        ix.owned = shared == nullptr;
        ix.store = shared != nullptr ? shared : &own;
    }

    std::span<const glm::vec3> input;   // the backend's input (float, before the scale)
    std::vector<glm::vec3> scaledCopy;  // input * scale when scale != 1
    std::span<const glm::vec3> points;  // what the device holds: input or scaledCopy
    double scale = 1.0;
    // A set prepared from device input: its own copy of the view's bytes
    // (set_points.hpp reads witnesses there after the embedder's call returned).
    Buffer inputCopy;
    SetPoints pts;  // where the host reads its points: `points`, or the embedder's buffer (device input)
};

// The grid as the shaders read it (rthdist_shared.h).
[[nodiscard]] sh::GridParams gridParams(const core::GridSpec& g);

}  // namespace rthdist::gpu_algo
