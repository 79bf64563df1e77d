// Step 2 of RT-HDIST on the device (cull.comp, compact.comp): each query's
// exact nearest neighbour inside its 3x3x3 cell block, with the early break
// against the running maximum; most queries end here. The survivors are
// compacted for the candidate search.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "gpu_algo/direction.hpp"
#include "gpu_algo/query_check.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

class NeighbourhoodPass {
public:
    NeighbourhoodPass(Workspace& workspace, QueryCheck& queryCheck) : m_ws(workspace), m_check(queryCheck) {}

    // Sets up h(Q, T) (Q's points in Q's cell order are the queries): its
    // bounds, epsilon and buffers (the workspace's for `direction`: 0 for
    // A->B, 1 for B->A); nothing is recorded.
    void startDirection(DirectionRun& d, size_t direction);

    // Records the neighbourhood pass and the compaction of the survivors
    // (their slots in active[0], their count at RTHDIST_CTR_ACTIVE).
    void cmdCull(VkCommandBuffer cmd, DirectionRun& d);

    // The culls of the directions (one or two) in one submission, each
    // followed by its self-check; returns each direction's survivors.
    // (At most two directions, each with a counter block of its own.)
    std::array<uint32_t, 2> runCulls(std::span<DirectionRun* const> dirs);

private:
    Workspace& m_ws;
    QueryCheck& m_check;
};

}  // namespace rthdist::gpu_algo
