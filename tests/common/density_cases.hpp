// Density cases (issue 17) shared by every backend's tests: inputs whose
// density is far from even — all points identical (200k per set), a dense
// cluster with one far point (in one set or both, the cluster at either end of
// the box), clusters of very different densities, Cauchy and log-normal
// radii, a real LiDAR scan with injected stray points, all points in one grid
// cell plus one outside — and their exact reference.
//
// The reference is the double brute force over the DISTINCT points of each
// set (copies share their nearest distance; a copy's nearest target is the
// first index of the nearest distinct point), so the 200k-copy cases cost a
// few distinct points, not 200k x 200k. Everything else is at most ~20k x 20k
// (one case 70k x 2k, so that the CPU's parallel refinement path runs).
#pragma once

#include <glm/vec3.hpp>

#include <vector>

#include "common/brute_force.hpp"
#include "common/oracle_cases.hpp"

namespace rthdist::test {

// The list, fixed seeds; names "density_<shape>[_<variant>]". The LiDAR case
// is left out (with a note on stdout) when ../shared/data is missing.
[[nodiscard]] std::vector<OracleCase> makeDensityCases();

// Exact per-point nearest neighbours both ways (brute force, double; ties to
// the smallest target index) and the directed maxima (ties to the smallest
// query index), as oracle::bruteForceDirected would give them.
struct DensityReference {
    std::vector<oracle::NearestExact> aNearest, bNearest;  // per point of A (into B), of B (into A)
    oracle::DirectedExact aToB, bToA;
};
[[nodiscard]] DensityReference densityReference(const OracleCase& c);

// gtest EXPECTs against the reference, with the case name and seed as
// SCOPED_TRACE (the checks of expectMatchesOracle): each directed value and H
// within oracleTolerance; each witness in range, its points the input's, its
// pair realizing the reported distance, its target a nearest neighbour of its
// query. directedOnly: only h(A,B).
void expectMatchesDensity(const OracleCase& c, const DensityReference& ref, const HausdorffResult& r,
                          bool directedOnly = false);

// Per-point arrays (Options::perPointDistances): every query's distance
// recomputed from its own pair and within oracleTolerance of the reference
// (the target may differ from the brute force's among ties, and at distance 0
// it is any copy of the query point). Skips B's array when it is empty.
void expectPerPointMatchesDensity(const OracleCase& c, const DensityReference& ref, const HausdorffResult& r);

}  // namespace rthdist::test
