// The candidate search's radius schedule (design.md §4): which radii the
// search traces, how many go in one submission, at which search level, and
// when a far tail of few open queries scans whole coarse levels instead.
// Host-only decisions, no Vulkan and no buffers: CandidateSearch
// (candidate_search.hpp) asks the schedule, records what it says and tells it
// what each submission reported. The schedule never decides a result: every
// query's nearest cell is refined exactly, whatever the radius (§3); it only
// decides how much work finds it.
//
// One schedule per direction's search; not thread-safe (one caller).
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "rthdist/tuning.hpp"
#include "rthdist_shared.h"

namespace rthdist::gpu_algo {

// Radii before a search is declared not converging.
inline constexpr uint32_t kMaxIterations = 4096;

// The far tail's scan (RadiusSchedule::tailLevel): at most this many
// (open query, search cell) tests, on a GPU and on a CPU device (lavapipe),
// and the level scanned the first with at most kTailScanCells cells (each
// query's thread walks all of them).
inline constexpr uint64_t kTailScanWorkGpu = uint64_t(1) << 28;
inline constexpr uint64_t kTailScanWorkCpuDevice = uint64_t(1) << 24;
// Before any radius (the queries the neighbourhood pass left): off by
// default. Measured on an H100 with 2^25 tests (docs/bench/prepared,
// 2026-11-27): prepared Dragon translated 0.3 4.1-4.4 -> 1.05-1.07 ms and
// surface-5M 2.6-2.7 -> 1.9 ms, but translated 0.7 5.4-5.6 -> 7.2-7.4 ms
// (its survivors far enough that each walks much of the level) and no
// change on the masks: no rule found yet that picks only the wins.
inline constexpr uint64_t kTailScanStartWorkGpu = 0;
inline constexpr uint32_t kTailScanCells = 4096;
// The sweep (every open query against every target, sweep_targets.comp)
// replaces the radii while (open queries) x (targets) is at most this, on a
// GPU and on a CPU device: a far query beside a dense cluster otherwise
// grows its radius through tens of iterations and scans the cluster's cells
// one thread each (the scale suite's cluster-100M spent 17 s there on an
// H200). 2^31 distances are ~2-3 ms on an H200 (memory-bound at one read of
// the targets per query); 2^24 ~30 ms on lavapipe's 2 cores.
inline constexpr uint64_t kSweepWorkGpu = uint64_t(1) << 31;
inline constexpr uint64_t kSweepWorkCpuDevice = uint64_t(1) << 24;

// Retry classes (RadiusSchedule::advance) at most: a class that still
// overflows the full buffer when a finer split would pass this, or that
// holds one query, ends the search with an error (retryExhausted).
inline constexpr uint32_t kMaxRetryClasses = uint32_t(1) << 16;

// The queries a search submission searches: those with qi % stride ==
// phase (stride 1: all); the others wait (RadiusSchedule::advance).
struct RetryClass {
    uint32_t stride = 1;
    uint32_t phase = 0;
};

// What the schedule knows of the target index (gpu_algo/point_index.hpp):
// its grid's cell edge s and bit count, and whether crowded cells were cut
// into leaves (then minEdge is the narrowest leaf's edge).
struct SearchGrid {
    double cellSize = 1.0;
    int bits = 1;
    bool split = false;
    double minEdge = 0.0;
};

// The knobs of every schedule of one workspace (Tuning's fields, the device's).
struct ScheduleSettings {
    // Radii per submission at most (1 to RTHDIST_SEARCH_LOG_MAX).
    uint32_t radiiPerSubmission = RTHDIST_SEARCH_LOG_MAX;
    // tailStep's squared growth (off: the plain growth every step).
    bool squaredTailGrowth = true;
    // tailLevel's work limit after radii (0: never a tail scan).
    uint64_t tailScanWork = kTailScanWorkGpu;
    // ... and before any radius (0: never).
    uint64_t tailScanStartWork = kTailScanStartWorkGpu;
    // The sweep's work limit: open queries x targets (0: never a sweep).
    uint64_t sweepWork = kSweepWorkGpu;
    // A tail scan takes a workgroup per query: at most the device's maxGroupsX queries.
    uint32_t tailQueriesMax = 65535;
};

// The settings a workspace's searches take: Tuning's fields where set, else
// the defaults above; the work limit after radii is kTailScanWorkCpuDevice on
// a CPU device (lavapipe), kTailScanWorkGpu on a GPU, and the sweep's
// kSweepWorkCpuDevice or kSweepWorkGpu. radiiPerSubmission is
// clamped to 1 .. RTHDIST_SEARCH_LOG_MAX.
[[nodiscard]] ScheduleSettings scheduleSettings(const Tuning& tuning, bool cpuDevice, uint32_t maxGroupsX);

// What the radii of one submission reported.
struct RadiiOutcome {
    uint32_t run = 0;         // radii that searched queries (the later ones had none left)
    uint32_t stillOpen = 0;   // queries going on after the last of them (or retrying)
    uint64_t lastPairs = 0;   // (query, cell) pairs the last of them appended
    bool overflowed = false;  // ... more than the buffer held: its queries that lost pairs retry
};

class RadiusSchedule {
public:
    // The search of one direction over `grid`: `searched` queries enter it,
    // of the direction's `queries`; the radius grows by `growth`
    // (CallOptions::radiusGrowth) per step.
    RadiusSchedule(const SearchGrid& grid, const ScheduleSettings& settings, double growth, uint32_t searched,
                   uint64_t queries);

    // The first radius: 2 cells, or half the narrowest leaf's edge when
    // smaller (a split index). Small and grown geometrically: measured
    // against starting at the threshold's root, which makes every ray visit
    // far more boxes (docs/bench/gpu.md, growth sweep); half the leaf edge
    // is about the nearest-neighbour spacing of ~8 points per leaf (measured
    // on lavapipe, cluster + outlier: 2x the edge made rays visit ~4x more
    // leaves, 1/4 cost an iteration).
    [[nodiscard]] static double startRadius(const SearchGrid& grid);

    // The search level of a radius: cells about an eighth of it wide, level
    // j with s * 2^j <= R / 8, at least 1, at most bits - 1. Wider cells mean
    // fewer boxes per ray but longer scans in the refinement; R/2 and R/4
    // were slower overall on the lavapipe scenarios (README). A split index
    // searches its leaves (level 0) until level 1 is due.
    [[nodiscard]] static int levelFor(const SearchGrid& grid, double radius);

    // The growth of the next radii after a submission that left `after` of
    // its `before` queries going on (`searched`: the direction's queries
    // that entered the search): `growth`, or growth^2 for a tail of far
    // queries (at most an eighth of `searched` left, and most of those of
    // the submission going on). Such a tail is a noisy mask's isolated
    // voxels, up to 300 mm from the other mask against a first radius of
    // 12 mm: each radius costs a BLAS refit and a trace pass whatever the
    // number of queries (~0.5 ms on an H100), so they reach their distance
    // in about half the radii.
    [[nodiscard]] static double tailStep(double growth, uint32_t searched, uint32_t before, uint32_t after);

    // Whether the `open` queries are a tail that scans whole cells instead
    // of tracing (more) radii, and at which level (-1: trace). A tail: at
    // most a quarter of those it is measured against left (the searched
    // queries after a submission of radii, all the direction's queries
    // before the first), at most tailQueriesMax of them, and `open` x the
    // level's cells at most the work limit (tailScanWork after radii,
    // tailScanStartWork before; each query then costs a walk over the
    // level's cells, against a BLAS refit and a trace pass for every radius,
    // ~0.5 ms on an H100 whatever the number of queries, that a noisy mask's
    // isolated voxels, up to 300 mm from the other mask, take 5 of). The
    // level: the first from max(1, `builtLevels`) with at most kTailScanCells
    // cells, up to the grid's last (max(1, bits - 1)). `cellsAt(j)` gives
    // level j's cell count (CandidateSearch builds the level: a submission);
    // it is asked only once the counts pass, in rising order of j.
    [[nodiscard]] int tailLevel(uint32_t open, int builtLevels,
                                const std::function<uint32_t(int)>& cellsAt) const;

    // Whether the `open` queries are measured against every one of the
    // `targets` instead (the sweep, asked before tailLevel at every step):
    // open x targets at most the sweep's work limit. A far query beside a
    // dense cluster then costs one read of the targets, not a radius grown
    // from the cluster's spacing to the gap.
    [[nodiscard]] bool sweeps(uint32_t open, uint64_t targets) const;

    // The radii of the next submission: the current radius and those that
    // follow it (the current step each time) at its search level, at most
    // the chunk (one while retry classes take turns; 2, doubled after a submission that left more than half
    // of its queries going on, up to RTHDIST_SEARCH_LOG_MAX; a radius recorded after the search ended costs a
    // BLAS refit, ~a submission's overhead on an H100: docs/bench/prepared) and radiiPerSubmission.
    [[nodiscard]] std::vector<double> nextRadii() const;
    // The search level of nextRadii().
    [[nodiscard]] int level() const { return levelFor(m_grid, m_radius); }

    // After the submission of `radii` (nextRadii()) that `before` queries
    // entered: the chunk and step for the next, and the radius it starts at,
    // the last radius that searched times the step, or that radius again
    // when its pairs overflowed (its queries that lost pairs retry).
    // `fullCapacity`: the pair buffer's size when it can grow no more (0:
    // it still can). A full buffer that overflows and leaves more than 7/8
    // of the queries going on (few queries' pairs all fitted: on an H200 the retries met the
    // same candidates in the same traversal order every time, and the search
    // never ended) splits the queries into retry classes by index,
    // qi % retryClass().stride: one class a submission at the same radius, the
    // others waiting (search_visit.glsl), as many classes as the pairs
    // reported would fill the buffer twice over, a class that overflows
    // again split further (its turns then come from its own on), until
    // every class has had its turn; then the radius grows. Each class's
    // queries searched alone at most kMaxRetryClasses apart: a class that
    // still overflows then is retryExhausted().
    // Precondition: out.run is 1 .. radii.size().
    void advance(std::span<const double> radii, uint32_t before, const RadiiOutcome& out,
                 uint64_t fullCapacity = 0);
    // The retry classes (stride 1: every query is searched) and the class
    // whose turn it is.
    [[nodiscard]] RetryClass retryClass() const { return m_retry; }
    // Whether a class that overflowed the full buffer cannot be split
    // further: it holds at most one query (stride >= `queries`: that
    // query's own candidate cells at this radius exceed the buffer), or the
    // split would pass kMaxRetryClasses.
    [[nodiscard]] bool retryExhausted() const { return m_exhausted; }

    [[nodiscard]] double radius() const { return m_radius; }
    [[nodiscard]] double step() const { return m_step; }
    [[nodiscard]] uint32_t chunk() const { return m_chunk; }
    // Whether a submission of radii has run (tailLevel's measure and limit).
    [[nodiscard]] bool traced() const { return m_traced; }

private:
    SearchGrid m_grid;
    ScheduleSettings m_settings;
    double m_growth;
    uint32_t m_searched;
    uint64_t m_queries;
    double m_radius;
    double m_step;
    uint32_t m_chunk = 2;
    bool m_traced = false;
    RetryClass m_retry;
    bool m_exhausted = false;
};

}  // namespace rthdist::gpu_algo
