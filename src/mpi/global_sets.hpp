// The two global point sets of hausdorffMpi as each rank holds them: the
// caller's slice, where it sits in the global order, and its float32 copy in
// the frame a one-process call would search (rthdist.hpp, Precision): every
// rank agrees on the union's box and on whether every coordinate is a
// float32 value, and rounds p - origin to float32 with origin 0 for float
// data, else the centre of the union's box (core::searchOrigin's rule); the
// floats are then scaled by the one-process call's exact power of two.
#pragma once

#include <mpi.h>

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"

namespace rthdist::mpi {

struct GlobalSet {
    PointView local;                // the caller's slice
    std::vector<uint64_t> offsets;  // slice r holds [offsets[r], offsets[r+1]); offsets.back() = total
    std::vector<glm::vec3> floats;  // the slice as searched: p - origin rounded to float32, times scale
    int rank = 0;

    [[nodiscard]] uint64_t offset() const { return offsets[size_t(rank)]; }
    [[nodiscard]] uint64_t total() const { return offsets.back(); }
};

struct GlobalSets {
    GlobalSet a, b;
    glm::dvec3 origin{0.0};
    // The exact power-of-two scale a one-process call applies (core::exactScale
    // of the largest float magnitude of both sets), applied here already, so
    // that every rank's engine compares the squared floats one engine would.
    double scale = 1.0;
    double diagonal = 0.0;  // of the union's box, in double, times scale
    // Every coordinate of both sets is a float32 value: the floats searched
    // are the inputs themselves (origin 0), so a result proven on them is
    // proven in double. Else the ranks' proofs hold on the shifted frame's
    // float32 points only (rthdist/mpi.hpp, Exactness).
    bool floatExact = true;
};

// Collective. Checks both slices (stride, NaN/Inf, naming the global index),
// both global sets (non-empty, < 2^31 points), agrees on the frame and makes
// the float copies; the same Error on every rank when any rank failed.
[[nodiscard]] Result<GlobalSets> makeGlobalSets(MPI_Comm comm, PointView localA, PointView localB);

// The caller's coordinates of global point g of `set`, broadcast by its
// owner to every rank.
[[nodiscard]] glm::dvec3 broadcastPoint(MPI_Comm comm, const GlobalSet& set, uint64_t g);

}  // namespace rthdist::mpi
