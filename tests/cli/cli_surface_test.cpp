// `rthdist A B --surface a|b` end to end (cli/surface_command.hpp): an OBJ
// height field and random points written by the test, the JSON's directed
// value and witness (a_to_b.triangle, a_to_b.b_point) against the brute
// force over every triangle (tests/common) with ==; --surface a's mirror
// image; the refusals (--verify: exit 2; a bad face index, a file without
// faces: exit 3 naming the file). Per-point outputs:
// cli_surface_per_point_test.cpp. The GPU backends:
// cli_surface_gpu_test.cpp; --surface both: cli_surface_pair_test.cpp.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "common/rng.hpp"
#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"

namespace rthdist::cli_test {
namespace {

using Json = nlohmann::json;

std::string number(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::string objText(const test::SurfaceCase& c) {
    std::string s = "# height field\n";
    for (const glm::dvec3& v : c.vertices)
        s += "v " + number(v.x) + " " + number(v.y) + " " + number(v.z) + "\n";
    for (size_t t = 0; t < c.indices.size(); t += 3) {
        s += "f " + std::to_string(c.indices[t] + 1) + " " + std::to_string(c.indices[t + 1] + 1) + " " +
             std::to_string(c.indices[t + 2] + 1) + "\n";
    }
    return s;
}

std::string xyzText(const std::vector<glm::dvec3>& points) {
    std::string s;
    for (const glm::dvec3& p : points) s += number(p.x) + " " + number(p.y) + " " + number(p.z) + "\n";
    return s;
}

class CliSurface : public ::testing::Test {
protected:
    void SetUp() override {
        m_case = test::heightField(3420, 10, 5.0);
        test::Rng rng(3420);
        for (int i = 0; i < 200; ++i)
            m_points.emplace_back(rng.uniform(-1, 6), rng.uniform(-1, 6), rng.uniform(-2, 2));
        m_mesh = m_dir.write("field.obj", objText(m_case));
        m_xyz = m_dir.write("points.xyz", xyzText(m_points));
        m_want = oracle::bruteForceSurface(m_points, m_case.vertices, m_case.indices);
        std::printf("seed 3420: %zu triangles, %zu points, h = %.17g\n", m_case.indices.size() / 3,
                    m_points.size(), m_want.distance);
    }

    void expectWitness(const Json& d, const std::string& q, const std::string& s) const {
        EXPECT_EQ(d["distance"].get<double>(), m_want.distance);
        EXPECT_EQ(d[q + "_index"].get<uint64_t>(), m_want.queryIndex);
        EXPECT_EQ(d["triangle"].get<uint32_t>(), m_want.nearest.triangle);
        const glm::dvec3& p = m_want.nearest.point;
        EXPECT_EQ(d[s + "_point"], Json::array({p.x, p.y, p.z}));
        const glm::dvec3& qp = m_points[m_want.queryIndex];
        EXPECT_EQ(d[q + "_point"], Json::array({qp.x, qp.y, qp.z}));
    }

    TempDir m_dir;
    test::SurfaceCase m_case;
    std::vector<glm::dvec3> m_points;
    std::string m_mesh, m_xyz;
    oracle::SurfaceDirectedExact m_want;
};

TEST_F(CliSurface, PointsToSurfaceOfBMatchTheBruteForce) {
    const CliRun run = runCli({m_xyz, m_mesh, "--surface", "b", "--json"});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = Json::parse(run.out);
    EXPECT_EQ(j["mode"], "point-to-surface");
    EXPECT_EQ(j["surface"], "b");
    EXPECT_EQ(j["backend"], "cpu");
    EXPECT_EQ(j["directed"], true);
    EXPECT_EQ(j["hausdorff"].get<double>(), m_want.distance);
    EXPECT_TRUE(j["b_to_a"].is_null());
    EXPECT_EQ(j["triangles"]["b"].get<size_t>(), m_case.indices.size() / 3);
    EXPECT_TRUE(j["triangles"]["a"].is_null());
    expectWitness(j["a_to_b"], "a", "b");
}

TEST_F(CliSurface, SurfaceOfAIsTheMirrorImage) {
    const CliRun run = runCli({m_mesh, m_xyz, "--surface", "a", "--json", "--threads", "1"});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = Json::parse(run.out);
    EXPECT_TRUE(j["a_to_b"].is_null());
    EXPECT_EQ(j["points"]["b"].get<size_t>(), m_points.size());
    expectWitness(j["b_to_a"], "b", "a");
}

TEST_F(CliSurface, SummaryNamesTheDirectedValue) {
    const CliRun run = runCli({m_xyz, m_mesh, "--surface", "b"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("h(A, surface B) = "), std::string::npos) << run;
    EXPECT_NE(run.out.find("triangle " + std::to_string(m_want.nearest.triangle)), std::string::npos) << run;
}

TEST_F(CliSurface, UnsupportedCombinationsAreUsageErrors) {
    EXPECT_EQ(runCli({m_xyz, m_mesh, "--surface", "c"}).exitCode, 2);
    EXPECT_EQ(runCli({m_xyz, m_mesh, "--surface", "b", "--verify"}).exitCode, 2);
}

TEST_F(CliSurface, BadFaceIndexNamesTheFileAndFace) {
    const std::string bad = m_dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n");
    const CliRun run = runCli({m_xyz, bad, "--surface", "b"});
    EXPECT_EQ(run.exitCode, 3) << run;
    EXPECT_NE(run.err.find(bad + ": line 4: face 0: vertex index 4 out of range (3 vertices)"),
              std::string::npos)
        << run;
}

TEST_F(CliSurface, SurfaceSideWithoutFacesIsBadInput) {
    const CliRun run = runCli({m_mesh, m_xyz, "--surface", "b"});
    EXPECT_EQ(run.exitCode, 3) << run;
    EXPECT_NE(run.err.find(m_xyz + ": file: '.xyz' files have no faces"), std::string::npos) << run;
}

}  // namespace
}  // namespace rthdist::cli_test
