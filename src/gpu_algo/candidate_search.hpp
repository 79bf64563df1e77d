// Step 3 of RT-HDIST on the device: the search cells' boxes grown by a
// radius R in a BLAS (refitted while the level stays, rebuilt when it
// changes), one ray per active query (ray query or ray-tracing pipeline);
// every reported cell within R becomes a (query, cell) pair for the
// refinement. R grows until no query is active.
#pragma once

#include <cstdint>

#include "gpu_algo/direction.hpp"
#include "gpu_algo/index_build.hpp"
#include "gpu_algo/refinement.hpp"
#include "gpu_algo/workspace.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::gpu_algo {

// Radii before a search is declared not converging.
inline constexpr uint32_t kMaxIterations = 4096;

// What one radius of the search reported.
struct IterationCounts {
    uint64_t pairs = 0;      // (query, cell) pairs the rays appended (some may not fit)
    uint32_t stillOpen = 0;  // queries going on to the next radius (or retrying)
};

class CandidateSearch {
public:
    CandidateSearch(Workspace& workspace, IndexBuild& indexBuild, Refinement& refinement)
        : m_ws(workspace), m_index(indexBuild), m_refine(refinement) {}

    // Candidate search with a growing radius until no query is active.
    void runSearch(DirectionRun& d, uint32_t numActive, const CallOptions& options, double progressFrom,
                   double progressTo);

    // One radius in one submission: the search (cmdSearch), then the
    // refinement sized by the device from the pairs the rays appended
    // (cmdRefine, indirect dispatch), then the resolution of every active
    // query. The host reads the counts once, at the end.
    IterationCounts iterate(DirectionRun& d, int level, bool sameLevel, double radius, Buffer& pairs,
                            uint64_t pairCapacity, uint32_t numActive);

    // Records the search of one radius: the level's boxes grown by the
    // radius, the BLAS refitted (same level) or rebuilt, one ray per active
    // query; the rays append (query, cell) pairs.
    void cmdSearch(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool sameLevel,
                   double radius, Buffer& pairs, uint64_t pairCapacity, uint32_t numActive);

    // One ray per active slot, in traces of at most maxRayDispatch rays
    // (each trace sees its first slot in SearchPush::slotBase).
    void cmdTraceRaysSplit(VkCommandBuffer cmd, sh::SearchPush sp);

private:
    Workspace& m_ws;
    IndexBuild& m_index;
    Refinement& m_refine;
};

}  // namespace rthdist::gpu_algo
