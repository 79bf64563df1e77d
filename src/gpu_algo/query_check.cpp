#include "gpu_algo/query_check.hpp"

#include "core/parallel.hpp"
#include "core/per_point_floor.hpp"
#include "gpu_algo/certificate_pass.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rthdist::gpu_algo {

bool QueryCheck::foldsIntoSearch(const DirectionRun& d) const {
    return d.perPoint == nullptr && m_ws.oneDispatchHolds(d.Q.n);
}

void QueryCheck::cmdCheckQueries(VkCommandBuffer cmd, const DirectionRun& d, CheckAt at) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "query check");
    d.blk.fields().checkBad = 0;
    if (d.above != nullptr) std::memset(d.blk.host + RTHDIST_CTR_ABOVE_COUNT, 0, 4);
    const VkDeviceSize readback = d.blk.offset + RTHDIST_CTR_READBACK;
    const VkDeviceSize witnessAt = readback + VkDeviceSize(d.checkSlots.size()) * 32;
    sh::CheckPush cp{d.Q.sorted->address(),
                     0,
                     d.state->address(),
                     d.blk.device,
                     {},
                     d.Q.n,
                     d.perPoint ? 1u : 0u,
                     m_ws.hostSmall.address() + witnessAt,
                     at == CheckAt::kBehindCull ? 1u : 0u,
                     uint32_t(d.checkSlots.size()),
                     d.nearest != nullptr ? d.nearest->address() : 0,
                     d.band != nullptr ? d.band->address() : 0,
                     d.bandCapacity,
                     deviceSlack(d)};
    if (at == CheckAt::kBehindSearch)  // groups written by search_advance.comp: none while queries go on
        m_ws.pipelines.cmdDispatchIndirect(cmd, Kernel::kCheckQueries, &cp, sizeof(cp),
                                           m_ws.hostSmall.handle(), d.blk.offset + RTHDIST_CTR_CHECK_ARGS);
    else
        m_ws.dispatch(cmd, Kernel::kCheckQueries, cp, d.Q.n);
    cmdScanWitness(m_ws, cmd, d, at);
    if (d.above != nullptr) {
        // A floor call: its list of the queries above the floor comes back
        // (the dense array only when the list overflowed: readAboveFloor).
        m_ws.barrier(cmd);
        const VkBufferCopy all{0, 0, VkDeviceSize(d.aboveCapacity) * 8};
        vkCmdCopyBuffer(cmd, d.above->handle(), d.aboveHost->handle(), 1, &all);
    } else if (d.nearest != nullptr) {
        // Per-point: the whole direction's nearest targets come back with
        // the check (a check behind the cull that found survivors copies
        // what the check after the search overwrites).
        m_ws.barrier(cmd);
        const VkBufferCopy all{0, 0, VkDeviceSize(d.Q.n) * 4};
        vkCmdCopyBuffer(cmd, d.nearest->handle(), d.nearestHost->handle(), 1, &all);
    }
}

void QueryCheck::fetchSampled(const DirectionRun& d, std::span<const SampledQuery> sampled) {
    std::vector<uint32_t> queries, targets;
    for (const SampledQuery& s : sampled) {
        queries.push_back(std::bit_cast<uint32_t>(s.sorted[3]));
        targets.push_back(uint32_t(s.state.best & 0xffffffffu));
    }
    fetchPoints(d, queries, targets);
}

void QueryCheck::fetchPoints(const DirectionRun& d, std::span<const uint32_t> queries,
                             std::span<const uint32_t> targets) {
    // Both sets' missing points in one submission, into the workspace's kept
    // host buffer (a buffer and a submission per set and check cost ~3 ms
    // per call on an H100).
    const std::vector<uint32_t> wq = d.qPts.missing(queries), wt = d.tPts.missing(targets);
    if (wq.empty() && wt.empty()) return;
    const VkDeviceSize qBytes = VkDeviceSize(wq.size()) * d.qPts.pointBytes();
    const VkDeviceSize tBytes = VkDeviceSize(wt.size()) * d.tPts.pointBytes();
    Buffer& host =
        m_ws.grow(m_ws.scratch.search.fetched, qBytes + tBytes, "fetched points", MemoryKind::kReadback);
    VkCommandBuffer cmd = m_ws.ctx.begin();
    d.qPts.cmdCopy(cmd, wq, host.handle(), 0);
    d.tPts.cmdCopy(cmd, wt, host.handle(), qBytes);
    m_ws.ctx.submitAndWait(cmd);
    const char* bytes = static_cast<const char*>(host.mapped());
    d.qPts.store(wq, bytes);
    d.tPts.store(wt, bytes + qBytes);
}

SampledQuery QueryCheck::finishCheck(const DirectionRun& d) {
    const uint64_t packed = d.blk.fields().maxPacked;
    const char* readback = d.blk.host + RTHDIST_CTR_READBACK;
    std::vector<SampledQuery> sampled(d.checkSlots.size() + 1);
    for (size_t k = 0; k < sampled.size(); ++k) {
        sampled[k].slot = k < d.checkSlots.size() ? d.checkSlots[k] : uint32_t(packed & 0xffffffffu);
        std::memcpy(sampled[k].sorted, readback + k * 32, 16);
        std::memcpy(&sampled[k].state, readback + k * 32 + 16, 16);
    }
    const uint64_t bad = d.blk.fields().checkBad;
    if (bad == 0) fetchSampled(d, sampled);
    std::string why =
        bad != 0 ? std::to_string(bad) + " of " + std::to_string(d.Q.n) +
                       " queries ended unsettled or above the maximum"
                 : sampledQueryFailure(sampled, d.qPts, d.tPts, packed, d.perPoint != nullptr, d.killFloor2);
    if (!why.empty()) throw SelfCheckError(d.name() + ": " + why);
    return sampled.back();
}

Directed QueryCheck::finishDirection(DirectionRun& d, const SampledQuery& witness) {
    Directed& out = d.out;
    out.queryIndex = std::bit_cast<uint32_t>(witness.sorted[3]);
    out.targetIndex = uint32_t(witness.state.best & 0xffffffffu);
    const uint32_t qi = uint32_t(out.queryIndex), ti = uint32_t(out.targetIndex);
    // The check compares the pair as searched with the device's float
    // maximum; the result carries the points as given (device input: the
    // embedder's own coordinates, in double).
    const double searched = glm::length(glm::dvec3(d.qPts.searched(qi)) - glm::dvec3(d.tPts.searched(ti)));
    std::string why = witnessFailure(searched, d.blk.fields().maxPacked, std::sqrt(d.lowerBound2Exact));
    if (!why.empty()) throw SelfCheckError(d.name() + ": " + why);
    out.queryPoint = d.qPts.original(qi);
    out.targetPoint = d.tPts.original(ti);
    out.distance = glm::length(out.queryPoint - out.targetPoint);
    return out;
}

std::optional<std::vector<detail::QueryNearest>> QueryCheck::readAboveFloor(DirectionRun& d,
                                                                            size_t direction) {
    uint32_t count = 0;
    std::memcpy(&count, d.blk.host + RTHDIST_CTR_ABOVE_COUNT, 4);
    if (count > d.aboveCapacity) {  // overflowed: the dense array, as readPerPoint reads it
        d.takeNearestHost(m_ws, direction);
        VkCommandBuffer cmd = m_ws.ctx.begin();
        const VkBufferCopy all{0, 0, VkDeviceSize(d.Q.n) * 4};
        vkCmdCopyBuffer(cmd, d.nearest->handle(), d.nearestHost->handle(), 1, &all);
        m_ws.ctx.submitAndWait(cmd);
        return std::nullopt;
    }
    const auto* words = static_cast<const uint32_t*>(d.aboveHost->mapped());
    std::vector<detail::QueryNearest> above(count);
    for (uint32_t k = 0; k < count; ++k) {
        above[k] = {words[2 * size_t(k)], words[2 * size_t(k) + 1]};
        if (above[k].query >= d.Q.n || above[k].nearest >= d.T.n)
            throw std::runtime_error("per-point read-back: entry " + std::to_string(k) + " of " + d.name() +
                                     "'s queries above the floor names query " +
                                     std::to_string(above[k].query) + " and target " +
                                     std::to_string(above[k].nearest));
    }
    std::sort(above.begin(), above.end(), [](const auto& x, const auto& y) { return x.query < y.query; });
    for (uint32_t k = 1; k < count; ++k)
        if (above[k].query == above[k - 1].query)
            throw std::runtime_error("per-point read-back: " + d.name() + " lists query " +
                                     std::to_string(above[k].query) + " twice above the floor");
    return above;
}

void QueryCheck::readPerPoint(const DirectionRun& d, PerPoint& out) {
    const std::span<const glm::vec3> qPts = d.qPts.all(), tPts = d.tPts.all();
    const auto* nearest = static_cast<const uint32_t*>(d.nearestHost->mapped());
    // Arrays recycled from an earlier call (Engine::recycle) are not
    // cleared first: every entry is written below.
    out.distance.resize(d.perPointDistances ? d.Q.n : 0);
    out.nearest.resize(d.Q.n);
    const bool distances = d.perPointDistances;
    // Cached host memory (MemoryKind::kReadback) read on every host thread,
    // in the queries' own order. Chunks of 2^13 queries: a mask's 10^5
    // boundary voxels take every thread.
    constexpr size_t kPerPointChunk = size_t(1) << 13;
    std::atomic<uint64_t> firstBad{UINT64_MAX};
    core::parallelChunks(d.Q.n, kPerPointChunk, m_ws.threads, [&](size_t begin, size_t end, int) {
        for (size_t qi = begin; qi < end; ++qi) {
            const uint32_t ti = nearest[qi];
            if (ti == RTHDIST_BELOW_FLOOR && d.killFloor2 > 0.0f) {  // core/per_point_floor.hpp
                out.nearest[qi] = core::kBelowFloor;
                if (distances) out.distance[qi] = -1.0;
                continue;
            }
            if (ti >= tPts.size()) {
                uint64_t seen = firstBad.load();
                while (qi < seen && !firstBad.compare_exchange_weak(seen, qi)) {
                }
                return;
            }
            out.nearest[qi] = ti;
            if (distances) out.distance[qi] = glm::length(glm::dvec3(qPts[qi]) - glm::dvec3(tPts[ti]));
        }
    });
    if (firstBad.load() != UINT64_MAX)
        throw std::runtime_error("per-point read-back: query " + std::to_string(firstBad.load()) +
                                 " has no nearest point of " + d.T.name);
    static_assert(RTHDIST_BELOW_FLOOR == core::kBelowFloor);
    // The queries the certificate settled in double take their exact nearest
    // targets, so that the array's maximum is the proven witness.
    for (const core::BandNearest& b : d.settled) {
        out.nearest[b.query] = uint32_t(b.target);
        if (distances) out.distance[b.query] = b.distance;
    }
}

}  // namespace rthdist::gpu_algo
