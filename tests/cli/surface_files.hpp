// Fixture files of the point-to-surface CLI tests: a triangle mesh as OBJ
// and points as XYZ, every coordinate written to the last bit (%.17g), so
// that the binary reads the doubles the brute force measures.
#pragma once

#include <glm/vec3.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "common/surface_cases.hpp"

namespace rthdist::cli_test {

inline std::string exactNumber(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

inline std::string objOf(const test::SurfaceCase& c) {
    std::string s = "# rthdist test mesh\n";
    for (const glm::dvec3& v : c.vertices)
        s += "v " + exactNumber(v.x) + " " + exactNumber(v.y) + " " + exactNumber(v.z) + "\n";
    for (size_t t = 0; t < c.indices.size(); t += 3) {
        s += "f " + std::to_string(c.indices[t] + 1) + " " + std::to_string(c.indices[t + 1] + 1) + " " +
             std::to_string(c.indices[t + 2] + 1) + "\n";
    }
    return s;
}

inline std::string xyzOf(const std::vector<glm::dvec3>& points) {
    std::string s;
    for (const glm::dvec3& p : points)
        s += exactNumber(p.x) + " " + exactNumber(p.y) + " " + exactNumber(p.z) + "\n";
    return s;
}

}  // namespace rthdist::cli_test
