#include "gpu_algo/radius_schedule.hpp"

#include <algorithm>
#include <cmath>

namespace rthdist::gpu_algo {

ScheduleSettings scheduleSettings(const Tuning& tuning, bool cpuDevice, uint32_t maxGroupsX) {
    ScheduleSettings s;
    if (tuning.searchRadiiPerSubmission)
        s.radiiPerSubmission =
            std::clamp<uint32_t>(*tuning.searchRadiiPerSubmission, 1, RTHDIST_SEARCH_LOG_MAX);
    s.squaredTailGrowth = tuning.squaredTailGrowth.value_or(true);
    s.tailScanWork = tuning.tailScanWork.value_or(cpuDevice ? kTailScanWorkCpuDevice : kTailScanWorkGpu);
    s.tailScanStartWork = tuning.tailScanStartWork.value_or(kTailScanStartWorkGpu);
    s.sweepWork = tuning.sweepWork.value_or(cpuDevice ? kSweepWorkCpuDevice : kSweepWorkGpu);
    s.tailQueriesMax = maxGroupsX;
    return s;
}

RadiusSchedule::RadiusSchedule(const SearchGrid& grid, const ScheduleSettings& settings, double growth,
                               uint32_t searched, uint64_t queries)
    : m_grid(grid),
      m_settings(settings),
      m_growth(growth),
      m_searched(searched),
      m_queries(queries),
      m_radius(startRadius(grid)),
      m_step(growth) {}

double RadiusSchedule::startRadius(const SearchGrid& grid) {
    const double cells = 2.0 * grid.cellSize;
    return grid.split && grid.minEdge > 0.0 ? std::min(cells, 0.5 * grid.minEdge) : cells;
}

int RadiusSchedule::levelFor(const SearchGrid& grid, double radius) {
    const int wanted = int(std::floor(std::log2(radius / (8.0 * grid.cellSize))));
    return grid.split && wanted < 1 ? 0 : std::clamp(wanted, 1, std::max(1, grid.bits - 1));
}

double RadiusSchedule::tailStep(double growth, uint32_t searched, uint32_t before, uint32_t after) {
    const bool fewLeft = uint64_t(after) * 8 <= searched;
    const bool mostGoOn = 2 * uint64_t(after) > before;
    return fewLeft && mostGoOn ? growth * growth : growth;
}

int RadiusSchedule::tailLevel(uint32_t open, int builtLevels,
                              const std::function<uint32_t(int)>& cellsAt) const {
    const uint64_t from = m_traced ? m_searched : m_queries;
    const uint64_t work = m_traced ? m_settings.tailScanWork : m_settings.tailScanStartWork;
    if (work == 0 || uint64_t(open) * 4 > from || open > m_settings.tailQueriesMax) return -1;
    const int last = std::max(1, m_grid.bits - 1);
    int level = std::max(1, builtLevels);
    uint32_t cells = cellsAt(level);
    while (cells > kTailScanCells && level < last) cells = cellsAt(++level);
    return uint64_t(open) * cells <= work ? level : -1;
}

std::vector<double> RadiusSchedule::nextRadii() const {
    const int first = level();
    std::vector<double> radii{m_radius};
    const uint32_t chunk = m_retry.stride > 1 ? 1u : std::min(m_chunk, m_settings.radiiPerSubmission);
    while (radii.size() < chunk) {
        const double next = radii.back() * m_step;
        if (levelFor(m_grid, next) != first) break;
        radii.push_back(next);
    }
    return radii;
}

namespace {

// The classes that share a full buffer's pairs: as many as the pairs
// reported would fill it twice over, at least 2 (classes of queries by
// index hold about even shares of them).
uint64_t classesFor(uint64_t pairs, uint64_t capacity) {
    return std::max<uint64_t>(2, (2 * pairs + capacity - 1) / std::max<uint64_t>(capacity, 1));
}

}  // namespace

void RadiusSchedule::advance(std::span<const double> radii, uint32_t before, const RadiiOutcome& out,
                             uint64_t fullCapacity) {
    m_traced = true;
    m_chunk =
        2 * uint64_t(out.stillOpen) > before ? std::min<uint32_t>(2 * m_chunk, RTHDIST_SEARCH_LOG_MAX) : 2;
    m_step = m_settings.squaredTailGrowth ? tailStep(m_growth, m_searched, before, out.stillOpen) : m_growth;
    m_radius = radii[out.run - 1];
    const bool full = out.overflowed && fullCapacity > 0;
    bool again = out.overflowed;  // the same radius next
    if (m_retry.stride > 1) {
        if (full) {
            // This class overflowed too: split it (its queries fall into
            // classes m_retry.phase + k * m_retry.stride of the finer split, which the
            // turns from m_retry.phase on reach; the earlier ones are done).
            const uint64_t finer =
                uint64_t(m_retry.stride) *
                std::min<uint64_t>(classesFor(out.lastPairs, fullCapacity), kMaxRetryClasses);
            m_exhausted = m_retry.stride >= m_queries || finer > kMaxRetryClasses;
            if (!m_exhausted) m_retry.stride = uint32_t(finer);
            again = true;
        } else if (!out.overflowed && ++m_retry.phase == m_retry.stride) {
            m_retry.stride = 1;  // every class had its turn: the radius grows
            m_retry.phase = 0;
        } else {
            again = true;  // the next class (or this one again, with a larger buffer)
        }
    } else if (full && uint64_t(out.stillOpen) * 8 > uint64_t(before) * 7) {
        m_retry.stride =
            uint32_t(std::min<uint64_t>(classesFor(out.lastPairs, fullCapacity), kMaxRetryClasses));
        m_retry.phase = 0;
    }
    if (!again) m_radius *= m_step;
}

bool RadiusSchedule::sweeps(uint32_t open, uint64_t targets) const {
    return m_settings.sweepWork > 0 && targets > 0 && uint64_t(open) <= m_settings.sweepWork / targets;
}

}  // namespace rthdist::gpu_algo
