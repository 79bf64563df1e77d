// The self-check of a direction on the device (check_query.comp, DESIGN §6):
// every query settled below the final maximum, sampled query records and
// the witness's compared with the host's copy of the points; the checked
// witness becomes the direction's result, with its per-point distances.
#pragma once

#include <span>

#include "gpu_algo/direction.hpp"
#include "gpu_algo/self_check.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

class QueryCheck {
public:
    explicit QueryCheck(Workspace& workspace) : m_ws(workspace) {}

    // Records the self-check of a direction (check_queries.comp: every query
    // settled below the final maximum, the witness's records copied by the
    // shader) and the copies of the sampled queries' records into the
    // block's read-back area. It is recorded behind the cull and behind each
    // submission of search radii (`behind`: RTHDIST_CHECK_BEHIND_*), so the
    // submission that settles the last query also checks them (no
    // submission of its own); while queries are open the shader returns at
    // once. Per-point calls: the check also writes each query's nearest
    // target and copies them all to the host.
    void cmdCheckQueries(VkCommandBuffer cmd, const DirectionRun& d, uint32_t behind);

    // The self-check's verdict once its submission completed: every query
    // settled, the sampled records and the witness's agree with the host's
    // copy of the points. Returns the witness's records (the query slot of
    // the maximum).
    SampledQuery finishCheck(const DirectionRun& d);

    // The direction's result from its checked witness (and its per-point
    // distances).
    Directed finishDirection(DirectionRun& d, const SampledQuery& witness);

    // Every query is EXACT after a per-point run (the check counted any
    // other): the nearest targets its self-check copied to the host, with
    // their distances in double.
    void readPerPoint(const DirectionRun& d, PerPoint& out);

private:
    // The sampled records' query and target points, for the host to compare
    // (device input: copied from the embedder's buffers, a few dozen points).
    void fetchSampled(const DirectionRun& d, std::span<const SampledQuery> sampled);

    Workspace& m_ws;
};

}  // namespace rthdist::gpu_algo
