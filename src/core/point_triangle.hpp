// The exact point-to-triangle measure every backend shares (design.md §11):
// shaders/shared/rthdist_point_triangle.h holds the rule, once, for C++ and
// GLSL; this is its one compiled C++ definition, in double, built without
// floating-point contraction (no FMA), so that the CPU search and the tests'
// brute force get the same bits for the same inputs.
#pragma once

#include <glm/vec3.hpp>

namespace rthdist::core {

// The closest point of triangle (a, b, c) to p: |p - closest|^2, the point
// and its barycentric coordinates (rthdist_point_triangle.h states the rule;
// zero-area triangles are measured by their edges).
struct TriangleClosest {
    double distance2 = 0.0;
    glm::dvec3 point{0.0};
    glm::dvec3 barycentric{0.0};
};

[[nodiscard]] TriangleClosest closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                                const glm::dvec3& c);

// The slack of a pruning test against this measure (a box lower bound set
// against the best distance so far): its rounding error and that of a
// point-to-box distance, for points and vertices whose coordinates are at
// most `magnitude` in absolute value (the proof: design.md §11). A box
// whose computed distance exceeds best + slack holds no triangle that
// measures below best.
[[nodiscard]] double closestSlack(double magnitude);

}  // namespace rthdist::core
