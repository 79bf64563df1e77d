#include "common/geo_cases.hpp"

#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstdio>

#include "common/rng.hpp"

namespace rthdist::test {

namespace {

using Points = std::vector<glm::dvec3>;

double roundTo(double v, double step) { return std::round(v / step) * step; }

// A rolling terrain of `extent` metres sampled at n random places,
// coordinates rounded to `detail`, shifted by `origin`.
Points terrain(Rng& r, size_t n, glm::dvec3 origin, double extent, double detail, double phase) {
    Points p(n);
    for (glm::dvec3& v : p) {
        const double x = r.uniform(0.0, extent), y = r.uniform(0.0, extent);
        const double z = 0.05 * extent * std::sin(x / extent * 6.0 + phase) * std::cos(y / extent * 4.0);
        v = {roundTo(origin.x + x, detail), roundTo(origin.y + y, detail), roundTo(origin.z + z, detail)};
    }
    return p;
}

// A part: a box shell of `extent` metres, millimetre detail.
Points part(Rng& r, size_t n, glm::dvec3 origin, double extent, double detail) {
    Points p(n);
    for (glm::dvec3& v : p) {
        glm::dvec3 u(r.uniform(), r.uniform(), r.uniform());
        u[int(r.index(3))] = double(r.index(2));  // on a face
        v = glm::dvec3(roundTo(origin.x + u.x * extent, detail), roundTo(origin.y + u.y * extent, detail),
                       roundTo(origin.z + u.z * extent, detail));
    }
    return p;
}

size_t sizeAt(size_t i) {
    const size_t sizes[] = {50, 300, 1000, 2500, 4000, 700};
    return sizes[i % 6];
}

double diagonal(std::span<const glm::dvec3> a, std::span<const glm::dvec3> b) {
    glm::dvec3 lo = a[0], hi = a[0];
    for (auto set : {a, b})
        for (const glm::dvec3& p : set) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    return glm::length(hi - lo);
}

}  // namespace

std::vector<GeoCase> makeGeoCases() {
    std::vector<GeoCase> cases;
    auto add = [&](const std::string& family, size_t count, auto make) {
        for (size_t i = 0; i < count; ++i) {
            GeoCase c;
            c.name = family + "_" + std::to_string(i);
            c.seed = 0x6e0ull * 1000003 + cases.size() * 7919 + i;
            Rng r(c.seed);
            make(r, i, c.a, c.b);
            cases.push_back(std::move(c));
        }
    };
    add("utm_cm", 6, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::dvec3 o(5.1e5 + 1000.0 * double(i), 5.4e6 + 333.0 * double(i), 100.0);
        a = terrain(r, sizeAt(i), o, 200.0, 0.01, 0.0);
        b = terrain(r, sizeAt(i + 2), o + glm::dvec3(0.37, -0.21, 0.05), 200.0, 0.01, 0.3);
    });
    add("ecef_mm", 6, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::dvec3 o(3.9e6 + 7.0 * double(i), 0.9e6, 4.9e6);
        a = part(r, sizeAt(i), o, 5.0, 0.001);
        b = part(r, sizeAt(i + 3), o + glm::dvec3(0.0123, 0.0, -0.0071), 5.0, 0.001);
    });
    add("one_offset", 4, [](Rng& r, size_t i, Points& a, Points& b) {
        a = terrain(r, sizeAt(i), glm::dvec3(0.0), 50.0, 0.001, 0.0);
        b = terrain(r, sizeAt(i + 1), glm::dvec3(2.5e6, -1.5e6, 10.0), 50.0, 0.001, 1.0);
        if (i % 2) std::swap(a, b);
    });
    add("negative", 4, [](Rng& r, size_t i, Points& a, Points& b) {
        const glm::dvec3 o(-5.1e5, -5.4e6 - 10.0 * double(i), -50.0);
        a = terrain(r, sizeAt(i + 4), o, 200.0, 0.01, 0.0);
        b = terrain(r, sizeAt(i + 5), o + glm::dvec3(-0.4, 0.2, 0.0), 200.0, 0.01, 0.2);
    });
    return cases;
}

DirectedDouble bruteForceDirectedDouble(std::span<const glm::dvec3> q, std::span<const glm::dvec3> t) {
    DirectedDouble out{-1.0, 0, 0};
    for (size_t i = 0; i < q.size(); ++i) {
        double best = INFINITY;
        uint32_t bestT = 0;
        for (size_t j = 0; j < t.size(); ++j) {
            const glm::dvec3 d = q[i] - t[j];
            const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            if (d2 < best) {
                best = d2;
                bestT = uint32_t(j);
            }
        }
        if (std::sqrt(best) > out.distance) out = {std::sqrt(best), uint32_t(i), bestT};
    }
    return out;
}

void expectMatchesGeoOracle(const GeoCase& c, const HausdorffResult& r) {
    std::printf("  %-14s seed %-20llu %5zu x %-5zu H %.17g origin (%.17g, %.17g, %.17g)\n", c.name.c_str(),
                static_cast<unsigned long long>(c.seed), c.a.size(), c.b.size(), r.hausdorff, r.origin.x,
                r.origin.y, r.origin.z);
    SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed) + " |A|=" + std::to_string(c.a.size()) +
                 " |B|=" + std::to_string(c.b.size()));
    const double tolerance = 1e-6 * diagonal(c.a, c.b);
    const DirectedDouble ab = bruteForceDirectedDouble(c.a, c.b), ba = bruteForceDirectedDouble(c.b, c.a);
    EXPECT_NEAR(r.aToB.distance, ab.distance, tolerance) << "h(A,B)";
    EXPECT_NEAR(r.bToA.distance, ba.distance, tolerance) << "h(B,A)";
    EXPECT_NEAR(r.hausdorff, std::max(ab.distance, ba.distance), tolerance) << "H";
    for (auto [d, q, t] : {std::tuple{&r.aToB, &c.a, &c.b}, std::tuple{&r.bToA, &c.b, &c.a}}) {
        ASSERT_LT(d->queryIndex, q->size());
        ASSERT_LT(d->targetIndex, t->size());
        EXPECT_EQ(d->queryPoint, (*q)[d->queryIndex]) << "witness points are the input doubles";
        EXPECT_EQ(d->targetPoint, (*t)[d->targetIndex]);
        EXPECT_EQ(d->distance, glm::length(d->queryPoint - d->targetPoint));
    }
}

}  // namespace rthdist::test
