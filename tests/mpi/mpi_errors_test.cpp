// Errors under MPI: a bad point, an empty set or an unsupported option found
// on any rank gives every rank the same Error (code and message), and no rank
// hangs (ctest's timeout would catch one).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mpi_test_support.hpp"

namespace rthdist::mpi_test {
namespace {

std::vector<glm::vec3> line(size_t n, float y = 0.0f) {
    std::vector<glm::vec3> v(n);
    for (size_t i = 0; i < n; ++i) v[i] = glm::vec3(float(i), y, 0.0f);
    return v;
}

Options cpu() {
    Options o;
    o.backend = Backend::kCpu;
    return o;
}

// The error as rank 0 sees it must be what this rank sees.
void expectAgreed(const Error& e) {
    std::string root = e.message;
    int code = int(e.code);
    MPI_Bcast(&code, 1, MPI_INT, 0, MPI_COMM_WORLD);
    uint64_t n = root.size();
    MPI_Bcast(&n, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    root.resize(n);
    MPI_Bcast(root.data(), int(n), MPI_CHAR, 0, MPI_COMM_WORLD);
    EXPECT_EQ(int(e.code), code);
    EXPECT_EQ(e.message, root);
}

TEST(MpiErrors, NanOnTheLastRankOnlyFailsEveryRank) {
    std::vector<glm::vec3> a = line(30), b = line(20, 1.0f);
    a[29].y = std::numeric_limits<float>::quiet_NaN();  // in the last rank's slice
    Result<HausdorffResult> r = hausdorffMpi(MPI_COMM_WORLD, sliceView(a), sliceView(b), cpu());
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("point 29"), std::string::npos) << r.error().message;  // global index
    expectAgreed(r.error());
}

TEST(MpiErrors, EmptyGlobalSetIsAnError) {
    const std::vector<glm::vec3> a = line(5), b;
    Result<HausdorffResult> r =
        hausdorffMpi(MPI_COMM_WORLD, sliceView(a), PointView(std::span<const glm::vec3>(b)), cpu());
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("point set B is empty"), std::string::npos) << r.error().message;
}

TEST(MpiErrors, PerPointDistancesAreRefused) {
    const std::vector<glm::vec3> a = line(5), b = line(4, 2.0f);
    Options o = cpu();
    o.perPointDistances = true;
    Result<HausdorffResult> r = hausdorffMpi(MPI_COMM_WORLD, sliceView(a), sliceView(b), o);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
}

TEST(MpiErrors, AgreeOnErrorTakesTheLowestFailingRank) {
    const int last = commSize() - 1;
    std::optional<Error> mine;
    if (commRank() == last)
        mine = Error{ErrorCode::kBadInput, "rank " + std::to_string(last) + " failed", {"why"}};
    std::optional<Error> agreed = agreeOnError(MPI_COMM_WORLD, mine);
    ASSERT_TRUE(agreed.has_value());
    EXPECT_EQ(agreed->code, ErrorCode::kBadInput);
    EXPECT_EQ(agreed->message, "rank " + std::to_string(last) + " failed");
    EXPECT_EQ(agreed->details, std::vector<std::string>{"why"});
    EXPECT_FALSE(agreeOnError(MPI_COMM_WORLD, std::nullopt).has_value());
}

TEST(MpiErrors, AfterAnErrorTheNextCallWorks) {
    const std::vector<glm::vec3> a = line(7), b = line(9, 3.0f);
    Result<HausdorffResult> r = hausdorffMpi(MPI_COMM_WORLD, sliceView(a), sliceView(b), cpu());
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->hausdorff, std::sqrt(9.0 + 4.0));  // b[8] = (8, 3, 0) -> a[6] = (6, 0, 0)
    EXPECT_EQ(r->bToA.queryIndex, 8u);
    EXPECT_EQ(r->bToA.targetIndex, 6u);
}

// Options that differ between ranks (issue 36: an option on one rank only
// hung the job): kInvalidArgument on every rank, naming the option.
TEST(MpiErrors, OptionsThatDifferBetweenRanksFailEveryRank) {
    const std::vector<glm::vec3> a = line(12), b = line(9, 1.0f);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size < 2) return;  // one rank: nothing can differ
    Options o = cpu();
    o.directedOnly = rank == size - 1;
    Result<HausdorffResult> r = hausdorffMpi(MPI_COMM_WORLD, sliceView(a), sliceView(b), o);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("CallOptions::directedOnly"), std::string::npos) << r.error().message;
    expectAgreed(r.error());
    MpiOptions mode;
    mode.mode = rank == 0 ? TargetMode::kSpatial : TargetMode::kReplicated;
    r = hausdorffMpi(MPI_COMM_WORLD, sliceView(a), sliceView(b), cpu(), mode);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().message.find("MpiOptions::mode"), std::string::npos) << r.error().message;
    expectAgreed(r.error());
}

// Coordinates past the float search's limits, on any rank: kBadInput on
// every rank, as one process refuses them (core/input_limits.hpp).
TEST(MpiErrors, InputLimitsFailEveryRank) {
    std::vector<glm::dvec3> a = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, {3.0, 0.0, 0.0}};
    const std::vector<glm::dvec3> b = {{0.5, 0.0, 0.0}, {1.5, 0.0, 0.0}, {2.5, 0.0, 0.0}};
    a[3].x = 1e308;  // the last rank's slice
    Result<HausdorffResult> r = hausdorffMpi(MPI_COMM_WORLD, sliceView(a), sliceView(b), cpu());
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().code, ErrorCode::kBadInput);
    EXPECT_NE(r.error().message.find("point set A: point 3 has x = 1e+308"), std::string::npos)
        << r.error().message;
    expectAgreed(r.error());
}

}  // namespace
}  // namespace rthdist::mpi_test
