// Oracle test cases shared by every backend's tests: fixed-seed point sets
// covering the shapes of design.md §3 and §6, and the comparison of a
// HausdorffResult against the double brute force (cpu/brute_force.hpp).
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rthdist/rthdist.hpp"

namespace rthdist::test {

struct OracleCase {
    std::string name;  // family_index, usable as a gtest parameter name
    uint64_t seed = 0;
    std::vector<glm::vec3> a, b;
};

// >= 300 cases with fixed seeds, 1..50,000 points per side (most small). The
// brute force over the whole list takes a few seconds on 2 cores. Families:
// uniform, gaussian blobs, sphere shells, planes, overlapping, partially
// overlapping, nested, far apart (>> extent and 1e6 cell widths), translated
// copies, subsets, duplicates, one point, all identical, coplanar, collinear,
// the 1-D counterexample of design.md §3 (embedded and 3-D), large offsets
// (~1e7, small extent), integer lattices with exact ties, clustered and
// heavy-tailed clouds, and a few large clouds.
[[nodiscard]] std::vector<OracleCase> makeOracleCases();

// Allowed |reported - brute force| of a PER-POINT distance (the directed
// values are exact in double: expectMatchesOracle allows nothing), for a
// Hausdorff value h of a and b:
//   1e-6 * (the larger bounding-box diagonal)      design.md §1 "exact"
// + 8 * 2^-24 * h                                  float rounding allowance
// The second term covers backends that compare squared distances in float:
// each float squared distance carries a relative error of a few 2^-24, so a
// backend may pick a neighbour (or a maximizing query) whose double distance
// differs from the true one by that much relative to h. It matters only when
// h >> diagonal (far-apart sets); otherwise the first term dominates.
[[nodiscard]] double oracleTolerance(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double h);

// gtest EXPECTs (with the case name and seed as SCOPED_TRACE):
// - h(A,B) and, unless directedOnly, h(B,A) and H equal bruteForceDirected
//   exactly (issue 32: exact in double), each with a confirmed certificate;
// - each witness pair is in range, its points are the input points, and
//   |a[i] - b[j]| recomputed in double equals the reported distance;
// - the witness target is a nearest neighbour of the witness query (its
//   distance equals the query's brute-force NN distance in double).
void expectMatchesOracle(const OracleCase& c, const HausdorffResult& r, bool directedOnly = false);

}  // namespace rthdist::test
