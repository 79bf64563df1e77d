// rthdist over MPI — the exact Hausdorff distance of two point sets that are
// spread over the ranks of an MPI communicator (one rank per GPU, or CPU
// ranks on nodes without one). Built only when Open MPI is found (CMake
// target rthdist_mpi; the core library does not depend on MPI).
//
// Contract
//   Collective over `comm`: every rank calls hausdorffMpi with its own slice
//   of A and of B (any sizes, empty slices allowed). The slices, in rank
//   order, are the global sets: global index = sum of the slice sizes of the
//   lower ranks + local index (MPI_Exscan). Every rank returns the same
//   value: H, both directed distances, witness indices (global) and witness
//   points (the caller's coordinates, in double), or the same Error
//   (ErrorCode and message) — an error found on one rank (NaN, an empty
//   global set, no device, out of memory) is agreed on by all ranks before
//   any collective that could block, so no rank hangs.
//
// Exactness: the result is the one of rthdist::hausdorff over the
//   concatenated sets, the double brute force (==) realized by the reported
//   pair. The ranks search the float32 points below; for float32 inputs
//   those are the inputs. For other double inputs each rank also keeps every
//   query's float pair distance (per point), and the queries whose distance
//   lies within 2^-16 of the scaled frame's magnitude of the largest (the
//   band: the float rounding of the points and the pairs' relative 2^-21
//   stay within half of it) are settled in double: each one's exact nearest
//   distance over every rank's slice of the targets as given (a brute force,
//   the smallest global index on a tie), the largest winning, the smallest
//   query on a tie. A band past 2^32 query x target pairs is not settled:
//   the value is then the shifted frame's (within 2e of the double answer)
//   and each Directed::certificate is unconfirmed with the reason in
//   `failure`. Why the searched points' answer holds:
//   - Frame: the ranks agree on the union's box and on whether every
//     coordinate is a float32 value, and round p - o to float32 with the very
//     origin o a one-process call uses (0 for float data, else the box's
//     centre). Every rank's engine then searches the same float32 points a
//     one-process call searches.
//   - h(Q,T) = max over q of NN_T(q). Each rank answers a subset of the
//     queries (a partition of Q) against a target set that holds every
//     query's true nearest neighbour (below); its engine's h is exact over
//     that subset, and the maximum over ranks is h. Queries and targets are
//     given to the engine in global index order, so ties resolve as in one
//     process (largest distance, then smallest query index; the engine's rule
//     for the target). The winner is chosen identically on every rank from an
//     allgather of (distance, query, target); its points are broadcast by the
//     ranks that own them and its distance is recomputed in double from the
//     caller's coordinates, exactly as rthdist::hausdorff does.
//   - Replicated targets (TargetMode::kReplicated): the target set is
//     allgathered as float32 (12 bytes per point per rank); each rank queries
//     its own slice against all of it. Trivially every NN is present.
//   - Spatial targets (TargetMode::kSpatial): the targets are cut into one
//     slab per rank along the longest axis of their global box (equal counts
//     from an allreduced histogram) and sent to their slab's rank; queries go
//     to the slab of their coordinate on that axis (clamped at both ends).
//     Rank r bounds every NN of its queries Q_r from above by
//     w_r = h(Q_r, T'_r ∪ S) (T'_r every 16th target of its slab, S a global
//     sample of about 4096 targets; both subsets of T, so NN_T(q) <= w_r for
//     q in Q_r),
//     widened by a relative 1e-4 and 1e-5 D against rounding. Every target t
//     with |t - q| <= w_r has |t_axis - q_axis| <= w_r, so the halo "targets
//     whose axis coordinate lies within w_r of [min, max] of Q_r's axis
//     coordinates" (sent to r by their owners) holds every NN: the final
//     engine pass over T_r ∪ halo is exact for Q_r. Far-apart sets give wide
//     halos (up to the whole target set): still exact, as memory-hungry as
//     replication.
//   - kAuto: replicated when both sets together fit replicateLimitBytes as
//     float32 (default 1 GiB, about 89 M points), else spatial.
//
// Options: backend, deviceIndex, validation, threads, pipelineCacheDir (per
//   rank), bits, directedOnly, radiusGrowth, cancel as in options.hpp. Not
//   supported: perPointDistances (kInvalidArgument). progress is not called.
//   GPU nodes: one rank per GPU; set deviceIndex per rank (e.g. from the
//   node-local rank) or leave -1 for the first usable device.
// Result fields beyond the witnesses: origin as above; counters summed over
//   ranks (queries = |Q|), except bits and iterations (their maximum over
//   ranks) — the work of the final pass; spatial mode's bound pass is not
//   counted. timings: each stage summed over the rank's engine calls
//   (spatial: bound and final pass), then the maximum over ranks; total = the
//   wall time of the whole collective call (frame, exchanges, both passes).
//   device and backend: rank 0's engine.
// Identical to one process: on the CPU backend, H, both directed distances
//   (bit for bit), witness indices and points equal those of
//   rthdist::hausdorff over the concatenated sets (tests/mpi, np 1..3, every
//   oracle and georeferenced case, and a near tie at UTM magnitude that the
//   floats order the other way). On the GPU backends the values keep the
//   contract above, but among queries whose squared float distances tie the
//   GPU keeps the one of the largest slot of its own query order, which
//   depends on the slice a rank holds: the witness (and, for double input,
//   the last bits of the recomputed distance) may then differ from one
//   process's.
// Limits: up to 2^31 - 1 points per global set (indices are 32-bit, as in
//   rthdist.hpp). Replicated mode holds the whole target set as float32 on
//   every rank; spatial mode holds the rank's slab, its halo and its queries.
// Threading: collective; call from one thread per rank (MPI_THREAD_SINGLE
//   suffices: the engine's worker threads make no MPI calls).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <optional>

#include "rthdist/options.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist {

enum class TargetMode {
    kAuto,        // replicated when it fits MpiOptions::replicateLimitBytes, else spatial
    kReplicated,  // every rank holds the whole target set (float32)
    kSpatial,     // one slab of the target set per rank, plus an exact halo
};

struct MpiOptions {
    TargetMode mode = TargetMode::kAuto;
    // kAuto: replicate when (|A| + |B|) * 12 bytes is at most this.
    uint64_t replicateLimitBytes = uint64_t(1) << 30;
};

// "auto", "replicated", "spatial".
[[nodiscard]] const char* targetModeName(TargetMode mode);
[[nodiscard]] bool parseTargetMode(const char* text, TargetMode& out);

// Collective: H over the ranks' slices with an Engine per rank (created by
// the caller with Engine::create; engine errors are agreed on as above).
[[nodiscard]] Result<HausdorffResult> hausdorffMpi(MPI_Comm comm, Engine& engine, PointView localA,
                                                   PointView localB, const CallOptions& call = {},
                                                   const MpiOptions& mpi = {});

// Collective one-shot: creates the rank's Engine from `options` (an Engine
// that fails on one rank fails the call on all), then computes as above.
[[nodiscard]] Result<HausdorffResult> hausdorffMpi(MPI_Comm comm, PointView localA, PointView localB,
                                                   const Options& options = {}, const MpiOptions& mpi = {});

// Collective: agrees on an error found by any rank. Returns the error of the
// lowest failing rank on every rank, or nothing when no rank failed. For
// callers that do fallible local work (loading files) before hausdorffMpi.
[[nodiscard]] std::optional<Error> agreeOnError(MPI_Comm comm, const std::optional<Error>& local);

}  // namespace rthdist
