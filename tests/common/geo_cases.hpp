// The double-precision oracle (issue 10, design.md §8): georeferenced point sets
// whose coordinates are far larger than their extent (UTM eastings and
// northings, Earth-centred coordinates), with centimetre or millimetre
// detail, compared with a brute force in double over the doubles as given.
// Rounding such coordinates to float32 (0.5 m spacing at 5.4e6) moves H by
// decimetres; "exact" allows 1e-6 of the union's diagonal.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rthdist/rthdist.hpp"

namespace rthdist::test {

struct GeoCase {
    std::string name;
    uint64_t seed = 0;
    std::vector<glm::dvec3> a, b;
};

// Families (fixed seeds, 50..4,000 points per side): utm_cm (a 200 m site at
// x ~ 5.1e5, y ~ 5.4e6, centimetre detail), ecef_mm (a 5 m part at ~4.9e6 m
// from the Earth's centre, millimetre detail), one_offset (only B far from
// the origin), negative (both at negative eastings and northings).
[[nodiscard]] std::vector<GeoCase> makeGeoCases();

struct DirectedDouble {
    double distance = 0.0;
    uint32_t queryIndex = 0, targetIndex = 0;
};
[[nodiscard]] DirectedDouble bruteForceDirectedDouble(std::span<const glm::dvec3> q,
                                                      std::span<const glm::dvec3> t);

// Prints the case's name, seed, sizes, H and origin; EXPECTs: both directed values and H within 1e-6 of the
// union's diagonal of the double brute force; witness points are the input doubles exactly and their double
// distance is the reported one.
void expectMatchesGeoOracle(const GeoCase& c, const HausdorffResult& r);

}  // namespace rthdist::test
