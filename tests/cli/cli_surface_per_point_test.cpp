// The per-point outputs of `rthdist A B --surface a|b`
// (cli/surface_per_point.hpp) end to end on the cpu backend: an OBJ height
// field and random points written by the test to the last bit, every
// point's distance, triangle, closest point and barycentric coordinates in
// the CSV against the brute force over every triangle (tests/common) with
// ==; the JSON statistics (count, min, max, mean, nearest-rank percentiles,
// HD95, histogram) against the same distances; the PLY's quality; the
// points' side alone (--surface a mirrors --surface b); the pictures; the
// refusals (--surface both, --eval: exit 2) and an unwritable file (exit
// 5); a GPU backend's statistics within its tolerance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "common/rng.hpp"
#include "common/surface_brute_force.hpp"
#include "common/surface_cases.hpp"
#include "surface_files.hpp"

namespace rthdist::cli_test {
namespace {

using Json = nlohmann::json;

class CliSurfacePerPoint : public ::testing::Test {
protected:
    void SetUp() override {
        m_case = test::heightField(3436, 9, 4.0);
        test::Rng rng(3436);
        for (int i = 0; i < 240; ++i)
            m_points.emplace_back(rng.uniform(-1, 5), rng.uniform(-1, 5), rng.uniform(-1.5, 2.5));
        m_points.push_back(m_case.vertices[7]);  // on the surface: distance 0
        m_mesh = m_dir.write("field.obj", objOf(m_case));
        m_xyz = m_dir.write("points.xyz", xyzOf(m_points));
        m_want = oracle::bruteForceSurface(m_points, m_case.vertices, m_case.indices);
        for (const oracle::SurfaceNearest& n : m_want.perQuery) m_distances.push_back(std::sqrt(n.distance2));
        std::printf("seed 3436: %zu triangles, %zu points, h = %.17g\n", m_case.indices.size() / 3,
                    m_points.size(), m_want.distance);
    }
    [[nodiscard]] std::string path(const std::string& name) const { return (m_dir.path() / name).string(); }

    // Nearest rank (rthdist/stats.hpp): the ceil(p n / 100)-th smallest.
    [[nodiscard]] double percentile(double p) const {
        std::vector<double> sorted = m_distances;
        std::sort(sorted.begin(), sorted.end());
        const auto n = double(sorted.size());
        const auto rank = size_t(std::clamp(std::ceil(p * n / 100.0), 1.0, n));
        return sorted[rank - 1];
    }

    TempDir m_dir;
    test::SurfaceCase m_case;
    std::vector<glm::dvec3> m_points;
    std::vector<double> m_distances;
    std::string m_mesh, m_xyz;
    oracle::SurfaceDirectedExact m_want;
};

double percentileOf(const Json& list, double p) {
    for (const Json& e : list) {
        if (e["p"].get<double>() == p) return e["value"].get<double>();
    }
    ADD_FAILURE() << "percentile " << p << " missing";
    return -1;
}

TEST_F(CliSurfacePerPoint, JsonStatisticsAreThoseOfTheBruteForceDistances) {
    const CliRun run = runCli({m_xyz, m_mesh, "--surface", "b", "--json", "--percentile", "50",
                               "--percentile", "100", "--percentile", "37.5", "--histogram-bins", "7"});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = Json::parse(run.out);
    EXPECT_EQ(j["hausdorff"].get<double>(), m_want.distance);
    const Json& pp = j["per_point"];
    ASSERT_TRUE(pp.is_object()) << run;
    EXPECT_TRUE(pp["b_to_a"].is_null());
    EXPECT_TRUE(pp["pooled"].is_null());
    const Json& s = pp["a_to_b"];
    EXPECT_EQ(s["count"].get<size_t>(), m_points.size());
    EXPECT_EQ(s["min"].get<double>(), 0.0);
    EXPECT_EQ(s["max"].get<double>(), m_want.distance);
    double sum = 0.0, squares = 0.0;
    for (double d : m_distances) {
        sum += d;
        squares += d * d;
    }
    EXPECT_DOUBLE_EQ(s["mean"].get<double>(), sum / double(m_distances.size()));
    EXPECT_DOUBLE_EQ(s["rms"].get<double>(), std::sqrt(squares / double(m_distances.size())));
    for (double p : {50.0, 100.0, 37.5, 95.0})
        EXPECT_EQ(percentileOf(s["percentiles"], p), percentile(p)) << "P" << p;
    EXPECT_EQ(percentile(100.0), m_want.distance);
    EXPECT_EQ(pp["hd95"]["max"].get<double>(), percentile(95.0));
    const Json& h = pp["histogram"];
    EXPECT_EQ(h["bins"].get<int>(), 7);
    EXPECT_EQ(h["lo"].get<double>(), 0.0);
    EXPECT_EQ(h["hi"].get<double>(), m_want.distance);
    std::vector<uint64_t> want(7, 0);
    for (double d : m_distances) ++want[std::min(size_t(d / m_want.distance * 7.0), size_t(6))];
    EXPECT_EQ(h["a_to_b"].get<std::vector<uint64_t>>(), want);
    EXPECT_TRUE(h["b_to_a"].is_null());
}

TEST_F(CliSurfacePerPoint, SurfaceOfAMirrorsTheKeys) {
    const CliRun b = runCli({m_xyz, m_mesh, "--surface", "b", "--json", "--per-point"});
    const CliRun a = runCli({m_mesh, m_xyz, "--surface", "a", "--json", "--per-point"});
    ASSERT_EQ(b.exitCode, 0) << b;
    ASSERT_EQ(a.exitCode, 0) << a;
    const Json pb = Json::parse(b.out)["per_point"], pa = Json::parse(a.out)["per_point"];
    EXPECT_TRUE(pa["a_to_b"].is_null());
    EXPECT_EQ(pa["b_to_a"], pb["a_to_b"]);
    EXPECT_EQ(pa["b_to_a"]["count"].get<size_t>(), m_points.size());
    EXPECT_EQ(pa["diagonal_b"], pb["diagonal_a"]);
    EXPECT_EQ(pa["diagonal_a"], pb["diagonal_b"]);
    EXPECT_EQ(pa["histogram"]["b_to_a"], pb["histogram"]["a_to_b"]);
    EXPECT_TRUE(pa["histogram"]["a_to_b"].is_null());
    EXPECT_EQ(pa["hd95"], pb["hd95"]);
}

TEST_F(CliSurfacePerPoint, SummaryShowsTheDirectedStatistics) {
    CliRun run = runCli({m_xyz, m_mesh, "--surface", "b", "--per-point"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("A->B"), std::string::npos) << run;
    EXPECT_NE(run.out.find("HD95"), std::string::npos) << run;
    run = runCli({m_mesh, m_xyz, "--surface", "a", "--per-point"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("B->A"), std::string::npos) << run;
    EXPECT_EQ(run.out.find("A->B"), std::string::npos) << run;
}

std::vector<std::string> split(const std::string& line) {
    std::vector<std::string> out;
    std::stringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');) out.push_back(cell);
    return out;
}

TEST_F(CliSurfacePerPoint, CsvRowsAreTheBruteForce) {
    for (const char* side : {"a", "b"}) {
        SCOPED_TRACE(side);
        const bool b = side[0] == 'b';
        const std::string prefix = path(std::string("d") + side);
        const CliRun run = b ? runCli({m_xyz, m_mesh, "--surface", "b", "--out-csv", prefix})
                             : runCli({m_mesh, m_xyz, "--surface", "a", "--out-csv", prefix});
        ASSERT_EQ(run.exitCode, 0) << run;
        // The points' side alone: --surface b writes PREFIX_a.csv.
        const std::string points = prefix + (b ? "_a.csv" : "_b.csv");
        const std::string mesh = prefix + (b ? "_b.csv" : "_a.csv");
        EXPECT_FALSE(std::filesystem::exists(mesh));
        std::stringstream in(readFile(points));
        std::string line;
        std::getline(in, line);
        EXPECT_EQ(line,
                  "index,x,y,z,distance,triangle,closest_x,closest_y,closest_z,barycentric_0,barycentric_1,"
                  "barycentric_2");
        size_t rows = 0, wrong = 0;
        for (; std::getline(in, line); ++rows) {
            const std::vector<std::string> cell = split(line);
            ASSERT_EQ(cell.size(), 12u) << line;
            const oracle::SurfaceNearest& n = m_want.perQuery.at(rows);
            auto number = [&](size_t k) { return std::strtod(cell[k].c_str(), nullptr); };
            const glm::vec3 q(m_points[rows]);
            auto single = [&](size_t k) { return std::strtof(cell[k].c_str(), nullptr); };
            const bool same = cell[0] == std::to_string(rows) && single(1) == q.x && single(2) == q.y &&
                              single(3) == q.z && number(4) == std::sqrt(n.distance2) &&
                              cell[5] == std::to_string(n.triangle) &&
                              glm::dvec3(number(6), number(7), number(8)) == n.point &&
                              glm::dvec3(number(9), number(10), number(11)) == n.barycentric;
            if (!same && ++wrong <= 3) ADD_FAILURE() << "row " << rows << ": " << line;
        }
        EXPECT_EQ(rows, m_points.size());
        EXPECT_EQ(wrong, 0u);
    }
}

TEST_F(CliSurfacePerPoint, PlyQualityIsTheDistance) {
    const CliRun run = runCli({m_xyz, m_mesh, "--surface", "b", "--out-ply", path("d"), "--range", "0", "1"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_FALSE(std::filesystem::exists(path("d_b.ply")));
    const std::string bytes = readFile(path("d_a.ply"));
    const size_t end = bytes.find("end_header\n");
    ASSERT_NE(end, std::string::npos);
    const std::string header = bytes.substr(0, end);
    EXPECT_NE(header.find("element vertex " + std::to_string(m_points.size())), std::string::npos) << header;
    EXPECT_NE(header.find("other file's triangles"), std::string::npos) << header;
    EXPECT_NE(header.find("colour range 0.000000 1.000000"), std::string::npos) << header;
    const size_t body = end + std::strlen("end_header\n");
    ASSERT_EQ(bytes.size(), body + m_points.size() * 19);
    for (size_t i = 0; i < m_points.size(); ++i) {
        float v[4];
        std::memcpy(v, bytes.data() + body + i * 19, sizeof v);
        ASSERT_EQ(glm::vec3(v[0], v[1], v[2]), glm::vec3(m_points[i])) << i;
        ASSERT_EQ(v[3], float(m_distances[i])) << i;
    }
}

// PNG signature and the IHDR width/height (big endian at bytes 16 and 20).
void expectPng(const std::string& file, uint32_t width, uint32_t height) {
    const std::string bytes = readFile(file);
    ASSERT_GE(bytes.size(), 33u) << file;
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    auto be32 = [&](size_t at) {
        return uint32_t(uint8_t(bytes[at])) << 24 | uint32_t(uint8_t(bytes[at + 1])) << 16 |
               uint32_t(uint8_t(bytes[at + 2])) << 8 | uint32_t(uint8_t(bytes[at + 3]));
    };
    EXPECT_EQ(be32(16), width);
    EXPECT_EQ(be32(20), height);
}

TEST_F(CliSurfacePerPoint, PngFiles) {
    const CliRun run = runCli({m_mesh, m_xyz, "--surface", "a", "--png", path("p.png"), "--render",
                               "software", "--histogram-png", path("h.png")});
    ASSERT_EQ(run.exitCode, 0) << run;
    expectPng(path("p.png"), 1600, 1000);
    expectPng(path("h.png"), 1000, 560);
}

TEST_F(CliSurfacePerPoint, UnwritableOutputIsExit5) {
    const CliRun run = runCli({m_xyz, m_mesh, "--surface", "b", "--out-csv", path("missing-dir/d")});
    EXPECT_EQ(run.exitCode, 5) << run;
    EXPECT_NE(run.err.find("missing-dir/d_a.csv"), std::string::npos) << run;
}

TEST_F(CliSurfacePerPoint, RefusalsNameTheReason) {
    CliRun run = runCli({m_mesh, m_mesh, "--surface", "both", "--per-point"});
    EXPECT_EQ(run.exitCode, 2) << run;
    EXPECT_NE(run.err.find("need --surface a or b"), std::string::npos) << run;
    run = runCli({m_xyz, m_mesh, "--surface", "b", "--eval", "0.1", "--per-point"});
    EXPECT_EQ(run.exitCode, 2) << run;
    EXPECT_NE(run.err.find("--eval"), std::string::npos) << run;
}

// A GPU backend's per-point statistics: h exact, every statistic within
// the JSON's tolerance above the brute force's (the device's float search
// per point), the summary saying so; the cpu backend's tolerance is 0.
TEST_F(CliSurfacePerPoint, GpuBackendsGiveStatisticsWithinTheirTolerance) {
    CliRun run = runCli({m_xyz, m_mesh, "--surface", "b", "--json", "--percentile", "90"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_EQ(Json::parse(run.out)["per_point"]["tolerance"].get<double>(), 0.0);
    for (const char* backend : {"ray-query", "rt-pipeline"}) {
        run = runCli({m_xyz, m_mesh, "--surface", "b", "--backend", backend, "--json", "--percentile", "90"});
        ASSERT_EQ(run.exitCode, 0) << run;
        const Json j = Json::parse(run.out);
        EXPECT_EQ(j["hausdorff"].get<double>(), m_want.distance) << backend;
        const double tolerance = j["per_point"]["tolerance"].get<double>();
        EXPECT_GT(tolerance, 0.0) << backend;
        EXPECT_LT(tolerance, 1e-3) << backend;
        const Json& s = j["per_point"]["a_to_b"];
        EXPECT_EQ(s["count"].get<size_t>(), m_points.size()) << backend;
        EXPECT_EQ(s["max"].get<double>(), m_want.distance) << backend;
        const double p90 = percentileOf(s["percentiles"], 90.0);
        EXPECT_GE(p90, percentile(90.0)) << backend;
        EXPECT_LE(p90, percentile(90.0) + tolerance) << backend;
        EXPECT_EQ(j["counters"]["a_to_b"]["cpu_recomputed"].get<int>(), 0) << backend;
        run = runCli({m_xyz, m_mesh, "--surface", "b", "--backend", backend, "--per-point"});
        ASSERT_EQ(run.exitCode, 0) << run;
        EXPECT_NE(run.out.find("per-point distances within"), std::string::npos) << run;
    }
}

}  // namespace
}  // namespace rthdist::cli_test
