#include "api/out_of_core.hpp"

#include "api/spatial_pieces.hpp"

#include "core/certificate.hpp"
#include "core/index_space.hpp"
#include "core/parallel.hpp"
#include "core/stopwatch.hpp"
#include "core/timings.hpp"
#include "core/uninit_vector.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace rthdist::api {

namespace {

using Span = std::span<const glm::vec3>;

// Points per task of the host passes over queries and targets.
constexpr size_t kHostChunk = size_t(1) << 16;
// Round two compares this many points on the host for a tile whatever its
// size (scanOnHost): about a millisecond on a few cores, below a call's
// fixed cost (a submission, the tile's upload and index).
constexpr uint64_t kHostScanPoints = uint64_t(1) << 20;

// The running state of one direction: its witness so far, every query's best
// pair (when the caller asked for per-point output), and the counters and
// timings of the calls.
struct DirectionState {
    Directed witness;
    float witnessD2 = -1.0f;  // the witness pair's searchDist2 (-1: none yet)
    PerPoint perPoint;
    Counters counters;
    Timings timings;
    // The certificate's band (core/certificate.hpp): the union of the
    // pieces' bands (query indices into the whole set). A query outside it
    // is nearer than its piece's hf - e, which the proof must reach: the
    // largest such bound over the pieces is `reach` (search units).
    core::DirectionBand band;
    double reach = 0.0;
};

// A piece's band into the direction's (its queries offset by q0).
void mergeBand(DirectionState& s, const core::DirectionBand& piece, uint64_t q0) {
    core::DirectionBand& band = s.band;
    if (!piece.present) {
        band.failure = "a piece's call kept no band";
        return;
    }
    if (!piece.failure.empty()) band.failure = piece.failure;
    for (const core::BandQuery& b : piece.queries) band.queries.push_back({b.query + q0, b.best});
    for (const auto& [q, list] : piece.candidates) band.candidates.emplace_back(q + q0, list);
    s.reach = std::max(s.reach, piece.hf - piece.slack);
    band.slack = std::max(band.slack, piece.slack);
}

// A direction's state shared by its lanes (one per device: chunks run in
// parallel): the witness, counters and timings under the mutex; per-point
// output is written by chunk, each range by one lane.
struct SharedDirection {
    std::mutex mutex;
    DirectionState state;
    double slack = 0.0;          // the certificate's e for the whole direction (search units)
    std::optional<Error> error;  // the first failure; the other lanes stop at their next chunk
    std::atomic<bool> failed{false};
};

void addCounters(Counters& into, const Counters& c, bool countTargets) {
    into.bits = std::max(into.bits, c.bits);
    if (countTargets) into.occupiedCells += c.occupiedCells;
    into.queries += c.queries;
    into.culledByNeighbourhood += c.culledByNeighbourhood;
    into.survivingQueries += c.survivingQueries;
    into.iterations = std::max(into.iterations, c.iterations);
    into.rays += c.rays;
    into.candidatePairs += c.candidatePairs;
    into.tailScanned += c.tailScanned;
}

// The squared distance of a pair as the backends compare pairs: in float, on
// the points scaled by the call's exact power of two (core::exactScale), so
// that the pieces choose among near-ties as one call would.
float squaredLength(const glm::vec3& d) {
    const float xy = d.x * d.x + d.y * d.y;
    return xy + d.z * d.z;
}

float searchDist2(const glm::vec3& q, const glm::vec3& t, double scale) {
    return squaredLength(core::scaled(q, scale) - core::scaled(t, scale));
}

// A chunk's witness (its query index within the chunk, its target index
// into the whole target set) against the direction's: the larger distance
// wins, the smaller query index among ties (chunks of several lanes finish in
// any order).
void offerWitness(SharedDirection& shared, const Directed& d, float d2, uint64_t queryOffset) {
    const uint64_t query = d.queryIndex + queryOffset;
    std::lock_guard lock(shared.mutex);
    DirectionState& s = shared.state;
    if (!(d2 > s.witnessD2 || (d2 == s.witnessD2 && query < s.witness.queryIndex))) return;
    s.witness = d;
    s.witness.queryIndex = query;
    s.witnessD2 = d2;
}

// What a call adds to the direction's counters and timings.
void addCall(SharedDirection& shared, const HausdorffResult& r, bool countTargets) {
    std::lock_guard lock(shared.mutex);
    addCounters(shared.state.counters, r.aToB.counters, countTargets);
    core::addStageTimings(shared.state.timings, r.timings);
}

// Progress of one call mapped into [from, from + width) of the whole.
CallOptions pieceOptions(const CallOptions& call, bool perPoint, double from, double width) {
    CallOptions piece = call;
    piece.directedOnly = true;
    piece.perPointDistances = perPoint;
    piece.perPointNearestOnly = false;  // the pieces are merged by their distances
    piece.perPointReady = nullptr;      // the merged result is handed back (engine.cpp)
    if (call.progress) {
        piece.progress = [progress = call.progress, from, width](const char* stage, double f) {
            progress(stage, from + width * f);
        };
    }
    return piece;
}

// A call of the pieces in space: per-point nearest targets only. The host
// computes each pair's distance itself as it merges (pairDistance: the
// distance every backend reports, core::exactDistance of the pair as given),
// so the call neither computes nor writes a distance per query.
CallOptions spaceOptions(const CallOptions& call, double from, double width) {
    CallOptions piece = pieceOptions(call, true, from, width);
    piece.perPointNearestOnly = true;
    return piece;
}

// A per-point pair's distance as the backends report it (PerPoint::distance).
double pairDistance(const glm::vec3& q, const glm::vec3& t) {
    return core::exactDistance(glm::dvec3(q), glm::dvec3(t));
}

// Where a lane's calls go: its device (the DirectedCall's lane argument),
// the host threads of its passes, and whether its calls report progress
// (lane 0, the calling thread, only).
struct Lane {
    int index = 0;
    int threads = 0;
    const DirectedCall* directed = nullptr;
    const RecycleCall* recycle = nullptr;
    void giveBack(PerPoint&& a, PerPoint&& b = PerPoint{}) const {
        if (recycle != nullptr && *recycle) (*recycle)(index, std::move(a), std::move(b));
    }
    [[nodiscard]] Result<HausdorffResult> call(Span q, Span t, const CallOptions& piece,
                                               const core::PerPointFloor& floor = {}) const {
        if (index == 0) return (*directed)(index, q, t, piece, floor);
        CallOptions quiet = piece;
        quiet.progress = nullptr;
        return (*directed)(index, q, t, quiet, floor);
    }
};

// A chunk against one tile holding every target: one directed call with the
// backend's own early break, or per-point when the caller asked for it.
std::optional<Error> chunkAgainstAll(Span qc, uint64_t q0, Span t, double scale, const CallOptions& piece,
                                     const Lane& lane, SharedDirection& shared) {
    Result<HausdorffResult> r = lane.call(qc, t, piece);
    if (!r) return r.error();
    addCall(shared, *r, q0 == 0);
    const Directed& w = r->aToB;
    offerWitness(shared, w, searchDist2(qc[w.queryIndex], t[w.targetIndex], scale), q0);
    {
        const std::lock_guard lock(shared.mutex);
        if (r->proofMaterial)
            mergeBand(shared.state, r->proofMaterial->aToB, q0);
        else
            shared.state.band.failure = "a piece's call kept no band";
    }
    if (piece.perPointDistances) {
        std::copy(r->aNearest.distance.begin(), r->aNearest.distance.end(),
                  shared.state.perPoint.distance.begin() + ptrdiff_t(q0));
        std::copy(r->aNearest.nearest.begin(), r->aNearest.nearest.end(),
                  shared.state.perPoint.nearest.begin() + ptrdiff_t(q0));
        lane.giveBack(std::move(r->aNearest));
    }
    return std::nullopt;
}

// The chunks of one direction as one lane takes them: the next chunk not yet
// taken, until none is left or a lane has failed. `from`/`step`: the
// direction's start and each chunk's share of the progress.
struct ChunkQueue {
    Span q, t;
    uint64_t chunkSize = 0, chunks = 0;
    std::atomic<uint64_t> next{0};
};

// One chunk as a lane runs it; a failure of the host's own memory (the
// lane may be a thread of its own, where nothing would catch it) becomes
// kOutOfMemory.
std::optional<Error> runChunk(const ChunkQueue& queue, uint64_t c, double scale, const CallOptions& call,
                              const Lane& lane, SharedDirection& shared, double from, double step) {
    const uint64_t q0 = c * queue.chunkSize;
    const Span qc = queue.q.subspan(q0, std::min<uint64_t>(queue.chunkSize, queue.q.size() - q0));
    const double at = from + step * double(c);
    try {
        return chunkAgainstAll(qc, q0, queue.t, scale, pieceOptions(call, call.perPointDistances, at, step),
                               lane, shared);
    } catch (const std::bad_alloc&) {
        return Error{ErrorCode::kOutOfMemory, "out of host memory in query chunk " + std::to_string(c) +
                                                  " (device lane " + std::to_string(lane.index) + ")"};
    }
}

void runLane(ChunkQueue& queue, double scale, const CallOptions& call, const Lane& lane,
             SharedDirection& shared, double from, double step) {
    for (;;) {
        const uint64_t c = queue.next.fetch_add(1);
        if (c >= queue.chunks || shared.failed.load()) return;
        if (std::optional<Error> err = runChunk(queue, c, scale, call, lane, shared, from, step)) {
            std::lock_guard lock(shared.mutex);
            if (!shared.error) shared.error = *err;
            shared.failed = true;
            return;
        }
    }
}

// Runs fn(lane) on `lanes` lanes at once, lane 0 on the calling thread.
template <class Fn>
void onLanes(int lanes, Fn&& fn) {
    std::vector<std::thread> helpers;
    for (int l = 1; l < lanes; ++l) helpers.emplace_back([&fn, l] { fn(l); });
    fn(0);
    for (std::thread& h : helpers) h.join();
}

// One direction Q -> T whose targets fit one call beside a chunk: chunks of
// `chunkSize` queries in input order, each against every target, spread over
// `lanes` lanes; `from`/`width`: its share of the progress.
Result<DirectionState> runChunks(Span q, Span t, double scale, const CallOptions& call, uint64_t chunkSize,
                                 const DirectedCall& directed, const RecycleCall& recycle, int lanes,
                                 int threads, double from, double width) {
    ChunkQueue queue;
    queue.q = q;
    queue.t = t;
    queue.chunkSize = chunkSize;
    queue.chunks = (q.size() + chunkSize - 1) / chunkSize;
    SharedDirection shared;
    shared.state.band.present = true;
    if (call.perPointDistances) {
        shared.state.perPoint.distance.resize(q.size());
        shared.state.perPoint.nearest.resize(q.size());
    }
    const double step = width / double(queue.chunks);  // each chunk's share of the progress
    lanes = int(std::min<uint64_t>(uint64_t(std::max(lanes, 1)), queue.chunks));
    // Every lane asks for all host threads: the pool lends idle workers to
    // whichever lane has host work while the others wait on their devices.
    onLanes(lanes, [&](int l) {
        runLane(queue, scale, call, Lane{l, threads, &directed, &recycle}, shared, from, step);
    });
    if (shared.error) return *shared.error;
    DirectionState s = std::move(shared.state);
    s.counters.queries = q.size();
    s.counters.queryChunks = uint32_t(queue.chunks);
    s.counters.targetTiles = 1;
    s.witness.counters = s.counters;
    s.band.hf = s.reach + s.band.slack;  // the proof's bound: hf - slack = the largest piece's reach
    s.band.scale = scale;
    return s;
}

// ---- Pieces ordered in space (spatial_pieces.hpp) ----------------------

// A query of round two: its position, its own piece, the piece it was sent
// to first when its own held no targets (UINT32_MAX: none), and its best
// pair so far (+inf: none yet; the target's position in T's gathered order).
struct OpenQuery {
    uint32_t p = 0;
    uint32_t home = 0;
    uint32_t visited = UINT32_MAX;
    uint32_t nearest = 0;
    double distance = std::numeric_limits<double>::infinity();
};

// A query round one settled whose pair may reach the band (keepFloor).
struct Candidate {
    uint32_t p = 0;
    uint32_t nearest = 0;
    double distance = 0.0;
};

// The least search-units distance a settled query needs to be kept as a
// candidate, given a settled maximum m (input units) of the same direction:
// below it, a query lies below the band's threshold of any maximum hf >= m
// (core::bandThreshold2: (hf - 2 slack)^2 (1 - 2^-20), hf in search units),
// so it can be neither the witness nor a query of the band.
double keepFloor(double m, double scale, double slack) {
    return m < 0.0 ? -std::numeric_limits<double>::infinity() : m * scale * (1.0 - 0x1p-18) - 4.0 * slack;
}

// The running maximum of round one's settled queries (design.md §3's early
// break): a query whose best pair is nearer cannot be the maximum, one as
// far cannot win the tie when the maximum's query has the smaller input
// index. Per-point output: nothing is dropped (distance -1).
struct SettledMaximum {
    double distance = -1.0;
    uint32_t input = UINT32_MAX;
    uint64_t at = 0;  // its position in the gathered order
    [[nodiscard]] bool beats(const SettledMaximum& o) const {
        return distance > o.distance || (distance == o.distance && input < o.input);
    }
    [[nodiscard]] bool drops(double best, uint32_t query) const {
        return best < distance || (best == distance && input < query);
    }
};

// One direction Q -> T of the pieces in space. A query's best pair: the
// distance its call reported (in double from the pair, as every route
// reports it; +inf: none yet) and the target's position in T's gathered
// order. Pairs are compared by that distance, then by the target's input
// index: the certificate settles the witness in double from the band
// whatever the order of near-ties, so the result is the one call's.
// Only the queries that may matter keep theirs: those round one left open
// (round two improves them), and the settled ones that may reach the band
// (candidates). With per-point output (keepAll) every query's best is kept
// as well, by its position in Q's gathered order (`distance`, `nearest`):
// 12 bytes a query of fresh memory written once, which the other route
// spares (on the H200 machine its first touch alone was 0.3 s of round
// one's 1.7-1.9 s on 700M queries).
struct SpaceDirection {
    int q = 0;  // Q's set in the pieces: 0 (A -> B) or 1 (B -> A)
    bool keepAll = false;
    core::UninitVector<double> distance;  // keepAll only
    core::UninitVector<uint32_t> nearest;
    SharedDirection shared;
    uint64_t crossPiece = 0;          // queries sent to another piece's targets
    uint64_t hostScanned = 0;         // of those, answered on the host (scanOnHost)
    std::atomic<uint64_t> judged{0};  // round one's queries with a pair (above the calls' floors)
    // Round one's verdicts, per query piece: its queries left open for round
    // two (in position order), the maximum over those it settled and the
    // settled ones that may reach the band (not with keepAll: every query's
    // pair is in the arrays then).
    std::vector<std::vector<OpenQuery>> openOf;
    std::vector<SettledMaximum> settledOf;
    std::vector<std::vector<Candidate>> candidatesOf;
    std::vector<OpenQuery> open;  // after round two: every open query with its best pair
    // The largest settled so far over the pieces round one has finished (by
    // any lane; under shared.mutex): the next calls' floor (callFloor) and
    // the verdicts' first keep floor.
    SettledMaximum settledSoFar;
    // The largest exact nearest distance of a sample of queries (seedFloor;
    // -1: none): a lower bound of h before round one settles anything.
    double seed = -1.0;
};

// The host's own work between the pieces' calls (Timings::pieces), added
// up by every lane.
struct HostClock {
    enum Part { kRoundOne, kOpen, kRoundTwo, kParts };
    std::mutex mutex;
    double ms = 0.0;
    double part[kParts] = {0.0, 0.0, 0.0};
    void add(core::Clock::time_point since, Part p) {
        const double t = core::msSince(since);
        std::lock_guard lock(mutex);
        ms += t;
        part[p] += t;
    }
};

// Whether the pair of a query with target g (gathered position) at distance
// d is better than its pair with target `at` at `best`: nearer, or as near
// with a smaller target input index. (`at` is read only on a tie, so it may
// be anything while best is +inf.)
bool betterPair(double d, uint32_t g, double best, uint32_t at, const SpatialPieces::Set& ts) {
    return d < best || (d == best && ts.input[g] < ts.input[at]);
}

// A call's per-point result merged into the open queries' bests: a nearer
// pair replaces, an equal one only with a smaller target input index.
// Queries: the call's, `batch` (indices into `open`) at `points`
// (gathered); targets: the gathered target piece starting at `tileStart`. A
// target's input index is read only on a tie.
void mergeBests(std::vector<OpenQuery>& open, const SpatialPieces::Set& ts,
                const std::vector<uint32_t>& batch, Span points, uint64_t tileStart, const PerPoint& pp,
                int threads) {
    const size_t n = pp.nearest.size();
    core::parallelChunks(n, kHostChunk, core::resolveThreads(threads, n / kHostChunk + 1),
                         [&](size_t begin, size_t end, int) {
                             for (size_t k = begin; k < end; ++k) {
                                 OpenQuery& o = open[batch[k]];
                                 const auto g = uint32_t(tileStart + pp.nearest[k]);
                                 const double d = pairDistance(points[k], ts.points[g]);
                                 if (betterPair(d, g, o.distance, o.nearest, ts)) {
                                     o.distance = d;
                                     o.nearest = g;
                                 }
                             }
                         });
}

// Round one's results for piece k, in one pass: every query of the piece
// gets its first pair, its distance computed here, and is settled or left
// open for round two (with that pair). Settled: its best pair lies in its
// own piece and no other piece's point can be as near (the box of its best
// distance, widened by a relative margin and the certificate's slack,
// touches cells of its own piece only); the maximum over those is kept for
// round two's early break, and those that may reach the band as
// candidates (keepFloor of the running maximum, then of the piece's). With
// keepAll every query's pair is written to the direction's arrays (each
// position once in round one, so nothing is compared and the arrays need no
// pass before it).
// A call handed back sparse (`above`, core/per_point_floor.hpp) lists the
// queries above its floor; every other query of the piece stopped below it.
void settlePiece(SpaceDirection& dir, const SpatialPieces& pieces, size_t k, const PerPoint& pp,
                 const std::vector<detail::QueryNearest>* above, double scale, int threads) {
    const SpatialPieces::Set& qs = pieces.set(dir.q);
    const SpatialPieces::Set& ts = pieces.set(1 - dir.q);
    const uint64_t first = qs.start[k], tileStart = ts.start[k];
    const double slack = dir.shared.slack;
    if (above != nullptr && dir.keepAll)
        throw std::logic_error("settlePiece: a sparse call where every query's pair is kept");
    const size_t n = above != nullptr ? above->size() : pp.nearest.size();
    // The i-th entry's query (its index in the piece) and its nearest target (in the tile).
    const auto queryOf = [&](size_t i) { return above != nullptr ? (*above)[i].query : uint32_t(i); };
    const auto nearestOf = [&](size_t i) { return above != nullptr ? (*above)[i].nearest : pp.nearest[i]; };
    const int workers = core::resolveThreads(threads, n / kHostChunk + 1);
    const size_t chunks = (n + kHostChunk - 1) / kHostChunk;
    std::vector<std::vector<OpenQuery>> parts(chunks);
    std::vector<std::vector<Candidate>> kept(chunks);
    SettledMaximum soFar;
    {
        std::lock_guard lock(dir.shared.mutex);
        soFar = dir.settledSoFar;
    }
    std::vector<SettledMaximum> maxima(static_cast<size_t>(workers), soFar);
    core::parallelChunks(n, kHostChunk, workers, [&](size_t begin, size_t end, int w) {
        std::vector<OpenQuery>& open = parts[begin / kHostChunk];
        std::vector<Candidate>& candidates = kept[begin / kHostChunk];
        SettledMaximum best = maxima[size_t(w)];  // a copy: no cache line shared while it runs
        double floor = keepFloor(best.distance, scale, slack);
        // In runs: first the pairs' distances, a loop of independent reads
        // of the targets (a piece's targets are gigabytes: each read is
        // asked for kAhead pairs early so that many are in flight); then the
        // verdicts, on what that loop left in the cache. One loop doing both
        // was 1.8x slower on the H200 machine than the two passes it
        // replaced (700M queries: 4.1 s against 2.3 + 0.7 s).
        constexpr size_t kRun = 2048, kAhead = 32;
        double distance[kRun];
        for (size_t r0 = begin; r0 < end; r0 += kRun) {
            const size_t r1 = std::min(end, r0 + kRun);
            for (size_t i = r0; i < r1; ++i) {
                if (i + kAhead < end && nearestOf(i + kAhead) != core::kBelowFloor)
                    __builtin_prefetch(&ts.points[tileStart + nearestOf(i + kAhead)]);
                distance[i - r0] =
                    nearestOf(i) == core::kBelowFloor
                        ? -1.0
                        : pairDistance(qs.points[first + queryOf(i)], ts.points[tileStart + nearestOf(i)]);
            }
            if (dir.keepAll) {
                for (size_t i = r0; i < r1; ++i) {
                    dir.distance[first + i] = distance[i - r0];
                    dir.nearest[first + i] = uint32_t(tileStart + pp.nearest[i]);
                }
            }
            uint64_t judged = 0;
            for (size_t i = r0; i < r1; ++i) {
                const uint64_t p = first + queryOf(i);
                const double d = distance[i - r0];
                if (d < 0.0) continue;  // below the call's floor: settled, neither maximum nor candidate
                ++judged;
                const auto g = uint32_t(tileStart + nearestOf(i));
                const double radius = d * scale * (1.0 + 0x1p-12) + slack;
                // Its cell: kept where every query is judged (per-point
                // output; computing one costs ~23 ns a point a thread on the
                // H200 machine's host, more than reading it), else computed.
                if (!pieces.solidAround(pieces.cellAt(dir.q, p), radius) &&
                    !pieces.boxInPiece(core::scaled(qs.points[p], scale), radius, uint32_t(k))) {
                    open.push_back({uint32_t(p), uint32_t(k), UINT32_MAX, g, d});
                    continue;
                }
                const SettledMaximum m{d, qs.input[p], p};
                if (m.beats(best)) {
                    best = m;
                    floor = keepFloor(best.distance, scale, slack);
                }
                if (!dir.keepAll && d * scale >= floor) candidates.push_back({uint32_t(p), g, d});
            }
            dir.judged.fetch_add(judged, std::memory_order_relaxed);
        }
        maxima[size_t(w)] = best;
    });
    SettledMaximum top;
    for (const SettledMaximum& m : maxima)
        if (m.beats(top)) top = m;
    {
        std::lock_guard lock(dir.shared.mutex);
        if (top.beats(dir.settledSoFar)) dir.settledSoFar = top;
    }
    dir.openOf[k] = core::concatenateParts<std::vector<OpenQuery>>(parts);
    dir.settledOf[k] = top;
    if (dir.keepAll) return;
    const double floor = keepFloor(top.distance, scale, slack);
    std::vector<Candidate>& candidates = dir.candidatesOf[k];
    candidates.clear();
    for (const std::vector<Candidate>& part : kept)
        for (const Candidate& c : part)
            if (c.distance * scale >= floor) candidates.push_back(c);
}

// A round-one call's floor for direction `dir` (search units,
// core/per_point_floor.hpp): the keep floor of the largest settled so far.
// A query below it has a pair below the band of any maximum the direction
// can reach, so it is settled without its nearest point (settlePiece). None
// with per-point output (every query's nearest is the result then).
double callFloor(SpaceDirection& dir, double scale) {
    if (dir.keepAll) return 0.0;
    std::lock_guard lock(dir.shared.mutex);
    return std::max(0.0, keepFloor(std::max(dir.settledSoFar.distance, dir.seed), scale, dir.shared.slack));
}

// Queries of a direction that may be sampled for its first floor
// (seedFloor), and the most pairs its sample measures.
constexpr size_t kSeedCandidates = 4096;
constexpr uint64_t kSeedWork = uint64_t(1) << 26;

// The first pieces' floor: without it round one's first calls (one a lane)
// would search every query to its end. A sample of the queries, each
// compared in double with the points of its own piece within a quarter cell
// of it on every axis (SpatialPieces::blocksNear holds them all): where the
// nearest of those lies nearer than that quarter cell, it is the query's
// nearest in its piece, and where it settles as round one settles (its
// widened ball within its own piece's cells), it is its nearest in the
// whole set: a lower bound of h. The largest such is the seed; a sample
// query that does not settle counts for nothing, and any sample gives a
// lower bound.
// The sample: of kSeedCandidates queries at a stride, first those whose
// quarter-cell box lies in their own piece's cells (boxInPiece: any nearest
// found within it then settles; a box across a piece's border holds fewer
// targets, so the cheapest were mostly such queries, most of which count
// for nothing), each group those whose blocks hold the fewest targets
// first, until kSeedWork pairs or a quarter of what every fourth candidate
// would measure, whichever is less. A query among few
// targets costs little and is where nearest distances are large, which is
// what the floor wants. Until session 18 the sample was every fourth
// candidate (1024), whose blocks of up to 64 cells each were ~90 % of round
// one's host time on the torus (session 16). Measured (docs/bench/scale,
// session 18): on the torus quarter in 5 pieces on an H200 host of 32
// cores, round one 359-440 -> 47-55 ms, floors 3.56e-4 and 3.52e-4 against
// 3.32e-4 and 3.79e-4 (H 5.90e-4; 2^24 pairs gave 2.88e-4 and 3.26e-4,
// 6x the queries above them); at 1B x 1B round one 1.21 s -> 49-73 ms,
// floors 2.32e-4 and 2.46e-4 against 3.11e-4 and 2.78e-4 (the calls'
// read-back of the queries above them 7 -> 77-95 ms). Those figures are
// without the first group (inside first); with it, on a 10M x 12M torus
// (2 cores, CPU backend) the floors of B -> A rose from 1.53e-3 to 1.95e-3
// in 5 and 10 pieces (the queries above them 6486 -> 177 and 2740 -> 86),
// A -> B's and the seed's cost the same: not measured on a GPU host.
void seedFloor(SpaceDirection& dir, const SpatialPieces& pieces, double scale, int threads) {
    if (dir.keepAll) return;
    const SpatialPieces::Set& qs = pieces.set(dir.q);
    const SpatialPieces::Set& ts = pieces.set(1 - dir.q);
    const size_t n = qs.points.size(), candidates = std::min(n, kSeedCandidates);
    const double reach = 0.25 * pieces.smallestCellEdge();
    // Each candidate's piece, blocks and pairs.
    struct Sample {
        uint64_t p = 0;
        uint32_t k = 0;
        uint64_t work = UINT64_MAX;  // UINT64_MAX: not a candidate (no targets, or too many cells)
        bool inside = false;         // its reach box holds cells of its own piece only
        std::vector<uint32_t> blocks;
    };
    std::vector<Sample> sample(candidates);
    const int workers = core::resolveThreads(threads, candidates / 64 + 1);
    core::parallelChunks(candidates, 64, workers, [&](size_t begin, size_t end, int) {
        for (size_t s = begin; s < end; ++s) {
            Sample& c = sample[s];
            c.p = uint64_t(s) * n / candidates;
            c.k = uint32_t(std::upper_bound(qs.start.begin(), qs.start.end(), c.p) - qs.start.begin() - 1);
            const glm::vec3 q = core::scaled(qs.points[c.p], scale);
            if (ts.size(c.k) == 0 || !pieces.blocksNear(q, reach, c.k, c.blocks)) continue;
            c.work = 0;
            for (const uint32_t b : c.blocks) c.work += ts.blockStart[b + 1] - ts.blockStart[b];
            c.inside = pieces.boxInPiece(q, reach, c.k);
        }
    });
    uint64_t strided = 0;  // what every fourth candidate would measure
    for (size_t s = 0; s < candidates; s += 4)
        if (sample[s].work != UINT64_MAX) strided += sample[s].work;
    std::vector<uint32_t> order;
    for (size_t s = 0; s < candidates; ++s)
        if (sample[s].work != UINT64_MAX) order.push_back(uint32_t(s));
    std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
        if (sample[x].inside != sample[y].inside) return sample[x].inside;
        return sample[x].work != sample[y].work ? sample[x].work < sample[y].work : x < y;
    });
    const uint64_t budget = std::min(kSeedWork, strided / 4);
    size_t taken = 0;
    for (uint64_t work = 0;
         taken < order.size() && (taken == 0 || work + sample[order[taken]].work <= budget); ++taken)
        work += sample[order[taken]].work;
    std::vector<double> best(size_t(workers), -1.0);
    core::parallelChunks(taken, 8, workers, [&](size_t begin, size_t end, int w) {
        double top = best[size_t(w)];
        for (size_t i = begin; i < end; ++i) {
            const Sample& c = sample[order[i]];
            double d = std::numeric_limits<double>::infinity();
            for (const uint32_t b : c.blocks)
                for (uint64_t t = ts.blockStart[b]; t < ts.blockStart[b + 1]; ++t)
                    d = std::min(d, pairDistance(qs.points[c.p], ts.points[t]));
            if (!(d * scale * (1.0 + 0x1p-20) < reach)) continue;  // the nearest may lie past the box
            const double radius = d * scale * (1.0 + 0x1p-12) + dir.shared.slack;
            if (pieces.solidAround(pieces.cellAt(dir.q, c.p), radius) ||
                pieces.boxInPiece(core::scaled(qs.points[c.p], scale), radius, c.k))
                top = std::max(top, d);
        }
        best[size_t(w)] = top;
    });
    for (const double d : best) dir.seed = std::max(dir.seed, d);
}

// Piece k's queries when the piece holds no targets: no pair yet, all open.
void openAll(SpaceDirection& dir, const SpatialPieces& pieces, size_t k) {
    const SpatialPieces::Set& qs = pieces.set(dir.q);
    const uint64_t begin = qs.start[k], end = qs.start[k + 1];
    std::vector<OpenQuery>& open = dir.openOf[k];
    open.clear();
    open.reserve(end - begin);
    for (uint64_t p = begin; p < end; ++p) open.push_back({uint32_t(p), uint32_t(k), UINT32_MAX});
    dir.settledOf[k] = {};
    dir.candidatesOf[k].clear();
}

void addCallTo(SharedDirection& shared, const Counters& c, const Timings* t) {
    std::lock_guard lock(shared.mutex);
    addCounters(shared.state.counters, c, true);
    if (t != nullptr) core::addStageTimings(shared.state.timings, *t);
}

// The first failure of the lanes of a round; the others stop at their next call.
struct RoundFailure {
    std::mutex mutex;
    std::optional<Error> error;
    std::atomic<bool> failed{false};
    void set(Error e) {
        std::lock_guard lock(mutex);
        if (!error) error = std::move(e);
        failed = true;
    }
};

// Round one: every piece's queries against the same piece's targets, both
// directions in one call where both are in pieces (`dirs` null where not).
// (The verdicts were tried on a thread of their own beside the lane's next
// call: on the H200 machine the call's upload then took as long as the
// verdicts saved, both bound by the host's memory.)
void roundOne(const SpatialPieces& pieces, SpaceDirection* const dirs[2], double scale,
              const CallOptions& call, const Lane& lane, std::atomic<size_t>& next, RoundFailure& failure,
              HostClock& host, double from, double width) {
    const bool both = dirs[0] != nullptr && dirs[1] != nullptr;
    const int qset = dirs[0] != nullptr ? 0 : 1;
    const SpatialPieces::Set& qs = pieces.set(qset);
    const SpatialPieces::Set& ts = pieces.set(1 - qset);
    for (;;) {
        const size_t k = next.fetch_add(1);
        if (k >= pieces.count() || failure.failed.load()) return;
        try {
            if (qs.size(k) == 0 || ts.size(k) == 0) {  // its queries go to other pieces in round two
                openAll(*dirs[qset], pieces, k);
                if (both) openAll(*dirs[1], pieces, k);
                continue;
            }
            CallOptions piece = spaceOptions(call, from + width * double(k) / double(pieces.count()),
                                             width / double(pieces.count()));
            piece.directedOnly = !both;
            core::PerPointFloor floor;
            floor.search[0] = callFloor(*dirs[qset], scale);
            if (both) floor.search[1] = callFloor(*dirs[1], scale);
            Result<HausdorffResult> r = lane.call(qs.piece(k), ts.piece(k), piece, floor);
            if (!r) {
                failure.set(r.error());
                return;
            }
            const core::Clock::time_point start = core::Clock::now();
            SpaceDirection& first = *dirs[qset];
            addCallTo(first.shared, r->aToB.counters, &r->timings);
            const auto sparse = [&r](int d) -> const std::vector<detail::QueryNearest>* {
                return r->aboveFloor != nullptr && r->aboveFloor->of[d] ? &*r->aboveFloor->of[d] : nullptr;
            };
            settlePiece(first, pieces, k, r->aNearest, sparse(0), scale, lane.threads);
            if (both) {
                addCallTo(dirs[1]->shared, r->bToA.counters, nullptr);
                settlePiece(*dirs[1], pieces, k, r->bNearest, sparse(1), scale, lane.threads);
            }
            lane.giveBack(std::move(r->aNearest), std::move(r->bNearest));
            host.add(start, HostClock::kRoundOne);
        } catch (const std::bad_alloc&) {
            failure.set(Error{ErrorCode::kOutOfMemory, "out of host memory in piece " + std::to_string(k) +
                                                           " (device lane " + std::to_string(lane.index) +
                                                           ")"});
            return;
        }
    }
}

// The target pieces as tiles of round two: each piece's box, scaled as
// searched (SpatialPieces::pieceBoxes: every point of the piece lies in it).
struct TileBox {
    glm::dvec3 lo{0.0}, hi{0.0};
    bool empty = true;
};

// A lower bound of the distance from q to any point of the box, squared, in
// search units (double from float coordinates scaled by a power of two;
// rounding is monotone).
double boxGap2(const glm::vec3& q, const TileBox& box, double scale) {
    const glm::dvec3 qs(core::scaled(q, scale));
    const glm::dvec3 d = glm::max(glm::max(box.lo - qs, qs - box.hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

// After round one: the queries it left open, in position order, and the
// maximum over those it settled (none with per-point output, keepAll:
// nothing is dropped then).
std::vector<OpenQuery> openQueries(SpaceDirection& dir, SettledMaximum& maximum) {
    maximum = {};
    if (!dir.keepAll)
        for (const SettledMaximum& m : dir.settledOf)
            if (m.beats(maximum)) maximum = m;
    std::vector<OpenQuery> open = core::concatenateParts<std::vector<OpenQuery>>(dir.openOf);
    dir.openOf = {};
    return open;
}

// Round two's shared state: the open queries, what they may meet, and the
// lock under which lanes select them and merge what their calls found.
struct RoundTwo {
    SpaceDirection* dir = nullptr;
    const SpatialPieces* pieces = nullptr;
    std::vector<OpenQuery> open;
    std::vector<TileBox> boxes;
    SettledMaximum maximum;
    uint64_t maxQueries = 1;  // queries beside a tile in one call (the budget less the tile)
    std::mutex mutex;
    std::atomic<size_t> next{0};
};

// The open queries that tile j may still improve: not dropped by the early
// break, neither from j nor sent there first, and no farther from j's box
// than their best pair (no point of the tile can be nearer, nor tie with a
// smaller index: the box gap is a lower bound, widened here by 2^-40).
// `first`: the queries without a pair yet, each to the tile nearest it only.
// Indices into round.open.
std::vector<uint32_t> selectFor(RoundTwo& round, uint32_t j, bool first, double scale, int threads) {
    SpaceDirection& dir = *round.dir;
    const SpatialPieces::Set& qs = round.pieces->set(dir.q);
    std::vector<std::vector<uint32_t>> parts((round.open.size() + kHostChunk - 1) / kHostChunk);
    core::parallelChunks(round.open.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
        std::vector<uint32_t>& keep = parts[begin / kHostChunk];
        for (size_t i = begin; i < end; ++i) {
            OpenQuery& o = round.open[i];
            const double d = o.distance;
            if (first) {
                if (d != std::numeric_limits<double>::infinity()) continue;
                uint32_t nearest = UINT32_MAX;
                double gap = 0.0;
                for (uint32_t k = 0; k < round.boxes.size(); ++k) {
                    if (round.boxes[k].empty) continue;
                    const double g = boxGap2(qs.points[o.p], round.boxes[k], scale);
                    if (nearest == UINT32_MAX || g < gap) {
                        gap = g;
                        nearest = k;
                    }
                }
                if (nearest != j) continue;
                o.visited = j;
                keep.push_back(uint32_t(i));
                continue;
            }
            const double reach = d * scale;
            if (o.home == j || o.visited == j || round.maximum.drops(d, qs.input[o.p]) ||
                boxGap2(qs.points[o.p], round.boxes[j], scale) * (1.0 - 0x1p-40) > reach * reach)
                continue;
            keep.push_back(uint32_t(i));
        }
    });
    return core::concatenateParts<std::vector<uint32_t>>(parts);
}

// Round two's selected queries for tile j that the host answers itself: a
// query whose reach (its best distance, widened as settlePiece widens it)
// touches few blocks of the tile (SpatialPieces::blocksNear) is compared in
// double with every point of those blocks, while the points so compared
// stay within the tile's size (or kHostScanPoints, a call's fixed cost): a
// call would upload and index every point of the tile (on the torus
// quarter, round two's calls for 24 queries doubled the calls' upload and
// index, docs/bench/scale session 14). Every point of
// the tile within the reach lies in those blocks, so the best pair found is
// the query's nearest in the tile in double, ties to the smaller input
// index, merged as a call's (mergeBests). Returns the queries left for calls.
std::vector<uint32_t> scanOnHost(RoundTwo& round, uint32_t j, const std::vector<uint32_t>& selected,
                                 double scale, int threads) {
    SpaceDirection& dir = *round.dir;
    const SpatialPieces& pieces = *round.pieces;
    const SpatialPieces::Set& qs = pieces.set(dir.q);
    const SpatialPieces::Set& ts = pieces.set(1 - dir.q);
    struct Range {
        uint32_t scan = 0;  // into `scanned`
        uint64_t begin = 0, end = 0;
    };
    std::vector<uint32_t> scanned, called, blocks;
    std::vector<glm::vec3> points;  // each scanned query's point
    std::vector<Range> ranges;
    uint64_t budget = std::max(ts.size(j), kHostScanPoints);
    {
        std::lock_guard lock(round.mutex);  // lanes merge into other tiles' queries meanwhile
        for (const uint32_t i : selected) {
            const OpenQuery& o = round.open[i];
            const double radius = o.distance * scale * (1.0 + 0x1p-12) + dir.shared.slack;
            if (std::isfinite(radius) &&
                pieces.blocksNear(core::scaled(qs.points[o.p], scale), radius, j, blocks)) {
                uint64_t count = 0;
                for (const uint32_t b : blocks) count += ts.blockStart[b + 1] - ts.blockStart[b];
                if (count <= budget) {
                    budget -= count;
                    for (const uint32_t b : blocks)
                        for (uint64_t at = ts.blockStart[b]; at < ts.blockStart[b + 1]; at += kHostChunk)
                            ranges.push_back({uint32_t(scanned.size()), at,
                                              std::min<uint64_t>(ts.blockStart[b + 1], at + kHostChunk)});
                    scanned.push_back(i);
                    points.push_back(qs.points[o.p]);
                    continue;
                }
            }
            called.push_back(i);
        }
    }
    struct Best {
        double distance = std::numeric_limits<double>::infinity();
        uint32_t nearest = UINT32_MAX;
    };
    std::vector<Best> best(ranges.size());
    core::parallelChunks(ranges.size(), 1, core::resolveThreads(threads, ranges.size()),
                         [&](size_t r0, size_t r1, int) {
                             for (size_t r = r0; r < r1; ++r) {
                                 const glm::vec3 q = points[ranges[r].scan];
                                 Best b;
                                 for (uint64_t t = ranges[r].begin; t < ranges[r].end; ++t) {
                                     const double d = pairDistance(q, ts.points[t]);
                                     if (betterPair(d, uint32_t(t), b.distance, b.nearest, ts)) {
                                         b.distance = d;
                                         b.nearest = uint32_t(t);
                                     }
                                 }
                                 best[r] = b;
                             }
                         });
    std::lock_guard lock(round.mutex);
    for (size_t r = 0; r < ranges.size(); ++r) {
        const Best& b = best[r];
        OpenQuery& o = round.open[scanned[ranges[r].scan]];
        if (b.nearest == UINT32_MAX) continue;
        if (betterPair(b.distance, b.nearest, o.distance, o.nearest, ts)) {
            o.distance = b.distance;
            o.nearest = b.nearest;
        }
    }
    dir.hostScanned += scanned.size();
    return called;
}

// A lane's share of round two: the next tile not yet taken, its selected
// queries answered on the host where few points are near them
// (scanOnHost), the rest in calls within the budget, merged under the
// round's lock.
void roundTwo(RoundTwo& round, bool first, double scale, const CallOptions& call, const Lane& lane,
              RoundFailure& failure, HostClock& host, double from, double width) {
    SpaceDirection& dir = *round.dir;
    const SpatialPieces::Set& qs = round.pieces->set(dir.q);
    const SpatialPieces::Set& ts = round.pieces->set(1 - dir.q);
    std::vector<glm::vec3> gathered;
    for (;;) {
        const size_t j = round.next.fetch_add(1);
        if (j >= round.boxes.size() || failure.failed.load()) return;
        if (round.boxes[j].empty) continue;
        try {
            core::Clock::time_point start = core::Clock::now();
            std::vector<uint32_t> selected;
            {
                std::lock_guard lock(round.mutex);
                selected = selectFor(round, uint32_t(j), first, scale, lane.threads);
                dir.crossPiece += selected.size();
            }
            if (!first) selected = scanOnHost(round, uint32_t(j), selected, scale, lane.threads);
            host.add(start, HostClock::kRoundTwo);
            const CallOptions piece =
                spaceOptions(call, from + width * double(j) / double(round.boxes.size()),
                             width / double(round.boxes.size()));
            for (size_t b0 = 0; b0 < selected.size(); b0 += round.maxQueries) {
                start = core::Clock::now();
                const size_t n = std::min<size_t>(round.maxQueries, selected.size() - b0);
                const std::vector<uint32_t> batch(selected.begin() + ptrdiff_t(b0),
                                                  selected.begin() + ptrdiff_t(b0 + n));
                gathered.resize(n);
                core::parallelChunks(n, kHostChunk, lane.threads, [&](size_t begin, size_t end, int) {
                    for (size_t k = begin; k < end; ++k) gathered[k] = qs.points[round.open[batch[k]].p];
                });
                host.add(start, HostClock::kRoundTwo);
                Result<HausdorffResult> r = lane.call(gathered, ts.piece(j), piece);
                if (!r) {
                    failure.set(r.error());
                    return;
                }
                start = core::Clock::now();
                {
                    std::lock_guard lock(round.mutex);
                    addCallTo(dir.shared, r->aToB.counters, &r->timings);
                    mergeBests(round.open, ts, batch, gathered, ts.start[j], r->aNearest, lane.threads);
                }
                lane.giveBack(std::move(r->aNearest), PerPoint{});
                host.add(start, HostClock::kRoundTwo);
            }
        } catch (const std::bad_alloc&) {
            failure.set(Error{ErrorCode::kOutOfMemory, "out of host memory at target piece " +
                                                           std::to_string(j) + " (device lane " +
                                                           std::to_string(lane.index) + ")"});
            return;
        }
    }
}

// Band queries the proof takes its candidates from the pieces for, at most
// (the farthest first; the others go to its brute force over every target).
constexpr size_t kBandCandidates = 64;

// The certificate's candidates (core::DirectionBand::candidates) of the
// band's farthest queries: every target within a query's upper bound U (its
// best pair's distance) lies in the box of half-side U s (widened as
// settlePiece widens a reach) around it, and every point of the box in the
// blocks blocksNear names in each piece. The proof then compares a band
// query with those targets, not with the whole set (the quarter torus's
// proof was 0.22 s, 1B x 1B's 0.65 s: a pass over every target per band
// query). A query whose box covers too many cells gets none.
void addBandCandidates(core::DirectionBand& band, std::vector<Candidate> inBand, const SpatialPieces& pieces,
                       int q, double scale) {
    const SpatialPieces::Set& qs = pieces.set(q);
    const SpatialPieces::Set& ts = pieces.set(1 - q);
    std::sort(inBand.begin(), inBand.end(),
              [](const Candidate& x, const Candidate& y) { return x.distance > y.distance; });
    if (inBand.size() > kBandCandidates) inBand.resize(kBandCandidates);
    std::vector<uint32_t> blocks;
    for (const Candidate& c : inBand) {
        const double radius = c.distance * scale * (1.0 + 0x1p-12) + band.slack;
        const glm::vec3 p = core::scaled(qs.points[c.p], scale);
        std::vector<uint64_t> targets;
        bool all = std::isfinite(radius);
        for (uint32_t k = 0; all && k < pieces.count(); ++k) {
            if (ts.size(k) == 0) continue;
            all = pieces.blocksNear(p, radius, k, blocks);
            for (size_t b = 0; all && b < blocks.size(); ++b)
                for (uint64_t t = ts.blockStart[blocks[b]]; t < ts.blockStart[blocks[b] + 1]; ++t)
                    targets.push_back(ts.input[t]);
        }
        if (all) band.candidates.emplace_back(qs.input[c.p], std::move(targets));
    }
}

// The direction's result from the best pairs that may matter: the witness
// (the largest, the smallest input index among ties), the certificate's
// band, per-point output by input index. With keepAll every query's, from
// the arrays (round two's open queries written back first); otherwise the
// candidates of round one and the open queries: every other query was
// settled below keepFloor of a settled maximum, hence below the band's
// threshold and the witness.
DirectionState finishDirection(SpaceDirection& dir, const SpatialPieces& pieces, Span q, Span t, double scale,
                               int threads) {
    const SpatialPieces::Set& qs = pieces.set(dir.q);
    const SpatialPieces::Set& ts = pieces.set(1 - dir.q);
    std::vector<Candidate> kept;
    if (dir.keepAll) {
        for (const OpenQuery& o : dir.open) {
            dir.distance[o.p] = o.distance;
            dir.nearest[o.p] = o.nearest;
        }
    } else {
        kept = core::concatenateParts<std::vector<Candidate>>(dir.candidatesOf);
        for (const OpenQuery& o : dir.open) kept.push_back({o.p, o.nearest, o.distance});
    }
    // The i-th best pair: its position, target position and distance.
    const size_t n = dir.keepAll ? qs.points.size() : kept.size();
    const auto at = [&](size_t i) {
        return dir.keepAll ? Candidate{uint32_t(i), dir.nearest[i], dir.distance[i]} : kept[i];
    };
    std::vector<SettledMaximum> maxima(size_t(core::resolveThreads(threads)));
    core::parallelChunks(n, kHostChunk, threads, [&](size_t begin, size_t end, int w) {
        SettledMaximum m = maxima[size_t(w)];  // a copy: no cache line shared while it runs
        for (size_t i = begin; i < end; ++i) {
            const Candidate c = at(i);
            const SettledMaximum here{c.distance, qs.input[c.p], i};
            if (here.beats(m)) m = here;
        }
        maxima[size_t(w)] = m;
    });
    SettledMaximum top;
    for (const SettledMaximum& m : maxima)
        if (m.beats(top)) top = m;
    const Candidate w = at(top.at);
    const uint32_t target = ts.input[w.nearest];
    DirectionState s = std::move(dir.shared.state);
    s.witness.distance = w.distance;
    s.witness.queryIndex = qs.input[w.p];
    s.witness.targetIndex = target;
    s.witness.queryPoint = glm::dvec3(q[qs.input[w.p]]);
    s.witness.targetPoint = glm::dvec3(t[target]);

    // The band: every query whose best pair (a real pair: its distance is an
    // upper bound of the query's own) reaches the maximum less the slack.
    core::DirectionBand& band = s.band;
    band.present = true;
    band.slack = dir.shared.slack;
    band.hf = w.distance * scale;
    band.scale = scale;
    s.reach = band.hf - band.slack;
    const double lo2 = core::bandThreshold2(band.hf * band.hf, band.slack);
    std::vector<std::vector<Candidate>> parts((n + kHostChunk - 1) / kHostChunk);
    core::parallelChunks(n, kHostChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            const Candidate c = at(i);
            const double d = c.distance * scale;
            if (d * d >= lo2) parts[begin / kHostChunk].push_back(c);
        }
    });
    std::vector<Candidate> inBand = core::concatenateParts<std::vector<Candidate>>(parts);
    for (const Candidate& c : inBand) band.queries.push_back({qs.input[c.p], ts.input[c.nearest]});
    addBandCandidates(band, inBand, pieces, dir.q, scale);

    if (dir.keepAll) {
        s.perPoint.distance.resize(n);
        s.perPoint.nearest.resize(n);
        core::parallelChunks(n, kHostChunk, threads, [&](size_t begin, size_t end, int) {
            for (size_t p = begin; p < end; ++p) {
                s.perPoint.distance[qs.input[p]] = dir.distance[p];
                s.perPoint.nearest[qs.input[p]] = ts.input[dir.nearest[p]];
            }
        });
    }
    uint32_t queryPieces = 0, targetPieces = 0;
    for (size_t k = 0; k < pieces.count(); ++k) {
        queryPieces += qs.size(k) != 0 ? 1 : 0;
        targetPieces += ts.size(k) != 0 ? 1 : 0;
    }
    s.counters.queries = qs.points.size();
    s.counters.queryChunks = queryPieces;
    s.counters.targetTiles = targetPieces;
    s.counters.crossPieceQueries = dir.crossPiece;
    s.witness.counters = s.counters;
    return s;
}

// The directions whose targets do not fit one call beside a chunk, in
// pieces ordered in space (`dirs`: null for a direction not in pieces):
// round one, every piece's queries against its own targets; round two, the
// open queries against the other pieces that may hold a nearer point.
std::optional<Error> runInSpace(const SpatialPieces& pieces, SpaceDirection* const dirs[2], double scale,
                                const CallOptions& call, uint64_t perCall, uint64_t maxPiece,
                                const DirectedCall& directed, const RecycleCall& recycle, int lanes,
                                int threads, HostClock& host) {
    // Unwritten: round one writes every position once (settlePiece), or
    // leaves it open (openAll; round two's result is written back).
    for (int d = 0; d < 2; ++d) {
        if (dirs[d] == nullptr) continue;
        const size_t n = pieces.set(dirs[d]->q).points.size();
        if (dirs[d]->keepAll) {
            dirs[d]->distance.resize(n);
            dirs[d]->nearest.resize(n);
        }
        dirs[d]->openOf.assign(pieces.count(), {});
        dirs[d]->settledOf.assign(pieces.count(), {});
        dirs[d]->candidatesOf.assign(pieces.count(), {});
    }
    core::Clock::time_point start = core::Clock::now();
    for (int d = 0; d < 2; ++d)
        if (dirs[d] != nullptr) seedFloor(*dirs[d], pieces, scale, threads);
    host.add(start, HostClock::kRoundOne);
    lanes = int(std::min<size_t>(size_t(std::max(lanes, 1)), pieces.count()));
    {
        RoundFailure failure;
        std::atomic<size_t> next{0};
        onLanes(lanes, [&](int l) {
            roundOne(pieces, dirs, scale, call, Lane{l, threads, &directed, &recycle}, next, failure, host,
                     0.0, 0.8);
        });
        if (failure.error) return failure.error;
    }
    // The pieces' boxes from the grid's cells (no pass over the points; the
    // same for both directions), once the first direction has open queries.
    std::vector<core::Bounds> boxes;
    for (int d = 0; d < 2; ++d) {
        SpaceDirection* dir = dirs[d];
        if (dir == nullptr) continue;
        start = core::Clock::now();
        RoundTwo round;
        round.dir = dir;
        round.pieces = &pieces;
        round.open = openQueries(*dir, round.maximum);
        if (round.open.empty()) {
            host.add(start, HostClock::kOpen);
            continue;
        }
        const SpatialPieces::Set& ts = pieces.set(1 - dir->q);
        if (boxes.empty()) boxes = pieces.pieceBoxes();
        round.boxes.resize(boxes.size());
        for (size_t k = 0; k < boxes.size(); ++k)
            round.boxes[k] = {boxes[k].lo, boxes[k].hi, ts.size(k) == 0};
        uint64_t largestTile = 0;
        for (size_t k = 0; k < pieces.count(); ++k) largestTile = std::max(largestTile, ts.size(k));
        round.maxQueries =
            std::max<uint64_t>(1, std::min(perCall - std::min(perCall - 1, largestTile), maxPiece));
        host.add(start, HostClock::kOpen);
        for (const bool first : {true, false}) {
            RoundFailure failure;
            round.next = 0;
            onLanes(lanes, [&](int l) {
                roundTwo(round, first, scale, call, Lane{l, threads, &directed, &recycle}, failure, host,
                         first ? 0.8 : 0.85, first ? 0.05 : 0.15);
            });
            if (failure.error) return failure.error;
        }
        dir->open = std::move(round.open);
    }
    return std::nullopt;
}

// Each set's most points a piece. One lane: the tile (the fewest pieces).
// Several: pieces of about equal size whose count is a multiple of the
// lanes and at least two a lane, so that the lanes' rounds end together
// (the torus quarter on two H200s came in 5 pieces, 3 on one lane and 2 on
// the other, docs/bench/scale session 20). A piece is cut at a cell's edge
// below its limit, so the limits leave 1/32 over the even share: p pieces
// of that limit hold a set whose cells are each below 1/32 of a share.
PieceLimits pieceLimits(uint64_t a, uint64_t b, uint64_t tile, int lanes) {
    if (lanes <= 1) return {tile, tile};
    const auto l = uint64_t(lanes);
    const uint64_t needed = std::max((a + tile - 1) / tile, (b + tile - 1) / tile);
    const uint64_t count = std::max<uint64_t>(2, (needed + l - 1) / l) * l;
    const auto share = [&](uint64_t n) {
        const uint64_t even = (n + count - 1) / count;
        return std::max<uint64_t>(1, std::min(tile, even + even / 32));
    };
    return {share(a), share(b)};
}

// The whole pair within one budget: each direction in chunks (its targets
// fit one call beside a chunk) or in pieces ordered in space.
Result<HausdorffResult> computeWithin(Span a, Span b, double scale, const CallOptions& call,
                                      const MemoryBudget& budget, const DirectedCall& directed,
                                      const RecycleCall& recycle, const std::function<void()>& release,
                                      int lanes, int threads, bool trace,
                                      const std::optional<core::Bounds>& box) {
    const Result<DirectionSplit> splitAB = splitDirection(budget, a.size(), b.size(), lanes);
    if (!splitAB) return splitAB.error();
    const uint64_t perCall = budget.pointsPerCall();
    const uint64_t maxPiece = std::min(budget.maxPiecePoints, kMaxCallPoints);
    const uint64_t tile = std::min(perCall / 2, maxPiece);
    const bool spaceAB = b.size() > splitAB->targetTile;
    const bool spaceBA = !call.directedOnly && a.size() > tile;
    std::optional<DirectionState> ab, ba;
    HostClock host;
    double partitionMs = 0.0, finishMs = 0.0;
    if (spaceAB || spaceBA) {
        if (a.size() > UINT32_MAX || b.size() > UINT32_MAX) {
            return Error{ErrorCode::kInvalidArgument,
                         "out of core: sets of " + std::to_string(a.size()) + " and " +
                             std::to_string(b.size()) +
                             " points; pieces ordered in space take at most 2^32 - 1 points a set"};
        }
        const PieceLimits limits = pieceLimits(a.size(), b.size(), tile, lanes);
        // Pieces (at most the grid's 2^15 cells plus a set's points over its
        // limit) are numbered below 2^31 in the partition (kSharedBlock).
        if (a.size() / limits.a + b.size() / limits.b > (uint64_t(1) << 30)) {
            return Error{ErrorCode::kOutOfMemory,
                         "out of core: a budget of " + std::to_string(perCall) + " points a call (" +
                             budget.source + ") cuts " + std::to_string(a.size()) + " + " +
                             std::to_string(b.size()) + " points into more than 2^30 pieces"};
        }
        core::Clock::time_point start = core::Clock::now();
        std::optional<SpatialPieces> cut;
        try {
            // Per-point output names each query's nearest point: pieces in input
            // order break ties as one call would, and round one judges every
            // query (its cell kept). Otherwise blocks in space, and the cells
            // of the few queries above round one's floors computed.
            cut = SpatialPieces::partition(a, b, scale, limits, threads,
                                           call.perPointDistances ? PieceOrder::kInput : PieceOrder::kBlocks,
                                           box ? &*box : nullptr, call.perPointDistances);
        } catch (const std::bad_alloc&) {
            return Error{
                ErrorCode::kOutOfMemory,
                "out of host memory cutting " + std::to_string(a.size()) + " + " + std::to_string(b.size()) +
                    " points into pieces in space (about " +
                    std::to_string((a.size() + b.size()) * (call.perPointDistances ? 22 : 18) / 1000000) +
                    " MB beside the inputs)"};
        }
        const SpatialPieces& pieces = *cut;
        partitionMs = core::msSince(start);
        SpaceDirection dirAB, dirBA;
        dirAB.q = 0;
        dirBA.q = 1;
        dirAB.shared.slack = dirBA.shared.slack = core::searchSlack(pieces.largestMagnitude() * scale);
        dirAB.keepAll = dirBA.keepAll = call.perPointDistances;
        SpaceDirection* const dirs[2] = {spaceAB ? &dirAB : nullptr, spaceBA ? &dirBA : nullptr};
        if (auto err = runInSpace(pieces, dirs, scale, call, perCall, maxPiece, directed, recycle, lanes,
                                  threads, host))
            return *err;
        start = core::Clock::now();
        if (spaceAB) ab = finishDirection(dirAB, pieces, a, b, scale, threads);
        if (spaceBA) ba = finishDirection(dirBA, pieces, b, a, scale, threads);
        finishMs = core::msSince(start);
        if (trace) {
            const SpatialPieces::PassTimes& p = pieces.passTimes();
            std::fprintf(
                stderr,
                "rthdist pieces: %zu in space (%u cells an axis), partition %.1f ms (box %.1f, keys "
                "%.1f, plan %.1f, scatter %.1f), between calls %.1f ms (round one %.1f, open queries "
                "%.1f, round two %.1f), results %.1f ms, queries past their piece %llu + %llu (on the host "
                "%llu + %llu), first floors %.6g + %.6g, round one judged %llu + %llu\n",
                pieces.count(), pieces.cellsPerAxis(), partitionMs, p.box, p.keys, p.plan, p.scatter, host.ms,
                host.part[HostClock::kRoundOne], host.part[HostClock::kOpen], host.part[HostClock::kRoundTwo],
                finishMs, (unsigned long long)dirAB.crossPiece, (unsigned long long)dirBA.crossPiece,
                (unsigned long long)dirAB.hostScanned, (unsigned long long)dirBA.hostScanned, dirAB.seed,
                dirBA.seed, (unsigned long long)dirAB.judged.load(), (unsigned long long)dirBA.judged.load());
        }
        if (release) release();
    }
    const double width = call.directedOnly ? 1.0 : 0.5;
    if (!spaceAB) {
        Result<DirectionState> s =
            runChunks(a, b, scale, call, splitAB->queryChunk, directed, recycle, lanes, threads, 0.0, width);
        if (!s) return s.error();
        ab = std::move(s.value());
        if (release) release();
    }
    if (!call.directedOnly && !spaceBA) {
        const Result<DirectionSplit> splitBA = splitDirection(budget, b.size(), a.size(), lanes);
        if (!splitBA) return splitBA.error();
        Result<DirectionState> s =
            runChunks(b, a, scale, call, splitBA->queryChunk, directed, recycle, lanes, threads, 0.5, 0.5);
        if (!s) return s.error();
        ba = std::move(s.value());
    }

    HausdorffResult r;
    r.directedOnly = call.directedOnly;
    auto material = std::make_shared<detail::ProofMaterial>();
    material->aToB = ab->band;
    r.aToB = ab->witness;
    r.aNearest = std::move(ab->perPoint);
    r.hausdorff = r.aToB.distance;
    r.timings = ab->timings;
    if (!call.directedOnly) {
        r.bToA = ba->witness;
        r.bNearest = std::move(ba->perPoint);
        r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
        core::addStageTimings(r.timings, ba->timings);
        material->bToA = ba->band;
    }
    // The certificate of the whole from the pieces' bands, on the float sets
    // the pieces searched: what a backend's own certificate pass is to one
    // call (the merged witness carries a piece's proof until then). The
    // result is still in the search frame; the Engine leaves it as every
    // route's (engine.cpp, leaveFrame: core::restoreOriginal proves it again
    // from the caller's coordinates when they differ).
    r.proofMaterial = std::move(material);
    const core::Clock::time_point proof = core::Clock::now();
    core::proveFromViews(r, PointView(a), PointView(b), threads);
    const double proofMs = core::msSince(proof);
    r.timings.pieces = partitionMs + host.ms + finishMs + proofMs;
    if (trace) std::fprintf(stderr, "rthdist pieces: the whole's proof %.1f ms\n", proofMs);
    return r;
}

}  // namespace

bool fitsOneCall(const MemoryBudget& budget, uint64_t na, uint64_t nb) {
    return na <= kMaxCallPoints && nb <= kMaxCallPoints && na + nb <= budget.pointsPerCall();
}

Result<DirectionSplit> splitDirection(const MemoryBudget& budget, uint64_t nq, uint64_t nt, int lanes) {
    const uint64_t perCall = budget.pointsPerCall();
    if (perCall < 2 || budget.maxPiecePoints < 1) {
        return Error{ErrorCode::kOutOfMemory, "a memory budget of " + std::to_string(budget.bytes) +
                                                  " bytes (" + budget.source +
                                                  ") holds fewer than 2 points at " +
                                                  std::to_string(kBytesPerPoint) + " bytes per point"};
    }
    DirectionSplit split;
    const uint64_t half = perCall / 2;
    const uint64_t maxPiece = std::min(budget.maxPiecePoints, kMaxCallPoints);
    if (nt <= std::min(half, maxPiece)) {
        split.targetTile = std::max<uint64_t>(nt, 1);
        split.queryChunk = std::min(perCall - split.targetTile, maxPiece);
    } else {
        split.targetTile = std::min(half, maxPiece);
        split.queryChunk = std::min(perCall - split.targetTile, maxPiece);
    }
    const uint64_t perLane = (nq + uint64_t(std::max(lanes, 1)) - 1) / uint64_t(std::max(lanes, 1));
    split.queryChunk = std::max<uint64_t>(1, std::min(split.queryChunk, perLane));
    return split;
}

Result<HausdorffResult> computeInPieces(Span a, Span b, double scale, const CallOptions& call,
                                        const MemoryBudget& given, const DirectedCall& directed,
                                        const std::function<void()>& release, int lanes, int threads,
                                        const RecycleCall& recycle, bool trace,
                                        const std::optional<core::Bounds>& box) {
    // The budget halved after each kOutOfMemory (the per-point figure is an
    // estimate; a device may hold less than it reports).
    MemoryBudget budget = given;
    for (;;) {
        Result<HausdorffResult> r =
            computeWithin(a, b, scale, call, budget, directed, recycle, release, lanes, threads, trace, box);
        // The host's own memory does not grow with a smaller budget.
        if (r || r.error().code != ErrorCode::kOutOfMemory || budget.pointsPerCall() < 4 ||
            r.error().message.rfind("out of host memory", 0) == 0)
            return r;
        if (release) release();
        budget.bytes /= 2;
        budget.source += ", halved after: " + r.error().message;
    }
}

}  // namespace rthdist::api
