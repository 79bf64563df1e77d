// `rthdist A B --surface both` end to end (cli/surface_pair_command.hpp):
// OBJ meshes written by the test whose H is known in closed form (a
// triangle and its parallel offset copy; a segment above a triangle), the
// JSON's bounds bracketing it within --tolerance, both witnesses' keys,
// --directed, the summary line; the refusals: --tolerance malformed, out
// of range, below the meshes' rounding floor or without --surface both,
// per-point outputs (exit 2 naming the option); a side without faces (exit
// 3 naming the file). The GPU backends: cli_surface_gpu_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cli_runner.hpp"

namespace rthdist::cli_test {
namespace {

using Json = nlohmann::json;

class CliSurfacePair : public ::testing::Test {
protected:
    void SetUp() override {
        m_a = m_dir.write("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        m_b = m_dir.write("b.obj", "v 0 0 0.25\nv 1 0 0.25\nv 0 1 0.25\nf 1 2 3\n");
        m_segment = m_dir.write("segment.off", "OFF\n2 1 0\n0 0 1\n1 0 1\n3 0 1 1\n");
        m_xyz = m_dir.write("points.xyz", "0 0 0\n1 1 1\n");
    }

    static void expectBrackets(const Json& j, double known, double tolerance) {
        const double lower = j["bounds"][0].get<double>(), upper = j["bounds"][1].get<double>();
        EXPECT_LE(lower, known);
        EXPECT_GE(upper, known);
        EXPECT_LE(upper - lower, tolerance);
    }

    TempDir m_dir;
    std::string m_a, m_b, m_segment, m_xyz;
};

TEST_F(CliSurfacePair, OffsetTriangleBoundsBracketTheOffset) {
    const CliRun run = runCli({m_a, m_b, "--surface", "both", "--tolerance", "1e-6", "--json"});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = Json::parse(run.out);
    EXPECT_EQ(j["mode"], "surface-to-surface");
    EXPECT_EQ(j["surface"], "both");
    EXPECT_EQ(j["backend"], "cpu");
    EXPECT_EQ(j["directed"], false);
    EXPECT_TRUE(j["hausdorff"].is_null());
    EXPECT_EQ(j["tolerance"].get<double>(), 1e-6);
    EXPECT_EQ(j["triangles"]["a"].get<int>(), 1);
    expectBrackets(j, 0.25, 1e-6);
    for (const char* dir : {"a_to_b", "b_to_a"}) {
        expectBrackets(j[dir], 0.25, 1e-6);
        EXPECT_EQ(j[dir]["distance"].get<double>(), 0.25) << dir;
        EXPECT_EQ(j[dir]["triangle"].get<int>(), 0) << dir;
    }
    // The witness: a point of A and its closest point on B, 0.25 above it.
    const Json& w = j["a_to_b"];
    EXPECT_EQ(w["b_point"][2].get<double>(), 0.25);
    EXPECT_EQ(w["a_point"][0].get<double>(), w["b_point"][0].get<double>());
    EXPECT_EQ(w["a_point"][2].get<double>(), 0.0);
    EXPECT_EQ(w["a_triangle"].get<int>(), 0);
}

TEST_F(CliSurfacePair, SegmentAboveTriangleAndDirected) {
    CliRun run = runCli({m_segment, m_a, "--surface", "both", "--json", "--tolerance", "1e-9"});
    ASSERT_EQ(run.exitCode, 0) << run;
    Json j = Json::parse(run.out);
    expectBrackets(j, std::sqrt(2.0), 1e-9);  // B's corner (0, 1, 0) to the segment
    EXPECT_EQ(j["b_to_a"]["b_point"], Json::array({0.0, 1.0, 0.0}));

    run = runCli({m_segment, m_a, "--surface", "both", "--json", "--tolerance", "1e-9", "--directed"});
    ASSERT_EQ(run.exitCode, 0) << run;
    j = Json::parse(run.out);
    EXPECT_EQ(j["directed"], true);
    EXPECT_TRUE(j["b_to_a"].is_null());
    expectBrackets(j, 1.0, 1e-9);  // h(segment, triangle): the segment is 1 above it
}

TEST_F(CliSurfacePair, SummaryNamesTheBounds) {
    const CliRun run = runCli({m_a, m_b, "--surface", "both"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("H(surface A, surface B) in [0.2499999"), std::string::npos) << run;
    EXPECT_NE(run.out.find("h(B, A) in ["), std::string::npos) << run;
}

TEST_F(CliSurfacePair, BadTolerancesAreUsageErrorsNamingTheOption) {
    for (const char* value : {"0", "-1", "abc", "inf", "nan", ""}) {
        const CliRun run = runCli({m_a, m_b, "--surface", "both", "--tolerance", value});
        EXPECT_EQ(run.exitCode, 2) << value << run;
        EXPECT_NE(run.err.find("'--tolerance'"), std::string::npos) << run;
        EXPECT_TRUE(run.out.empty()) << run;
    }
    // Below 4 x 2^-40 of the meshes' extent: known only once they are read.
    CliRun run = runCli({m_a, m_b, "--surface", "both", "--tolerance", "1e-15"});
    EXPECT_EQ(run.exitCode, 2) << run;
    EXPECT_NE(
        run.err.find("option '--tolerance': tolerance 1.0000000000000001e-15 is below the rounding floor"),
        std::string::npos)
        << run;
    run = runCli({m_a, m_b, "--surface", "b", "--tolerance", "1e-3"});
    EXPECT_EQ(run.exitCode, 2) << run;
    EXPECT_NE(run.err.find("'--tolerance'"), std::string::npos) << run;
    EXPECT_NE(run.err.find("--surface both"), std::string::npos) << run;
    run = runCli({m_a, m_b, "--tolerance", "1e-3"});
    EXPECT_EQ(run.exitCode, 2) << run;
}

TEST_F(CliSurfacePair, PerPointIsRefused) {
    const CliRun run = runCli({m_a, m_b, "--surface", "both", "--per-point"});
    EXPECT_EQ(run.exitCode, 2) << run;
    EXPECT_NE(run.err.find("not per-point distances"), std::string::npos) << run;
}

TEST_F(CliSurfacePair, SideWithoutFacesIsBadInputNamingTheFile) {
    CliRun run = runCli({m_a, m_xyz, "--surface", "both"});
    EXPECT_EQ(run.exitCode, 3) << run;
    EXPECT_NE(run.err.find(m_xyz), std::string::npos) << run;
    run = runCli({m_xyz, m_b, "--surface", "both"});
    EXPECT_EQ(run.exitCode, 3) << run;
    EXPECT_NE(run.err.find(m_xyz), std::string::npos) << run;
}

}  // namespace
}  // namespace rthdist::cli_test
