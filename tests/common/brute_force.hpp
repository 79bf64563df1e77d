// Brute-force directed Hausdorff distance: the test oracle of rthdist.
//
// Contract: O(|queries| * |targets|) in double over the float32 input; no
// early break, no spatial index, nothing clever, so that it can be trusted.
// Multithreaded over queries (threads = 0: all hardware threads). Both spans
// must be non-empty.
// Ties: the smallest query index among queries achieving the maximum, and the
// smallest target index among a query's equally near targets.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace rthdist::oracle {

struct DirectedExact {
    double distance = 0.0;     // h(queries, targets)
    uint32_t queryIndex = 0;   // the query realizing it
    uint32_t targetIndex = 0;  // its nearest target
};

[[nodiscard]] DirectedExact bruteForceDirected(std::span<const glm::vec3> queries,
                                               std::span<const glm::vec3> targets, int threads = 0);

// Exact nearest-neighbour distance of every query (double), in query order.
[[nodiscard]] std::vector<double> bruteForceNearest(std::span<const glm::vec3> queries,
                                                    std::span<const glm::vec3> targets, int threads = 0);

struct NearestExact {
    double distance = 0.0;     // exact NN distance in double
    uint32_t targetIndex = 0;  // smallest index among equally near targets
};

// Exact nearest neighbour (distance and index) of every query, in query order.
[[nodiscard]] std::vector<NearestExact> bruteForceNearestIndexed(std::span<const glm::vec3> queries,
                                                                 std::span<const glm::vec3> targets,
                                                                 int threads = 0);

// The nearest of double `targets` (non-empty) to p as the exact per-point
// entries order them (cpu/exact_nearest.hpp): core::exactDistance, the
// smallest index among equal distances. One thread.
[[nodiscard]] NearestExact bruteForceNearestInDouble(const glm::dvec3& p,
                                                     std::span<const glm::dvec3> targets);

}  // namespace rthdist::oracle
