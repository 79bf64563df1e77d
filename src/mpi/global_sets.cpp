#include "mpi/global_sets.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/index_space.hpp"
#include "core/input_frame.hpp"
#include "core/input_limits.hpp"
#include "mpi/collectives.hpp"
#include "rthdist/mpi.hpp"

namespace rthdist::mpi {

namespace {

constexpr uint64_t kMaxPoints = 0x7fffffffu;

struct SliceSummary {
    glm::dvec3 lo{std::numeric_limits<double>::infinity()};
    glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
    bool floatExact = true;
};

// Local: box and precision of one slice, or the error naming its first bad point.
Result<SliceSummary> summarizeSlice(const GlobalSet& set, const char* name) {
    const PointView& v = set.local;
    SliceSummary s;
    if (v.count == 0) return s;
    const size_t scalar = scalarBytes(v.scalar);
    if (v.data == nullptr || v.strideBytes < 3 * scalar || v.strideBytes % scalar != 0) {
        return Error{ErrorCode::kInvalidArgument,
                     std::string("point set ") + name + ": a stride of " + std::to_string(v.strideBytes) +
                         " bytes cannot hold a point (or the data pointer is null)"};
    }
    for (size_t i = 0; i < v.count; ++i) {
        const glm::dvec3 p = v.at(i);
        if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))) {
            return Error{ErrorCode::kInvalidArgument, std::string("point set ") + name + ": point " +
                                                          std::to_string(set.offset() + i) +
                                                          " has a NaN or infinite coordinate"};
        }
        for (int k = 0; k < 3; ++k) s.floatExact = s.floatExact && double(float(p[k])) == p[k];
        s.lo = glm::min(s.lo, p);
        s.hi = glm::max(s.hi, p);
    }
    return s;
}

GlobalSet sliceOf(MPI_Comm comm, PointView local) {
    GlobalSet set;
    set.local = local;
    set.rank = rankOf(comm);
    set.offsets = offsetsOf(allgatherCounts(comm, local.count));
    return set;
}

std::optional<Error> globalSizeError(const GlobalSet& set, const char* name) {
    if (set.total() == 0)
        return Error{ErrorCode::kInvalidArgument,
                     std::string("point set ") + name + " is empty: the Hausdorff distance is undefined"};
    if (set.total() > kMaxPoints)
        return Error{ErrorCode::kInvalidArgument,
                     std::string("point set ") + name + " has more than 2^31-1 points"};
    return std::nullopt;
}

// p - origin rounded to float32 (FloatSet's rounding), then times the exact
// power-of-two scale (core::scaled's rounding): the values a one-process call
// compares.
void roundInto(GlobalSet& set, const glm::dvec3& origin, double scale) {
    set.floats.resize(set.local.count);
    for (size_t i = 0; i < set.local.count; ++i)
        set.floats[i] = core::scaled(glm::vec3(set.local.at(i) - origin), scale);
}

// Largest |coordinate| of the slice after the shift, in float (core::largestMagnitude's measure).
double sliceMagnitude(const GlobalSet& set, const glm::dvec3& origin) {
    float m = 0.0f;
    for (size_t i = 0; i < set.local.count; ++i) {
        const glm::vec3 p(set.local.at(i) - origin);
        m = std::max({m, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    }
    return double(m);
}

}  // namespace

Result<GlobalSets> makeGlobalSets(MPI_Comm comm, PointView localA, PointView localB) {
    GlobalSets sets;
    sets.a = sliceOf(comm, localA);
    sets.b = sliceOf(comm, localB);
    for (const auto* e : {&sets.a, &sets.b}) {
        if (auto error = globalSizeError(*e, e == &sets.a ? "A" : "B")) return *error;  // same on every rank
    }
    SliceSummary sa, sb;
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        Result<SliceSummary> ra = summarizeSlice(sets.a, "A");
        if (!ra) return ra.error();
        Result<SliceSummary> rb = summarizeSlice(sets.b, "B");
        if (!rb) return rb.error();
        sa = *ra;
        sb = *rb;
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;

    double lo[3], hi[3];
    int floatExact = sa.floatExact && sb.floatExact ? 1 : 0;
    for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(sa.lo[k], sb.lo[k]);
        hi[k] = std::max(sa.hi[k], sb.hi[k]);
    }
    MPI_Allreduce(MPI_IN_PLACE, lo, 3, MPI_DOUBLE, MPI_MIN, comm);
    MPI_Allreduce(MPI_IN_PLACE, hi, 3, MPI_DOUBLE, MPI_MAX, comm);
    MPI_Allreduce(MPI_IN_PLACE, &floatExact, 1, MPI_INT, MPI_LAND, comm);
    const glm::dvec3 boxLo(lo[0], lo[1], lo[2]), boxHi(hi[0], hi[1], hi[2]);
    const core::SetSummary unionBox{core::Bounds{boxLo, boxHi}, floatExact != 0};
    sets.origin = core::searchOrigin(unionBox, unionBox);  // 0 for float data, else the centre
    sets.floatExact = floatExact != 0;

    // The float search's limits (core/input_limits.hpp), as one process checks
    // them: the sets in checkBFirst's order of their global boxes; within a
    // set, the lowest failing rank's slice names the point.
    if (!floatExact || sets.origin != glm::dvec3(0.0)) {
        double boxes[12];  // A's lo, B's lo, -A's hi, -B's hi: one MIN reduction
        for (int k = 0; k < 3; ++k) {
            boxes[k] = sa.lo[k];
            boxes[3 + k] = sb.lo[k];
            boxes[6 + k] = -sa.hi[k];
            boxes[9 + k] = -sb.hi[k];
        }
        MPI_Allreduce(MPI_IN_PLACE, boxes, 12, MPI_DOUBLE, MPI_MIN, comm);
        const core::Bounds boxA{glm::dvec3(boxes[0], boxes[1], boxes[2]),
                                -glm::dvec3(boxes[6], boxes[7], boxes[8])};
        const core::Bounds boxB{glm::dvec3(boxes[3], boxes[4], boxes[5]),
                                -glm::dvec3(boxes[9], boxes[10], boxes[11])};
        const bool bFirst = core::checkBFirst(boxA, boxB, sets.origin);
        for (const GlobalSet* set : {bFirst ? &sets.b : &sets.a, bFirst ? &sets.a : &sets.b}) {
            // The rank holding the farthest point (farthestShifted's order, the
            // lowest rank on a tie) names it, as one process would.
            const SliceSummary& summary = set == &sets.a ? sa : sb;
            core::ShiftedReach reach;
            local = guarded([&]() -> std::optional<Error> {
                if (set->local.count > 0) reach = core::farthestShifted(set->local, sets.origin);
                return std::nullopt;
            });
            if (auto error = agreeOnError(comm, local)) return *error;
            std::vector<double> reaches(2 * size_t(set->offsets.size() - 1));
            const double mine[2] = {reach.distance, reach.magnitude};
            MPI_Allgather(mine, 2, MPI_DOUBLE, reaches.data(), 2, MPI_DOUBLE, comm);
            int chosen = -1;
            for (int r = 0; 2 * size_t(r) < reaches.size(); ++r) {
                const std::pair<double, double> key{reaches[2 * size_t(r)], reaches[2 * size_t(r) + 1]};
                if (key.first >= 0.0 && (chosen < 0 || key > std::pair{reaches[2 * size_t(chosen)],
                                                                       reaches[2 * size_t(chosen) + 1]}))
                    chosen = r;
            }
            if (chosen < 0) continue;
            local = guarded([&]() -> std::optional<Error> {
                if (chosen != set->rank) return std::nullopt;
                return core::checkShiftedRange(set->local, core::Bounds{summary.lo, summary.hi}, sets.origin,
                                               set == &sets.a ? "A" : "B", set->offset());
            });
            if (auto error = agreeOnError(comm, local)) return *error;
        }
        if (auto error = core::checkShiftedExtent(core::Bounds{boxLo, boxHi}, sets.origin, "A and B"))
            return *error;  // the same on every rank: from the agreed box
    }
    double magnitude = std::max(sliceMagnitude(sets.a, sets.origin), sliceMagnitude(sets.b, sets.origin));
    MPI_Allreduce(MPI_IN_PLACE, &magnitude, 1, MPI_DOUBLE, MPI_MAX, comm);
    sets.scale = core::exactScale(magnitude);
    sets.diagonal = glm::length(boxHi - boxLo) * sets.scale;

    local = guarded([&]() -> std::optional<Error> {
        roundInto(sets.a, sets.origin, sets.scale);
        roundInto(sets.b, sets.origin, sets.scale);
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return sets;
}

glm::dvec3 broadcastPoint(MPI_Comm comm, const GlobalSet& set, uint64_t g) {
    const int owner = ownerOf(set.offsets, g);
    glm::dvec3 p(0.0);
    if (owner == set.rank) p = set.local.at(size_t(g - set.offset()));
    double xyz[3] = {p.x, p.y, p.z};
    MPI_Bcast(xyz, 3, MPI_DOUBLE, owner, comm);
    return glm::dvec3(xyz[0], xyz[1], xyz[2]);
}

}  // namespace rthdist::mpi
