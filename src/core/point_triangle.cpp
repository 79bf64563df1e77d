#include "core/point_triangle.hpp"

#include "rthdist_point_triangle.h"

namespace rthdist::core {

TriangleClosest closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                  const glm::dvec3& c) {
    TriangleClosest out;
    out.distance2 = shared::pointTriangleClosest(p, a, b, c, out.point, out.barycentric);
    return out;
}

// Every computed closest point lies within ~20 u m of a point of the
// triangle (u = 2^-53, m = magnitude: the differences, the weights in
// [0, 1] and the sums each round by u times at most 3 m), and the distance
// and the box distance each round by a few u of their value (<= 4 m): the
// total is below 64 u m. 2^-40 m leaves a factor above 100 on top.
double closestSlack(double magnitude) { return magnitude * 0x1p-40; }

}  // namespace rthdist::core
