// hausdorffMpi: the frame, one directed pass per direction (replicated or
// spatial targets), the winner of each direction chosen identically on every
// rank, and its distance recomputed in double from the caller's points.
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "core/certificate.hpp"
#include "mpi/collectives.hpp"
#include "mpi/directed_pass.hpp"
#include "mpi/global_sets.hpp"
#include "rthdist/mpi.hpp"

namespace rthdist {

namespace {

using Clock = std::chrono::steady_clock;

// Largest distance first, then the smallest query index: one engine's rule.
// The ranks' witnesses compared by their exact values (each rank's engine
// proved its own: Directed::certificate), the smaller query index among
// ties; the winner is confirmed when every rank's value was.
mpi::Candidate winnerOf(MPI_Comm comm, const mpi::Candidate& mine) {
    Result<std::vector<mpi::Candidate>> all = mpi::allgatherRecords(comm, std::vector<mpi::Candidate>{mine});
    mpi::Candidate best;
    if (!all) return best;  // a few bytes per rank; agreed on every rank
    bool confirmed = true;
    uint64_t band = 0;
    for (const mpi::Candidate& c : *all) {
        if (!c.any) continue;
        confirmed = confirmed && c.confirmed != 0;
        band += c.band;
        if (!best.any || c.distance > best.distance || (c.distance == best.distance && c.query < best.query))
            best = c;
    }
    best.confirmed = confirmed ? 1 : 0;
    best.band = band;
    return best;
}

// Sums the counters over ranks; bits and iterations are the maximum.
Counters reduceCounters(MPI_Comm comm, const Counters& c) {
    uint64_t sums[7] = {c.occupiedCells,  c.queries,    c.culledByNeighbourhood, c.survivingQueries, c.rays,
                        c.candidatePairs, c.tailScanned};
    uint32_t maxima[2] = {c.bits, c.iterations};
    MPI_Allreduce(MPI_IN_PLACE, sums, 7, MPI_UINT64_T, MPI_SUM, comm);
    MPI_Allreduce(MPI_IN_PLACE, maxima, 2, MPI_UINT32_T, MPI_MAX, comm);
    Counters out;
    out.occupiedCells = sums[0];
    out.queries = sums[1];
    out.culledByNeighbourhood = sums[2];
    out.survivingQueries = sums[3];
    out.rays = sums[4];
    out.candidatePairs = sums[5];
    out.tailScanned = sums[6];
    out.bits = maxima[0];
    out.iterations = maxima[1];
    return out;
}

// Each stage's maximum over ranks.
Timings reduceTimings(MPI_Comm comm, const Timings& t) {
    double v[12] = {t.setup, t.upload, t.index,    t.cull,    t.search,    t.refine,
                    t.check, t.total,  t.gpuIndex, t.gpuCull, t.gpuSearch, t.gpuRefine};
    MPI_Allreduce(MPI_IN_PLACE, v, 12, MPI_DOUBLE, MPI_MAX, comm);
    Timings out;
    double* fields[12] = {&out.setup,    &out.upload,  &out.index,     &out.cull,
                          &out.search,   &out.refine,  &out.check,     &out.total,
                          &out.gpuIndex, &out.gpuCull, &out.gpuSearch, &out.gpuRefine};
    for (int i = 0; i < 12; ++i) *fields[i] = v[i];
    return out;
}

// The settle in double of a direction whose inputs are not float32 values
// (one process settles its band the same way, core/certificate.hpp): the
// ranks searched the shifted frame's floats, whose every query's pair
// distance (the engine's per-point entry, scaled) lies within
// kSettleSlackLog2 of the scaled frame's magnitude m of the query's exact
// nearest distance (float rounding of the points: < 2^-21.8 m; the entry's
// own relative 2^-21 of a distance <= 2 sqrt(3) m: < 2^-19 m). So only a
// query whose entry is within twice that of the largest entry can realize
// (or tie) the exact maximum: those (the band) are measured exactly, by a
// brute force in double over every rank's slice of the targets as given,
// the smallest index on a tie, and the largest wins (the smallest query on
// a tie). A band past kSettleMaxWork query x target pairs is not settled.
constexpr int kSettleSlackLog2 = -17;
constexpr double kSettleMaxWork = 0x1p32;

struct BandQuery {
    glm::dvec3 p;
    uint32_t id = 0;
    uint32_t padding = 0;
};

// The exact h over the band, or nullopt when the band is too large.
std::optional<Directed> settleInDouble(MPI_Comm comm, const mpi::GlobalSet& q, const mpi::GlobalSet& t,
                                       const mpi::PassOutcome& pass) {
    double m = 0.0, largest = -1.0;
    for (const std::vector<glm::vec3>* floats : {&q.floats, &t.floats})
        for (const glm::vec3& p : *floats)
            m = std::max({m, double(std::abs(p.x)), double(std::abs(p.y)), double(std::abs(p.z))});
    for (double d : pass.queryDistances) largest = std::max(largest, d);
    double reduced[2] = {m, largest};
    MPI_Allreduce(MPI_IN_PLACE, reduced, 2, MPI_DOUBLE, MPI_MAX, comm);
    const double floor = reduced[1] - 2.0 * std::ldexp(reduced[0], kSettleSlackLog2);
    std::vector<uint32_t> mine;
    for (size_t i = 0; i < pass.queryDistances.size(); ++i)
        if (pass.queryDistances[i] >= floor) mine.push_back(pass.queryIds[i]);
    uint64_t count = mine.size();
    MPI_Allreduce(MPI_IN_PLACE, &count, 1, MPI_UINT64_T, MPI_SUM, comm);
    if (double(count) * double(t.total()) > kSettleMaxWork) return std::nullopt;
    Result<std::vector<uint32_t>> ids = mpi::allgatherRecords(comm, mine);
    if (!ids || ids->empty()) return std::nullopt;
    std::sort(ids->begin(), ids->end());
    // Each band query's coordinates as given, from the rank whose slice holds it.
    std::vector<BandQuery> owned;
    for (const uint32_t id : *ids)
        if (id >= q.offset() && id < q.offset() + q.local.count)
            owned.push_back(BandQuery{q.local.at(size_t(id - q.offset())), id, 0});
    Result<std::vector<BandQuery>> band = mpi::allgatherRecords(comm, owned);
    if (!band || band->size() != ids->size()) return std::nullopt;
    std::sort(band->begin(), band->end(), [](const BandQuery& x, const BandQuery& y) { return x.id < y.id; });
    // This rank's nearest of each over its own slice of the targets (the
    // host brute force of every proof, core/certificate.hpp; every
    // hardware thread of the rank), in global indices.
    std::vector<core::BandNearest> nearest(band->size());
    for (size_t k = 0; k < band->size(); ++k) nearest[k].query = k;
    const core::BruteForce bruteForce =
        core::hostBruteForce([&band](uint64_t k) { return (*band)[size_t(k)].p; }, t.local, 0);
    if (!bruteForce(nearest)) return std::nullopt;
    for (core::BandNearest& n : nearest)
        if (n.target != std::numeric_limits<uint64_t>::max()) n.target += t.offset();
    Result<std::vector<core::BandNearest>> all = mpi::allgatherRecords(comm, nearest);
    if (!all) return std::nullopt;
    // Each query's nearest over every rank's (BandNearest::offer: the
    // smaller index on a tie), the largest winning, the smaller query on a tie.
    Directed d;
    bool any = false;
    for (size_t k = 0; k < band->size(); ++k) {
        core::BandNearest best;
        for (size_t r = 0; r * band->size() + k < all->size(); ++r) {
            const core::BandNearest& c = (*all)[r * band->size() + k];
            best.offer(c.target, c.distance);
        }
        if (!any || best.distance > d.distance) {
            any = true;
            d.distance = best.distance;
            d.queryIndex = (*band)[k].id;
            d.targetIndex = best.target;
            d.queryPoint = (*band)[k].p;
        }
    }
    d.targetPoint = mpi::broadcastPoint(comm, t, d.targetIndex);
    d.certificate.confirmed = core::exactDistance(d.queryPoint, d.targetPoint) == d.distance;
    d.certificate.query = d.queryIndex;
    d.certificate.nearest = d.targetIndex;
    d.certificate.distance = d.distance;
    d.certificate.band = band->size();
    return d;
}

// One direction: the pass, then the winner with its points in the caller's coordinates.
Result<Directed> direction(MPI_Comm comm, Engine& engine, const mpi::GlobalSets& sets, bool aToB,
                           bool spatial, const CallOptions& call, Timings& timings, uint64_t& validation) {
    const mpi::GlobalSet& q = aToB ? sets.a : sets.b;
    const mpi::GlobalSet& t = aToB ? sets.b : sets.a;
    // Inputs that are not float32 values: every query's float pair kept for the settle in double.
    const bool settle = !sets.floatExact;
    Result<mpi::PassOutcome> pass = spatial
                                        ? mpi::spatialPass(comm, engine, q, t, sets.diagonal, call, settle)
                                        : mpi::replicatedPass(comm, engine, q, t, call, settle);
    if (!pass) return pass.error();
    const mpi::Candidate best = winnerOf(comm, pass->best);
    if (!best.any) return Error{ErrorCode::kInternal, "no rank reported a witness"};
    if (settle) {
        const auto settleStart = Clock::now();
        std::optional<Directed> exact = settleInDouble(comm, q, t, *pass);
        if (exact) {
            exact->counters = reduceCounters(comm, pass->counters);
            pass->timings.refine +=
                std::chrono::duration<double, std::milli>(Clock::now() - settleStart).count();
            mpi::addTimings(timings, pass->timings);
            validation += pass->validationMessages;
            return *exact;
        }
    }
    Directed d;
    d.queryIndex = best.query;
    d.targetIndex = best.target;
    d.queryPoint = mpi::broadcastPoint(comm, q, best.query);
    d.targetPoint = mpi::broadcastPoint(comm, t, best.target);
    d.distance = glm::length(d.queryPoint - d.targetPoint);
    // Double inputs that are not float32 values whose band was too large to
    // settle in double: the ranks proved the value on the shifted frame's
    // float32 points only, within 2e of the double answer: reported
    // unconfirmed, with the reason.
    d.certificate.confirmed = best.confirmed != 0 && sets.floatExact;
    if (best.confirmed != 0 && !sets.floatExact)
        d.certificate.failure =
            "double inputs over MPI: too many queries near the maximum to settle in double; proven on the "
            "shifted frame's float32 points (within 2e of the double answer), not in double";
    d.certificate.query = d.queryIndex;
    d.certificate.nearest = d.targetIndex;
    d.certificate.distance = d.distance;
    d.certificate.band = best.band;
    d.counters = reduceCounters(comm, pass->counters);
    mpi::addTimings(timings, pass->timings);
    validation += pass->validationMessages;
    return d;
}

bool replicate(const mpi::GlobalSets& sets, const MpiOptions& mpi) {
    if (mpi.mode != TargetMode::kAuto) return mpi.mode == TargetMode::kReplicated;
    return (sets.a.total() + sets.b.total()) * sizeof(glm::vec3) <= mpi.replicateLimitBytes;
}

}  // namespace

const char* targetModeName(TargetMode mode) {
    switch (mode) {
        case TargetMode::kAuto: return "auto";
        case TargetMode::kReplicated: return "replicated";
        case TargetMode::kSpatial: return "spatial";
    }
    return "auto";
}

bool parseTargetMode(const char* text, TargetMode& out) {
    for (TargetMode m : {TargetMode::kAuto, TargetMode::kReplicated, TargetMode::kSpatial}) {
        if (std::strcmp(text, targetModeName(m)) == 0) {
            out = m;
            return true;
        }
    }
    return false;
}

namespace {

// The options that steer the collectives (how many directions, which mode)
// or the values (bits, radius growth) are the same on every rank: a rank
// with others would enter other collectives (a hang) or compute another H.
// kInvalidArgument on every rank, naming the first option that differs.
std::optional<Error> optionsDiffer(MPI_Comm comm, const CallOptions& call, const MpiOptions& mpi) {
    float growth = call.radiusGrowth;
    uint32_t growthBits = 0;
    std::memcpy(&growthBits, &growth, sizeof(growthBits));
    const std::pair<const char*, int64_t> fields[] = {
        {"CallOptions::directedOnly", call.directedOnly ? 1 : 0},
        {"CallOptions::perPointDistances", call.perPointDistances ? 1 : 0},
        {"CallOptions::bits", call.bits},
        {"CallOptions::radiusGrowth", int64_t(growthBits)},
        {"MpiOptions::mode", int64_t(mpi.mode)},
        {"MpiOptions::replicateLimitBytes", int64_t(mpi.replicateLimitBytes)}};
    constexpr int kFields = int(sizeof(fields) / sizeof(fields[0]));
    int64_t lo[kFields], hi[kFields];
    for (int k = 0; k < kFields; ++k) lo[k] = hi[k] = fields[k].second;
    MPI_Allreduce(MPI_IN_PLACE, lo, kFields, MPI_INT64_T, MPI_MIN, comm);
    MPI_Allreduce(MPI_IN_PLACE, hi, kFields, MPI_INT64_T, MPI_MAX, comm);
    for (int k = 0; k < kFields; ++k) {
        if (lo[k] != hi[k])
            return Error{ErrorCode::kInvalidArgument,
                         std::string("hausdorffMpi: the ranks passed different ") + fields[k].first +
                             "; every rank must pass the same options"};
    }
    return std::nullopt;
}

}  // namespace

Result<HausdorffResult> hausdorffMpi(MPI_Comm comm, Engine& engine, PointView localA, PointView localB,
                                     const CallOptions& call, const MpiOptions& mpi) {
    const Clock::time_point start = Clock::now();
    if (auto error = optionsDiffer(comm, call, mpi)) return *error;  // the same on every rank
    std::optional<Error> local;
    if (call.perPointDistances)
        local = Error{ErrorCode::kInvalidArgument, "hausdorffMpi does not compute per-point distances"};
    if (auto error = agreeOnError(comm, local)) return *error;
    Result<mpi::GlobalSets> sets = mpi::makeGlobalSets(comm, localA, localB);
    if (!sets) return sets.error();
    const bool spatial = !replicate(*sets, mpi);

    HausdorffResult r;
    Timings timings;
    uint64_t validation = 0;
    Result<Directed> ab = direction(comm, engine, *sets, true, spatial, call, timings, validation);
    if (!ab) return ab.error();
    r.aToB = *ab;
    r.hausdorff = r.aToB.distance;
    r.directedOnly = call.directedOnly;
    if (!call.directedOnly) {
        Result<Directed> ba = direction(comm, engine, *sets, false, spatial, call, timings, validation);
        if (!ba) return ba.error();
        r.bToA = *ba;
        r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
    }
    r.backend = engine.backend();
    r.device = engine.deviceName();
    mpi::broadcastString(comm, 0, r.device);
    int backend = int(r.backend);
    MPI_Bcast(&backend, 1, MPI_INT, 0, comm);
    r.backend = Backend(backend);
    r.origin = sets->origin;
    r.timings = reduceTimings(comm, timings);
    r.timings.total = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    MPI_Allreduce(MPI_IN_PLACE, &r.timings.total, 1, MPI_DOUBLE, MPI_MAX, comm);
    MPI_Allreduce(&validation, &r.validationMessages, 1, MPI_UINT64_T, MPI_SUM, comm);
    return r;
}

Result<HausdorffResult> hausdorffMpi(MPI_Comm comm, PointView localA, PointView localB,
                                     const Options& options, const MpiOptions& mpi) {
    std::optional<Engine> engine;
    std::optional<Error> local = mpi::guarded([&]() -> std::optional<Error> {
        Result<Engine> e = Engine::create(static_cast<const EngineOptions&>(options));
        if (!e) return e.error();
        engine.emplace(std::move(e).value());
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return hausdorffMpi(comm, *engine, localA, localB, static_cast<const CallOptions&>(options), mpi);
}

}  // namespace rthdist
