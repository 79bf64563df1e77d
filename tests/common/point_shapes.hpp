// Point-set building blocks shared by the test case lists (oracle_cases,
// density_cases): uniform samples of an axis-aligned box and concatenation.
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <vector>

#include "common/rng.hpp"

namespace rthdist::test {

// n points uniform in [lo, hi) per axis (drawn in double, stored as float).
inline std::vector<glm::vec3> uniformBox(Rng& r, size_t n, glm::dvec3 lo, glm::dvec3 hi) {
    std::vector<glm::vec3> p(n);
    for (glm::vec3& v : p) {
        v = glm::vec3(r.uniform(lo.x, hi.x), r.uniform(lo.y, hi.y), r.uniform(lo.z, hi.z));
    }
    return p;
}

// a followed by b.
inline std::vector<glm::vec3> concat(std::vector<glm::vec3> a, const std::vector<glm::vec3>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

}  // namespace rthdist::test
