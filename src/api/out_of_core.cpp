#include "api/out_of_core.hpp"

#include "core/certificate.hpp"
#include "core/index_space.hpp"
#include "core/parallel.hpp"
#include "core/timings.hpp"
#include "core/uninit_vector.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
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

// The early break of a chunk starting at query index q0 against the witness
// of the chunks finished so far (design.md §3): a query whose best pair is
// nearer than the witness's cannot be the maximum; one at the same distance
// cannot win the tie when the witness's query index is smaller (an earlier
// chunk). Per-point output: nothing is dropped.
struct EarlyBreak {
    float d2 = -1.0f;
    bool dropTies = false;
    [[nodiscard]] bool drops(float best) const { return best < d2 || (dropTies && best == d2); }
};

EarlyBreak earlyBreak(SharedDirection& shared, uint64_t q0, bool perPoint) {
    if (perPoint) return {};
    std::lock_guard lock(shared.mutex);
    return {shared.state.witnessD2, shared.state.witness.queryIndex < q0};
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

// A tile of the targets: consecutive input indices from `offset`, and the box
// of its points scaled as searched (searchDist2's frame).
struct Tile {
    Span points;
    uint64_t offset = 0;
    glm::vec3 lo{0.0f}, hi{0.0f};
};

// The float squared distance from q to a tile's box, computed as searchDist2
// computes a pair: rounding is monotone, so it never exceeds searchDist2(q, p)
// for a point p of the tile.
float boxDist2(const glm::vec3& q, const Tile& tile, double scale) {
    const glm::vec3 qs = core::scaled(q, scale);
    return squaredLength(glm::max(glm::max(tile.lo - qs, qs - tile.hi), glm::vec3(0.0f)));
}

// The box of `points` (non-empty), scaled as searched; on `threads` threads.
Tile boxOf(Span points, uint64_t offset, double scale, int threads) {
    threads = core::resolveThreads(threads, points.size() / kHostChunk + 1);
    std::vector<Tile> parts(size_t(threads), Tile{{}, 0, points[0], points[0]});
    core::parallelChunks(points.size(), kHostChunk, threads, [&](size_t begin, size_t end, int w) {
        Tile& part = parts[size_t(w)];
        for (size_t i = begin; i < end; ++i) {
            part.lo = glm::min(part.lo, points[i]);
            part.hi = glm::max(part.hi, points[i]);
        }
    });
    Tile box{points, offset, points[0], points[0]};
    for (const Tile& part : parts) {
        box.lo = glm::min(box.lo, part.lo);
        box.hi = glm::max(box.hi, part.hi);
    }
    box.lo = core::scaled(box.lo, scale);  // an exact power of two: monotone
    box.hi = core::scaled(box.hi, scale);
    return box;
}

std::vector<Tile> makeTiles(Span t, uint64_t tileSize, double scale, int threads) {
    std::vector<Tile> tiles;
    for (uint64_t t0 = 0; t0 < t.size(); t0 += tileSize)
        tiles.push_back(
            boxOf(t.subspan(t0, std::min<uint64_t>(tileSize, t.size() - t0)), t0, scale, threads));
    return tiles;
}

// The tiles nearest the chunk first (box to box), so that its queries' best
// distances shrink early and later tiles are skipped.
std::vector<size_t> tileOrder(Span chunk, const std::vector<Tile>& tiles, double scale, int threads) {
    const Tile box = boxOf(chunk, 0, scale, threads);
    std::vector<double> gap(tiles.size());
    for (size_t j = 0; j < tiles.size(); ++j) {
        const glm::dvec3 d = glm::max(glm::max(glm::dvec3(tiles[j].lo) - glm::dvec3(box.hi),
                                               glm::dvec3(box.lo) - glm::dvec3(tiles[j].hi)),
                                      glm::dvec3(0.0));
        gap[j] = glm::dot(d, d);
    }
    std::vector<size_t> order(tiles.size());
    for (size_t j = 0; j < order.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return gap[x] < gap[y]; });
    return order;
}

// What a direction's chunks reuse: every query's best pair over the tiles
// seen so far (searchDist2, the distance the call reported, the target's index
// in the whole set), its home tile, and the gathered queries of one call.
// UninitVector: filled, and first touched, by the parallel passes below
// (10^8 entries per chunk).
struct ChunkScratch {
    core::UninitVector<float> d2;
    core::UninitVector<double> distance;
    core::UninitVector<uint64_t> nearest;  // index into the whole target set
    core::UninitVector<uint32_t> home;
    core::UninitVector<glm::vec3> subset;
};

// Each query's best pair set to none, and its home tile: the one whose box
// is nearest (the first among ties). A query's first call goes to its home
// tile, so that a query inside one tile's box meets its neighbourhood first
// and its best pair is short before it is offered to any other tile.
void startChunk(Span qc, const std::vector<Tile>& tiles, double scale, int threads, ChunkScratch& x) {
    x.d2.resize(qc.size());
    x.distance.resize(qc.size());
    x.nearest.resize(qc.size());
    x.home.resize(qc.size());
    threads = core::resolveThreads(threads, qc.size() / kHostChunk + 1);
    core::parallelChunks(qc.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) {
            x.d2[i] = std::numeric_limits<float>::infinity();
            x.distance[i] = 0.0;
            x.nearest[i] = UINT64_MAX;
            uint32_t home = 0;
            float nearest = boxDist2(qc[i], tiles[0], scale);
            for (size_t j = 1; j < tiles.size() && nearest > 0.0f; ++j) {
                const float d2 = boxDist2(qc[i], tiles[j], scale);
                if (d2 < nearest) {
                    nearest = d2;
                    home = uint32_t(j);
                }
            }
            x.home[i] = home;
        }
    });
}

// Ascending query indices gathered by parallel tasks, each task's list in
// task order.
std::vector<uint32_t> concatenate(const std::vector<std::vector<uint32_t>>& parts) {
    size_t total = 0;
    for (const std::vector<uint32_t>& part : parts) total += part.size();
    std::vector<uint32_t> all;
    all.reserve(total);
    for (const std::vector<uint32_t>& part : parts) all.insert(all.end(), part.begin(), part.end());
    return all;
}

// The queries of each tile's first round: those whose home it is (one pass).
std::vector<std::vector<uint32_t>> queriesByHome(const ChunkScratch& x, size_t tiles, int threads) {
    const size_t n = x.home.size();
    threads = core::resolveThreads(threads, n / kHostChunk + 1);
    std::vector<std::vector<std::vector<uint32_t>>> parts((n + kHostChunk - 1) / kHostChunk,
                                                          std::vector<std::vector<uint32_t>>(tiles));
    core::parallelChunks(n, kHostChunk, threads, [&](size_t begin, size_t end, int) {
        std::vector<std::vector<uint32_t>>& mine = parts[begin / kHostChunk];
        for (size_t i = begin; i < end; ++i) mine[x.home[i]].push_back(uint32_t(i));
    });
    std::vector<std::vector<uint32_t>> lists(tiles);
    std::vector<std::vector<uint32_t>> column(parts.size());
    for (size_t j = 0; j < tiles; ++j) {
        for (size_t t = 0; t < parts.size(); ++t) column[t] = std::move(parts[t][j]);
        lists[j] = concatenate(column);
    }
    return lists;
}

// The queries of the chunk that tile `j` may still improve after the first
// round: those whose home it is not, except where the tile's box is farther
// than the query's best pair (no point of the tile can be nearer, nor tie
// with a smaller index: the box distance is a lower bound) and, without
// per-point output, where the best pair is dropped by the early break.
std::vector<uint32_t> queriesForTile(Span qc, const Tile& tile, uint32_t j, const ChunkScratch& x,
                                     const EarlyBreak& drop, double scale, int threads) {
    threads = core::resolveThreads(threads, qc.size() / kHostChunk + 1);
    std::vector<std::vector<uint32_t>> parts((qc.size() + kHostChunk - 1) / kHostChunk);
    core::parallelChunks(qc.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
        std::vector<uint32_t>& keep = parts[begin / kHostChunk];
        for (size_t i = begin; i < end; ++i) {
            if (x.home[i] == j || drop.drops(x.d2[i]) || boxDist2(qc[i], tile, scale) > x.d2[i]) continue;
            keep.push_back(uint32_t(i));
        }
    });
    return concatenate(parts);
}

// Where a lane's calls go: its device (the DirectedCall's lane argument),
// the host threads of its passes, and whether its calls report progress
// (lane 0, the calling thread, only).
struct Lane {
    int index = 0;
    int threads = 0;
    const DirectedCall* directed = nullptr;
    const RecycleCall* recycle = nullptr;
    void giveBack(PerPoint&& spent) const {
        if (recycle != nullptr && *recycle) (*recycle)(index, std::move(spent));
    }
    [[nodiscard]] Result<HausdorffResult> call(Span q, Span t, const CallOptions& piece) const {
        if (index == 0) return (*directed)(index, q, t, piece);
        CallOptions quiet = piece;
        quiet.progress = nullptr;
        return (*directed)(index, q, t, quiet);
    }
};

// One tile's call for the selected queries (per-point), merged into the
// chunk's best pairs: a nearer pair replaces, an equal one only with a
// smaller target index.
std::optional<Error> searchTile(Span qc, const std::vector<uint32_t>& selected, const Tile& tile,
                                double scale, const CallOptions& piece, const Lane& lane, ChunkScratch& x,
                                SharedDirection& shared) {
    const int threads = core::resolveThreads(lane.threads, selected.size() / kHostChunk + 1);
    Span queries = qc;
    if (selected.size() < qc.size()) {
        x.subset.clear();  // a larger array is not copied when it grows
        x.subset.resize(selected.size());
        core::parallelChunks(selected.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
            for (size_t k = begin; k < end; ++k) x.subset[k] = qc[selected[k]];
        });
        queries = x.subset;
    }
    Result<HausdorffResult> r = lane.call(queries, tile.points, piece);
    if (!r) return r.error();
    addCall(shared, *r, true);
    const PerPoint& pp = r->aNearest;
    core::parallelChunks(selected.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t k = begin; k < end; ++k) {
            const uint32_t i = selected[k];  // each query once
            const float d2 = searchDist2(qc[i], tile.points[pp.nearest[k]], scale);
            const uint64_t target = pp.nearest[k] + tile.offset;
            if (d2 < x.d2[i] || (d2 == x.d2[i] && target < x.nearest[i])) {
                x.d2[i] = d2;
                x.distance[i] = pp.distance[k];
                x.nearest[i] = target;
            }
        }
    });
    lane.giveBack(std::move(r->aNearest));
    return std::nullopt;
}

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

// A chunk against several tiles: every query against its home tile, then the
// other tiles nearest the chunk first, each for the queries it may still
// improve (the early break read again before each tile: other lanes' chunks
// may have raised the maximum); then the chunk's witness (its largest best
// pair, the smallest query index among ties). `from`/`step`: the chunk's
// share of the progress.
std::optional<Error> chunkAgainstTiles(Span qc, uint64_t q0, Span t, const std::vector<Tile>& tiles,
                                       double scale, const CallOptions& call, const Lane& lane,
                                       ChunkScratch& x, SharedDirection& shared, double from, double step) {
    const int threads = lane.threads;
    startChunk(qc, tiles, scale, threads, x);
    const std::vector<size_t> order = tileOrder(qc, tiles, scale, threads);
    const std::vector<std::vector<uint32_t>> home = queriesByHome(x, tiles.size(), threads);
    for (const bool homeRound : {true, false}) {
        for (size_t k = 0; k < order.size(); ++k) {
            const uint32_t j = uint32_t(order[k]);
            const std::vector<uint32_t> selected =
                homeRound ? home[j]
                          : queriesForTile(qc, tiles[j], j, x, earlyBreak(shared, q0, call.perPointDistances),
                                           scale, threads);
            if (selected.empty()) continue;
            const double at =
                from + step * (0.5 * double(k) / double(order.size()) + (homeRound ? 0.0 : 0.5));
            const CallOptions piece = pieceOptions(call, true, at, step * 0.5 / double(order.size()));
            if (auto err = searchTile(qc, selected, tiles[j], scale, piece, lane, x, shared)) return err;
        }
    }
    const size_t w = size_t(std::max_element(x.d2.begin(), x.d2.end()) - x.d2.begin());
    Directed d;
    d.distance = x.distance[w];
    d.queryIndex = w;
    d.targetIndex = x.nearest[w];
    d.queryPoint = glm::dvec3(qc[w]);
    d.targetPoint = glm::dvec3(t[x.nearest[w]]);
    offerWitness(shared, d, x.d2[w], q0);
    {
        // The chunk's band from every query's best pair over the tiles (a
        // real pair, searched as one call compares pairs).
        core::DirectionBand band;
        band.present = true;
        band.hf = std::sqrt(double(x.d2[w]));
        band.slack = shared.slack;
        const double lo2 = core::bandThreshold2(double(x.d2[w]), band.slack);
        for (size_t i = 0; i < qc.size(); ++i)
            if (double(x.d2[i]) >= lo2) band.queries.push_back({i, x.nearest[i]});
        const std::lock_guard lock(shared.mutex);
        mergeBand(shared.state, band, q0);
    }
    if (call.perPointDistances) {
        PerPoint& pp = shared.state.perPoint;
        std::copy(x.distance.begin(), x.distance.end(), pp.distance.begin() + ptrdiff_t(q0));
        // Per-point output holds 32-bit indices: the Engine refuses it past 2^32 - 1 targets.
        std::transform(x.nearest.begin(), x.nearest.end(), pp.nearest.begin() + ptrdiff_t(q0),
                       [](uint64_t i) { return uint32_t(i); });
    }
    return std::nullopt;
}

// The chunks of one direction as one lane takes them: the next chunk not yet
// taken, until none is left or a lane has failed. Each lane keeps its own
// scratch. `from`/`step`: the direction's start and each chunk's share of
// the progress.
struct ChunkQueue {
    Span q, t;
    const std::vector<Tile>* tiles = nullptr;
    uint64_t chunkSize = 0, chunks = 0;
    std::atomic<uint64_t> next{0};
};

// One chunk as a lane runs it; a failure of the host's own memory (the
// lane may be a thread of its own, where nothing would catch it) becomes
// kOutOfMemory.
std::optional<Error> runChunk(const ChunkQueue& queue, uint64_t c, double scale, const CallOptions& call,
                              const Lane& lane, ChunkScratch& scratch, SharedDirection& shared, double from,
                              double step) {
    const uint64_t q0 = c * queue.chunkSize;
    const Span qc = queue.q.subspan(q0, std::min<uint64_t>(queue.chunkSize, queue.q.size() - q0));
    const double at = from + step * double(c);
    try {
        return queue.tiles->empty()
                   ? chunkAgainstAll(qc, q0, queue.t, scale,
                                     pieceOptions(call, call.perPointDistances, at, step), lane, shared)
                   : chunkAgainstTiles(qc, q0, queue.t, *queue.tiles, scale, call, lane, scratch, shared, at,
                                       step);
    } catch (const std::bad_alloc&) {
        return Error{ErrorCode::kOutOfMemory, "out of host memory in query chunk " + std::to_string(c) +
                                                  " (device lane " + std::to_string(lane.index) + ")"};
    }
}

void runLane(ChunkQueue& queue, double scale, const CallOptions& call, const Lane& lane,
             SharedDirection& shared, double from, double step) {
    ChunkScratch scratch;
    for (;;) {
        const uint64_t c = queue.next.fetch_add(1);
        if (c >= queue.chunks || shared.failed.load()) return;
        if (std::optional<Error> err = runChunk(queue, c, scale, call, lane, scratch, shared, from, step)) {
            std::lock_guard lock(shared.mutex);
            if (!shared.error) shared.error = *err;
            shared.failed = true;
            return;
        }
    }
}

// One direction Q -> T within `split`, its chunks spread over `lanes` lanes
// (lane 0 on the calling thread); `from`/`width`: its share of the progress.
Result<DirectionState> runDirection(Span q, Span t, double scale, const CallOptions& call,
                                    const DirectionSplit& split, const DirectedCall& directed,
                                    const RecycleCall& recycle, int lanes, int threads, double from,
                                    double width) {
    const std::vector<Tile> tiles =
        t.size() > split.targetTile ? makeTiles(t, split.targetTile, scale, threads) : std::vector<Tile>{};
    ChunkQueue queue;
    queue.q = q;
    queue.t = t;
    queue.tiles = &tiles;
    queue.chunkSize = split.queryChunk;
    queue.chunks = (q.size() + split.queryChunk - 1) / split.queryChunk;
    SharedDirection shared;
    shared.slack = core::searchSlack(
        std::max(core::largestMagnitude(q, threads), core::largestMagnitude(t, threads)) * scale);
    shared.state.band.present = true;
    if (call.perPointDistances) {
        shared.state.perPoint.distance.resize(q.size());
        shared.state.perPoint.nearest.resize(q.size());
    }
    const double step = width / double(queue.chunks);  // each chunk's share of the progress
    lanes = int(std::min<uint64_t>(uint64_t(std::max(lanes, 1)), queue.chunks));
    // Every lane asks for all host threads: the pool lends idle workers to
    // whichever lane has host work while the others wait on their devices.
    std::vector<std::thread> helpers;
    for (int l = 1; l < lanes; ++l)
        helpers.emplace_back([&, l] {
            runLane(queue, scale, call, Lane{l, threads, &directed, &recycle}, shared, from, step);
        });
    runLane(queue, scale, call, Lane{0, threads, &directed, &recycle}, shared, from, step);
    for (std::thread& h : helpers) h.join();
    if (shared.error) return *shared.error;
    DirectionState s = std::move(shared.state);
    s.counters.queries = q.size();  // tiles' calls count their queries again
    s.counters.queryChunks = uint32_t(queue.chunks);
    s.counters.targetTiles = uint32_t(std::max<size_t>(1, tiles.size()));
    s.witness.counters = s.counters;
    s.band.hf = s.reach + s.band.slack;  // the proof's bound: hf - slack = the largest piece's reach
    s.band.scale = scale;
    return s;
}

// runDirection, with the budget halved after each kOutOfMemory (the per-point
// figure is an estimate; a device may hold less than it reports).
Result<DirectionState> runDirectionWithin(Span q, Span t, double scale, const CallOptions& call,
                                          MemoryBudget budget, const DirectedCall& directed,
                                          const RecycleCall& recycle, const std::function<void()>& release,
                                          int lanes, int threads, double from, double width) {
    for (;;) {
        Result<DirectionSplit> split = splitDirection(budget, q.size(), t.size(), lanes);
        if (!split) return split.error();
        Result<DirectionState> s =
            runDirection(q, t, scale, call, *split, directed, recycle, lanes, threads, from, width);
        if (s || s.error().code != ErrorCode::kOutOfMemory || budget.pointsPerCall() < 4) return s;
        if (release) release();
        budget.bytes /= 2;
        budget.source += ", halved after: " + s.error().message;
    }
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
                                        const MemoryBudget& budget, const DirectedCall& directed,
                                        const std::function<void()>& release, int lanes, int threads,
                                        const RecycleCall& recycle) {
    const double width = call.directedOnly ? 1.0 : 0.5;
    Result<DirectionState> ab =
        runDirectionWithin(a, b, scale, call, budget, directed, recycle, release, lanes, threads, 0.0, width);
    if (!ab) return ab.error();
    HausdorffResult r;
    r.directedOnly = call.directedOnly;
    auto material = std::make_shared<detail::ProofMaterial>();
    material->aToB = ab->band;
    r.aToB = ab->witness;
    r.aNearest = std::move(ab->perPoint);
    r.hausdorff = r.aToB.distance;
    r.timings = ab->timings;
    if (!call.directedOnly) {
        if (release) release();
        Result<DirectionState> ba = runDirectionWithin(b, a, scale, call, budget, directed, recycle, release,
                                                       lanes, threads, 0.5, 0.5);
        if (!ba) return ba.error();
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
    core::proveFromViews(r, PointView(a), PointView(b), threads);
    return r;
}

}  // namespace rthdist::api
