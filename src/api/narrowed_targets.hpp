// A direction's targets narrowed to those that can be some query's nearest
// (issue 33's far-cluster family; design.md §13).
//
// Why: the float search's rounding slack e (core/certificate.hpp) grows with
// the largest coordinate of the pair. A dense cluster in one set and a few
// strays kilometres away in the other make e larger than the cluster's whole
// extent in the direction whose queries are the cluster alone: no query can
// be settled within e, every one goes to the rays and the band holds them all.
// Yet no stray can be such a query's nearest target.
//
// The argument: for any query q0 of Q, every query q has
//   d(q, T) <= |q - q0| + d(q0, T) <= diag(box Q) + d(q0, T) = R,
// so q's nearest target lies within R of q, hence within R of Q's box. The
// targets whose distance to Q's box exceeds R are never a nearest target nor
// tie one: h(Q, T) = h(Q, T'), T' the others, and every query's nearest
// target in T' is its nearest in T (same distance, same smallest index once
// T' indices map back in order). R is computed in double and grown by a
// relative 2^-30 (keeping a target too many costs nothing).
//
// The narrowed pair is searched in its own frame (its own origin and scale,
// core/input_frame.hpp), where the slack scales with the cluster, not the strays.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/index_space.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::api {

// A packed copy of some points of a view, in its scalar type, with their
// indices in it (ascending).
struct PointSubset {
    std::vector<unsigned char> bytes;
    std::vector<uint64_t> original;  // position -> index in the view
    PointView view;                  // over `bytes`
};

struct NarrowedTargets {
    PointSubset targets;  // within R of the core's box
    double radius = 0.0;  // R, grown
    // Queries outside the core (at most kMaxStrayQueries; empty: none, the
    // core is every query): searched apart against every target. `core`:
    // the other queries, set only when there are strays.
    PointSubset core, strays;
};

// Queries a direction may set apart to narrow the rest (api/narrowed_targets.hpp).
inline constexpr size_t kMaxStrayQueries = 256;

// The stray queries' exact answer, a brute force in double on the host over
// every target (at most kMaxStrayQueries queries): the directed value with
// its witness (ties: the smaller query, then the smaller target; positions
// in `strays`, input indices of t), its certificate (the brute force is
// exact: confirmed, every stray in the band) and, when `perPoint`, each
// stray's nearest target and distance. threads as EngineOptions::threads.
[[nodiscard]] Directed strayQueries(const PointSubset& strays, const PointView& t, PerPoint* perPoint,
                                    int threads);

// The largest |coordinate| of a box after the frame's origin (zero for
// float32 coordinates, else the box's centre: core::searchOrigin's rule for
// one box), as the search would see it.
[[nodiscard]] double frameMagnitude(const core::Bounds& box, bool floatExact);

// A box around most of q's points (q not empty): a strided sample's box
// (about `samples` points) without its 8 most extreme values on each side of
// each axis, grown by its extent on every side (the sample misses the
// core's own extremes). Where the strays are few, they lie outside it.
[[nodiscard]] core::Bounds sampledCore(const PointView& q, size_t samples = 1024);

// The targets of direction q -> t within R of the queries' core box, when
// narrowing them leaves a pair whose frame magnitude is at most
// 2^-kNarrowGainLog2 of the whole pair's (route_planner.hpp, narrowingPays)
// and drops a target; else nullopt. The core is every query, or, when the
// queries' own box is too large (strays among them), the queries within a
// box taken from a sample of them and grown by its extent on every side,
// when at most kMaxStrayQueries lie outside it: h(Q, T) is then the larger
// of h(core, narrowed T) and h(strays, T), the latter by strayQueries. Boxes and precision from
// core::summarizeSet; threads as EngineOptions::threads. Passes: one over
// the queries when they have strays, one over t for d(q0, T), one to keep.
[[nodiscard]] std::optional<NarrowedTargets> narrowTargets(const PointView& q, const core::Bounds& qBox,
                                                           bool qFloatExact, const PointView& t,
                                                           const core::Bounds& tBox, bool tFloatExact,
                                                           int threads);

}  // namespace rthdist::api
