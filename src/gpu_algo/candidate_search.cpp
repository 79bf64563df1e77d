#include "gpu_algo/candidate_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "gpu/barriers.hpp"

namespace rthdist::gpu_algo {

// Two timestamps per radius of a submission, and the submission's own two.
static_assert(2 * RTHDIST_SEARCH_LOG_MAX + 2 < gpu::Context::kTimestampSlots);

CandidateSearch::CandidateSearch(Workspace& workspace, IndexBuild& indexBuild, Refinement& refinement,
                                 QueryCheck& check)
    : m_schedule(
          scheduleSettings(workspace.tuning, workspace.ctx.cpuDevice(), workspace.ctx.limits().maxGroupsX)),
      m_ws(workspace),
      m_index(indexBuild),
      m_refine(refinement),
      m_check(check) {}

namespace {

SearchGrid searchGridOf(const PointIndex& T) { return {T.grid.cellSize, T.grid.bits, T.split, T.minEdge}; }

}  // namespace

void CandidateSearch::runSearch(DirectionRun& d, uint32_t numActive, const CallOptions& options,
                                double progressFrom, double progressTo) {
    PointIndex& T = d.T;
    RadiusSchedule schedule(searchGridOf(T), m_schedule, double(options.radiusGrowth), numActive, d.Q.n);
    // Room for ~4 pairs per cell, or per query when a split index sends
    // the crowded regions' queries to the search (a full buffer costs a
    // repeated iteration).
    const uint64_t pairBase = std::max<uint64_t>(T.numCells, T.split ? numActive : 0u);
    uint64_t pairCapacity =
        std::min(std::clamp<uint64_t>(pairBase * 4, 1u << 16, 1u << 22), m_ws.maxPairCapacity);
    Buffer* pairs = nullptr;
    int builtLevel = -1;  // level of the BLAS now built (-1: none yet)
    uint64_t steps = 0;   // radii searched, a retry class's turns at a radius as one (kMaxIterations)
    while (numActive > 0) {
        if (!pairs) {
            pairs = &m_ws.grow(m_ws.scratch.search.pairs, pairCapacity * 8, "pairs");
            pairCapacity = std::min<uint64_t>(pairs->size() / 8, m_ws.maxPairCapacity);
        }
        if (schedule.sweeps(numActive, T.n)) {
            const RadiiOutcome out =
                runRadii(d, 0, false, {}, *pairs, pairCapacity, numActive, SearchStep::kSweep);
            if (out.stillOpen != 0) throw std::runtime_error("candidate search: the sweep left queries open");
            d.out.counters.iterations += out.run;
            d.out.counters.tailScanned += numActive;
            break;
        }
        const int tail = tailScanLevel(schedule, T, numActive);
        if (tail >= 0) {
            const RadiiOutcome out =
                runRadii(d, tail, false, {}, *pairs, pairCapacity, numActive, SearchStep::kTailScan);
            if (out.stillOpen != 0)
                throw std::runtime_error("candidate search: the tail scan left queries open");
            d.out.counters.iterations += out.run;
            d.out.counters.tailScanned += numActive;
            break;
        }
        const int level = schedule.level();
        const std::vector<double> submitted = schedule.nextRadii();
        const RetryClass retry = schedule.retryClass();
        const RadiiOutcome out = runRadii(d, level, level == builtLevel, submitted, *pairs, pairCapacity,
                                          numActive, SearchStep::kRadii, retry);
        schedule.advance(submitted, numActive, out, pairCapacity >= m_ws.maxPairCapacity ? pairCapacity : 0);
        if (schedule.retryExhausted())
            throw std::runtime_error("candidate search: the candidate cells of one retry class of " +
                                     std::to_string(schedule.retryClass().stride) + " at radius " +
                                     std::to_string(submitted[out.run - 1]) + " exceed the pair buffer's " +
                                     std::to_string(pairCapacity) + " pairs, its most");
        builtLevel = level;
        d.out.counters.iterations += out.run;
        // A retry class's turns at one radius (bounded by the classes) are one step.
        steps += retry.stride > 1 ? 0u : out.run;
        if (steps > kMaxIterations)
            throw std::runtime_error("candidate search did not converge within " +
                                     std::to_string(kMaxIterations) + " radii");
        numActive = out.stillOpen;
        reportProgress(
            options, "search",
            progressFrom +
                (progressTo - progressFrom) *
                    (0.2 + 0.8 * (1.0 - double(numActive) /
                                            double(std::max<uint64_t>(1, d.out.counters.survivingQueries)))));
        if (out.overflowed && pairCapacity < m_ws.maxPairCapacity) {
            // Some queries lost pairs: redo them at the same radius with room.
            pairCapacity =
                std::min<uint64_t>(m_ws.maxPairCapacity, std::max<uint64_t>(out.lastPairs, pairCapacity * 2));
            pairs = nullptr;
        }
    }
}

int CandidateSearch::tailScanLevel(const RadiusSchedule& schedule, PointIndex& T, uint32_t open) {
    return schedule.tailLevel(open, int(T.levels.size()),
                              [&](int level) { return m_index.levelCells(T, level).count; });
}

RadiiOutcome CandidateSearch::runRadii(DirectionRun& d, int level, bool sameLevel,
                                       std::span<const double> radii, Buffer& pairs, uint64_t pairCapacity,
                                       uint32_t numActive, SearchStep step, RetryClass retry) {
    const bool wholeLevel = step != SearchStep::kRadii;
    const PointIndex::Level lv = m_index.levelCells(d.T, level);  // may build the level (a submission)
    const auto t0 = Clock::now();
    sh::CounterFields& counters = d.blk.fields();
    counters.pairs = 0;
    counters.nextActive = 0;
    counters.searchActive = numActive;
    const uint32_t firstSize[6] = {gpu::groupsFor(numActive, RTHDIST_WG), 1, 1, numActive, 1, 1};
    std::memcpy(d.blk.host + RTHDIST_CTR_SEARCH_ARGS, firstSize, sizeof(firstSize));
    const int firstActive = d.cur;
    const bool folded = m_check.foldsIntoSearch(d);
    const uint32_t checkGroups = folded ? gpu::groupsFor(d.Q.n, RTHDIST_WG) : 0u;
    std::vector<std::pair<uint32_t, uint32_t>> marks;  // before and after each radius's search
    const size_t steps = wholeLevel ? 1 : radii.size();
    VkCommandBuffer cmd = m_ws.ctx.begin();
    for (size_t i = 0; i < steps; ++i) {
        if (i > 0)  // everything of the radius before, before anything of this one
            gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                             VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
        if (step == SearchStep::kSweep) {  // no rays: its device time counts as refinement
            m_refine.cmdSweep(cmd, d, numActive);
        } else if (step == SearchStep::kTailScan) {
            m_refine.cmdTailScan(cmd, d, lv, level > 0, numActive);
        } else {
            const uint32_t before = i == 0 ? 0 : marks.back().second + 1;
            cmdSearch(cmd, d, lv, sameLevel || i > 0, radii[i], pairs, pairCapacity, numActive, retry);
            marks.emplace_back(before, m_ws.ctx.cmdMark(cmd));
            m_ws.barrier(cmd);
            m_refine.cmdRefine(cmd, d, lv, level > 0, float(radii[i]), sameLevel || i > 0, pairs,
                               pairCapacity, numActive);
        }
        m_ws.barrier(cmd);
        const sh::SearchAdvancePush ap{d.blk.device, uint32_t(i), uint32_t(pairCapacity), checkGroups, 0u};
        m_ws.pipelines.cmdDispatch(cmd, Kernel::kSearchAdvance, &ap, sizeof(ap), 1);
        if (i + 1 < steps) m_ws.ctx.cmdMark(cmd);
        d.cur = 1 - d.cur;
    }
    // The self-check, given groups by search_advance.comp only if these
    // radii settled the last query (one submission fewer than a check of
    // its own).
    if (folded) {  // its groups are indirect arguments search_advance.comp wrote
        gpu::cmdBarrier2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                         VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
        m_check.cmdCheckQueries(cmd, d, CheckAt::kBehindSearch);
    }
    m_ws.ctx.submitAndWait(cmd);
    double searchGpu = 0.0;
    for (const auto& [from, to] : marks) searchGpu += m_ws.ctx.gpuMsBetween(from, to);
    const double allGpu = m_ws.ctx.lastGpuMs();
    m_ws.timings->gpuSearch += searchGpu;
    m_ws.timings->gpuRefine += allGpu - searchGpu;
    // The wall time split between the two stages as their device time is.
    const double wall = msSince(t0), searchShare = allGpu > 0.0 ? searchGpu / allGpu : 1.0;
    m_ws.timings->search += wall * searchShare;
    m_ws.timings->refine += wall * (1.0 - searchShare);
    // The radii that searched queries; the active list they left is the
    // last one resolve.comp wrote.
    RadiiOutcome out;
    const auto* log = reinterpret_cast<const sh::SearchLogEntry*>(d.blk.host + RTHDIST_CTR_SEARCH_LOG);
    for (size_t i = 0; i < steps && log[i].searched > 0; ++i) {
        ++out.run;
        out.stillOpen = log[i].goingOn;
        out.lastPairs = log[i].pairs;
        out.overflowed = log[i].pairs > pairCapacity;
        if (!wholeLevel) d.out.counters.rays += log[i].searched;  // the tail scan casts none
        d.out.counters.candidatePairs += std::min<uint64_t>(log[i].pairs, pairCapacity);
    }
    if (out.run == 0) throw std::runtime_error("candidate search: the device searched no query");
    if (m_ws.ctx.tracingSubmits() && step == SearchStep::kSweep)
        std::fprintf(stderr, "rthdist sweep of %u targets: searched %u, going on %u\n", d.T.n,
                     log[0].searched, log[0].goingOn);
    else if (m_ws.ctx.tracingSubmits() && wholeLevel)
        std::fprintf(stderr, "rthdist tail scan level %d (%u cells): searched %u, going on %u\n", level,
                     lv.count, log[0].searched, log[0].goingOn);
    else if (m_ws.ctx.tracingSubmits())
        for (size_t i = 0; i < steps; ++i)
            std::fprintf(
                stderr,
                "rthdist radius %zu/%zu level %d r %.6g: searched %u, going on %u, pairs %llu (room %llu)\n",
                i + 1, steps, level, radii[i], log[i].searched, log[i].goingOn,
                static_cast<unsigned long long>(log[i].pairs), static_cast<unsigned long long>(pairCapacity));
    d.cur = out.run % 2 == 0 ? firstActive : 1 - firstActive;
    return out;
}

void CandidateSearch::cmdSearch(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv,
                                bool sameLevel, double radius, Buffer& pairs, uint64_t pairCapacity,
                                uint32_t numActive, RetryClass retry) {
    const gpu::ScopedLabel label(m_ws.ctx, cmd, "candidate search");
    PointIndex& T = d.T;
    const float r = float(radius);
    // The ray only has to start inside the grown boxes: a short one
    // crosses few other boxes (leaves are far smaller than grid cells).
    const float rayTMax = float(std::min(T.grid.cellSize, T.split ? radius : T.grid.cellSize) * 1e-3);
    Buffer& aabbs = m_ws.grow(m_ws.scratch.search.aabbs, VkDeviceSize(lv.count) * 24, "aabbs");
    // Per-box slack: float rounding at the box's magnitude (the old
    // global epsilon used the largest coordinate of both sets) plus,
    // for a grid index, the grid's absolute term.
    sh::BoxesPush bp{lv.cells->address(), aabbs.address(), lv.count,
                     r + r * 1e-6f,       4e-7f,           T.split ? 0.0f : float(T.grid.cellSize * 1e-5)};
    m_ws.dispatch(cmd, Kernel::kGrowBoxes, bp, lv.count);
    gpu::cmdBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                    VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_ACCESS_SHADER_READ_BIT);
    // Same cells: the boxes only grew, so refit; new level: rebuild.
    if (m_ws.accel.cmdBuild(cmd, aabbs.address(), lv.count, sameLevel, m_ws.pipelines.shaderStages()) ||
        !m_ws.tlasBound) {
        m_ws.pipelines.bindTlas(m_ws.accel.tlas());
        m_ws.tlasBound = true;
    }
    sh::SearchPush sp{};
    setRadiusAddresses(sp, d, lv, pairs);
    sp.numActive = numActive;
    sp.pairCapacity = uint32_t(pairCapacity);
    sp.radius = r;
    sp.lowerBound2 = d.lowerBound2;
    sp.rayTMax = rayTMax;
    sp.skipScanned = sameLevel ? 1u : 0u;
    sp.slotBase = 0u;
    sp.retryStride = retry.stride;
    sp.retryPhase = retry.phase;
    // Sized by the device (search_advance.comp: the queries still searched)
    // where one dispatch or trace holds them all; else numActive slots, the
    // ones past the device's count returning at once.
    if (m_ws.rayQuery)
        m_ws.dispatchSearched(cmd, Kernel::kSearchRayQuery, sp, numActive, d.blk);
    else if (m_ws.pipelines.tracesIndirect() && numActive <= m_ws.ctx.limits().maxRayDispatch)
        m_ws.pipelines.cmdTraceRaysIndirect(cmd, &sp, sizeof(sp), d.blk.addr(RTHDIST_CTR_SEARCH_ARGS + 12));
    else
        cmdTraceRaysSplit(cmd, sp);
}

void CandidateSearch::cmdTraceRaysSplit(VkCommandBuffer cmd, sh::SearchPush sp) {
    const uint64_t chunk = std::max<uint64_t>(1, m_ws.ctx.limits().maxRayDispatch);
    for (uint64_t first = 0; first < sp.numActive; first += chunk) {
        sp.slotBase = uint32_t(first);
        m_ws.pipelines.cmdTraceRays(cmd, &sp, sizeof(sp),
                                    uint32_t(std::min<uint64_t>(chunk, sp.numActive - first)));
    }
}

}  // namespace rthdist::gpu_algo
