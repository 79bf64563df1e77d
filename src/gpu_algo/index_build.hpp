// Step 1 of RT-HDIST on the device: a point set into its index (cell keys,
// counting sort over the dense key table, run-length encoding into cells
// with tight boxes, the index's self-check), from host arrays staged by the
// host (index_build.cpp) or ingested by the device (ingest.cpp); crowded
// cells cut into leaves (leaf_split.cpp); coarser search levels built on
// first use (search_levels.cpp).
#pragma once

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "gpu_algo/point_index.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

// The dense key table costs O(2^(3k)) to clear and scan: an automatic bit
// count keeps it within a few entries per point.
[[nodiscard]] int clampedBits(int bits, uint32_t n);

class IndexBuild {
public:
    explicit IndexBuild(Workspace& workspace) : m_ws(workspace) {}

    // Host half of an index build: the points into the set's staging buffer
    // (vec4) in one parallel pass that also takes their bounds, then the bit
    // count and the grid (past kChunkedUploadPoints: nothing yet, the points
    // go up in chunks whose pass takes the bounds, uploadChunked, and the
    // grid follows there). Nothing is submitted.
    void stageIndex(PointIndex& ix, std::span<const glm::vec3> pts, int bits);

    // The bounds of per-thread boxes [lo, hi] (reduced into lo[0], hi[0]),
    // then the bit count (`bits`, or chosen from pts when <= 0) and the grid.
    void setGrid(PointIndex& ix, std::span<const glm::vec3> pts, std::span<glm::vec3> lo,
                 std::span<glm::vec3> hi, int bits);

    // The staged points' copy to the device (before cmdBuildIndex, with a
    // barrier between: several sets' copies run back to back).
    void cmdUpload(VkCommandBuffer cmd, PointIndex& ix);

    // A large set's upload (ix.hostSource, set by stageIndex past
    // kChunkedUploadPoints): chunks of half of kUploadChunkPoints, packed
    // floats copied by the host's threads into one reused host buffer, each
    // copied by a submission of its own into one chunk-sized device buffer
    // and turned into vec4 records in the set's points there (ingest.comp:
    // 12 bytes a point cross the bus, not 16); the same pass takes the set's
    // bounds, then its grid follows (setGrid). buildIndexes runs it before
    // the build's submission.
    void uploadChunked(PointIndex& ix);

    // Device half of an index build, recorded into `cmd` after the upload:
    // cell keys, counting sort over the dense key table, run-length encoding
    // into cells with tight boxes, the self-check. Counters go to `blk`;
    // scratch buffers are the set's own (ix.scratch), so two sets can be
    // built in one submission.
    void cmdBuildIndex(VkCommandBuffer cmd, PointIndex& ix, const CounterBlock& blk);

    // After the build's submission: the self-check's verdict and the cell
    // count from `blk`; true when crowded cells are to be split into leaves
    // (splitLeaves, own submissions).
    [[nodiscard]] bool finishIndex(PointIndex& ix, const CounterBlock& blk);

    // Indexes the staged sets (one or two) in one submission: both uploads
    // back to back, then each build; then each set's checks and leaves.
    // (At most one set per counter block: two.)
    void buildIndexes(std::span<PointIndex* const> sets, bool ingested = false);

    // One Cell per run of equal keys (heads flagged and scanned before):
    // small cells' boxes by their head thread, large cells' in parallel;
    // each set's (one push each) steps side by side.
    void cmdCellBuild(VkCommandBuffer cmd, std::span<const sh::CellsPush> cps);

    // Self-check of an index, recorded after its build (check_index.comp);
    // verifyIndex reads the verdict once the submission has completed.
    void cmdCheckIndex(VkCommandBuffer cmd, const PointIndex& ix, const CounterBlock& blk);

    void verifyIndex(const PointIndex& ix, uint64_t cellCapacity, const CounterBlock& blk);

    // The device ingest path (ingest.comp) for packed float host arrays:
    // the device reads each array from a host-visible copy (the host's only
    // pass over the points) or, with imports on (gpu/host_import.hpp), where
    // it lies. The device uploads it, checks it and takes its bounds. Sets
    // `ix.n`; nothing is submitted.
    void stageSource(PointIndex& ix, std::span<const glm::vec3> pts);

    // Records the upload of a staged source (stageSource) into device memory.
    void cmdUploadSource(VkCommandBuffer cmd, const PointIndex& ix);

    // Records the ingest of an uploaded source into the set's vec4 points
    // and its summary in `blk`. `source`: the points' device address (three
    // floats every `stride` bytes; device input, device_input.hpp); 0: the
    // uploaded copy (packed).
    void cmdIngest(VkCommandBuffer cmd, const PointIndex& ix, const CounterBlock& blk,
                   VkDeviceAddress source = 0, uint32_t stride = 12);

    // After the ingest's submission: the set's bounds from `blk`, or the
    // error naming its first point that is not finite (as summarizeSet
    // words it for host input).
    void finishIngest(PointIndex& ix, const CounterBlock& blk);

    // Cuts the crowded cells of each set (one or two) into leaves
    // (leaf_*.comp), round by round, then checks the indexes again. Each
    // round is two submissions: a counting sort by slot inside every cell
    // that also counts the new cells, then the cells of the new order in a
    // buffer of that size. Two sets split side by side (each step's kernels
    // of both before one barrier, set k on counter block k and leaf scratch
    // k) until each holds no leaf past kLeafMax: at 200k points a set, the
    // two sets' steps cost about what one set's did, and half the
    // submissions.
    void splitLeaves(std::span<PointIndex* const> sets);

    // One set's round of a leaf split: its index, the cells, points and keys
    // in and out, its leaf scratch and counter block.
    struct LeafRound {
        PointIndex* ix = nullptr;
        Buffer* cellsIn = nullptr;
        Buffer* sortedIn = nullptr;
        Buffer* keysIn = nullptr;
        Buffer* sortedOut = nullptr;
        Buffer* keysOut = nullptr;
        Buffer* cellsOut = nullptr;
        uint64_t numSlots = 0;  // one per kept cell, 8^k <= count per split one
        LeafScratch* leaf = nullptr;
        const CounterBlock* blk = nullptr;
        std::string leafName;  // labels of its scratch buffers
    };
    // Records each set's round sort: a counting sort by slot inside every
    // cell, the new order's cell heads scanned and counted (cells_total.comp,
    // into the set's cells counter), so that the host sizes the leaves' buffer.
    void cmdSplitRound(VkCommandBuffer cmd, std::span<const LeafRound> rounds);
    // Records each set's `leaves[k]` cells of the new order into
    // rounds[k].cellsOut (sized by the host for them) and their tight boxes.
    void cmdBuildLeaves(VkCommandBuffer cmd, std::span<const LeafRound> rounds,
                        std::span<const uint32_t> leaves);

    // Search cells of level `level` (>= 1) of T, coarsened from the level
    // below on first use (coarsen.comp: head flags, scan, build).
    const PointIndex::Level& searchLevel(PointIndex& T, int level);

    // The search cells of `level` (0: the index's own cells or leaves).
    PointIndex::Level levelCells(PointIndex& T, int level);

private:
    Workspace& m_ws;
};

}  // namespace rthdist::gpu_algo
