// cpuHausdorff on the density cases of issue 17 (tests/common/density_cases):
// directed, symmetric and per-point results against the exact reference,
// independence of the thread count (one thread never takes the parallel
// refinement path), the identical-points answers, and a bound on the work
// per query that a degenerate index breaks (a counter, not a time).
#include <gtest/gtest.h>

#include <map>
#include <mutex>

#include "common/density_cases.hpp"
#include "cpu/cpu_hausdorff.hpp"

namespace rthdist::test {
namespace {

const std::vector<OracleCase>& cases() {
    static const std::vector<OracleCase> all = makeDensityCases();
    return all;
}

// One reference per case, shared by the tests of this binary.
const DensityReference& reference(size_t i) {
    static std::mutex mutex;
    static std::map<size_t, DensityReference> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(i);
    if (it == cache.end()) it = cache.emplace(i, densityReference(cases()[i])).first;
    return it->second;
}

const OracleCase& named(const std::string& name) {
    for (const OracleCase& c : cases()) {
        if (c.name == name) return c;
    }
    static const OracleCase none;
    ADD_FAILURE() << "no density case " << name;
    return none;
}

HausdorffResult run(const OracleCase& c, Options options = {}) {
    options.backend = Backend::kCpu;
    Result<HausdorffResult> r = cpu::cpuHausdorff(c.a, c.b, options);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    return r.ok() ? r.value() : HausdorffResult{};
}

class CpuDensity : public ::testing::TestWithParam<size_t> {};

TEST_P(CpuDensity, MatchesReference) {
    const OracleCase& c = cases()[GetParam()];
    expectMatchesDensity(c, reference(GetParam()), run(c));
}

TEST_P(CpuDensity, DirectedOnlyMatchesReference) {
    const OracleCase& c = cases()[GetParam()];
    Options o;
    o.directedOnly = true;
    expectMatchesDensity(c, reference(GetParam()), run(c, o), true);
}

TEST_P(CpuDensity, PerPointMatchesReference) {
    const OracleCase& c = cases()[GetParam()];
    Options o;
    o.perPointDistances = true;
    const HausdorffResult r = run(c, o);
    expectMatchesDensity(c, reference(GetParam()), r);
    expectPerPointMatchesDensity(c, reference(GetParam()), r);
}

// One thread refines every run with std::sort, two threads the long ones
// with the parallel radix path: the same order, so the same answers.
TEST_P(CpuDensity, ThreadCountDoesNotChangeTheResult) {
    const OracleCase& c = cases()[GetParam()];
    Options one, two;
    one.threads = 1;
    two.threads = 2;
    for (bool perPoint : {false, true}) {
        one.perPointDistances = two.perPointDistances = perPoint;
        const HausdorffResult r1 = run(c, one), r2 = run(c, two);
        EXPECT_EQ(r1.hausdorff, r2.hausdorff);
        EXPECT_EQ(r1.aToB.queryIndex, r2.aToB.queryIndex);
        EXPECT_EQ(r1.aToB.targetIndex, r2.aToB.targetIndex);
        EXPECT_EQ(r1.bToA.queryIndex, r2.bToA.queryIndex);
        EXPECT_EQ(r1.bToA.targetIndex, r2.bToA.targetIndex);
        EXPECT_EQ(r1.aNearest.nearest, r2.aNearest.nearest);
        EXPECT_EQ(r1.bNearest.nearest, r2.bNearest.nearest);
    }
}

INSTANTIATE_TEST_SUITE_P(Cases, CpuDensity, ::testing::Range<size_t>(0, cases().size()),
                         [](const ::testing::TestParamInfo<size_t>& info) {
                             return cases()[info.param].name;
                         });

TEST(CpuDensityList, HasTheShapesOfIssue17) {
    for (const char* name :
         {"density_identical_200k", "density_cluster_far_in_a", "density_cluster_far_in_b_cluster_at_max",
          "density_cluster_far_in_both", "density_cluster_far_in_both_cluster_at_max", "density_densities",
          "density_cauchy", "density_lognormal_radii", "density_one_cell_plus_one"}) {
        EXPECT_FALSE(named(name).a.empty()) << name;
    }
    EXPECT_GE(named("density_identical_200k").a.size(), 200000u);
}

// H = 0 with 200k copies per set: the witnesses are copies of each other.
TEST(CpuDensityIdentical, ZeroWithCopiesAsWitnesses) {
    const OracleCase& c = named("density_identical_200k");
    Options o;
    o.perPointDistances = true;
    for (bool perPoint : {false, true}) {
        o.perPointDistances = perPoint;
        const HausdorffResult r = run(c, o);
        EXPECT_EQ(r.hausdorff, 0.0);
        for (const Directed* d : {&r.aToB, &r.bToA}) {
            EXPECT_EQ(d->distance, 0.0);
            EXPECT_EQ(d->queryIndex, 0u);  // smallest query index among the ties
            EXPECT_EQ(d->queryPoint, d->targetPoint);
        }
    }
}

// The work of a per-point pass (every query to its exact nearest neighbour,
// deterministic) on a 20k cluster + far point, counted in scans of 8 targets
// (hint bucket, own cell, BVH buckets): an index whose cost follows the
// bounding box (the cluster in one cell, in input order) needs thousands per
// query; the adaptive order needs a few dozen.
TEST(CpuDensityWork, BoundedScansPerQueryInADenseCluster) {
    for (const char* name : {"density_cluster_far_in_both", "density_cluster_far_in_both_cluster_at_max",
                             "density_one_cell_plus_one", "density_cauchy"}) {
        const OracleCase& c = named(name);
        Options o;
        o.perPointDistances = true;
        o.threads = 1;
        const HausdorffResult r = run(c, o);
        for (const Directed* d : {&r.aToB, &r.bToA}) {
            const double perQuery = double(d->counters.candidatePairs) / double(d->counters.queries);
            std::printf("[ info ] %s: %.1f scans of 8 targets per query\n", name, perQuery);
            EXPECT_LE(perQuery, 64.0) << name;
        }
    }
}

}  // namespace
}  // namespace rthdist::test
