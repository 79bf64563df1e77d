// cpuHausdorff against the brute-force oracle: the shared oracle cases, the
// degenerate inputs of design.md §6 as named tests, directedOnly, and thread-count
// independence.
#include <gtest/gtest.h>

#include <cmath>

#include "common/brute_force.hpp"
#include "common/oracle_cases.hpp"
#include "cpu/cpu_hausdorff.hpp"

namespace rthdist::test {
namespace {

const std::vector<OracleCase>& cases() {
    static const std::vector<OracleCase> all = makeOracleCases();
    return all;
}

HausdorffResult run(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b, Options options = {}) {
    options.backend = Backend::kCpu;
    Result<HausdorffResult> r = cpu::cpuHausdorff(a, b, options);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? r.value() : HausdorffResult{};
}

OracleCase named(std::string name, std::vector<glm::vec3> a, std::vector<glm::vec3> b) {
    return OracleCase{std::move(name), 0, std::move(a), std::move(b)};
}

class CpuOracle : public ::testing::TestWithParam<size_t> {};

TEST_P(CpuOracle, MatchesBruteForce) {
    const OracleCase& c = cases()[GetParam()];
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
    EXPECT_EQ(r.backend, Backend::kCpu);
    EXPECT_EQ(r.device, "cpu");
    EXPECT_EQ(r.aToB.counters.queries, c.a.size());
    EXPECT_EQ(r.bToA.counters.queries, c.b.size());
}

INSTANTIATE_TEST_SUITE_P(Cases, CpuOracle, ::testing::Range<size_t>(0, cases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                             return cases()[info.param].name;
                         });

TEST(CpuOracleList, HasEnoughCases) {
    EXPECT_GE(cases().size(), 300u);
    for (const OracleCase& c : cases()) {
        EXPECT_GE(c.a.size(), 1u) << c.name;
        EXPECT_GE(c.b.size(), 1u) << c.name;
        EXPECT_LE(c.a.size(), 50000u) << c.name;
        EXPECT_LE(c.b.size(), 50000u) << c.name;
    }
}

TEST(CpuHausdorff, EmptySetIsAnError) {
    const std::vector<glm::vec3> one{{0, 0, 0}}, none;
    for (auto [a, b] : {std::pair{&one, &none}, std::pair{&none, &one}}) {
        Result<HausdorffResult> r = cpu::cpuHausdorff(*a, *b, Options{});
        ASSERT_FALSE(r.ok());
        EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    }
}

TEST(CpuHausdorff, OnePointEach) {
    const OracleCase c = named("one_each", {{1, 2, 3}}, {{4, 6, 3}});
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
    EXPECT_DOUBLE_EQ(r.hausdorff, 5.0);
}

TEST(CpuHausdorff, AllIdenticalPoints) {
    const OracleCase c =
        named("identical", std::vector<glm::vec3>(100, {1, 1, 1}), std::vector<glm::vec3>(50, {1, 1, 1}));
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
    EXPECT_EQ(r.hausdorff, 0.0);
}

TEST(CpuHausdorff, EqualSetsGiveZero) {
    const OracleCase& src = cases()[0];
    const HausdorffResult r = run(src.a, src.a);
    EXPECT_EQ(r.hausdorff, 0.0);
    EXPECT_EQ(r.aToB.counters.queries, src.a.size());
}

TEST(CpuHausdorff, StrictSubsetIsZeroOneWay) {
    std::vector<glm::vec3> b;
    for (int i = 0; i < 1000; ++i) b.emplace_back(float(i % 10), float(i / 10 % 10), float(i / 100) * 0.5f);
    std::vector<glm::vec3> a(b.begin() + 100, b.begin() + 300);
    const OracleCase c = named("subset", a, b);
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
    EXPECT_EQ(r.aToB.distance, 0.0);
    EXPECT_GT(r.bToA.distance, 0.0);
}

TEST(CpuHausdorff, Duplicates) {
    std::vector<glm::vec3> a(300, {0, 0, 0});
    a.insert(a.end(), 300, {1, 0, 0});
    const OracleCase c = named("duplicates", a, {{0, 0, 0}, {0, 0, 0}, {0.25f, 0, 0}});
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
    EXPECT_DOUBLE_EQ(r.aToB.distance, 0.75);
}

TEST(CpuHausdorff, Collinear) {
    std::vector<glm::vec3> a, b;
    for (int i = 0; i < 500; ++i) a.emplace_back(0.01f * float(i), 0, 0);
    for (int i = 0; i < 97; ++i) b.emplace_back(0.05f * float(i) + 0.003f, 0, 0);
    const OracleCase c = named("collinear", a, b);
    expectMatchesOracle(c, run(c.a, c.b));
}

TEST(CpuHausdorff, Coplanar) {
    std::vector<glm::vec3> a, b;
    for (int i = 0; i < 40; ++i)
        for (int j = 0; j < 40; ++j) a.emplace_back(float(i) * 0.1f, 2.0f, float(j) * 0.1f);
    for (int i = 0; i < 13; ++i)
        for (int j = 0; j < 11; ++j) b.emplace_back(float(i) * 0.31f, 2.0f, float(j) * 0.37f);
    const OracleCase c = named("coplanar", a, b);
    expectMatchesOracle(c, run(c.a, c.b));
}

// design.md §3: the corner-representative test reports 1.49; the truth is 0.6.
TEST(CpuHausdorff, CounterExample1D) {
    for (int axis = 0; axis < 3; ++axis) {
        glm::vec3 q(0.0f), t1(0.0f), t2(0.0f);
        q[axis] = 0.5f;
        t1[axis] = 1.99f;
        t2[axis] = -0.1f;
        const OracleCase c = named("counterexample_axis" + std::to_string(axis), {q}, {t1, t2});
        for (int bits = 0; bits <= 8; ++bits) {
            Options o;
            o.bits = bits;
            const HausdorffResult r = run(c.a, c.b, o);
            expectMatchesOracle(c, r);
            EXPECT_NEAR(r.aToB.distance, 0.6, 1e-6);
            EXPECT_EQ(r.aToB.targetIndex, 1u);
        }
    }
}

TEST(CpuHausdorff, FarApartByMillionCellWidths) {
    std::vector<glm::vec3> a, b;
    for (int i = 0; i < 1000; ++i) b.emplace_back(float(i % 10), float(i / 10 % 10), float(i / 100));
    for (const glm::vec3& p : b) a.push_back(p + glm::vec3(1e6f * 9.0f, 0.0f, 0.0f));
    const OracleCase c = named("far_1e6_cells", a, b);
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
    EXPECT_NEAR(r.hausdorff, 9e6, 1.0);
}

TEST(CpuHausdorff, LargeOffsetSmallExtent) {
    std::vector<glm::vec3> a, b;
    const glm::vec3 o(1.0e7f, -1.0e7f, 1.0e7f);
    for (int i = 0; i < 500; ++i) a.push_back(o + glm::vec3(float(i % 8), float(i / 8 % 8), float(i / 64)));
    for (int i = 0; i < 100; ++i)
        b.push_back(o + glm::vec3(float(i % 5) * 2.0f, float(i / 5 % 5) * 2.0f, float(i / 25) * 2.0f));
    const OracleCase c = named("offset_1e7", a, b);
    const HausdorffResult r = run(c.a, c.b);
    expectMatchesOracle(c, r);
}

TEST(CpuHausdorff, ExtremeMagnitudesAreScaledExactly) {
    for (float s : {1e30f, 1e-30f}) {
        std::vector<glm::vec3> a, b;
        for (int i = 0; i < 300; ++i) a.emplace_back(float(i % 7) * s, float(i % 11) * s, float(i % 13) * s);
        for (int i = 0; i < 50; ++i)
            b.emplace_back(float(i % 5) * 1.5f * s, float(i % 3) * s, float(i % 9) * s);
        const OracleCase c = named(s > 1 ? "huge" : "tiny", a, b);
        const HausdorffResult r = run(c.a, c.b);
        expectMatchesOracle(c, r);
        EXPECT_GT(r.hausdorff, 0.0);
    }
}

TEST(CpuHausdorff, EveryFixedBitCount) {
    const OracleCase& c = cases()[11];
    for (int bits = 1; bits <= 8; ++bits) {
        Options o;
        o.bits = bits;
        const HausdorffResult r = run(c.a, c.b, o);
        SCOPED_TRACE(bits);
        expectMatchesOracle(c, r);
        EXPECT_EQ(r.aToB.counters.bits, uint32_t(bits));
    }
}

TEST(CpuHausdorff, DirectedOnly) {
    for (size_t i = 0; i < cases().size(); i += 17) {
        const OracleCase& c = cases()[i];
        Options o;
        o.directedOnly = true;
        const HausdorffResult r = run(c.a, c.b, o);
        EXPECT_TRUE(r.directedOnly);
        expectMatchesOracle(c, r, true);
        EXPECT_EQ(r.bToA.counters.queries, 0u) << c.name;
    }
}

TEST(CpuHausdorff, ThreadCountDoesNotChangeTheResult) {
    for (size_t i = 0; i < cases().size(); i += 7) {
        const OracleCase& c = cases()[i];
        SCOPED_TRACE(c.name);
        Options one;
        one.threads = 1;
        const HausdorffResult r1 = run(c.a, c.b, one);
        for (int threads : {0, 2, 5}) {
            Options o;
            o.threads = threads;
            const HausdorffResult r = run(c.a, c.b, o);
            EXPECT_EQ(r.hausdorff, r1.hausdorff);
            EXPECT_EQ(r.aToB.queryIndex, r1.aToB.queryIndex);
            EXPECT_EQ(r.aToB.targetIndex, r1.aToB.targetIndex);
            EXPECT_EQ(r.bToA.queryIndex, r1.bToA.queryIndex);
            EXPECT_EQ(r.bToA.targetIndex, r1.bToA.targetIndex);
        }
    }
}

TEST(CpuHausdorff, CountersAndTimingsAreFilled) {
    const OracleCase& c = cases().back();
    const HausdorffResult r = run(c.a, c.b);
    for (const Directed* d : {&r.aToB, &r.bToA}) {
        EXPECT_GE(d->counters.bits, 1u);
        EXPECT_GE(d->counters.occupiedCells, 1u);
        EXPECT_EQ(d->counters.culledByNeighbourhood + d->counters.survivingQueries, d->counters.queries);
    }
    EXPECT_GT(r.timings.total, 0.0);
    EXPECT_GE(r.timings.total, r.timings.index);
}

}  // namespace
}  // namespace rthdist::test
