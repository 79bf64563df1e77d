// A per-point call with a floor (core/per_point_floor.hpp) against the
// double brute force, for the backends' tests: the floor of each direction
// is the median of its queries' nearest distances, and every query comes
// back either below the floor (core::kBelowFloor, and its nearest distance
// is below the floor) or with its exact nearest point.
#pragma once

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <span>
#include <vector>

#include "common/brute_force.hpp"
#include "common/oracle_cases.hpp"
#include "core/index_space.hpp"
#include "core/per_point_floor.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::test {

// The exact power of two a pair is searched at (core::exactScale).
inline double searchScale(std::span<const glm::vec3> a, std::span<const glm::vec3> b) {
    return core::exactScale(std::max(core::largestMagnitude(a), core::largestMagnitude(b)));
}

// A case's nearest distances by brute force, per direction (0: a -> b).
struct CaseNearest {
    std::vector<double> distance[2];
    explicit CaseNearest(const OracleCase& c)
        : distance{oracle::bruteForceNearest(c.a, c.b), oracle::bruteForceNearest(c.b, c.a)} {}
};

// Floors at the median nearest distance of each direction, search units.
inline core::PerPointFloor medianFloors(const CaseNearest& nearest, double scale) {
    core::PerPointFloor floor;
    for (int d = 0; d < 2; ++d) {
        std::vector<double> near = nearest.distance[d];
        std::nth_element(near.begin(), near.begin() + ptrdiff_t(near.size() / 2), near.end());
        floor.search[d] = near[near.size() / 2] * scale;
    }
    return floor;
}

// Checks both directions of `r` (a direction handed back sparse, as its
// dense equivalent: `sparse` counts them); returns how many queries came
// back below their floor.
inline size_t expectFloorHolds(const OracleCase& c, const CaseNearest& nearest, const HausdorffResult& r,
                               const core::PerPointFloor& floor, double scale, size_t* sparse = nullptr) {
    size_t below = 0;
    for (int d = 0; d < 2; ++d) {
        SCOPED_TRACE("direction " + std::to_string(d));
        const std::vector<glm::vec3>& q = d == 0 ? c.a : c.b;
        const std::vector<glm::vec3>& t = d == 0 ? c.b : c.a;
        PerPoint pp = d == 0 ? r.aNearest : r.bNearest;
        if (r.aboveFloor != nullptr && r.aboveFloor->of[d]) {
            EXPECT_TRUE(pp.nearest.empty() && pp.distance.empty());
            pp.nearest.assign(q.size(), core::kBelowFloor);
            uint32_t last = 0;
            for (const detail::QueryNearest& e : *r.aboveFloor->of[d]) {
                EXPECT_LT(e.query, q.size());
                if (e.query >= q.size()) return below;
                EXPECT_TRUE(&e == &r.aboveFloor->of[d]->front() || e.query > last)
                    << "queries in order, once";
                last = e.query;
                pp.nearest[e.query] = e.nearest;
            }
            if (sparse != nullptr) ++*sparse;
        }
        const std::vector<double>& want = nearest.distance[d];
        EXPECT_EQ(pp.nearest.size(), q.size());
        if (pp.nearest.size() != q.size()) return below;
        double h = 0.0;
        for (const std::vector<double>& near : nearest.distance)
            for (const double x : near) h = std::max(h, x);
        const double tol = oracleTolerance(c.a, c.b, h);
        size_t bad = 0;
        for (size_t k = 0; k < q.size() && bad < 5; ++k) {
            const uint32_t j = pp.nearest[k];
            if (j == core::kBelowFloor) {
                ++below;
                if (!(want[k] * scale < floor.search[d])) {
                    ADD_FAILURE() << "query " << k << " stopped below the floor " << floor.search[d]
                                  << " but its nearest is " << want[k] * scale << " away";
                    ++bad;
                }
                continue;
            }
            if (j >= t.size() || std::abs(glm::length(glm::dvec3(q[k]) - glm::dvec3(t[j])) - want[k]) > tol) {
                ADD_FAILURE() << "query " << k << ": nearest " << j << " is not its nearest";
                ++bad;
            }
        }
    }
    return below;
}

}  // namespace rthdist::test
