// `rthdist A B --surface b --backend ray-query|rt-pipeline` end to end on
// lavapipe (design.md §11, "The GPU backends"): a georeferenced OBJ height
// field and points around it, the JSON's directed value and witness against
// the brute force over every triangle (tests/common) with ==, the
// validation layer silent; per-point rows within the JSON's tolerance of
// the brute force. `--surface
// both` on each GPU backend: the bounds bracket a closed form (a triangle
// and its parallel offset copy) within --tolerance and meet the cpu
// backend's; a tolerance below the GPU floor is a usage error naming it.
// Never skipped: without a device the runs fail (CI must have lavapipe).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "common/rng.hpp"
#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "core/point_triangle.hpp"
#include "surface_files.hpp"

namespace rthdist::cli_test {
namespace {

using Json = nlohmann::json;

class CliSurfaceGpu : public ::testing::Test {
protected:
    void SetUp() override {
        const glm::dvec3 utm(512345.25, 5412345.5, 250.0);
        m_case = test::heightField(3440, 10, 20.0);
        for (glm::dvec3& v : m_case.vertices) v += utm;
        test::Rng rng(3440);
        for (int i = 0; i < 300; ++i)
            m_points.push_back(utm +
                               glm::dvec3(rng.uniform(-2, 22), rng.uniform(-2, 22), rng.uniform(-5, 5)));
        m_mesh = m_dir.write("field.obj", objOf(m_case));
        m_xyz = m_dir.write("points.xyz", xyzOf(m_points));
        m_want = oracle::bruteForceSurface(m_points, m_case.vertices, m_case.indices);
        std::printf("seed 3440: %zu triangles, %zu points, h = %.17g\n", m_case.indices.size() / 3,
                    m_points.size(), m_want.distance);
    }

    TempDir m_dir;
    test::SurfaceCase m_case;
    std::vector<glm::dvec3> m_points;
    std::string m_mesh, m_xyz;
    oracle::SurfaceDirectedExact m_want;
};

TEST_F(CliSurfaceGpu, PointsToSurfaceMatchTheBruteForceOnEveryGpuBackend) {
    for (const char* backend : {"ray-query", "rt-pipeline"}) {
        const CliRun run =
            runCli({m_xyz, m_mesh, "--surface", "b", "--backend", backend, "--json", "--validation"});
        ASSERT_EQ(run.exitCode, 0) << run;
        const Json j = Json::parse(run.out);
        EXPECT_EQ(j["backend"], backend);
        EXPECT_EQ(j["mode"], "point-to-surface");
        EXPECT_EQ(j["hausdorff"].get<double>(), m_want.distance) << backend;
        EXPECT_EQ(j["validation_messages"].get<uint64_t>(), 0u) << backend;
        const Json& d = j["a_to_b"];
        EXPECT_EQ(d["distance"].get<double>(), m_want.distance) << backend;
        EXPECT_EQ(d["a_index"].get<uint64_t>(), m_want.queryIndex) << backend;
        EXPECT_EQ(d["triangle"].get<uint32_t>(), m_want.nearest.triangle) << backend;
        const glm::dvec3& p = m_want.nearest.point;
        EXPECT_EQ(d["b_point"], Json::array({p.x, p.y, p.z})) << backend;
        const Json& c = j["counters"]["a_to_b"];
        // The device searched every point: by the radii (a ray each at the
        // first), or, for this small mesh, by the tree's descent alone.
        if (c["radii"].get<uint32_t>() == 0)
            EXPECT_EQ(c["tail_queries"].get<uint64_t>(), m_points.size()) << backend;
        else
            EXPECT_GE(c["rays"].get<uint64_t>(), m_points.size()) << backend;
        EXPECT_GE(c["band"].get<uint64_t>(), 1u) << backend;
    }
}

TEST_F(CliSurfaceGpu, SurfaceToSurfaceOnEveryGpuBackend) {
    const std::string a = m_dir.write("a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const std::string b = m_dir.write("b.obj", "v 0 0 0.25\nv 1 0 0.25\nv 0 1 0.25\nf 1 2 3\n");
    const CliRun cpu =
        runCli({a, b, "--surface", "both", "--backend", "cpu", "--tolerance", "1e-3", "--json"});
    ASSERT_EQ(cpu.exitCode, 0) << cpu;
    const Json c = Json::parse(cpu.out);
    for (const char* backend : {"ray-query", "rt-pipeline"}) {
        const CliRun run = runCli({a, b, "--surface", "both", "--backend", backend, "--tolerance", "1e-3",
                                   "--json", "--validation"});
        ASSERT_EQ(run.exitCode, 0) << run;
        const Json j = Json::parse(run.out);
        EXPECT_EQ(j["backend"], backend);
        EXPECT_EQ(j["mode"], "surface-to-surface");
        EXPECT_EQ(j["validation_messages"].get<uint64_t>(), 0u) << backend;
        const double lower = j["bounds"][0].get<double>(), upper = j["bounds"][1].get<double>();
        EXPECT_LE(lower, 0.25) << backend;
        EXPECT_GE(upper, 0.25) << backend;
        EXPECT_LE(upper - lower, 1e-3) << backend;
        EXPECT_LE(std::max(lower, c["bounds"][0].get<double>()),
                  std::min(upper, c["bounds"][1].get<double>()));
        EXPECT_EQ(j["a_to_b"]["distance"].get<double>(), 0.25) << backend;
        // Below the float search's floor (2^-14 of the box's largest
        // coordinate around its centre, 0.5 here, rounded up to a power of
        // two: 2^-14): refused, named.
        const CliRun low = runCli({a, b, "--surface", "both", "--backend", backend, "--tolerance", "2e-5"});
        EXPECT_EQ(low.exitCode, 2) << low;
        EXPECT_NE(low.err.find("below the " + std::string(backend) + " backend's floor 6.103515625e-05"),
                  std::string::npos)
            << low;
    }
}

// Per-point distances of the georeferenced field on each GPU backend: every
// CSV row's distance within the JSON's tolerance above the brute force's,
// and the rule in double to the row's own triangle (its closest point).
TEST_F(CliSurfaceGpu, PerPointRowsLieWithinTheTolerance) {
    for (const char* backend : {"ray-query", "rt-pipeline"}) {
        const std::string prefix = (m_dir.path() / (std::string("pp-") + backend)).string();
        const CliRun run =
            runCli({m_xyz, m_mesh, "--surface", "b", "--backend", backend, "--json", "--out-csv", prefix});
        ASSERT_EQ(run.exitCode, 0) << run;
        const Json j = Json::parse(run.out);
        EXPECT_EQ(j["hausdorff"].get<double>(), m_want.distance) << backend;
        const double tolerance = j["per_point"]["tolerance"].get<double>();
        // The frame is the field's own box (~24 m), not the UTM magnitude.
        EXPECT_GT(tolerance, 0.0) << backend;
        EXPECT_LE(tolerance, std::ldexp(24.0, -13)) << backend;
        std::stringstream in(readFile(prefix + "_a.csv"));
        std::string line;
        std::getline(in, line);
        size_t rows = 0, wrong = 0;
        for (; std::getline(in, line); ++rows) {
            std::vector<double> cell;
            std::stringstream row(line);
            for (std::string c; std::getline(row, c, ',');) cell.push_back(std::strtod(c.c_str(), nullptr));
            ASSERT_EQ(cell.size(), 12u) << line;
            const double exact = std::sqrt(m_want.perQuery.at(rows).distance2);
            const auto t = size_t(cell[5]);
            ASSERT_LT(t, m_case.indices.size() / 3) << line;
            const core::TriangleClosest rule = core::closestOnTriangle(
                m_points[rows], m_case.vertices[m_case.indices[3 * t]],
                m_case.vertices[m_case.indices[3 * t + 1]], m_case.vertices[m_case.indices[3 * t + 2]]);
            const bool ok = cell[4] >= exact && cell[4] <= exact + tolerance &&
                            cell[4] == std::sqrt(rule.distance2) &&
                            glm::dvec3(cell[6], cell[7], cell[8]) == rule.point;
            if (!ok && ++wrong <= 3) ADD_FAILURE() << backend << " row " << rows << ": " << line;
        }
        EXPECT_EQ(rows, m_points.size()) << backend;
        EXPECT_EQ(wrong, 0u) << backend;
    }
}

}  // namespace
}  // namespace rthdist::cli_test
