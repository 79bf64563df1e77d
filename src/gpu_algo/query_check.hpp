// The self-check of a direction on the device (check_query.comp, design.md §6):
// every query settled below the final maximum, sampled query records and
// the witness's compared with the host's copy of the points; the checked
// witness becomes the direction's result, with its per-point distances.
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "core/per_point_floor.hpp"
#include "gpu_algo/direction.hpp"
#include "gpu_algo/self_check.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

// Where a direction's self-check is recorded: behind the cull (it returns
// at once when queries survived it), behind each submission of search radii
// (dispatched indirectly: groups only once no query goes on), or in a
// submission of its own after the search.
enum class CheckAt { kBehindCull, kBehindSearch, kFinal };

class QueryCheck {
public:
    explicit QueryCheck(Workspace& workspace) : m_ws(workspace) {}

    // Records the self-check of a direction (check_queries.comp: every query
    // settled below the final maximum, the witness's records copied by the
    // shader) and the copies of the sampled queries' records into the
    // block's read-back area, at `at`: the submission that settles a
    // direction's last query (the cull's, or the search's when the check
    // folds into it) also checks it. Per-point calls: the check also writes
    // each query's nearest target and copies them all to the host.
    void cmdCheckQueries(VkCommandBuffer cmd, const DirectionRun& d, CheckAt at);

    // Whether d's check is recorded behind its search radii (kBehindSearch)
    // rather than in a submission of its own: not in per-point calls, whose
    // copy of every query's nearest point would cross the bus after each
    // submission of radii, nor past one dispatch's groups.
    [[nodiscard]] bool foldsIntoSearch(const DirectionRun& d) const;

    // The self-check's verdict once its submission completed: every query
    // settled, the sampled records and the witness's agree with the host's
    // copy of the points. Returns the witness's records (the query slot of
    // the maximum).
    SampledQuery finishCheck(const DirectionRun& d);

    // The direction's result from its checked witness (its per-point
    // output: readPerPoint).
    Directed finishDirection(DirectionRun& d, const SampledQuery& witness);

    // Every query is EXACT after a per-point run (the check counted any
    // other): the nearest targets its self-check copied to the host, with
    // their distances in double unless d.perPointDistances is off (then
    // `out.distance` is left empty). Reads only d's own read-back buffer and
    // the host's points: may run on another thread while the other
    // direction is searched.
    void readPerPoint(const DirectionRun& d, PerPoint& out);
    // A call with a floor (d.above set): its queries above the floor, in
    // query order, from the list its self-check copied back, when they fit
    // it; otherwise nothing (the dense array is then copied back for
    // readPerPoint, into the read-back buffer of `direction`, taken then).
    [[nodiscard]] std::optional<std::vector<detail::QueryNearest>> readAboveFloor(DirectionRun& d,
                                                                                  size_t direction);

    // Device input: copies the query points `queries` and target points
    // `targets` (input indices) from the embedder's buffers to the host in
    // one submission, so that d.qPts / d.tPts.original() can read them; host
    // arrays: nothing to do.
    void fetchPoints(const DirectionRun& d, std::span<const uint32_t> queries,
                     std::span<const uint32_t> targets);

private:
    // The sampled records' query and target points, for the host to compare
    // (device input: copied from the embedder's buffers, a few dozen points).
    void fetchSampled(const DirectionRun& d, std::span<const SampledQuery> sampled);

    Workspace& m_ws;
};

}  // namespace rthdist::gpu_algo
