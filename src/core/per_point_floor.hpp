// A per-point call's floors: the out-of-core pieces' round one (design.md
// §9) needs every query's exact nearest point only where it may matter,
// that is where it is at least the keep floor of a maximum already settled
// (api/out_of_core.cpp keepFloor). Below it, any target nearer than the
// floor is proof enough: the backend may stop there (its early break with a
// threshold given from outside, instead of its own running maximum, which
// in a piece is not a lower bound of the whole's h).
//
// Contract (ComputeBackend::computeFramed, per direction, 0: A -> B,
// 1: B -> A): with CallOptions::perPointDistances, a query that has a
// target whose distance (search units: the floats as searched, at the
// pair's scale) lies below the direction's floor may come back as
// kBelowFloor in PerPoint::nearest (its PerPoint::distance, where filled,
// -1); every other query's entry is its exact nearest, as without a floor.
// A call with any floor leaves its result's witnesses, hausdorff and proof
// empty: only the per-point arrays and the counters mean anything. A
// floor of 0 (or below) is none. A backend may hand a direction back
// sparse instead (HausdorffResult::aboveFloor, detail::AboveFloor below):
// its PerPoint arrays empty, the queries that did not stop listed with
// their exact nearest targets, every other query below the floor.
#pragma once

#include <bit>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace rthdist::core {

// PerPoint::nearest of a query whose target nearer than its floor ended its
// search (UINT32_MAX is the device's "never written").
inline constexpr uint32_t kBelowFloor = 0xfffffffeu;

struct PerPointFloor {
    double search[2] = {0.0, 0.0};  // per direction; <= 0: none

    [[nodiscard]] bool any() const { return search[0] > 0.0 || search[1] > 0.0; }

    // The float squared-distance threshold under which a search may call a
    // query below direction d's floor: every float squared distance of
    // float points below it (float differences, squares and sums: at most
    // about 5 * 2^-24 relative above the real square, and only where it is
    // a normal float) is the square of a distance below the floor. 0 when
    // there is no floor or it is too small for that argument.
    [[nodiscard]] float kill2(int d) const {
        const double f = search[d];
        if (!(f > 0.0)) return 0.0f;
        const double k = f * f * (1.0 - 0x1p-18);
        if (!(k >= double(std::numeric_limits<float>::min()) * 4.0)) return 0.0f;
        if (k >= double(std::numeric_limits<float>::max())) return std::numeric_limits<float>::max();
        float r = float(k);  // to nearest: at most 2^-24 relative above k
        if (double(r) > k)
            r = std::bit_cast<float>(std::bit_cast<uint32_t>(r) - 1u);  // positive: one step down
        return r;
    }
};

}  // namespace rthdist::core

namespace rthdist::detail {

// A query of a per-point call with a floor that did not stop below it, and
// its exact nearest target (indices into the call's sets).
struct QueryNearest {
    uint32_t query = 0;
    uint32_t nearest = 0;
};

// HausdorffResult::aboveFloor: per direction (0: A -> B), when handed back
// sparse, its queries above the floor in query order (unset: the
// direction's PerPoint arrays hold it densely).
struct AboveFloor {
    std::optional<std::vector<QueryNearest>> of[2];
};

}  // namespace rthdist::detail
