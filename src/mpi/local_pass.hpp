// One rank's share of a directed pass h(Q,T) of hausdorffMpi: its queries
// against a target set that holds each of their nearest neighbours, on the
// rank's Engine, with the witness mapped to global indices. Local (no MPI).
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::mpi {

// A rank's best query of one direction, in global indices. Ranks compare
// squaredFloat, the pair's squared distance in float as the CPU backend
// computes it ((dx*dx + dy*dy) + dz*dz of the scaled float32 points), largest
// first, then the smallest query index: the one-process winner rule.
struct Candidate {
    double distance = -1.0;  // the engine's, in double from the scaled float32 points
    float squaredFloat = -1.0f;
    uint32_t query = 0;
    uint32_t target = 0;
    int32_t any = 0;        // 0: this rank had no query
    int32_t confirmed = 0;  // the rank's engine proved its value (Directed::certificate)
    uint64_t band = 0;      // the rank's certificate's band
};

struct PassOutcome {
    Candidate best;
    // With `perPoint` (double inputs that are not float32 values, for the
    // settle in double): every query's float pair distance in the search
    // frame (the engine's per-point entry), and its global index.
    std::vector<uint32_t> queryIds;
    std::vector<double> queryDistances;
    Counters counters;
    Timings timings;
    uint64_t validationMessages = 0;
};

// h(queries, targets) with the engine (directed only); queryIds[i] and
// targetIds[j] are the global indices of queries[i] and targets[j], each
// sorted ascending so that the engine's ties (smallest index) are the global
// ones. Empty queries: an outcome with best.any = 0 and no engine call.
// into += t, field by field.
void addTimings(Timings& into, const Timings& t);

[[nodiscard]] Result<PassOutcome> searchLocal(Engine& engine, std::span<const glm::vec3> queries,
                                              std::span<const uint32_t> queryIds,
                                              std::span<const glm::vec3> targets,
                                              std::span<const uint32_t> targetIds, const CallOptions& call,
                                              bool perPoint = false);

// As searchLocal, with the queries prepared once by the caller
// (Engine::prepare of `queries`, kept for several passes: the spatial mode's
// bound and final pass order them once). The targets are prepared here; the
// time of that is added to timings.index and total. `prepared` may be null
// only when `queries` is empty.
[[nodiscard]] Result<PassOutcome> searchPrepared(Engine& engine, const PreparedSet* prepared,
                                                 std::span<const glm::vec3> queries,
                                                 std::span<const uint32_t> queryIds,
                                                 std::span<const glm::vec3> targets,
                                                 std::span<const uint32_t> targetIds, const CallOptions& call,
                                                 bool perPoint = false);

}  // namespace rthdist::mpi
