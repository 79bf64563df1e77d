// The exact point-to-triangle measure every backend shares (design.md §11):
// shaders/shared/rthdist_point_triangle.h holds the rule, once, for C++ and
// GLSL; this is its one compiled C++ definition, in double, built without
// floating-point contraction (no FMA), so that the CPU search and the tests'
// brute force get the same bits for the same inputs.
#pragma once

#include <glm/common.hpp>
#include <glm/geometric.hpp>
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

// Precision: within ~16 u m of the exact closest point and distance (u =
// 2^-53, m the largest |coordinate|) for every triangle: a thin one
// (thinTriangle) is measured by the same rule in 113-bit arithmetic (about
// 100x the time of the double rule), its point rounded to double once.
[[nodiscard]] TriangleClosest closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                                const glm::dvec3& c);
// The same, with thin = thinTriangle(a, b, c) computed by the caller once
// per triangle (the CPU BVH keeps it); the same bits as the overload above.
[[nodiscard]] TriangleClosest closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                                const glm::dvec3& c, bool thin);
// Whether the rule in double may be off by more than ~16 u m on triangle
// (a, b, c): its longest edge L over its width above ~16 m / L, m its
// corners' largest |coordinate| (point_triangle.cpp). A property of the
// triangle alone.
[[nodiscard]] bool thinTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);

// The slack of a pruning test against this measure (a box lower bound set
// against the best distance so far): its rounding error and that of a
// point-to-box distance, for points and vertices whose coordinates are at
// most `magnitude` in absolute value (the proof: design.md §11). A box
// whose computed distance exceeds best + slack holds no triangle that
// measures below best.
[[nodiscard]] double closestSlack(double magnitude);

// The squared distance from p to the box [lo, hi] (0 inside): the pruning
// tests' point-to-box distance, the one closestSlack covers (every search
// and brute force that skips boxes uses this one).
[[nodiscard]] inline double boxDistance2(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

}  // namespace rthdist::core
