#include "mpi/local_pass.hpp"

namespace rthdist::mpi {

void addTimings(Timings& into, const Timings& t) {
    into.setup += t.setup;
    into.upload += t.upload;
    into.index += t.index;
    into.cull += t.cull;
    into.search += t.search;
    into.refine += t.refine;
    into.check += t.check;
    into.total += t.total;
    into.gpuIndex += t.gpuIndex;
    into.gpuCull += t.gpuCull;
    into.gpuSearch += t.gpuSearch;
    into.gpuRefine += t.gpuRefine;
}

Result<PassOutcome> searchLocal(Engine& engine, std::span<const glm::vec3> queries,
                                std::span<const uint32_t> queryIds, std::span<const glm::vec3> targets,
                                std::span<const uint32_t> targetIds, const CallOptions& call) {
    PassOutcome out;
    if (queries.empty()) return out;
    if (targets.empty()) return Error{ErrorCode::kInternal, "a rank's target set is empty"};
    CallOptions directed = call;
    directed.directedOnly = true;
    directed.perPointDistances = false;
    directed.progress = nullptr;
    Result<HausdorffResult> r = engine.compute(queries, targets, directed);
    if (!r) return r.error();
    const glm::vec3 q = queries[r->aToB.queryIndex], t = targets[r->aToB.targetIndex];
    const float dx = q.x - t.x, dy = q.y - t.y, dz = q.z - t.z;
    out.best.squaredFloat = dx * dx + dy * dy + dz * dz;
    out.best.distance = r->aToB.distance;
    out.best.query = queryIds[r->aToB.queryIndex];
    out.best.target = targetIds[r->aToB.targetIndex];
    out.best.any = 1;
    out.counters = r->aToB.counters;
    out.timings = r->timings;
    out.validationMessages = r->validationMessages;
    return out;
}

}  // namespace rthdist::mpi
