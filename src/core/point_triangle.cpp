#include "core/point_triangle.hpp"

#include <algorithm>
#include <cmath>

#include "rthdist_point_triangle.h"

namespace rthdist::core {
namespace {

// The thin triangles' precision: 113 bits where the compiler has a binary128
// type (GCC and Clang on x86-64), else long double (binary128 on aarch64).
#if defined(__SIZEOF_FLOAT128__)
using Wide = __float128;
#else
using Wide = long double;
#endif

// A 3-vector of Wide with what the rule uses (rthdist_point_triangle.h).
struct WideVec3 {
    using value_type = Wide;
    Wide x = 0, y = 0, z = 0;
    WideVec3() = default;
    WideVec3(Wide x_, Wide y_, Wide z_) : x(x_), y(y_), z(z_) {}
    explicit WideVec3(const glm::dvec3& v) : x(v.x), y(v.y), z(v.z) {}
    [[nodiscard]] glm::dvec3 rounded() const { return {double(x), double(y), double(z)}; }
};
WideVec3 operator+(const WideVec3& a, const WideVec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
WideVec3 operator-(const WideVec3& a, const WideVec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
WideVec3 operator*(const WideVec3& a, Wide s) { return {a.x * s, a.y * s, a.z * s}; }
Wide dot(const WideVec3& a, const WideVec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
WideVec3 cross(const WideVec3& a, const WideVec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

}  // namespace

// The rule in double may be off by ~u L^3 / |n| for a longest edge L and
// n = (b - a) x (c - a): its signed areas share n, whose direction double
// carries to ~u L^2 / |n| radians (measured against exact rationals: a
// point on the face of a unit triangle 1000 times longer than wide measured
// ~3e-14, 1e15 times longer: 0.02). Thin when that may pass 16 u m (m the
// largest |coordinate| of a, b, c), L^6 > 2^8 m^2 |n|^2, in units of m (no
// overflow below m ~ 1e77; past it, or where |n|^2 underflows in those
// units, the triangle counts as thin, which costs time, not precision).
bool thinTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 ab = b - a, ac = c - a, bc = c - b;
    const glm::dvec3 n = glm::cross(ab, ac);
    const glm::dvec3 big = glm::max(glm::max(glm::abs(a), glm::abs(b)), glm::abs(c));
    const double m2 = std::max({big.x * big.x, big.y * big.y, big.z * big.z});
    if (!(m2 > 0.0)) return false;  // every corner at 0: one point
    const double inv = 1.0 / m2;
    const double l2 = std::max({glm::dot(ab, ab), glm::dot(ac, ac), glm::dot(bc, bc)}) * inv;
    const double n2 = glm::dot(n, n) * inv * inv;
    return l2 * l2 * l2 > 0x1p8 * n2;
}

TriangleClosest closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                  const glm::dvec3& c) {
    return closestOnTriangle(p, a, b, c, thinTriangle(a, b, c));
}

TriangleClosest closestOnTriangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b,
                                  const glm::dvec3& c, bool thin) {
    TriangleClosest out;
    if (!thin) {
        out.distance2 = shared::pointTriangleClosest(p, a, b, c, out.point, out.barycentric);
        return out;
    }
    // A thin triangle: the same rule in Wide (the doubles exactly, their
    // differences and the degree-4 areas to ~2^-113), the point rounded to
    // double once and its distance measured from it in double, as the rule
    // does (the distance is realized by the reported point).
    WideVec3 closest, bary;
    (void)shared::pointTriangleClosest(WideVec3(p), WideVec3(a), WideVec3(b), WideVec3(c), closest, bary);
    out.point = closest.rounded();
    out.barycentric = bary.rounded();
    const glm::dvec3 e = p - out.point;
    out.distance2 = glm::dot(e, e);
    return out;
}

// Every computed closest point lies within ~20 u m of a point of the
// triangle (u = 2^-53, m = magnitude: the differences, the weights in
// [0, 1] and the sums each round by u times at most 3 m; a thin triangle's
// point is the Wide rule's, a point of the triangle to ~2^-113 m, rounded
// once), and the distance and the box distance each round by a few u of
// their value (<= 4 m): the total is below 64 u m. 2^-40 m leaves a factor
// above 100 on top.
double closestSlack(double magnitude) { return magnitude * 0x1p-40; }

}  // namespace rthdist::core
