// Step 3 of RT-HDIST on the device: the search cells' boxes grown by a
// radius R in a BLAS (refitted while the level stays, rebuilt when it
// changes), one ray per active query (ray query or ray-tracing pipeline);
// every reported cell within R becomes a (query, cell) pair for the
// refinement. R grows until no query is active. The radii that share a
// search level go in one submission (the BLAS refitted between them), the
// count of queries each searches kept on the device (search_advance.comp).
// A far tail of few open queries skips the rays: they scan every cell of a
// coarse level instead (tailScanLevel, Refinement::cmdTailScan).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gpu_algo/direction.hpp"
#include "gpu_algo/index_build.hpp"
#include "gpu_algo/query_check.hpp"
#include "gpu_algo/refinement.hpp"
#include "gpu_algo/workspace.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::gpu_algo {

// Radii before a search is declared not converging.
inline constexpr uint32_t kMaxIterations = 4096;

// The far tail's scan (CandidateSearch::tailScanLevel): at most this many
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

// What one step of the search does: radii (rays and pairs), the far tail's
// scan of a whole level, or the sweep of every target.
enum class SearchStep { kRadii, kTailScan, kSweep };

// What the radii of one submission reported.
struct RadiiOutcome {
    uint32_t run = 0;         // radii that searched queries (the later ones had none left)
    uint32_t stillOpen = 0;   // queries going on after the last of them (or retrying)
    uint64_t lastPairs = 0;   // (query, cell) pairs the last of them appended
    bool overflowed = false;  // ... more than the buffer held: its queries that lost pairs retry
};

class CandidateSearch {
public:
    CandidateSearch(Workspace& workspace, IndexBuild& indexBuild, Refinement& refinement, QueryCheck& check);

    // Candidate search with a growing radius until no query is active; where
    // the check folds into the search (QueryCheck::foldsIntoSearch), the
    // submission that settles the last query also ran it.
    void runSearch(DirectionRun& d, uint32_t numActive, const CallOptions& options, double progressFrom,
                   double progressTo);

    // The growth of the next radii after a submission that left `after` of
    // its `before` queries going on (`searched`: the direction's queries
    // that entered the search): `growth`, or growth^2 for a tail of far
    // queries (at most an eighth of `searched` left, and most of those of
    // the submission going on). Such a tail is a noisy mask's isolated
    // voxels, up to 300 mm from the other mask against a first radius of
    // 12 mm: each radius costs a BLAS refit and a trace pass whatever the
    // number of queries (~0.5 ms on an H100), so they reach their distance
    // in about half the radii. The radii never decide a result (every
    // query's nearest cell is refined exactly, whatever the radius).
    [[nodiscard]] static double tailStep(double growth, uint32_t searched, uint32_t before, uint32_t after);

    // Whether the `open` queries left of `from` (the direction's searched
    // queries after radii, all its queries before the first) are a tail
    // that scans whole cells instead of tracing (more) radii, and at which
    // level (-1: trace). A tail: at most a quarter of `from` left (at most
    // the device's maxGroupsX: a workgroup each), and `open` x the level's
    // cells at most `work` (tailScanWork after radii, tailScanStartWork
    // before; each query then costs a walk over the level's cells, against a BLAS
    // refit and a trace pass for every radius, ~0.5 ms on an H100 whatever
    // the number of queries, that a noisy mask's isolated voxels, up to
    // 300 mm from the other mask, take 5 of). The level: the first from
    // the coarsest built with at most kTailScanCells cells, building coarser
    // ones (a submission each) up to the grid's last. The result is exact
    // either way.
    [[nodiscard]] int tailScanLevel(PointIndex& T, uint32_t open, uint64_t from, uint64_t work);

    // The radii that follow `radius` (growth each time) at its search level,
    // at most `most` (and radiiPerSubmission) of them.
    [[nodiscard]] std::vector<double> radiiAtLevel(const PointIndex& T, double radius, double growth,
                                                   uint32_t most) const;

    // Radii of one level in one submission, each: the search (cmdSearch),
    // the refinement sized by the device from the pairs the rays appended
    // (cmdRefine, indirect dispatch), the resolution of every active query,
    // then search_advance.comp, which logs the radius and hands the queries
    // going on to the next (none after a pair-buffer overflow). numActive:
    // the queries of the first radius (the later ones search at most as
    // many). The host reads the log once, at the end. The direction's
    // self-check follows the radii where it folds into the search (groups
    // only once no query goes on). `step` kTailScan: one step, the far
    // tail's scan of every cell of `level`; kSweep: one step, every target
    // (radii unused); after either no query goes on.
    RadiiOutcome runRadii(DirectionRun& d, int level, bool sameLevel, std::span<const double> radii,
                          Buffer& pairs, uint64_t pairCapacity, uint32_t numActive,
                          SearchStep step = SearchStep::kRadii);

    // Radii per submission at most (1 to RTHDIST_SEARCH_LOG_MAX;
    // Tuning::searchRadiiPerSubmission sets it for tests and benchmarks).
    uint32_t radiiPerSubmission = RTHDIST_SEARCH_LOG_MAX;
    // tailStep's squared growth (Tuning::squaredTailGrowth = false turns it
    // off, for tests and benchmarks).
    bool squaredTailGrowth = true;
    // tailScanLevel's work limit: kTailScanWorkGpu, or kTailScanWorkCpuDevice
    // on a CPU device; Tuning::tailScanWork sets it for tests and
    // benchmarks (0: never).
    uint64_t tailScanWork = kTailScanWorkGpu;
    // Before any radius: kTailScanStartWorkGpu (0: never), also on a CPU
    // device; Tuning::tailScanStartWork sets it (tests, benchmarks).
    uint64_t tailScanStartWork = kTailScanStartWorkGpu;
    // The sweep's work limit: kSweepWorkGpu or kSweepWorkCpuDevice;
    // Tuning::sweepWork sets it (0: never).
    uint64_t sweepWork = kSweepWorkGpu;

    // Records the search of one radius: the level's boxes grown by the
    // radius, the BLAS refitted (same level) or rebuilt, one ray per active
    // query; the rays append (query, cell) pairs.
    void cmdSearch(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool sameLevel,
                   double radius, Buffer& pairs, uint64_t pairCapacity, uint32_t numActive);

    // One ray per active slot, in traces of at most maxRayDispatch rays
    // (each trace sees its first slot in SearchPush::slotBase).
    void cmdTraceRaysSplit(VkCommandBuffer cmd, sh::SearchPush sp);

private:
    Workspace& m_ws;
    IndexBuild& m_index;
    Refinement& m_refine;
    QueryCheck& m_check;
};

}  // namespace rthdist::gpu_algo
