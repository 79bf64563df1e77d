// hausdorffMpi against one process: every oracle case (tests/common) and
// every georeferenced double case, sliced over the ranks of MPI_COMM_WORLD,
// in both target modes. Run by ctest under mpirun -np 1, 2 and 3
// (tests/mpi/CMakeLists.txt).
// - CPU backend: the very H, directed distances (bit for bit), witness
//   indices and points that rthdist::hausdorff on the CPU backend gives in
//   one process.
// - ray-query (lavapipe in CI): the exactness contract against the double
//   brute force (expectMatchesOracle: values within the tolerance, the
//   witness realizes its distance and its target is a nearest neighbour) and
//   H within that tolerance of the one-process CPU value. Not bit-identical
//   witnesses: among queries whose squared float distances tie, the GPU
//   backend keeps the one of the largest slot of its own query order
//   (shaders/resolve.comp), which depends on the query set a rank holds.
#include <gtest/gtest.h>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <limits>

#include "common/case_sample.hpp"
#include "common/geo_cases.hpp"
#include "common/oracle_cases.hpp"
#include "mpi_test_support.hpp"

namespace rthdist::mpi_test {
namespace {

using test::GeoCase;
using test::OracleCase;

void expectContract(const OracleCase& c, const HausdorffResult& r, bool directedOnly) {
    test::expectMatchesOracle(c, r, directedOnly);
}
void expectContract(const GeoCase& c, const HausdorffResult& r, bool) { test::expectMatchesGeoOracle(c, r); }

double tolerance(const OracleCase& c, double h) { return test::oracleTolerance(c.a, c.b, h); }
// The geo oracle's bound: 1e-6 of the union's diagonal.
double tolerance(const GeoCase& c, double) {
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const auto* set : {&c.a, &c.b})
        for (const glm::dvec3& p : *set) lo = glm::min(lo, p), hi = glm::max(hi, p);
    return 1e-6 * glm::length(hi - lo);
}

Options oneProcessCpu() {
    Options o;
    o.backend = Backend::kCpu;
    return o;
}

template <class Case>
void runCases(const std::vector<Case>& cases, Backend backend, TargetMode mode, bool directedOnly = false) {
    Result<Engine>* engine = sharedEngine(backend);
    if (!*engine) GTEST_SKIP() << "no " << backendName(backend) << " device: " << engine->error().message;
    MpiOptions mpi;
    mpi.mode = mode;
    CallOptions call;
    call.directedOnly = directedOnly;
    Options reference = oneProcessCpu();
    reference.directedOnly = directedOnly;
    if (commRank() == 0)
        std::printf("%zu cases, %s on %s, %s targets, %d ranks\n", cases.size(), backendName(backend),
                    (*engine)->deviceName().c_str(), targetModeName(mode), commSize());
    for (const Case& c : cases) {
        SCOPED_TRACE("case " + c.name + " seed " + std::to_string(c.seed));
        Result<HausdorffResult> one = hausdorff(c.a, c.b, reference);
        ASSERT_TRUE(one.ok()) << one.error().message;
        Result<HausdorffResult> r =
            hausdorffMpi(MPI_COMM_WORLD, **engine, sliceView(c.a), sliceView(c.b), call, mpi);
        ASSERT_TRUE(r.ok()) << r.error().message;  // errors are agreed: every rank stops here together
        EXPECT_EQ(r->backend, backend);
        if (backend == Backend::kCpu) {
            expectSameAsOneProcess(*r, *one);
        } else {
            expectContract(c, *r, directedOnly);
            EXPECT_NEAR(r->hausdorff, one->hausdorff, tolerance(c, one->hausdorff));
        }
    }
}

class MpiOracle : public testing::TestWithParam<std::tuple<Backend, TargetMode>> {};

TEST_P(MpiOracle, EveryOracleCaseAsOneProcess) {
    const auto [backend, mode] = GetParam();
    runCases(test::sampledCases(test::makeOracleCases()), backend, mode);
}

TEST_P(MpiOracle, GeoCasesAsOneProcess) {
    const auto [backend, mode] = GetParam();
    runCases(test::sampledCases(test::makeGeoCases()), backend, mode);
}

TEST_P(MpiOracle, DirectedOnlyAsOneProcess) {
    const auto [backend, mode] = GetParam();
    std::vector<OracleCase> some;
    const std::vector<OracleCase> all = test::makeOracleCases();
    for (size_t i = 0; i < all.size(); i += 5) some.push_back(all[i]);
    runCases(some, backend, mode, true);
}

std::string paramName(const testing::TestParamInfo<MpiOracle::ParamType>& info) {
    const Backend backend = std::get<0>(info.param);
    return std::string(backend == Backend::kCpu ? "Cpu" : "RayQuery") +
           (std::get<1>(info.param) == TargetMode::kSpatial ? "Spatial" : "Replicated");
}

INSTANTIATE_TEST_SUITE_P(Backends, MpiOracle,
                         testing::Combine(testing::Values(Backend::kCpu, Backend::kRayQuery),
                                          testing::Values(TargetMode::kReplicated, TargetMode::kSpatial)),
                         paramName);

}  // namespace
}  // namespace rthdist::mpi_test
