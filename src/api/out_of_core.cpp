#include "api/out_of_core.hpp"

#include <algorithm>
#include <limits>
#include <vector>

namespace rthdist::api {

namespace {

using Span = std::span<const glm::vec3>;

// The running state of one direction: its witness so far, every query's best
// so far (with tiles, or when the caller asked for per-point output), and
// the counters and timings of the calls.
struct DirectionState {
    Directed witness;
    float witnessD2 = -1.0f;  // the witness pair's searchDist2 (-1: none yet)
    PerPoint perPoint;
    Timings timings;
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
}

void addTimings(Timings& into, const Timings& t) {
    into.upload += t.upload;
    into.index += t.index;
    into.cull += t.cull;
    into.search += t.search;
    into.refine += t.refine;
    into.check += t.check;
    into.gpuIndex += t.gpuIndex;
    into.gpuCull += t.gpuCull;
    into.gpuSearch += t.gpuSearch;
    into.gpuRefine += t.gpuRefine;
    into.gpuUpload += t.gpuUpload;
}

// The squared distance of a pair as the backends compare pairs: in float, on
// the points scaled by the call's exact power of two (core::exactScale), so
// that the pieces choose among near-ties as one call would.
float searchDist2(const glm::vec3& q, const glm::vec3& t, double scale) {
    const glm::vec3 d = glm::vec3(glm::dvec3(q) * scale) - glm::vec3(glm::dvec3(t) * scale);
    const float xy = d.x * d.x + d.y * d.y;
    return xy + d.z * d.z;
}

// A chunk's witness against the direction's: the larger distance wins, the
// earlier chunk (smaller query index) among ties.
void offerWitness(DirectionState& s, const Directed& d, float d2, uint64_t queryOffset,
                  uint64_t targetOffset) {
    if (!(d2 > s.witnessD2)) return;
    const Counters keep = s.witness.counters;
    s.witness = d;
    s.witness.queryIndex = uint32_t(d.queryIndex + queryOffset);
    s.witness.targetIndex = uint32_t(d.targetIndex + targetOffset);
    s.witness.counters = keep;
    s.witnessD2 = d2;
}

// Progress of one call mapped into [from, from + width) of the whole.
CallOptions pieceOptions(const CallOptions& call, bool perPoint, double from, double width) {
    CallOptions piece = call;
    piece.directedOnly = true;
    piece.perPointDistances = perPoint;
    if (call.progress) {
        piece.progress = [progress = call.progress, from, width](const char* stage, double f) {
            progress(stage, from + width * f);
        };
    }
    return piece;
}

// One direction Q -> T within `split`; `from`/`width`: its share of the progress.
Result<DirectionState> runDirection(Span q, Span t, double scale, const CallOptions& call,
                                    const DirectionSplit& split, const DirectedCall& directed, double from,
                                    double width) {
    const uint64_t chunks = (q.size() + split.queryChunk - 1) / split.queryChunk;
    const uint64_t tiles = (t.size() + split.targetTile - 1) / split.targetTile;
    const bool perPoint = tiles > 1 || call.perPointDistances;
    DirectionState s;
    if (call.perPointDistances) {
        s.perPoint.distance.resize(q.size());
        s.perPoint.nearest.resize(q.size());
    }
    const double step = width / double(chunks * tiles);
    std::vector<float> best2;  // per query of the chunk: the best pair's searchDist2
    std::vector<double> best;  // its distance (as the call reported it)
    std::vector<uint32_t> nearest;
    for (uint64_t c = 0; c < chunks; ++c) {
        const uint64_t q0 = c * split.queryChunk;
        const Span qc = q.subspan(q0, std::min<uint64_t>(split.queryChunk, q.size() - q0));
        if (perPoint) {
            best2.assign(qc.size(), std::numeric_limits<float>::infinity());
            best.assign(qc.size(), 0.0);
            nearest.assign(qc.size(), 0);
        }
        for (uint64_t j = 0; j < tiles; ++j) {
            const uint64_t t0 = j * split.targetTile;
            const Span tj = t.subspan(t0, std::min<uint64_t>(split.targetTile, t.size() - t0));
            Result<HausdorffResult> r =
                directed(qc, tj, pieceOptions(call, perPoint, from + step * double(c * tiles + j), step));
            if (!r) return r.error();
            addCounters(s.witness.counters, r->aToB.counters, c == 0);
            addTimings(s.timings, r->timings);
            if (!perPoint) {
                const Directed& w = r->aToB;
                offerWitness(s, w, searchDist2(qc[w.queryIndex], tj[w.targetIndex], scale), q0, t0);
                continue;
            }
            const PerPoint& pp = r->aNearest;
            for (size_t i = 0; i < qc.size(); ++i) {
                const float d2 = searchDist2(qc[i], tj[pp.nearest[i]], scale);
                if (d2 < best2[i]) {  // the earlier tile (smaller target index) among ties
                    best2[i] = d2;
                    best[i] = pp.distance[i];
                    nearest[i] = uint32_t(pp.nearest[i] + t0);
                }
            }
        }
        if (!perPoint) continue;
        // The chunk's witness: its largest best distance, the smallest index among ties.
        const size_t w = size_t(std::max_element(best2.begin(), best2.end()) - best2.begin());
        Directed d;
        d.distance = best[w];
        d.queryIndex = uint32_t(w);
        d.targetIndex = nearest[w];
        d.queryPoint = glm::dvec3(qc[w]);
        d.targetPoint = glm::dvec3(t[nearest[w]]);
        offerWitness(s, d, best2[w], q0, 0);
        if (call.perPointDistances) {
            std::copy(best.begin(), best.end(), s.perPoint.distance.begin() + ptrdiff_t(q0));
            std::copy(nearest.begin(), nearest.end(), s.perPoint.nearest.begin() + ptrdiff_t(q0));
        }
    }
    s.witness.counters.queries = q.size();  // each tile's calls counted them again
    s.witness.counters.queryChunks = uint32_t(chunks);
    s.witness.counters.targetTiles = uint32_t(tiles);
    return s;
}

// runDirection, with the budget halved after each kOutOfMemory (the per-point
// figure is an estimate; a device may hold less than it reports).
Result<DirectionState> runDirectionWithin(Span q, Span t, double scale, const CallOptions& call,
                                          MemoryBudget budget, const DirectedCall& directed,
                                          const std::function<void()>& release, double from, double width) {
    for (;;) {
        Result<DirectionSplit> split = splitDirection(budget, q.size(), t.size());
        if (!split) return split.error();
        Result<DirectionState> s = runDirection(q, t, scale, call, *split, directed, from, width);
        if (s || s.error().code != ErrorCode::kOutOfMemory || budget.pointsPerCall() < 4) return s;
        if (release) release();
        budget.bytes /= 2;
        budget.source += ", halved after: " + s.error().message;
    }
}

}  // namespace

bool fitsOneCall(const MemoryBudget& budget, uint64_t na, uint64_t nb) {
    return na + nb <= budget.pointsPerCall();
}

Result<DirectionSplit> splitDirection(const MemoryBudget& budget, uint64_t nq, uint64_t nt) {
    const uint64_t perCall = budget.pointsPerCall();
    if (perCall < 2 || budget.maxPiecePoints < 1) {
        return Error{ErrorCode::kOutOfMemory, "a memory budget of " + std::to_string(budget.bytes) +
                                                  " bytes (" + budget.source +
                                                  ") holds fewer than 2 points at " +
                                                  std::to_string(kBytesPerPoint) + " bytes per point"};
    }
    DirectionSplit split;
    const uint64_t half = perCall / 2;
    if (nt <= std::min(half, budget.maxPiecePoints)) {
        split.targetTile = std::max<uint64_t>(nt, 1);
        split.queryChunk = std::min(perCall - split.targetTile, budget.maxPiecePoints);
    } else {
        split.targetTile = std::min(half, budget.maxPiecePoints);
        split.queryChunk = std::min(perCall - split.targetTile, budget.maxPiecePoints);
    }
    split.queryChunk = std::max<uint64_t>(1, std::min(split.queryChunk, nq));
    return split;
}

Result<HausdorffResult> computeInPieces(Span a, Span b, double scale, const CallOptions& call,
                                        const MemoryBudget& budget, const DirectedCall& directed,
                                        const std::function<void()>& release) {
    const double width = call.directedOnly ? 1.0 : 0.5;
    Result<DirectionState> ab = runDirectionWithin(a, b, scale, call, budget, directed, release, 0.0, width);
    if (!ab) return ab.error();
    HausdorffResult r;
    r.directedOnly = call.directedOnly;
    r.aToB = ab->witness;
    r.aNearest = std::move(ab->perPoint);
    r.hausdorff = r.aToB.distance;
    r.timings = ab->timings;
    if (!call.directedOnly) {
        if (release) release();
        Result<DirectionState> ba =
            runDirectionWithin(b, a, scale, call, budget, directed, release, 0.5, 0.5);
        if (!ba) return ba.error();
        r.bToA = ba->witness;
        r.bNearest = std::move(ba->perPoint);
        r.hausdorff = std::max(r.hausdorff, r.bToA.distance);
        addTimings(r.timings, ba->timings);
    }
    return r;
}

}  // namespace rthdist::api
