// Support of the MPI tests (run under mpirun -np 1, 2, 3): this rank's slice
// of a whole set, one Engine per rank and backend for the whole run, and the
// comparison of an MPI result with a one-process result.
#pragma once

#include <gtest/gtest.h>
#include <mpi.h>

#include <glm/vec3.hpp>

#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "rthdist/mpi.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::mpi_test {

inline int commRank() {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

inline int commSize() {
    int s = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
}

// Points [rank * n / size, (rank + 1) * n / size) of `all`: uneven, and
// empty on some ranks when n < size.
template <class P>
PointView sliceView(const std::vector<P>& all) {
    const size_t n = all.size(), r = size_t(commRank()), s = size_t(commSize());
    const size_t begin = n * r / s, end = n * (r + 1) / s;
    PointView v(std::span<const P>(all.data() + begin, end - begin));
    if (begin == end) v.data = all.data();  // an empty slice still has a valid pointer
    return v;
}

// This rank's Engine for a backend, created once (agreed over ranks), or the
// agreed error.
inline Result<Engine>* sharedEngine(Backend backend) {
    static std::optional<Result<Engine>> engines[4];
    std::optional<Result<Engine>>& slot = engines[int(backend)];
    if (!slot) {
        EngineOptions options;
        options.backend = backend;
        options.threads = 1;
        slot.emplace(Engine::create(options));
        std::optional<Error> local = *slot ? std::nullopt : std::optional<Error>((*slot).error());
        if (auto agreed = agreeOnError(MPI_COMM_WORLD, local)) slot.emplace(*agreed);
    }
    return &*slot;
}

// Same H, directed distances (bit for bit) and witness pairs as one process.
inline void expectSameAsOneProcess(const HausdorffResult& mpi, const HausdorffResult& one) {
    EXPECT_EQ(mpi.hausdorff, one.hausdorff);
    EXPECT_EQ(mpi.directedOnly, one.directedOnly);
    EXPECT_EQ(mpi.origin.x, one.origin.x);
    EXPECT_EQ(mpi.origin.y, one.origin.y);
    EXPECT_EQ(mpi.origin.z, one.origin.z);
    auto same = [](const Directed& m, const Directed& o, const char* what) {
        SCOPED_TRACE(what);
        EXPECT_EQ(m.distance, o.distance);
        EXPECT_EQ(m.queryIndex, o.queryIndex);
        EXPECT_EQ(m.targetIndex, o.targetIndex);
        EXPECT_EQ(m.queryPoint, o.queryPoint);
        EXPECT_EQ(m.targetPoint, o.targetPoint);
        EXPECT_EQ(m.counters.queries, o.counters.queries);
    };
    same(mpi.aToB, one.aToB, "a_to_b");
    if (!one.directedOnly) same(mpi.bToA, one.bToA, "b_to_a");
}

}  // namespace rthdist::mpi_test
