#include "mpi/local_pass.hpp"

#include <chrono>
#include <iterator>

#include "core/stopwatch.hpp"

namespace rthdist::mpi {

using core::msSince;

namespace {

// Every field of Timings (the static_assert catches one added later).
constexpr double Timings::*kTimingFields[] = {
    &Timings::setup,     &Timings::upload,      &Timings::index,          &Timings::cull,
    &Timings::search,    &Timings::refine,      &Timings::check,          &Timings::total,
    &Timings::gpuIndex,  &Timings::gpuCull,     &Timings::gpuSearch,      &Timings::gpuRefine,
    &Timings::gpuUpload, &Timings::certificate, &Timings::gpuCertificate, &Timings::pieces};
static_assert(sizeof(Timings) == std::size(kTimingFields) * sizeof(double), "a Timings field is missing");

}  // namespace

void addTimings(Timings& into, const Timings& t) {
    for (double Timings::*field : kTimingFields) into.*field += t.*field;
}

namespace {

CallOptions directedCall(const CallOptions& call, bool perPoint) {
    CallOptions directed = call;
    directed.directedOnly = true;
    directed.perPointDistances = perPoint;
    directed.perPointNearestOnly = false;
    directed.perPointReady = nullptr;
    directed.progress = nullptr;
    return directed;
}

// The outcome of a directed engine result, its witness in global indices.
PassOutcome outcomeOf(const HausdorffResult& r, std::span<const glm::vec3> queries,
                      std::span<const uint32_t> queryIds, std::span<const glm::vec3> targets,
                      std::span<const uint32_t> targetIds) {
    PassOutcome out;
    const glm::vec3 q = queries[r.aToB.queryIndex], t = targets[r.aToB.targetIndex];
    const float dx = q.x - t.x, dy = q.y - t.y, dz = q.z - t.z;
    out.best.squaredFloat = dx * dx + dy * dy + dz * dz;
    out.best.distance = r.aToB.distance;
    out.best.query = queryIds[r.aToB.queryIndex];
    out.best.target = targetIds[r.aToB.targetIndex];
    out.best.any = 1;
    out.best.confirmed = r.aToB.certificate.confirmed ? 1 : 0;
    out.best.band = r.aToB.certificate.band;
    out.counters = r.aToB.counters;
    out.timings = r.timings;
    out.validationMessages = r.validationMessages;
    if (!r.aNearest.distance.empty()) {
        out.queryIds.assign(queryIds.begin(), queryIds.end());
        out.queryDistances = r.aNearest.distance;
    }
    return out;
}

}  // namespace

Result<PassOutcome> searchLocal(Engine& engine, std::span<const glm::vec3> queries,
                                std::span<const uint32_t> queryIds, std::span<const glm::vec3> targets,
                                std::span<const uint32_t> targetIds, const CallOptions& call, bool perPoint) {
    if (queries.empty()) return PassOutcome{};
    if (targets.empty()) return Error{ErrorCode::kInternal, "a rank's target set is empty"};
    Result<HausdorffResult> r = engine.compute(queries, targets, directedCall(call, perPoint));
    if (!r) return r.error();
    return outcomeOf(*r, queries, queryIds, targets, targetIds);
}

Result<PassOutcome> searchPrepared(Engine& engine, const PreparedSet* prepared,
                                   std::span<const glm::vec3> queries, std::span<const uint32_t> queryIds,
                                   std::span<const glm::vec3> targets, std::span<const uint32_t> targetIds,
                                   const CallOptions& call, bool perPoint) {
    if (queries.empty()) return PassOutcome{};
    if (targets.empty()) return Error{ErrorCode::kInternal, "a rank's target set is empty"};
    const auto start = std::chrono::steady_clock::now();
    PrepareOptions options;
    options.bits = call.bits;
    Result<PreparedSet> t = engine.prepare(targets, options);
    if (!t) return t.error();
    const double prepareMs = msSince(start);
    Result<HausdorffResult> r = engine.compute(*prepared, *t, directedCall(call, perPoint));
    if (!r) return r.error();
    PassOutcome out = outcomeOf(*r, queries, queryIds, targets, targetIds);
    out.timings.index += prepareMs;  // the target's index is built by prepare()
    out.timings.total += prepareMs;
    return out;
}

}  // namespace rthdist::mpi
