// The shared point-triangle rule (core/point_triangle.hpp,
// shaders/shared/rthdist_point_triangle.h): closed-form answers in every
// region, exact zeros on the surface, degenerate triangles measured by their
// edges, and random triangles against an independent long-double
// minimisation.
#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "common/rng.hpp"
#include "core/point_triangle.hpp"

namespace rthdist {
namespace {

using glm::dvec3;

const dvec3 kA(0, 0, 0), kB(4, 0, 0), kC(0, 4, 0);

TEST(PointTriangle, AboveTheInteriorIsTheHeight) {
    const core::TriangleClosest r = core::closestOnTriangle(dvec3(1, 1, 3), kA, kB, kC);
    EXPECT_EQ(r.distance2, 9.0);
    EXPECT_EQ(r.point, dvec3(1, 1, 0));
    EXPECT_EQ(r.barycentric, dvec3(0.5, 0.25, 0.25));
}

TEST(PointTriangle, OutsideEachVertexIsThatVertex) {
    EXPECT_EQ(core::closestOnTriangle(dvec3(-1, -2, 0), kA, kB, kC).point, kA);
    EXPECT_EQ(core::closestOnTriangle(dvec3(6, -1, 2), kA, kB, kC).point, kB);
    const core::TriangleClosest r = core::closestOnTriangle(dvec3(-1, 7, 0), kA, kB, kC);
    EXPECT_EQ(r.point, kC);
    EXPECT_EQ(r.distance2, 1.0 + 9.0);
    EXPECT_EQ(r.barycentric, dvec3(0, 0, 1));
}

TEST(PointTriangle, OutsideEachEdgeIsItsFoot) {
    core::TriangleClosest r = core::closestOnTriangle(dvec3(1, -2, 0), kA, kB, kC);
    EXPECT_EQ(r.point, dvec3(1, 0, 0));
    EXPECT_EQ(r.distance2, 4.0);
    EXPECT_EQ(r.barycentric, dvec3(0.75, 0.25, 0));
    r = core::closestOnTriangle(dvec3(-3, 2, 1), kA, kB, kC);
    EXPECT_EQ(r.point, dvec3(0, 2, 0));
    EXPECT_EQ(r.distance2, 10.0);
    r = core::closestOnTriangle(dvec3(3, 3, 0), kA, kB, kC);  // beyond the hypotenuse
    EXPECT_EQ(r.point, dvec3(2, 2, 0));
    EXPECT_EQ(r.distance2, 2.0);
}

TEST(PointTriangle, PointsOnTheTriangleMeasureExactlyZero) {
    for (const dvec3& p :
         {kA, kB, kC, dvec3(1, 0, 0), dvec3(0, 3, 0), dvec3(2, 2, 0), dvec3(1, 1, 0), dvec3(0.5, 0.25, 0)}) {
        const core::TriangleClosest r = core::closestOnTriangle(p, kA, kB, kC);
        EXPECT_EQ(r.distance2, 0.0) << p.x << " " << p.y;
        EXPECT_EQ(r.point, p);
    }
}

TEST(PointTriangle, VerticesOfAnyTriangleMeasureExactlyZero) {
    test::Rng rng(3411);
    for (int i = 0; i < 1000; ++i) {
        const dvec3 a(rng.uniform(-1e6, 1e6), rng.uniform(-1, 1), rng.uniform(0, 1e-3));
        const dvec3 b = a + rng.direction() * rng.uniform(1e-9, 10.0);
        const dvec3 c = a + rng.direction() * rng.uniform(1e-9, 10.0);
        for (const dvec3& v : {a, b, c}) {
            const core::TriangleClosest r = core::closestOnTriangle(v, a, b, c);
            ASSERT_EQ(r.distance2, 0.0) << "seed 3411, triangle " << i;
            ASSERT_EQ(r.point, v);
        }
    }
}

TEST(PointTriangle, CollinearTriangleIsItsLongestSegment) {
    const dvec3 a(0, 0, 0), b(2, 0, 0), c(8, 0, 0);  // b between a and c
    core::TriangleClosest r = core::closestOnTriangle(dvec3(5, 3, 4), a, b, c);
    EXPECT_EQ(r.distance2, 25.0);
    EXPECT_EQ(r.point, dvec3(5, 0, 0));
    r = core::closestOnTriangle(dvec3(10, 0, 0), a, b, c);
    EXPECT_EQ(r.point, c);
    EXPECT_EQ(r.distance2, 4.0);
    r = core::closestOnTriangle(dvec3(1, 0, 0), a, b, c);
    EXPECT_EQ(r.distance2, 0.0);
}

TEST(PointTriangle, RepeatedVertexIsASegment) {
    const dvec3 a(1, 1, 1), b(1, 1, 1), c(1, 5, 1);
    const core::TriangleClosest r = core::closestOnTriangle(dvec3(4, 3, 5), a, b, c);
    EXPECT_EQ(r.point, dvec3(1, 3, 1));
    EXPECT_EQ(r.distance2, 25.0);
}

TEST(PointTriangle, ThreeEqualVerticesAreAPoint) {
    const dvec3 a(2, -1, 7);
    const core::TriangleClosest r = core::closestOnTriangle(dvec3(2, 2, 3), a, a, a);
    EXPECT_EQ(r.point, a);
    EXPECT_EQ(r.distance2, 25.0);
    EXPECT_EQ(core::closestOnTriangle(a, a, a, a).distance2, 0.0);
}

// An independent measure in long double: the minimum over the plane's
// projection (when inside, by a 2x2 solve) and over the three edges.
long double referenceDistance(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
    using L = long double;
    auto sub = [](const dvec3& u, const dvec3& v) {
        return std::array<L, 3>{L(u.x) - v.x, L(u.y) - v.y, L(u.z) - v.z};
    };
    auto dot = [](const std::array<L, 3>& u, const std::array<L, 3>& v) {
        return u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    };
    auto segment = [&](const dvec3& s0, const dvec3& s1) {
        const auto d = sub(s1, s0), w = sub(p, s0);
        const L len2 = dot(d, d);
        const L t = len2 > 0 ? std::clamp(dot(w, d) / len2, L(0), L(1)) : L(0);
        const std::array<L, 3> e{w[0] - t * d[0], w[1] - t * d[1], w[2] - t * d[2]};
        return std::sqrt(dot(e, e));
    };
    L best = std::min({segment(a, b), segment(b, c), segment(c, a)});
    const auto ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const L m00 = dot(ab, ab), m01 = dot(ab, ac), m11 = dot(ac, ac), r0 = dot(ab, ap), r1 = dot(ac, ap);
    const L det = m00 * m11 - m01 * m01;
    if (det > 0) {
        const L v = (m11 * r0 - m01 * r1) / det, w = (m00 * r1 - m01 * r0) / det;
        if (v >= 0 && w >= 0 && v + w <= 1) {
            const std::array<L, 3> e{ap[0] - v * ab[0] - w * ac[0], ap[1] - v * ab[1] - w * ac[1],
                                     ap[2] - v * ab[2] - w * ac[2]};
            best = std::min(best, std::sqrt(dot(e, e)));
        }
    }
    return best;
}

TEST(PointTriangle, RandomTrianglesAgreeWithALongDoubleReference) {
    const uint64_t seed = 3412;
    std::printf("seed %llu\n", static_cast<unsigned long long>(seed));
    test::Rng rng(seed);
    for (int i = 0; i < 20000; ++i) {
        const dvec3 a(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const dvec3 b = a + rng.direction() * rng.uniform(0.01, 1.0);
        const dvec3 c = a + rng.direction() * rng.uniform(0.01, 1.0);
        const dvec3 p(rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(-2, 2));
        const core::TriangleClosest r = core::closestOnTriangle(p, a, b, c);
        const long double ref = referenceDistance(p, a, b, c);
        ASSERT_NEAR(std::sqrt(r.distance2), double(ref), 1e-12) << "triangle " << i;
        // The point is the triangle's: its barycentric coordinates are a convex combination giving it.
        const dvec3 w = r.barycentric;
        ASSERT_GE(std::min({w.x, w.y, w.z}), 0.0);
        ASSERT_NEAR(w.x + w.y + w.z, 1.0, 1e-12);
        ASSERT_NEAR(glm::length(r.point - (a * w.x + b * w.y + c * w.z)), 0.0, 1e-12);
        ASSERT_EQ(r.distance2, glm::dot(p - r.point, p - r.point));
    }
}

TEST(PointTriangle, SliverClosestPointStaysOnTheSliver) {
    test::Rng rng(3413);
    for (int i = 0; i < 5000; ++i) {
        const dvec3 a(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const dvec3 b = a + rng.direction() * rng.uniform(0.1, 1.0);
        const dvec3 c =
            a + (b - a) * rng.uniform() + rng.direction() * std::pow(10.0, -4.0 - 12.0 * rng.uniform());
        const dvec3 p = a + rng.direction() * rng.uniform(0.0, 2.0);
        const core::TriangleClosest r = core::closestOnTriangle(p, a, b, c);
        const long double ref = referenceDistance(p, a, b, c);
        // Never below the true distance (it is a point of the triangle, up to rounding), and close to it.
        ASSERT_GE(std::sqrt(r.distance2), double(ref) - 1e-14) << "seed 3413, sliver " << i;
        ASSERT_NEAR(std::sqrt(r.distance2), double(ref), 1e-9) << "seed 3413, sliver " << i;
    }
}

// Points on a thin triangle (its face and its edges, each rounded once to
// double) measure within rounding of 0 whatever its aspect: its width down
// to 1e-15 of its length, where the rule in double alone measured up to
// ~0.1 for unit sizes (the normal's direction lost), and the closest point
// stays within that of the point.
TEST(PointTriangle, PointsOnAThinTriangleMeasureWithinRoundingOfZero) {
    test::Rng rng(3414);
    for (const double width : {1e-3, 1e-6, 1e-9, 1e-12, 1e-15}) {
        double worst = 0.0;
        for (int i = 0; i < 400; ++i) {
            const dvec3 a(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
            const dvec3 b = a + rng.direction() * rng.uniform(0.1, 1.0);
            const dvec3 c = a + (b - a) * rng.uniform() + rng.direction() * width;
            const double s = rng.uniform(), t = rng.uniform() * (1.0 - s);
            const double e = rng.uniform();
            for (const dvec3& p :
                 {a + (b - a) * s + (c - a) * t, a + (b - a) * e, b + (c - b) * e, c + (a - c) * e}) {
                const double m =
                    std::max({glm::length(p), glm::length(a), glm::length(b), glm::length(c), 1e-300});
                const core::TriangleClosest r = core::closestOnTriangle(p, a, b, c);
                worst = std::max(worst, std::sqrt(r.distance2) / m);
                ASSERT_LE(std::sqrt(r.distance2), 32 * 0x1p-53 * m)
                    << "width " << width << ", triangle " << i << ": a point on it measures away from it";
            }
        }
        std::printf("width %g: the largest distance of a point on the triangle %.3g of the magnitude\n",
                    width, worst);
    }
}

TEST(PointTriangle, SlackGrowsWithTheMagnitude) {
    EXPECT_EQ(core::closestSlack(0.0), 0.0);
    EXPECT_GT(core::closestSlack(1e6), core::closestSlack(1.0));
    EXPECT_LT(core::closestSlack(1.0), 1e-11);
}

}  // namespace
}  // namespace rthdist
