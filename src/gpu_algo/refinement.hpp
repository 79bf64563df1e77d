// Step 4 of RT-HDIST on the device (refine_args.comp, refine.comp,
// resolve.comp): the exact scan of the (query, cell) pairs the rays
// appended, sized by the device (indirect dispatch), with the early break;
// then every active query resolved: exact, dead, or on to the next radius.
// The search's far tail skips the rays: every open query scans all cells of
// one level (tail_scan.comp), or every target (sweep_targets.comp), and is
// then settled.
#pragma once

#include "gpu_algo/direction.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

class Refinement {
public:
    explicit Refinement(Workspace& workspace) : m_ws(workspace) {}

    // Records the refinement of one radius: the pairs that fit are scanned
    // exactly (as many groups as the device counted pairs for), then every
    // active query is resolved (exact, dead, or on to the next radius) into
    // the other active buffer. sameLevel: the radius before searched this
    // level too (the search skipped the cells within each query's rLo).
    void cmdRefine(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool coarse, float r,
                   bool sameLevel, Buffer& pairs, uint64_t pairCapacity, uint32_t numActive);

    // Records the far tail's scan: each of the numActive open queries scans
    // every cell of level `lv` (coarse: through its level-0 cells), then all
    // are resolved at radius +inf (exact or dead; none goes on). One
    // workgroup per query: numActive at most the device's maxGroupsX.
    void cmdTailScan(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool coarse,
                     uint32_t numActive);

    // Records the sweep: each of the numActive open queries against every
    // target of the direction (sweep_targets.comp), then all are resolved at
    // radius +inf (exact or dead; none goes on).
    void cmdSweep(VkCommandBuffer cmd, DirectionRun& d, uint32_t numActive);

private:
    // Every active query resolved at `radius` (resolve.comp): exact, dead,
    // or into the other active buffer for the next radius (a query that lost
    // pairs keeps its rLo only when sameLevel, resolve.comp).
    void cmdResolve(VkCommandBuffer cmd, DirectionRun& d, uint32_t numActive, float radius, bool sameLevel);

    Workspace& m_ws;
};

}  // namespace rthdist::gpu_algo
