// Spatial targets (rthdist/mpi.hpp has the exactness argument): slabs of T
// along its longest axis, equal counts from an allreduced histogram; each
// rank bounds its queries' nearest distances from above with its own slab
// plus a global sample, receives every target within that bound of its
// queries' axis range (the halo), and answers its queries exactly.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "mpi/collectives.hpp"
#include "mpi/directed_pass.hpp"

namespace rthdist::mpi {

namespace {

// A point in search coordinates with its global index; 16 bytes on the wire.
struct Record {
    glm::vec3 p;
    uint32_t id;
};

// Histogram bins per rank: slabs balance to about 1/256 of a rank's share.
constexpr int kBinsPerRank = 256;
// Targets in the global sample S that bounds every query's nearest distance.
constexpr uint64_t kSampleSize = 4096;
// The bound pass searches every kBoundStride-th target of the rank's slab.
constexpr size_t kBoundStride = 16;

// Slabs along one axis: bin b of [lo, hi] belongs to rank owner[b].
struct Slabs {
    int axis = 0;
    double lo = 0.0, hi = 0.0;
    std::vector<int> owner;

    [[nodiscard]] int binOf(double v) const {
        const int bins = int(owner.size());
        if (!(hi > lo)) return 0;
        const double f = std::floor((v - lo) / (hi - lo) * bins);
        return f < 0 ? 0 : f >= bins ? bins - 1 : int(f);
    }
    [[nodiscard]] int rankOf(const glm::vec3& p) const { return owner[size_t(binOf(double(p[axis])))]; }
};

Slabs makeSlabs(MPI_Comm comm, const GlobalSet& t) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const glm::vec3& p : t.floats) {
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], double(p[k]));
            hi[k] = std::max(hi[k], double(p[k]));
        }
    }
    MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, comm);
    MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, comm);
    Slabs s;
    for (int k = 1; k < 3; ++k)
        if (hi[k] - lo[k] > hi[s.axis] - lo[s.axis]) s.axis = k;
    s.lo = lo[s.axis];
    s.hi = hi[s.axis];
    const int size = sizeOf(comm);
    s.owner.assign(size_t(kBinsPerRank) * size_t(size), 0);
    std::vector<uint64_t> histogram(s.owner.size(), 0);
    for (const glm::vec3& p : t.floats) ++histogram[size_t(s.binOf(double(p[s.axis])))];
    MPI_Allreduce(MPI_IN_PLACE, histogram.data(), int(histogram.size()), MPI_UINT64_T, MPI_SUM, comm);
    // Bin b goes to the rank whose share of the total holds the targets before it.
    uint64_t before = 0;
    for (size_t b = 0; b < histogram.size(); ++b) {
        s.owner[b] = int(std::min<uint64_t>(uint64_t(size - 1), before * uint64_t(size) / t.total()));
        before += histogram[b];
    }
    return s;
}

// Sends each point of `set` to its slab's rank; the result sorted by global index.
Result<std::vector<Record>> distribute(MPI_Comm comm, const GlobalSet& set, const Slabs& slabs) {
    std::vector<std::vector<Record>> out(size_t(sizeOf(comm)));
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        for (size_t i = 0; i < set.floats.size(); ++i) {
            const glm::vec3& p = set.floats[i];
            out[size_t(slabs.rankOf(p))].push_back(Record{p, uint32_t(set.offset() + i)});
        }
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    Result<std::vector<Record>> mine = exchangeRecords(comm, out);
    if (mine)
        std::sort(mine->begin(), mine->end(), [](const Record& x, const Record& y) { return x.id < y.id; });
    return mine;
}

// Every stride-th target of the global order, on every rank.
Result<std::vector<Record>> globalSample(MPI_Comm comm, const GlobalSet& t) {
    const uint64_t stride = std::max<uint64_t>(1, t.total() / kSampleSize);
    std::vector<Record> mine;
    for (uint64_t g = (t.offset() + stride - 1) / stride * stride; g < t.offset() + t.floats.size();
         g += stride)
        mine.push_back(Record{t.floats[size_t(g - t.offset())], uint32_t(g)});
    return allgatherRecords(comm, mine);
}

// A rank's queries as the engine takes them: points, global indices, and
// their prepared set (ordered once for the bound and the final pass).
struct Queries {
    std::vector<glm::vec3> points;
    std::vector<uint32_t> ids;
    std::optional<PreparedSet> prepared;
    double prepareMs = 0.0;  // ordering them (Engine::prepare)
};

Result<Queries> prepareQueries(MPI_Comm comm, Engine& engine, const std::vector<Record>& records,
                               const CallOptions& call) {
    Queries q;
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        q.points.resize(records.size());
        q.ids.resize(records.size());
        for (size_t i = 0; i < records.size(); ++i) q.points[i] = records[i].p, q.ids[i] = records[i].id;
        if (records.empty()) return std::nullopt;
        PrepareOptions options;
        options.bits = call.bits;
        const auto start = std::chrono::steady_clock::now();
        Result<PreparedSet> p = engine.prepare(q.points, options);
        if (!p) return p.error();
        q.prepared.emplace(std::move(p).value());
        q.prepareMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return q;
}

Result<PassOutcome> search(MPI_Comm comm, Engine& engine, const Queries& queries,
                           const std::vector<Record>& targets, const CallOptions& call,
                           bool perPoint = false) {
    Result<PassOutcome> out = Error{};
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        std::vector<glm::vec3> tp(targets.size());
        std::vector<uint32_t> ti(targets.size());
        for (size_t i = 0; i < targets.size(); ++i) tp[i] = targets[i].p, ti[i] = targets[i].id;
        const PreparedSet* prepared = queries.prepared ? &*queries.prepared : nullptr;
        out = searchPrepared(engine, prepared, queries.points, queries.ids, tp, ti, call, perPoint);
        return out ? std::nullopt : std::optional<Error>(out.error());
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return out;
}

// The axis range that holds every nearest neighbour of this rank's queries.
struct Interval {
    double lo = 0.0, hi = 0.0;
    int32_t any = 0;
    int32_t padding = 0;
};

Interval haloInterval(const std::vector<Record>& queries, int axis, double bound, double diagonal) {
    Interval in;
    if (queries.empty()) return in;
    in.any = 1;
    in.lo = INFINITY;
    in.hi = -INFINITY;
    for (const Record& q : queries) {
        in.lo = std::min(in.lo, double(q.p[axis]));
        in.hi = std::max(in.hi, double(q.p[axis]));
    }
    const double w = bound * (1.0 + 1e-4) + 1e-5 * diagonal;  // against rounding (mpi.hpp)
    in.lo -= w;
    in.hi += w;
    return in;
}

// This rank's own targets plus every other rank's targets inside its interval.
Result<std::vector<Record>> withHalo(MPI_Comm comm, const std::vector<Record>& owned,
                                     const std::vector<Interval>& intervals, int axis) {
    const int rank = rankOf(comm);
    std::vector<std::vector<Record>> out(intervals.size());
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        for (const Record& t : owned) {
            const double v = double(t.p[axis]);
            for (size_t r = 0; r < intervals.size(); ++r) {
                const Interval& in = intervals[r];
                if (int(r) != rank && in.any && v >= in.lo && v <= in.hi) out[r].push_back(t);
            }
        }
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    Result<std::vector<Record>> halo = exchangeRecords(comm, out);
    if (!halo) return halo;
    local = guarded([&]() -> std::optional<Error> {
        halo->insert(halo->end(), owned.begin(), owned.end());
        std::sort(halo->begin(), halo->end(), [](const Record& x, const Record& y) { return x.id < y.id; });
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return halo;
}

}  // namespace

Result<PassOutcome> spatialPass(MPI_Comm comm, Engine& engine, const GlobalSet& q, const GlobalSet& t,
                                double diagonal, const CallOptions& call, bool perPoint) {
    const Slabs slabs = makeSlabs(comm, t);
    Result<std::vector<Record>> owned = distribute(comm, t, slabs);
    if (!owned) return owned.error();
    Result<std::vector<Record>> queries = distribute(comm, q, slabs);
    if (!queries) return queries.error();
    Result<std::vector<Record>> sample = globalSample(comm, t);
    if (!sample) return sample.error();
    Result<Queries> prepared = prepareQueries(comm, engine, *queries, call);
    if (!prepared) return prepared.error();

    // Upper bound of every query's nearest distance: every kBoundStride-th
    // target of its slab and the global sample are subsets of T. (A subset
    // keeps the bound pass cheap; the halo it gives is a few spacings wider.)
    std::vector<Record> boundSet;
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        for (size_t i = 0; i < owned->size(); i += kBoundStride) boundSet.push_back((*owned)[i]);
        boundSet.insert(boundSet.end(), sample->begin(), sample->end());
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    Result<PassOutcome> bound = search(comm, engine, *prepared, boundSet, call);
    if (!bound) return bound.error();
    boundSet = {};

    Result<std::vector<Interval>> intervals = allgatherRecords(
        comm, std::vector<Interval>{haloInterval(*queries, slabs.axis, bound->best.distance, diagonal)});
    if (!intervals) return intervals.error();
    Result<std::vector<Record>> targets = withHalo(comm, *owned, *intervals, slabs.axis);
    if (!targets) return targets.error();
    Result<PassOutcome> out = search(comm, engine, *prepared, *targets, call, perPoint);
    if (!out) return out;
    addTimings(out->timings, bound->timings);
    out->timings.index += prepared->prepareMs;
    out->timings.total += prepared->prepareMs;
    return out;
}

}  // namespace rthdist::mpi
