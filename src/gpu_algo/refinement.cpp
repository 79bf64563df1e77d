#include "gpu_algo/refinement.hpp"

#include <algorithm>
#include <limits>

namespace rthdist::gpu_algo {

void Refinement::cmdRefine(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool coarse,
                           float r, bool sameLevel, Buffer& pairs, uint64_t pairCapacity,
                           uint32_t numActive) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "refinement");
    Buffer& args = m_ws.grow(m_ws.scratch.search.refineArgs, 16, "refineArgs");
    sh::RefineArgsPush ap{d.blk.device, args.address(), uint32_t(pairCapacity),
                          std::max<uint32_t>(1, m_ws.ctx.limits().maxGroupsX)};
    m_ws.pipelines.cmdDispatch(cmd, Kernel::kRefineArgs, &ap, sizeof(ap), 1);
    gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                    VK_ACCESS_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
    sh::RefinePush rp{};
    setRadiusAddresses(rp, d, lv, pairs);
    rp.fineCells = d.T.cells->address();
    rp.fineFirst = coarse ? lv.fineFirst->address() : 0;
    rp.pairCapacity = uint32_t(pairCapacity);
    rp.lowerBound2 = d.lowerBound2;
    rp.numSearchCells = lv.count;
    rp.numFineCells = d.T.numCells;
    rp.mutant = m_ws.mutant ? 1u : 0u;
    m_ws.pipelines.cmdDispatchIndirect(cmd, Kernel::kRefine, &rp, sizeof(rp), args.handle(), 0);
    m_ws.barrier(cmd);
    cmdResolve(cmd, d, numActive, r, sameLevel);
}

void Refinement::cmdTailScan(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool coarse,
                             uint32_t numActive) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "tail scan");
    const sh::TailScanPush tp{d.Q.sorted->address(),
                              d.T.sorted->address(),
                              lv.cells->address(),
                              d.state->address(),
                              d.active[d.cur]->address(),
                              d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                              d.T.cells->address(),
                              coarse ? lv.fineFirst->address() : 0,
                              numActive,
                              d.lowerBound2,
                              lv.count,
                              d.T.numCells};
    m_ws.pipelines.cmdDispatch(cmd, Kernel::kTailScan, &tp, sizeof(tp), numActive);  // a group per query
    m_ws.barrier(cmd);
    // Everything was scanned (no query lost pairs here: the scan appends none).
    cmdResolve(cmd, d, numActive, std::numeric_limits<float>::infinity(), true);
}

void Refinement::cmdSweep(VkCommandBuffer cmd, DirectionRun& d, uint32_t numActive) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "sweep");
    const sh::SweepPush sp{d.Q.sorted->address(),
                           d.T.sorted->address(),
                           d.state->address(),
                           d.active[d.cur]->address(),
                           d.T.n,
                           numActive};
    const uint64_t perBlock = uint64_t(RTHDIST_WG) * RTHDIST_SWEEP_PER_THREAD;
    const uint64_t items = (uint64_t(d.T.n) + perBlock - 1) / perBlock * numActive;
    const uint32_t groups =
        uint32_t(std::clamp<uint64_t>(items, 1, std::max<uint32_t>(1, m_ws.ctx.limits().maxGroupsX)));
    m_ws.pipelines.cmdDispatch(cmd, Kernel::kSweepTargets, &sp, sizeof(sp),
                               groups);  // grid-stride over items
    m_ws.barrier(cmd);
    cmdResolve(cmd, d, numActive, std::numeric_limits<float>::infinity(), true);
}

void Refinement::cmdResolve(VkCommandBuffer cmd, DirectionRun& d, uint32_t numActive, float radius,
                            bool sameLevel) {
    const sh::ResolvePush rs{d.state->address(),
                             d.active[d.cur]->address(),
                             d.active[1 - d.cur]->address(),
                             d.blk.device,
                             d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                             numActive,
                             radius,
                             d.lowerBound2,
                             sameLevel ? 1u : 0u};
    m_ws.dispatchSearched(cmd, Kernel::kResolve, rs, numActive, d.blk);
}

}  // namespace rthdist::gpu_algo
