#include "gpu_algo/neighbourhood_pass.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <glm/glm.hpp>

namespace rthdist::gpu_algo {
namespace {

// The square of the largest excess of q's box over t's box along one axis
// (0 when q's box lies inside t's): a lower bound of h(Q, T)^2.
double boxLowerBound2(const core::Bounds& q, const core::Bounds& t) {
    const glm::dvec3 excess = glm::max(glm::max(q.hi - t.hi, t.lo - q.lo), glm::dvec3(0.0));
    const double e = std::max({excess.x, excess.y, excess.z});
    return e * e;
}

}  // namespace

void NeighbourhoodPass::startDirection(DirectionRun& d, size_t direction) {
    Counters& cnt = d.out.counters;
    cnt.bits = uint32_t(d.T.grid.bits);
    cnt.occupiedCells = d.T.numCells;
    cnt.queries = d.Q.n;
    // Witness-less lower bound from the two boxes alone (no pass over the
    // points): each face of Q's tight box holds a query, whose distance
    // to BV(T), hence to T, is at least that face's excess over T's box
    // on its axis. Shrunk a little so float rounding never kills the
    // query that realizes h.
    d.lowerBound2Exact = boxLowerBound2(d.Q.bounds, d.T.bounds);
    // Per-point distances need every query's NN: a negative bound turns
    // the early break off in every shader (deadThreshold returns the
    // host's floor instead, killFloor2: 0 but in the pieces' round one).
    d.lowerBound2 = d.perPoint ? -1.0f : float(d.lowerBound2Exact * (1.0 - 1e-5));
    if (d.perPoint == nullptr) d.killFloor2 = 0.0f;
    std::memcpy(d.blk.host + RTHDIST_CTR_KILL_FLOOR, &d.killFloor2, 4);
    double maxAbs = 0.0;
    for (const core::Bounds* b : {&d.Q.bounds, static_cast<const core::Bounds*>(&d.T.bounds)})
        maxAbs = std::max({maxAbs, std::abs(b->lo.x), std::abs(b->lo.y), std::abs(b->lo.z), std::abs(b->hi.x),
                           std::abs(b->hi.y), std::abs(b->hi.z)});
    d.epsilon = float(maxAbs * 4e-7 + d.T.grid.cellSize * 1e-5);
    DirectionBuffers& memory = m_ws.scratch.directions[direction];
    d.state = &m_ws.grow(memory.state, VkDeviceSize(d.Q.n) * sizeof(sh::QueryState), d.name() + ".state");
    d.active[0] = &m_ws.grow(memory.active[0], VkDeviceSize(d.Q.n) * 4, d.name() + ".active0");
    d.active[1] = &m_ws.grow(memory.active[1], VkDeviceSize(d.Q.n) * 4, d.name() + ".active1");
    // A floor call hands back its queries above the floor sparse, while they
    // fit its capacity (kAboveFloorCapacity; query_check.cpp readAboveFloor),
    // and takes the dense read-back buffer only when the list overflows
    // (host-visible memory costs ~3 ms a 10 MiB to allocate on the H200
    // machine: 0.24 s for a torus quarter's first piece).
    const bool sparse = d.perPoint && d.killFloor2 > 0.0f;
    d.nearestHost = nullptr;
    if (d.perPoint) {
        const VkDeviceSize bytes = VkDeviceSize(d.Q.n) * 4;
        d.nearest = &m_ws.grow(memory.nearest, bytes, d.name() + ".nearest");
        if (!sparse) d.takeNearestHost(m_ws, direction);
    }
    d.above = d.aboveHost = nullptr;
    d.aboveCapacity = 0;
    if (sparse) {
        d.aboveCapacity = std::min(d.Q.n, m_ws.aboveFloorCapacity);
        const VkDeviceSize bytes = VkDeviceSize(d.aboveCapacity) * 8;
        d.above = &m_ws.grow(memory.above, bytes, d.name() + ".above");
        d.aboveHost = &m_ws.grow(memory.aboveHost, bytes, d.name() + ".aboveHost", MemoryKind::kReadback);
    }
    const uint64_t aboveAt = d.above != nullptr ? d.above->address() : 0;
    const uint32_t none = 0;
    std::memcpy(d.blk.host + RTHDIST_CTR_ABOVE_COUNT, &none, 4);
    std::memcpy(d.blk.host + RTHDIST_CTR_ABOVE_CAPACITY, &d.aboveCapacity, 4);
    std::memcpy(d.blk.host + RTHDIST_CTR_ABOVE_OUT, &aboveAt, 8);
    d.checkSlots = sampleSlots(d.Q.n, kCheckSamples);
}

void NeighbourhoodPass::cmdCull(VkCommandBuffer cmd, DirectionRun& d) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "neighbourhood pass");
    sh::CounterFields& c = d.blk.fields();
    c.active = c.maxCount = c.nextActive = c.cells = 0;
    c.maxPacked = c.pairs = 0;
    c.searchOpen = 0;
    const bool leaves = d.T.split && m_ws.cullCellTests > 0;
    sh::CullPush cull{d.Q.sorted->address(),
                      d.T.sorted->address(),
                      d.T.dense->address(),
                      d.state->address(),
                      d.blk.addr(RTHDIST_CTR_MAX_PACKED),
                      gridParams(d.T.grid),
                      d.Q.n,
                      d.lowerBound2,
                      d.epsilon,
                      0u,            // search cells are coarser than the block's cells
                      kCrowdedCell,  // past it: its leaves near the query, or copies of one point
                      m_ws.mutant ? 1u : 0u,
                      m_ws.cullCellTests,
                      0u,
                      leaves ? d.T.cells->address() : 0,
                      leaves ? d.T.groupFirst->address() : 0,
                      leaves ? d.T.groups->address() : 0};
    m_ws.dispatch(cmd, Kernel::kCull, cull, d.Q.n);
    m_ws.barrier(cmd);
    sh::CompactPush comp{
        d.state->address(), d.active[0]->address(), d.blk.device, d.blk.addr(RTHDIST_CTR_MAX_PACKED), d.Q.n,
        d.lowerBound2};
    m_ws.dispatch(cmd, Kernel::kCompact, comp, d.Q.n);
    // Per-point: no query's nearest target yet. The checks write every
    // query's; one the device never wrote reads back out of range, which
    // readPerPoint refuses (never a stale value of an earlier call).
    if (d.nearest != nullptr) vkCmdFillBuffer(cmd, d.nearest->handle(), 0, VkDeviceSize(d.Q.n) * 4, ~0u);
}

std::array<uint32_t, 2> NeighbourhoodPass::runCulls(std::span<DirectionRun* const> dirs) {
    if (dirs.size() > 2) throw std::logic_error("runCulls: more directions than counter blocks");
    const auto t0 = Clock::now();
    VkCommandBuffer cmd = m_ws.ctx.begin();
    for (DirectionRun* d : dirs) cmdCull(cmd, *d);
    m_ws.barrier(cmd);
    const uint32_t culled = m_ws.ctx.cmdMark(cmd);
    for (DirectionRun* d : dirs) m_check.cmdCheckQueries(cmd, *d, CheckAt::kBehindCull);
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuCull += m_ws.ctx.gpuMsBetween(0, culled);
    std::array<uint32_t, 2> survivors{};
    for (size_t k = 0; k < dirs.size(); ++k) {
        survivors[k] = dirs[k]->blk.fields().active;
        dirs[k]->out.counters.survivingQueries = survivors[k];
        dirs[k]->out.counters.culledByNeighbourhood = dirs[k]->Q.n - survivors[k];
    }
    m_ws.timings->cull += msSince(t0);
    return survivors;
}

}  // namespace rthdist::gpu_algo
