// A direction's targets narrowed to those that can be some query's nearest
// (issue 33's far-cluster family; design.md §8, "Narrowed targets").
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
// relative 2^-30 (keeping a target too many costs nothing). Any target t
// bounds it too: d(q, T) <= |q - t| <= the farthest point of Q's box from t.
//
// The narrowed pair is searched in its own frame (its own origin and scale,
// core/input_frame.hpp), where the slack scales with the cluster, not the
// strays. When both sets' strays lie beyond the other's reach, each
// direction's kept targets are the other set's core: one call on the two
// cores answers both directions (narrowPair).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "core/index_space.hpp"
#include "core/input_frame.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::api {

// Some points of a view, in its scalar type, with the way back to their
// indices in it (ascending): `listed` (position -> index), or, for a core
// (every point but the ascending `skipped` ones), the position plus the
// skipped indices before it. `view` is a packed copy in `bytes`, or, where
// the points are one run of the view (a core whose strays are its first or
// last points), that run of the view itself (`bytes` empty).
struct PointSubset {
    std::vector<unsigned char> bytes;
    PointView view;
    bool core = false;              // every point but `skipped` (else `listed`)
    std::vector<uint64_t> listed;   // position -> index (not a core)
    std::vector<uint64_t> shifted;  // a core's skipped[k] - k, ascending
    [[nodiscard]] uint64_t indexOf(uint64_t position) const;
    // Calls fn(position, index) for positions [begin, end) in order.
    template <class Fn>
    void forIndices(uint64_t begin, uint64_t end, Fn&& fn) const;
    // Whether it holds every point of its view's set (a core without strays).
    [[nodiscard]] bool whole() const { return core && shifted.empty(); }
};

// Queries a direction may set apart to narrow the rest (api/narrowed_targets.hpp).
inline constexpr size_t kMaxStrayQueries = 256;

// The joint call's strays against the other set (strays x points, both
// directions) at most: its brute force on the host costs about 1 ns a pair
// and core; past it the directions narrow apart (narrowTargets), where a
// set's strays of its own leave its direction whole.
inline constexpr uint64_t kMaxJointStrayWork = uint64_t(1) << 28;

// The same bound for a direction narrowed apart: its strays against every
// target (strays x targets) at most; past it the direction is searched whole
// (exact all the same), so that a few hundred strays of a set against
// billions of targets never become a host brute force of minutes.
inline constexpr uint64_t kMaxApartStrayWork = uint64_t(1) << 30;

// A set split into its core and at most kMaxStrayQueries strays.
struct CoreSplit {
    core::SetSummary core;         // the core's box (exact) and precision
    std::vector<uint64_t> strays;  // ascending input indices; empty: the core is every point
};

struct NarrowedTargets {
    PointSubset targets;  // within R of the core's box (listed)
    double radius = 0.0;  // R, grown
    // Queries outside the core (at most kMaxStrayQueries; empty: none, the
    // core is every query, a PointSubset over the whole query view):
    // searched apart against every target.
    PointSubset core, strays;
    core::SetSummary coreSummary, targetsSummary;
};

// Both directions of a pair whose strays (of either set) lie beyond the
// other set's reach: one call on (coreA, coreB), each set's strays against
// every point of the other by strayQueries. A set without strays is its own
// core (a subset over its whole view).
struct JointCores {
    PointSubset coreA, coreB, straysA, straysB;
    core::SetSummary summaryA, summaryB;  // the cores'
};

// How a pair narrows: one call on both cores, or a direction apart (a -> b
// with B's targets narrowed, b -> a with A's), the other direction whole.
struct PairNarrowing {
    std::optional<JointCores> joint;
    std::optional<NarrowedTargets> targetsB, targetsA;
};

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

// A box around most of q's points (q not empty): the box of a sample of
// about `samples` points (one of each stride of q.count / samples, at a
// fixed pseudo-random place in it) without its 8 most extreme values on each
// side of each axis, grown by its extent on every side (the sample misses
// the core's own extremes). Where the strays are few, they lie outside it.
[[nodiscard]] core::Bounds sampledCore(const PointView& q, size_t samples = 1024);

// q's core when its frame can gain against the pair's magnitude `whole`
// (2^-kNarrowGainLog2 of it, route_planner.hpp's narrowingPays): every
// point when q's own box gains, else the points within sampledCore's box
// when at most kMaxStrayQueries (and not all) lie outside it, else nullopt.
// One pass over q in the latter case (strays, the core's box and precision).
// frameFloatExact: the pair's frame keeps origin 0 (both sets float32).
[[nodiscard]] std::optional<CoreSplit> splitCore(const PointView& q, const core::SetSummary& summary,
                                                 bool frameFloatExact, double whole, int threads);

// The targets of direction q -> t within R of the queries' core box, when
// narrowing them leaves a pair whose frame magnitude is at most
// 2^-kNarrowGainLog2 of the whole pair's and drops a target; else nullopt.
// The core is splitCore's (`split` when the caller has it): h(Q, T) is the
// larger of h(core, narrowed T) and h(strays, T), the latter by
// strayQueries; a stray whose nearest distance is at least 2^(8-20) of the
// pair's magnitude (strays of their own) leaves the direction whole. Boxes
// and precision from core::summarizeSet; threads as EngineOptions::threads.
// Passes: one over the queries when they have strays (splitCore), one or
// two over t for d(q0, T), one to keep (with the copy of the kept targets).
[[nodiscard]] std::optional<NarrowedTargets> narrowTargets(const PointView& q, const core::Bounds& qBox,
                                                           bool qFloatExact, const PointView& t,
                                                           const core::Bounds& tBox, bool tFloatExact,
                                                           int threads,
                                                           const std::optional<CoreSplit>* split = nullptr);

// How the pair (a, b) narrows, nullopt when it does not: one call on both
// cores (JointCores) when both sets split (splitCore), the cores' joint box
// gains, at least one set has strays and no stray of either set lies within
// the other's reach (each direction's kept targets are then the other
// core); else each direction by narrowTargets. `directedOnly`: a -> b alone.
// Before any pass over the points: nullopt when a's box reaches 2^(8-20) of
// the pair's magnitude past b's on some axis and (unless directedOnly) b's
// past a's (strays of their own both ways, known from the boxes).
// `ownStrays` (per-point output, which needs every query's nearest, and
// the GPU backends: BackendCaps::coresForOwnStrays): strays of their own do
// not leave the pair whole, the cores are looked for and searched jointly
// where they gain (a 2M double cluster beside a km stray in each set: the
// cores' frame is the clusters', not the strays').
[[nodiscard]] std::optional<PairNarrowing> narrowPair(const PointView& a, const core::SetSummary& sa,
                                                      const PointView& b, const core::SetSummary& sb,
                                                      bool directedOnly, int threads, bool ownStrays = false);

template <class Fn>
void PointSubset::forIndices(uint64_t begin, uint64_t end, Fn&& fn) const {
    if (!core) {
        for (uint64_t p = begin; p < end; ++p) fn(p, listed[p]);
        return;
    }
    // Positions [p, stop) map to p + j: j strays lie before them.
    size_t j = indexOf(begin) - begin;
    for (uint64_t p = begin; p < end;) {
        const uint64_t stop = j < shifted.size() && shifted[j] < end ? shifted[j] : end;
        for (; p < stop; ++p) fn(p, p + j);
        while (j < shifted.size() && shifted[j] <= p) ++j;
    }
}

}  // namespace rthdist::api
