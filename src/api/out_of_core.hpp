// Out-of-core: a pair of sets larger than the memory budget of one call is
// computed as a sequence of smaller calls (design.md §9), each of which fits.
//
// Exactness. h(Q,T) = max over q of min over t of |q - t|.
//   - Queries are split into chunks Q_1..Q_m of consecutive input indices:
//     h(Q,T) = max_i h(Q_i,T), each chunk an ordinary directed call.
//   - When the targets do not fit beside a chunk, they are split into tiles
//     T_1..T_n of consecutive input indices, and every query of the chunk
//     keeps its best pair over the tiles: NN(q,T) = min_j NN(q,T_j). A
//     tile's call returns the exact nearest point in that tile of every query
//     sent to it (per-point mode), so the minimum over the tiles is q's exact
//     nearest distance in T in whatever order the tiles come: no tile order
//     can lose the maximum, which is taken only once every tile has been
//     seen or ruled out for every query.
//   - A tile is ruled out for a query (the query not sent) when the tile's
//     bounding box is farther than the query's best pair so far: no point of
//     the tile can be nearer, nor tie with a smaller index, because the box
//     distance is computed as pairs are and rounding is monotone. Tiles go
//     nearest the chunk first, so best pairs shrink early.
//   - Early break across chunks (design.md §3): without per-point output, a
//     query whose best pair is no farther than the running maximum M of the
//     earlier chunks is sent to no further tile: its nearest distance is at
//     most M and its index is larger than theirs, so it can neither exceed M
//     nor win a tie. Within a call the backend's own early break applies
//     (one tile), or none (per-point mode, several tiles).
//   - Pairs are compared as the backends compare them (float squared
//     distances of the scaled points), and ties keep the first: the witness
//     of the earliest chunk (smallest query index), the nearest point with
//     the smallest target index, as the backends do within one call.
// Each call searches the float sets in the frame and exact scale of the whole
// pair, so its distances are those of the unsplit call; witnesses come back as
// indices into the whole sets.
//
// Cost: every call indexes its tile again (up to chunks x tiles index
// builds), and queries sent to a tile search it to the end (per-point).
// Inputs in spatial order (scans, lattices, sorted files) give tiles with
// small boxes, so most (chunk, tile) pairs are ruled out; a shuffled input
// gives every tile the whole box and every query meets every tile.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "core/index_space.hpp"
#include "core/per_point_floor.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::api {

// Device bytes one point of a call is assumed to need (its records, keys,
// cells, leaves, query state and scratch; the measured figure is about 110 B
// on lavapipe and under 180 B on an H200 run of 400M + 400M points).
inline constexpr uint64_t kBytesPerPoint = 128;
// Points of one set in one backend call: the backends index points with
// 32-bit integers (and pack them beside 32-bit distances). Larger sets run in
// pieces whatever the memory budget; a prepared set (one call's set) is
// refused past it.
inline constexpr uint64_t kMaxCallPoints = 0x7fffffff;
// Bytes per point of the largest single buffer of a call (cells and leaves:
// 32 B per point), which the device's maxMemoryAllocationSize bounds.
inline constexpr uint64_t kLargestBufferBytesPerPoint = 32;

// What one call may hold.
struct MemoryBudget {
    uint64_t bytes = UINT64_MAX;           // all buffers of one call together
    uint64_t maxPiecePoints = UINT64_MAX;  // points of one set in one call (the largest buffer)
    std::string source;                    // where `bytes` came from, for messages
    // Points (query chunk + target tile) one call may hold.
    [[nodiscard]] uint64_t pointsPerCall() const { return bytes / kBytesPerPoint; }
};

// How one direction is split: chunks of `queryChunk` queries, tiles of `targetTile` targets.
struct DirectionSplit {
    uint64_t queryChunk = 0;
    uint64_t targetTile = 0;
};

// Whether the pair (na, nb) fits one call's bytes as it is, each set within
// kMaxCallPoints. maxPiecePoints bounds the pieces only: some drivers grant buffers past their advertised
// maxMemoryAllocationSize, so the whole pair is tried first (Engine: a
// kOutOfMemory under the automatic budget then falls back to pieces).
[[nodiscard]] bool fitsOneCall(const MemoryBudget& budget, uint64_t na, uint64_t nb);

// The split of direction Q -> T (nq queries, nt targets) within the budget:
// one tile when the targets fit beside a chunk of at least half the call,
// else tiles and chunks of half a call each; with several lanes, at least
// one chunk per lane; no piece past maxPiecePoints or kMaxCallPoints. kOutOfMemory when the budget holds
// fewer than two points.
[[nodiscard]] Result<DirectionSplit> splitDirection(const MemoryBudget& budget, uint64_t nq, uint64_t nt,
                                                    int lanes = 1);

// One directed call of a backend on float sets of the whole pair's frame, on
// lane `lane` (a device of the Engine; 0..lanes-1): call.directedOnly is
// set; call.perPointDistances is set when the caller needs every query's
// nearest point. Lanes are called from their own threads at once; one lane's
// calls come one at a time. Only lane 0 (the calling thread) gets
// call.progress. `floor`: round one's per-point calls may leave a query
// below it unsearched (core/per_point_floor.hpp); none elsewhere.
using DirectedCall = std::function<Result<HausdorffResult>(
    int lane, std::span<const glm::vec3> queries, std::span<const glm::vec3> targets, const CallOptions& call,
    const core::PerPointFloor& floor)>;
// Hands the per-point arrays of a lane's call, once merged, back to that
// lane's backend for its next call (GpuHausdorff::recyclePerPoint); may be empty.
using RecycleCall = std::function<void(int lane, PerPoint&& a, PerPoint&& b)>;

// H(A,B) (or h(A,B) with call.directedOnly) of float sets searched at the
// exact power-of-two `scale` (core::exactScale), as a sequence of calls of
// `directed`, each within `budget`. `release` (may be empty) frees what the
// calls keep between calls (the GPU backend's scratch): after h(A,B), and
// before a direction is run again with half the budget after a call found
// the device short of memory (kOutOfMemory). Counters add up over the calls
// (iterations: the largest), with Counters::queryChunks/targetTiles set.
// The host's passes over the points (tile boxes, the queries a tile may
// improve, merging) run on `threads` threads (0: all).
//
// Lanes (several devices): each direction's chunks are taken by `lanes`
// lanes in parallel, lane 0 on the calling thread, each lane's calls on its
// own device; a chunk's early break reads the witness of every chunk
// finished so far, by any lane, before each tile (a tie drops a query only
// when that witness's query index is smaller), and witnesses merge by
// distance, then smallest query index: the result is the one-lane result.
// `release` is called between directions and after a failure, with no lane
// running. Timings::pieces: the host's own work of the pieces (partition,
// merges, selections, the proof); `trace` prints its parts to stderr.
// `box`: the box of a and b together as given, when the caller has it
// exactly (SpatialPieces::partition).
[[nodiscard]] Result<HausdorffResult> computeInPieces(
    std::span<const glm::vec3> a, std::span<const glm::vec3> b, double scale, const CallOptions& call,
    const MemoryBudget& budget, const DirectedCall& directed, const std::function<void()>& release,
    int lanes = 1, int threads = 0, const RecycleCall& recycle = {}, bool trace = false,
    const std::optional<core::Bounds>& box = std::nullopt);

}  // namespace rthdist::api
