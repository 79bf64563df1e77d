// The two ways hausdorffMpi runs one directed pass h(Q,T) over the ranks
// (rthdist/mpi.hpp states both and why each is exact). Collective; each rank
// returns its own PassOutcome (global indices), or the same Error on every
// rank.
#pragma once

#include <mpi.h>

#include "mpi/global_sets.hpp"
#include "mpi/local_pass.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::mpi {

// Every rank holds all of T (float32) and answers its own slice of Q.
// perPoint: the outcome keeps every query's float pair distance (PassOutcome).
[[nodiscard]] Result<PassOutcome> replicatedPass(MPI_Comm comm, Engine& engine, const GlobalSet& q,
                                                 const GlobalSet& t, const CallOptions& call, bool perPoint);

// Rank r owns a slab of T along its longest axis and the queries in that
// slab, and receives the halo of targets that can hold their nearest
// neighbours. `diagonal`: of the union's box (widens the halo against rounding).
[[nodiscard]] Result<PassOutcome> spatialPass(MPI_Comm comm, Engine& engine, const GlobalSet& q,
                                              const GlobalSet& t, double diagonal, const CallOptions& call,
                                              bool perPoint);

}  // namespace rthdist::mpi
