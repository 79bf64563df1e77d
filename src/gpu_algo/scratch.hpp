// The typed scratch buffers of the GPU stages. Each stage's buffers are
// named members, not names in a map; they live in the Workspace, are reused
// by the next call and only grow (Workspace::grow). A buffer is replaced
// only between submissions: inside one command buffer each member serves
// one purpose.
#pragma once

#include <array>
#include <vector>

#include "gpu/buffer.hpp"

namespace rthdist::gpu_algo {

using gpu::Buffer;

// The block sums of an exclusive scan, one buffer per recursion level.
using ScanScratch = std::vector<Buffer>;

// One index build (index_build.cpp, ingest.cpp). Two exist so that two sets
// are built in one submission.
struct BuildScratch {
    Buffer staging;  // host: the points as vec4 (host path, sets of at most kChunkedUploadPoints)
    Buffer source;   // host: the caller's packed floats (device ingest)
    Buffer raw;      // the packed floats on the device (device ingest)
    Buffer points;   // vec4 points before the sort
    Buffer keys;     // cell key per point
    Buffer flags;    // cell-head flags, scanned into cell numbers
    Buffer boundsU;  // the parallel box reduction of large cells (6 uints per cell)
    ScanScratch scanKeys, scanFlags;
};

// The rounds of a leaf split (leaf_split.cpp).
struct LeafScratch {
    Buffer slotKeys, outSlotKeys, flags, slotBase, slotDense, boundsU;
    ScanScratch scanSlots, scanDense, scanFlags;
};

// The coarsening of a search level (search_levels.cpp).
struct LevelScratch {
    Buffer flags;
    ScanScratch scan;
};

// One direction's query states and active lists (ping-pong); per-point
// calls: each query's nearest target, written by the self-check, and its
// host copy.
struct DirectionBuffers {
    Buffer state;
    std::array<Buffer, 2> active;
    Buffer nearest;
    Buffer nearestHost;
    Buffer above;      // a floor call's queries above it (check_queries.comp), device
    Buffer aboveHost;  // and its read-back
    Buffer band;       // host: the certificate's band (check_queries.comp)
};

// The certificate's brute force (certificate_pass.hpp): its band queries and
// the candidates it found, both in host memory.
struct CertificateScratch {
    Buffer entries;
    Buffer candidates;
};

// The candidate search, refinement and per-point read-back.
struct SearchScratch {
    Buffer pairs;       // (query, cell) pairs the rays append
    Buffer aabbs;       // the search cells' grown boxes (BLAS input)
    Buffer refineArgs;  // the refinement's indirect dispatch
    Buffer fetched;     // host: the self-check's points of device input (SetPoints::cmdCopy)
};

// computeBatch's small pairs (small_pairs.hpp).
struct BatchScratch {
    Buffer directions;  // host: BatchDirection per direction
    Buffer chunks;      // host: uvec2 per workgroup (seed chunks, then the scans')
    Buffer maxPacked;   // uint64 per direction
    Buffer nearest;     // uint per query of every direction
    Buffer witnesses;   // host: uvec4 per direction
    Buffer perPoint;    // host: `nearest` read back (per-point calls)
    Buffer staged;      // host: records of a one-shot pair's host arrays
    Buffer records;     // the same on the device
};

struct Scratch {
    std::array<BuildScratch, 2> builds;  // set A (and every single build), set B
    Buffer uploadChunk;    // host: two chunks of a large set's packed floats (IndexBuild::uploadChunked)
    Buffer uploadPacked;   // one chunk of them on the device, which ingest.comp turns into vec4 records
    Buffer uploadSummary;  // ingest.comp's summary of those chunks (bounds come from the host's pass)
    std::array<LeafScratch, 2> leaves;  // set A (and every single split), set B (IndexBuild::splitLeaves)
    LevelScratch levels;
    std::array<DirectionBuffers, 2> directions;  // A->B, B->A
    SearchScratch search;
    CertificateScratch certificate;
    BatchScratch batch;
};

}  // namespace rthdist::gpu_algo
