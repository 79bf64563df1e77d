#include "gpu_algo/index_build.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/parallel.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {

void IndexBuild::cmdSplitRound(VkCommandBuffer cmd, const PointIndex& ix, const LeafRound& r) {
    LeafScratch& leaf = m_ws.scratch.leaves;
    const uint64_t n = ix.n;
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "leaf split");
    Buffer& slotBase = m_ws.grow(leaf.slotBase, VkDeviceSize(ix.numCells) * 4, "leaf.slotBase");
    Buffer& dense = m_ws.grow(leaf.slotDense, VkDeviceSize(r.numSlots) * 4, "leaf.slotDense");
    Buffer& slotKeys = m_ws.grow(leaf.slotKeys, n * 4, "leaf.slotKeys");
    Buffer& outSlotKeys = m_ws.grow(leaf.outSlotKeys, n * 4, "leaf.outSlotKeys");
    Buffer& flags = m_ws.grow(leaf.flags, n * 4, "leaf.flags");
    sh::SplitPush sp{r.cellsIn->address(),
                     slotBase.address(),
                     r.sortedIn->address(),
                     r.keysIn->address(),
                     dense.address(),
                     slotKeys.address(),
                     r.sortedOut->address(),
                     r.keysOut->address(),
                     outSlotKeys.address(),
                     m_ws.blocks[0].addr(RTHDIST_CTR_MIN_EDGE),
                     ix.numCells,
                     ix.n,
                     kLeafMax};
    m_ws.dispatch(cmd, Kernel::kLeafSlots, sp, ix.numCells);
    vkCmdFillBuffer(cmd, dense.handle(), 0, VkDeviceSize(r.numSlots) * 4, 0);
    m_ws.barrier(cmd);
    m_ws.cmdScan(cmd, slotBase.address(), ix.numCells, leaf.scanSlots, "leaf.scanSlots");
    m_ws.barrier(cmd);
    m_ws.dispatch(cmd, Kernel::kLeafKeys, sp, ix.n);
    m_ws.barrier(cmd);
    m_ws.cmdScan(cmd, dense.address(), uint32_t(r.numSlots), leaf.scanDense, "leaf.scanDense");
    m_ws.barrier(cmd);
    m_ws.dispatch(cmd, Kernel::kLeafScatter, sp, ix.n);
    m_ws.barrier(cmd);
    sh::CellsPush cp{r.sortedOut->address(),
                     outSlotKeys.address(),
                     flags.address(),
                     dense.address(),
                     0,  // cells and boundsU: the leaf build's (cmdBuildLeaves, sized by the leaves)
                     m_ws.cellsCounterAddr(),
                     m_ws.maxCountAddr(),
                     0,
                     m_ws.blocks[0].addr(RTHDIST_CTR_LARGE_CELLS),
                     ix.n,
                     ix.n};
    m_ws.dispatch(cmd, Kernel::kCellHeads, cp, ix.n);
    m_ws.barrier(cmd);
    m_ws.cmdScan(cmd, flags.address(), ix.n, leaf.scanFlags, "leaf.scanFlags");
    m_ws.barrier(cmd);
    m_ws.pipelines.cmdDispatch(cmd, Kernel::kCellsTotal, &cp, sizeof(cp), 1);
}

void IndexBuild::cmdBuildLeaves(VkCommandBuffer cmd, const PointIndex& ix, const LeafRound& r,
                                uint32_t leaves) {
    LeafScratch& leaf = m_ws.scratch.leaves;
    const uint64_t n = ix.n;
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "leaf build");
    sh::CellsPush cp{r.sortedOut->address(),
                     m_ws.grow(leaf.outSlotKeys, n * 4, "leaf.outSlotKeys").address(),
                     m_ws.grow(leaf.flags, n * 4, "leaf.flags").address(),
                     m_ws.grow(leaf.slotDense, VkDeviceSize(r.numSlots) * 4, "leaf.slotDense").address(),
                     r.cellsOut->address(),
                     m_ws.cellsCounterAddr(),
                     m_ws.maxCountAddr(),
                     m_ws.grow(leaf.boundsU, VkDeviceSize(leaves) * 24, "leaf.boundsU").address(),
                     m_ws.blocks[0].addr(RTHDIST_CTR_LARGE_CELLS),
                     ix.n,
                     leaves};
    cmdCellBuild(cmd, cp);
}

void IndexBuild::splitLeaves(PointIndex& ix) {
    const VkDeviceSize n = ix.n;
    Buffer* sorted[2] = {ix.sorted, &m_ws.setBuffer(ix, ix.store->sorted2, ".sorted2", n * 16)};
    Buffer* gridKeys[2] = {ix.sortedKeys, &m_ws.setBuffer(ix, ix.store->sortedKeys2, ".sortedKeys2", n * 4)};
    Buffer* leaves[2] = {&ix.store->leaves0, &ix.store->leaves1};  // sized each round by its leaves
    Buffer* cells = ix.cells;
    int cur = 0;
    m_ws.counters().minEdge = 0x7f800000u;  // +inf
    for (int round = 0; round < kMaxSplitRounds; ++round) {
        // All slots together: one per kept cell, 8^k <= count per split one.
        const uint64_t numSlots = uint64_t(ix.n) + ix.numCells;
        gpu::requireWithin(numSlots, uint64_t(UINT32_MAX), "slots of a leaf split", "2^32 - 1");
        const LeafRound r{cells,           sorted[cur],       gridKeys[cur],
                          sorted[1 - cur], gridKeys[1 - cur], leaves[round % 2],
                          numSlots};
        m_ws.counters().maxCount = 0;
        m_ws.counters().largeCells = 0;
        VkCommandBuffer cmd = m_ws.ctx.begin();
        cmdSplitRound(cmd, ix, r);
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
        // The leaves of this round, counted on the device: their buffer and
        // the large ones' box reduction sized by them, then built.
        const uint32_t count = m_ws.counters().cells;
        const char* name = round % 2 == 0 ? ".leaves0" : ".leaves1";
        m_ws.setBuffer(ix, *r.cellsOut, name, VkDeviceSize(std::max<uint32_t>(count, 1)) * sizeof(sh::Cell));
        cmd = m_ws.ctx.begin();
        cmdBuildLeaves(cmd, ix, r, count);
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
        cur = 1 - cur;
        cells = r.cellsOut;
        ix.numCells = m_ws.counters().cells;
        if (m_ws.counters().maxCount <= kLeafMax) break;
    }
    ix.sorted = sorted[cur];
    ix.sortedKeys = gridKeys[cur];
    ix.cells = cells;
    ix.split = true;
    const float edge = std::bit_cast<float>(m_ws.counters().minEdge);
    ix.minEdge = std::isfinite(edge) ? double(edge) : 0.0;
    // The neighbourhood pass's view of the crowded cells: their leaves in
    // groups (leaf_groups.comp), and the first group of each cell by grid
    // key, which first holds the first leaf of each cell (leaf_first.comp).
    // A crowded cell of L leaves has ceil(L / G) groups, and at most
    // n / (kCrowdedCell + 1) cells are crowded.
    const uint32_t groupLeaves = std::max<uint32_t>(1, m_ws.leafGroupLeaves);
    const VkDeviceSize groupBound = ix.numCells / groupLeaves + n / (kCrowdedCell + 1) + 1;
    ix.groupFirst =
        &m_ws.setBuffer(ix, ix.store->groupFirst, ".groupFirst", VkDeviceSize(1u << (3 * ix.grid.bits)) * 4);
    ix.groups = &m_ws.setBuffer(ix, ix.store->leafGroups, ".leafGroups", groupBound * sizeof(sh::LeafGroup));
    Buffer& flags = m_ws.grow(m_ws.scratch.leaves.flags, n * 4, "leaf.flags");
    VkCommandBuffer cmd = m_ws.ctx.begin();
    const sh::LeafFirstPush lp{ix.cells->address(), ix.sortedKeys->address(), ix.groupFirst->address(),
                               ix.numCells, 0u};
    m_ws.dispatch(cmd, Kernel::kLeafFirst, lp, ix.numCells);
    m_ws.barrier(cmd);
    sh::LeafGroupPush gp{ix.cells->address(), ix.sortedKeys->address(),
                         ix.dense->address(), ix.groupFirst->address(),
                         flags.address(),     ix.groups->address(),
                         ix.numCells,         groupLeaves,
                         kCrowdedCell,        0u};
    m_ws.dispatch(cmd, Kernel::kLeafGroups, gp, ix.numCells);
    m_ws.barrier(cmd);
    m_ws.cmdScan(cmd, flags.address(), ix.numCells, m_ws.scratch.leaves.scanFlags, "leaf.scanFlags");
    m_ws.barrier(cmd);
    for (uint32_t mode : {1u, 2u}) {
        gp.mode = mode;
        m_ws.dispatch(cmd, Kernel::kLeafGroups, gp, ix.numCells);
        m_ws.barrier(cmd);
    }
    cmdCheckIndex(cmd, ix, m_ws.blocks[0]);
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
    verifyIndex(ix, ix.n, m_ws.blocks[0]);
    // A one-shot set's spent ping-pong halves serve the rest of the call
    // (Workspace::spare); a prepared set drops them (SetBuffers::releaseUnused).
    if (!ix.owned) {
        m_ws.recycle(*sorted[1 - cur]);
        m_ws.recycle(*gridKeys[1 - cur]);
    }
}

}  // namespace rthdist::gpu_algo
