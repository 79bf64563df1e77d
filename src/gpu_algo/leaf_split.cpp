#include "gpu_algo/index_build.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/parallel.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {

namespace {

sh::SplitPush splitPush(const IndexBuild::LeafRound& r, Workspace& ws) {
    LeafScratch& leaf = *r.leaf;
    const PointIndex& ix = *r.ix;
    const uint64_t n = ix.n;
    const std::string& name = r.leafName;
    Buffer& slotBase = ws.grow(leaf.slotBase, VkDeviceSize(ix.numCells) * 4, name + ".slotBase");
    Buffer& dense = ws.grow(leaf.slotDense, VkDeviceSize(r.numSlots) * 4, name + ".slotDense");
    Buffer& slotKeys = ws.grow(leaf.slotKeys, n * 4, name + ".slotKeys");
    Buffer& outSlotKeys = ws.grow(leaf.outSlotKeys, n * 4, name + ".outSlotKeys");
    return sh::SplitPush{r.cellsIn->address(),
                         slotBase.address(),
                         r.sortedIn->address(),
                         r.keysIn->address(),
                         dense.address(),
                         slotKeys.address(),
                         r.sortedOut->address(),
                         r.keysOut->address(),
                         outSlotKeys.address(),
                         r.blk->addr(RTHDIST_CTR_MIN_EDGE),
                         ix.numCells,
                         ix.n,
                         kLeafMax};
}

}  // namespace

// Each step is recorded for every set before the barrier that ends it, so
// the sets' kernels of one step run side by side.
void IndexBuild::cmdSplitRound(VkCommandBuffer cmd, std::span<const LeafRound> rounds) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "leaf split");
    std::vector<sh::SplitPush> sp;
    std::vector<sh::CellsPush> cp;
    for (const LeafRound& r : rounds) {
        sp.push_back(splitPush(r, m_ws));
        const uint32_t n = r.ix->n;
        cp.push_back(sh::CellsPush{
            r.sortedOut->address(), sp.back().outSlotKeys,
            m_ws.grow(r.leaf->flags, VkDeviceSize(n) * 4, r.leafName + ".flags").address(), sp.back().dense,
            0,  // cells and boundsU: the leaf build's (cmdBuildLeaves, sized by the leaves)
            r.blk->addr(RTHDIST_CTR_CELLS), r.blk->addr(RTHDIST_CTR_MAX_COUNT), 0,
            r.blk->addr(RTHDIST_CTR_LARGE_CELLS), n, n});
    }
    for (size_t k = 0; k < rounds.size(); ++k) {
        m_ws.dispatch(cmd, Kernel::kLeafSlots, sp[k], rounds[k].ix->numCells);
        vkCmdFillBuffer(cmd, rounds[k].leaf->slotDense.handle(), 0, VkDeviceSize(rounds[k].numSlots) * 4, 0);
    }
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k)
        m_ws.cmdScan(cmd, sp[k].slotBase, rounds[k].ix->numCells, rounds[k].leaf->scanSlots,
                     "leaf.scanSlots");
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k) m_ws.dispatch(cmd, Kernel::kLeafKeys, sp[k], rounds[k].ix->n);
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k)
        m_ws.cmdScan(cmd, sp[k].dense, uint32_t(rounds[k].numSlots), rounds[k].leaf->scanDense,
                     "leaf.scanDense");
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k)
        m_ws.dispatch(cmd, Kernel::kLeafScatter, sp[k], rounds[k].ix->n);
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k) m_ws.dispatch(cmd, Kernel::kCellHeads, cp[k], rounds[k].ix->n);
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k)
        m_ws.cmdScan(cmd, cp[k].flags, rounds[k].ix->n, rounds[k].leaf->scanFlags, "leaf.scanFlags");
    m_ws.barrier(cmd);
    for (size_t k = 0; k < rounds.size(); ++k)
        m_ws.pipelines.cmdDispatch(cmd, Kernel::kCellsTotal, &cp[k], sizeof(sh::CellsPush), 1);
}

void IndexBuild::cmdBuildLeaves(VkCommandBuffer cmd, std::span<const LeafRound> rounds,
                                std::span<const uint32_t> leaves) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "leaf build");
    std::vector<sh::CellsPush> cp;
    for (size_t k = 0; k < rounds.size(); ++k) {
        const LeafRound& r = rounds[k];
        LeafScratch& leaf = *r.leaf;
        const VkDeviceSize n = r.ix->n;
        cp.push_back(sh::CellsPush{
            r.sortedOut->address(), m_ws.grow(leaf.outSlotKeys, n * 4, r.leafName + ".outSlotKeys").address(),
            m_ws.grow(leaf.flags, n * 4, r.leafName + ".flags").address(),
            m_ws.grow(leaf.slotDense, VkDeviceSize(r.numSlots) * 4, r.leafName + ".slotDense").address(),
            r.cellsOut->address(), r.blk->addr(RTHDIST_CTR_CELLS), r.blk->addr(RTHDIST_CTR_MAX_COUNT),
            m_ws.grow(leaf.boundsU, VkDeviceSize(leaves[k]) * 24, r.leafName + ".boundsU").address(),
            r.blk->addr(RTHDIST_CTR_LARGE_CELLS), uint32_t(n), leaves[k]});
    }
    cmdCellBuild(cmd, cp);
}

void IndexBuild::splitLeaves(std::span<PointIndex* const> sets) {
    if (sets.size() > m_ws.blocks.size() || sets.size() > m_ws.scratch.leaves.size())
        throw std::logic_error("splitLeaves: more sets than counter blocks");
    if (sets.empty()) return;
    // One set's progress: its ping-pong buffers and where its round stands.
    struct SetSplit {
        PointIndex* ix;
        LeafRound round;
        Buffer* sorted[2];
        Buffer* gridKeys[2];
        Buffer* leaves[2];  // sized each round by its leaves
        Buffer* cells;
        int cur = 0;
        bool done = false;
    };
    std::vector<SetSplit> split;
    for (size_t k = 0; k < sets.size(); ++k) {
        PointIndex& ix = *sets[k];
        const VkDeviceSize n = ix.n;
        SetSplit s{&ix,
                   {},
                   {ix.sorted, &m_ws.setBuffer(ix, ix.store->sorted2, ".sorted2", n * 16)},
                   {ix.sortedKeys, &m_ws.setBuffer(ix, ix.store->sortedKeys2, ".sortedKeys2", n * 4)},
                   {&ix.store->leaves0, &ix.store->leaves1},
                   ix.cells};
        s.round.ix = &ix;
        s.round.leaf = &m_ws.scratch.leaves[k];
        s.round.blk = &m_ws.blocks[k];
        s.round.leafName = k == 0 ? "leaf" : "leafB";
        s.round.blk->fields().minEdge = 0x7f800000u;  // +inf
        split.push_back(s);
    }
    std::vector<LeafRound> rounds;
    std::vector<uint32_t> counts;
    for (int round = 0; round < kMaxSplitRounds; ++round) {
        rounds.clear();
        for (SetSplit& s : split) {
            if (s.done) continue;
            // All slots together: one per kept cell, 8^k <= count per split one.
            const uint64_t numSlots = uint64_t(s.ix->n) + s.ix->numCells;
            gpu::requireWithin(numSlots, uint64_t(UINT32_MAX), "slots of a leaf split", "2^32 - 1");
            s.round.cellsIn = s.cells;
            s.round.sortedIn = s.sorted[s.cur];
            s.round.keysIn = s.gridKeys[s.cur];
            s.round.sortedOut = s.sorted[1 - s.cur];
            s.round.keysOut = s.gridKeys[1 - s.cur];
            s.round.cellsOut = s.leaves[round % 2];
            s.round.numSlots = numSlots;
            s.round.blk->fields().maxCount = 0;
            s.round.blk->fields().largeCells = 0;
            rounds.push_back(s.round);
        }
        if (rounds.empty()) break;
        VkCommandBuffer cmd = m_ws.ctx.begin();
        cmdSplitRound(cmd, rounds);
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
        // The leaves of this round, counted on the device: their buffer and
        // the large ones' box reduction sized by them, then built.
        counts.clear();
        for (const LeafRound& r : rounds) {
            const uint32_t count = r.blk->fields().cells;
            m_ws.setBuffer(*r.ix, *r.cellsOut, round % 2 == 0 ? ".leaves0" : ".leaves1",
                           VkDeviceSize(std::max<uint32_t>(count, 1)) * sizeof(sh::Cell));
            counts.push_back(count);
        }
        cmd = m_ws.ctx.begin();
        cmdBuildLeaves(cmd, rounds, counts);
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
        for (SetSplit& s : split) {
            if (s.done) continue;
            s.cur = 1 - s.cur;
            s.cells = s.round.cellsOut;
            s.ix->numCells = s.round.blk->fields().cells;
            s.done = s.round.blk->fields().maxCount <= kLeafMax;
        }
    }
    // The neighbourhood pass's view of the crowded cells: their leaves in
    // groups (leaf_groups.comp), and the first group of each cell by grid
    // key, which first holds the first leaf of each cell (leaf_first.comp).
    // A crowded cell of L leaves has ceil(L / G) groups, and at most
    // n / (kCrowdedCell + 1) cells are crowded. Every set's steps side by side.
    const uint32_t groupLeaves = std::max<uint32_t>(1, m_ws.leafGroupLeaves);
    std::vector<sh::LeafGroupPush> gp;
    for (SetSplit& s : split) {
        PointIndex& ix = *s.ix;
        ix.sorted = s.sorted[s.cur];
        ix.sortedKeys = s.gridKeys[s.cur];
        ix.cells = s.cells;
        ix.split = true;
        const float edge = std::bit_cast<float>(s.round.blk->fields().minEdge);
        ix.minEdge = std::isfinite(edge) ? double(edge) : 0.0;
        const VkDeviceSize groupBound = ix.numCells / groupLeaves + ix.n / (kCrowdedCell + 1) + 1;
        ix.groupFirst = &m_ws.setBuffer(ix, ix.store->groupFirst, ".groupFirst",
                                        VkDeviceSize(1u << (3 * ix.grid.bits)) * 4);
        ix.groups =
            &m_ws.setBuffer(ix, ix.store->leafGroups, ".leafGroups", groupBound * sizeof(sh::LeafGroup));
        Buffer& flags = m_ws.grow(s.round.leaf->flags, VkDeviceSize(ix.n) * 4, s.round.leafName + ".flags");
        gp.push_back(sh::LeafGroupPush{ix.cells->address(), ix.sortedKeys->address(), ix.dense->address(),
                                       ix.groupFirst->address(), flags.address(), ix.groups->address(),
                                       ix.numCells, groupLeaves, kCrowdedCell, 0u});
    }
    VkCommandBuffer cmd = m_ws.ctx.begin();
    for (const SetSplit& s : split) {
        const sh::LeafFirstPush lp{s.ix->cells->address(), s.ix->sortedKeys->address(),
                                   s.ix->groupFirst->address(), s.ix->numCells, 0u};
        m_ws.dispatch(cmd, Kernel::kLeafFirst, lp, s.ix->numCells);
    }
    m_ws.barrier(cmd);
    for (size_t k = 0; k < split.size(); ++k)
        m_ws.dispatch(cmd, Kernel::kLeafGroups, gp[k], split[k].ix->numCells);
    m_ws.barrier(cmd);
    for (size_t k = 0; k < split.size(); ++k)
        m_ws.cmdScan(cmd, gp[k].flags, split[k].ix->numCells, split[k].round.leaf->scanFlags,
                     "leaf.scanFlags");
    m_ws.barrier(cmd);
    for (uint32_t mode : {1u, 2u}) {
        for (size_t k = 0; k < split.size(); ++k) {
            gp[k].mode = mode;
            m_ws.dispatch(cmd, Kernel::kLeafGroups, gp[k], split[k].ix->numCells);
        }
        m_ws.barrier(cmd);
    }
    for (const SetSplit& s : split) cmdCheckIndex(cmd, *s.ix, *s.round.blk);
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
    for (SetSplit& s : split) {
        verifyIndex(*s.ix, s.ix->n, *s.round.blk);
        // A one-shot set's spent ping-pong halves serve the rest of the call
        // (Workspace::spare); a prepared set drops them (SetBuffers::releaseUnused).
        if (!s.ix->owned) {
            m_ws.recycle(*s.sorted[1 - s.cur]);
            m_ws.recycle(*s.gridKeys[1 - s.cur]);
        }
    }
}

}  // namespace rthdist::gpu_algo
