// Step 3 of RT-HDIST on the device: the search cells' boxes grown by a
// radius R in a BLAS (refitted while the level stays, rebuilt when it
// changes), one ray per active query (ray query or ray-tracing pipeline);
// every reported cell within R becomes a (query, cell) pair for the
// refinement. R grows until no query is active. The radii that share a
// search level go in one submission (the BLAS refitted between them), the
// count of queries each searches kept on the device (search_advance.comp).
// A far tail of few open queries skips the rays: they scan every cell of a
// coarse level instead (Refinement::cmdTailScan). Which radii, how many per
// submission and when the tail scans are the radius schedule's decisions
// (radius_schedule.hpp); this file records them and reads what they found.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gpu_algo/direction.hpp"
#include "gpu_algo/index_build.hpp"
#include "gpu_algo/query_check.hpp"
#include "gpu_algo/radius_schedule.hpp"
#include "gpu_algo/refinement.hpp"
#include "gpu_algo/workspace.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::gpu_algo {

// What one step of the search does: radii (rays and pairs), the far tail's
// scan of a whole level, or the sweep of every target.
enum class SearchStep { kRadii, kTailScan, kSweep };

class CandidateSearch {
public:
    CandidateSearch(Workspace& workspace, IndexBuild& indexBuild, Refinement& refinement, QueryCheck& check);

    // Candidate search with a growing radius until no query is active; where
    // the check folds into the search (QueryCheck::foldsIntoSearch), the
    // submission that settles the last query also ran it.
    void runSearch(DirectionRun& d, uint32_t numActive, const CallOptions& options, double progressFrom,
                   double progressTo);

    // Whether the `open` queries scan whole cells of a level instead of
    // tracing (more) radii, and which (-1: trace): the schedule's tailLevel,
    // building the levels it asks about (a submission each).
    [[nodiscard]] int tailScanLevel(const RadiusSchedule& schedule, PointIndex& T, uint32_t open);

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
    // `retry`: the queries the radii search (the others wait).
    RadiiOutcome runRadii(DirectionRun& d, int level, bool sameLevel, std::span<const double> radii,
                          Buffer& pairs, uint64_t pairCapacity, uint32_t numActive,
                          SearchStep step = SearchStep::kRadii, RetryClass retry = {});

    // Records the search of one radius: the level's boxes grown by the
    // radius, the BLAS refitted (same level) or rebuilt, one ray per active
    // query; the rays append (query, cell) pairs.
    void cmdSearch(VkCommandBuffer cmd, DirectionRun& d, const PointIndex::Level& lv, bool sameLevel,
                   double radius, Buffer& pairs, uint64_t pairCapacity, uint32_t numActive, RetryClass retry);

    // One ray per active slot, in traces of at most maxRayDispatch rays
    // (each trace sees its first slot in SearchPush::slotBase).
    void cmdTraceRaysSplit(VkCommandBuffer cmd, sh::SearchPush sp);

private:
    // The knobs of every search's radius schedule (Tuning's fields and the
    // device's limits; tests and benchmarks set the Tuning fields).
    ScheduleSettings m_schedule;
    Workspace& m_ws;
    IndexBuild& m_index;
    Refinement& m_refine;
    QueryCheck& m_check;
};

}  // namespace rthdist::gpu_algo
