// The proof of a point-to-surface answer from candidate triangles
// (api/surface_certify.hpp, design.md §11 "The GPU backends"), on the host:
// whatever the candidates (each query's true nearest, none, the wrong
// triangle, a random one), the value and witness equal (==) the brute
// force over every triangle; good candidates keep the band small. Queries
// the search left open are measured exactly first: their candidates then
// do not matter, not even to the band.
#include <gtest/gtest.h>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "api/surface_certify.hpp"
#include "common/rng.hpp"
#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"

namespace rthdist {
namespace {

double magnitude(const test::SurfaceCase& c) {
    double m = 0.0;
    for (const auto* set : {&c.vertices, &c.queries}) {
        for (const glm::dvec3& v : *set) m = std::max({m, std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    }
    return m;
}

Result<SurfaceResult> certify(const test::SurfaceCase& c, const std::vector<uint32_t>& candidate,
                              const std::vector<uint32_t>& open = {}) {
    return api::certifySurface(PointView(c.queries), MeshView{PointView(c.vertices), c.indices}, magnitude(c),
                               candidate, SurfaceOptions{}, open);
}

// The queries at h: the band of exact candidates.
size_t queriesAtMax(const oracle::SurfaceDirectedExact& want) {
    size_t atMax = 0;
    for (const oracle::SurfaceNearest& n : want.perQuery) atMax += std::sqrt(n.distance2) == want.distance;
    return atMax;
}

void expectExact(const test::SurfaceCase& c, const Result<SurfaceResult>& r,
                 const oracle::SurfaceDirectedExact& want, const char* candidates) {
    ASSERT_TRUE(r) << c.name << " (" << candidates << "): " << r.error().message;
    EXPECT_EQ(r->hausdorff, want.distance) << c.name << " (" << candidates << ")";
    EXPECT_EQ(r->directed.queryIndex, want.queryIndex) << c.name << " (" << candidates << ")";
    EXPECT_EQ(r->directed.triangle, want.nearest.triangle) << c.name << " (" << candidates << ")";
    EXPECT_EQ(r->directed.surfacePoint, want.nearest.point) << c.name << " (" << candidates << ")";
    EXPECT_EQ(r->directed.queryPoint, c.queries[want.queryIndex]) << c.name << " (" << candidates << ")";
    EXPECT_EQ(r->directed.counters.queries, c.queries.size());
}

TEST(SurfaceCertify, AnyCandidatesGiveTheBruteForce) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        std::printf("%s: seed %llu, %zu triangles, %zu queries\n", c.name.c_str(),
                    static_cast<unsigned long long>(c.seed), c.indices.size() / 3, c.queries.size());
        const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
        const auto triangles = uint32_t(c.indices.size() / 3);
        std::vector<uint32_t> nearest(c.queries.size()), none(c.queries.size(), UINT32_MAX);
        std::vector<uint32_t> shiftedByOne(c.queries.size()), random(c.queries.size());
        test::Rng rng(c.seed);
        for (size_t q = 0; q < c.queries.size(); ++q) {
            nearest[q] = want.perQuery[q].triangle;
            shiftedByOne[q] = (nearest[q] + 1) % triangles;
            random[q] = uint32_t(rng.uniform(0.0, double(triangles))) % triangles;
        }
        const Result<SurfaceResult> exact = certify(c, nearest);
        expectExact(c, exact, want, "nearest");
        // The band is the queries at h: the witness and its ties.
        if (exact) EXPECT_EQ(exact->directed.counters.band, queriesAtMax(want)) << c.name;
        expectExact(c, certify(c, none), want, "none");
        expectExact(c, certify(c, shiftedByOne), want, "the next triangle");
        expectExact(c, certify(c, random), want, "random");
        // An index past the last triangle is none.
        std::vector<uint32_t> past(c.queries.size(), triangles);
        expectExact(c, certify(c, past), want, "past the last");
    }
}

// The device's distances (api/surface_certify.hpp, searched2): where they
// are the candidates' distances in the search frame, the proof measures
// only the queries they do not rule out, and the answer is the brute
// force's; distances that disagree with the candidates on the proof's
// sample (here: all zero, or all scaled by 4) are not used, and the answer
// is the brute force's all the same.
TEST(SurfaceCertify, TheDevicesDistancesGiveTheSameAnswer) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
        // The search frame of api/surface_gpu.cpp: a power of two bringing
        // every coordinate about the union box's centre to at most 1.
        glm::dvec3 lo(INFINITY), hi(-INFINITY);
        for (const auto* set : {&c.vertices, &c.queries})
            for (const glm::dvec3& v : *set) {
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
        const glm::dvec3 half = (hi - lo) * 0.5;
        int exponent = 0;
        std::frexp(std::max({half.x, half.y, half.z, 0x1p-1000}), &exponent);
        const double scale = std::ldexp(1.0, -exponent);
        const auto triangles = uint32_t(c.indices.size() / 3);
        std::vector<uint32_t> candidate(c.queries.size());
        std::vector<float> searched(c.queries.size()), zero(c.queries.size(), 0.0f), far(c.queries.size());
        test::Rng rng(c.seed + 1);
        for (size_t q = 0; q < c.queries.size(); ++q) {
            // The nearest triangle for most, another for every fifth query.
            candidate[q] = q % 5 == 0 ? uint32_t(rng.uniform(0.0, double(triangles))) % triangles
                                      : want.perQuery[q].triangle;
            const std::vector<glm::dvec3> query{c.queries[q]};
            const size_t t = 3 * size_t(candidate[q]);
            const std::vector<uint32_t> one{c.indices[t], c.indices[t + 1], c.indices[t + 2]};
            const double u2 = oracle::bruteForceSurface(query, c.vertices, one).perQuery[0].distance2;
            searched[q] = float(u2 * scale * scale);
            far[q] = 16.0f * searched[q] + 1.0f;
        }
        const MeshView mesh{PointView(c.vertices), c.indices};
        for (const auto& [name, distances] :
             {std::pair<const char*, const std::vector<float>*>{"device", &searched},
              {"zero", &zero},
              {"too far", &far}}) {
            const Result<SurfaceResult> r = api::certifySurface(
                PointView(c.queries), mesh, magnitude(c), candidate, SurfaceOptions{}, {}, *distances, scale);
            expectExact(c, r, want, name);
        }
        // The device's distances summarized by chunks (core::SearchedTops,
        // as the search's read-back writes them): the same answer and band
        // whatever the chunk size.
        const Result<SurfaceResult> whole = api::certifySurface(
            PointView(c.queries), mesh, magnitude(c), candidate, SurfaceOptions{}, {}, searched, scale);
        ASSERT_TRUE(whole) << c.name;
        for (const size_t chunk : {size_t(1), size_t(5), size_t(1) << 20}) {
            core::SearchedTops tops;
            tops.chunk = chunk;
            for (size_t begin = 0; begin < searched.size(); begin += chunk)
                tops.top.push_back(
                    core::SearchedTops::topOf(searched, begin, std::min(searched.size(), begin + chunk)));
            const Result<SurfaceResult> r =
                api::certifySurface(PointView(c.queries), mesh, magnitude(c), candidate, SurfaceOptions{}, {},
                                    searched, scale, nullptr, nullptr, &tops);
            expectExact(c, r, want, "device, summarized");
            if (r)
                EXPECT_EQ(r->directed.counters.band, whole->directed.counters.band)
                    << c.name << " chunk " << chunk;
        }
    }
}

// A small band is measured against every triangle, a large one (no
// candidates: every query is in it) by the CPU backend's BVH search.
TEST(SurfaceCertify, ALargeBandTakesTheBvhSearch) {
    test::SurfaceCase c = test::heightField(3437, 64, 32.0);
    test::Rng rng(3437);
    for (int i = 0; i < 2100; ++i)
        c.queries.emplace_back(rng.uniform(-1, 33), rng.uniform(-1, 33), rng.uniform(-4, 4));
    std::printf("%s: seed %llu, %zu triangles, %zu queries\n", c.name.c_str(),
                static_cast<unsigned long long>(c.seed), c.indices.size() / 3, c.queries.size());
    const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
    std::vector<uint32_t> nearest(c.queries.size()), none(c.queries.size(), UINT32_MAX);
    for (size_t q = 0; q < c.queries.size(); ++q) nearest[q] = want.perQuery[q].triangle;
    const Result<SurfaceResult> small = certify(c, nearest);
    expectExact(c, small, want, "nearest");
    ASSERT_TRUE(small);
    EXPECT_EQ(small->directed.counters.bvhNodes, 0u);
    const Result<SurfaceResult> large = certify(c, none);
    expectExact(c, large, want, "none");
    ASSERT_TRUE(large);
    EXPECT_EQ(large->directed.counters.band, c.queries.size());
    EXPECT_GT(large->directed.counters.bvhNodes, 0u);
}

// Open queries (the search's `open`: every third query and the witness,
// with no candidate, the next triangle or a random one) are measured
// exactly before the bounds: the brute force's answer, the band of exact
// candidates (the queries at h), and each open query's triangles counted.
// Without them open, the queries with no candidate join the band.
TEST(SurfaceCertify, OpenQueriesAreMeasuredExactlyFirst) {
    for (const test::SurfaceCase& c : test::makeSurfaceCases()) {
        if (c.queries.empty()) continue;
        std::printf("%s: seed %llu, %zu triangles, %zu queries\n", c.name.c_str(),
                    static_cast<unsigned long long>(c.seed), c.indices.size() / 3, c.queries.size());
        const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
        const auto triangles = uint32_t(c.indices.size() / 3);
        std::vector<uint32_t> candidate(c.queries.size()), open;
        test::Rng rng(c.seed);
        size_t none = 0;
        for (size_t q = 0; q < c.queries.size(); ++q) {
            candidate[q] = want.perQuery[q].triangle;
            if (q % 3 != 0 && q != want.queryIndex) continue;
            open.push_back(uint32_t(q));
            switch (open.size() % 3) {
                case 0:
                    candidate[q] = UINT32_MAX;
                    ++none;
                    break;
                case 1: candidate[q] = (candidate[q] + 1) % triangles; break;
                default: candidate[q] = uint32_t(rng.uniform(0.0, double(triangles))) % triangles;
            }
        }
        const Result<SurfaceResult> measured = certify(c, candidate, open);
        expectExact(c, measured, want, "open");
        ASSERT_TRUE(measured);
        EXPECT_EQ(measured->directed.counters.band, queriesAtMax(want)) << c.name;
        EXPECT_GE(measured->directed.counters.trianglesTested, open.size()) << c.name;
        const Result<SurfaceResult> bounded = certify(c, candidate);
        expectExact(c, bounded, want, "not open");
        ASSERT_TRUE(bounded);
        EXPECT_GE(bounded->directed.counters.band, none) << c.name;
    }
}

// Every query open with no candidate: each is measured exactly first, so
// the band is the queries at h and needs no BVH (ALargeBandTakesTheBvhSearch
// below: the same queries not open).
TEST(SurfaceCertify, EveryQueryOpenNeedsNoBvh) {
    test::SurfaceCase c = test::heightField(3438, 32, 16.0);
    test::Rng rng(3438);
    for (int i = 0; i < 600; ++i)
        c.queries.emplace_back(rng.uniform(-1, 17), rng.uniform(-1, 17), rng.uniform(-4, 4));
    const oracle::SurfaceDirectedExact want = oracle::bruteForceSurface(c.queries, c.vertices, c.indices);
    const std::vector<uint32_t> none(c.queries.size(), UINT32_MAX);
    std::vector<uint32_t> all(c.queries.size());
    for (size_t q = 0; q < all.size(); ++q) all[q] = uint32_t(q);
    const Result<SurfaceResult> r = certify(c, none, all);
    expectExact(c, r, want, "every query open");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->directed.counters.band, queriesAtMax(want));
    EXPECT_EQ(r->directed.counters.bvhNodes, 0u);
}

// An open list out of range or out of order is the caller's bug: kInternal.
TEST(SurfaceCertify, OpenQueriesOutOfRangeOrOrderAreErrors) {
    test::SurfaceCase c = test::heightField(3439, 4, 1.0);
    c.queries = {{0.5, 0.5, 1.0}, {0.25, 0.5, -1.0}, {0.75, 0.25, 0.5}};
    const std::vector<uint32_t> none(c.queries.size(), UINT32_MAX);
    for (const std::vector<uint32_t>& open :
         {std::vector<uint32_t>{3}, std::vector<uint32_t>{1, 0}, std::vector<uint32_t>{1, 1}}) {
        const Result<SurfaceResult> r = certify(c, none, open);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, ErrorCode::kInternal);
        EXPECT_NE(r.error().message.find("open query"), std::string::npos) << r.error().message;
    }
}

TEST(SurfaceCertify, PerPointAndWrongSizesAreErrors) {
    const test::SurfaceCase c = test::heightField(3436, 4, 1.0);
    const std::vector<glm::dvec3> points{{0.5, 0.5, 1.0}, {0.25, 0.5, -1.0}};
    const MeshView mesh{PointView(c.vertices), c.indices};
    SurfaceOptions perPoint;
    perPoint.perPointDistances = true;
    const std::vector<uint32_t> two{0, 1}, one{0};
    Result<SurfaceResult> r = api::certifySurface(PointView(points), mesh, 2.0, two, perPoint);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    r = api::certifySurface(PointView(points), mesh, 2.0, one, SurfaceOptions{});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInternal);
}

}  // namespace
}  // namespace rthdist
