// The CLI on georeferenced input (issue 10): LAS files written by the test
// (the LiDAR scenes of ../shared/data and small fixtures), --las-classes,
// .laz and damaged LAS (exit 3), and a double PLY at UTM coordinates against
// a brute force in double.
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli_runner.hpp"
#include "common/geo_cases.hpp"
#include "io/las_test_support.hpp"
#include "rthdist/io.hpp"

namespace rthdist::cli_test {
namespace {

using io::test::lasBytes;
using io::test::LasPoint;
using io::test::LasSpec;

const std::string kSharedData = RTHDIST_SHARED_DATA_DIR;

double unionDiagonal(const io::PointCloud& a, const io::PointCloud& b) {
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const io::PointCloud* c : {&a, &b}) {
        const PointView v = c->view();
        for (size_t i = 0; i < v.size(); ++i) {
            lo = glm::min(lo, v.at(i));
            hi = glm::max(hi, v.at(i));
        }
    }
    return glm::length(hi - lo);
}

// The cloud as LAS 1.4 point format 6: X = round((x - offset) / scale).
std::string toLas(const io::PointCloud& cloud, double scale, const glm::dvec3& offset) {
    LasSpec s;
    s.minor = 4;
    s.format = 6;
    s.scale = {scale, scale, scale};
    s.offset = {offset.x, offset.y, offset.z};
    const PointView v = cloud.view();
    s.points.resize(v.size());
    for (size_t i = 0; i < v.size(); ++i) {
        const glm::dvec3 p = v.at(i);
        for (int axis = 0; axis < 3; ++axis) {
            const double q = std::round((p[axis] - offset[axis]) / scale);
            EXPECT_LT(std::abs(q), 2147483647.0) << "point " << i << " does not fit int32 at this scale";
            s.points[i].xyz[static_cast<size_t>(axis)] = static_cast<int32_t>(q);
        }
    }
    return lasBytes(s);
}

double hausdorffOf(const CliRun& run) { return parseJson(run)["hausdorff"].get<double>(); }

// ---- the LiDAR scenes as LAS ----------------------------------------------------

// FSite8 and CSite1 (ISPRS, UTM 32U; README of ../shared/data: stored as
// float32, 0.5 m apart in y, with duplicates), written to LAS with a scale of
// 1 mm and an integer offset at the data's lower corner, must give the H of
// their PLY. Why the tolerance: the float PLY values v are exact doubles,
// v - offset is exact, so each LAS coordinate is v moved by at most half the
// scale (plus the double rounding of X * scale + offset, ~1e-10 m): every
// point moves by at most d = sqrt(3) * scale / 2, and H, a max of min
// distances over both sets, by at most 2 d = sqrt(3) * scale. Each run is
// within 1e-6 of the union's diagonal D of its exact value (the contract):
// |H_las - H_ply| <= sqrt(3) * scale + 2e-6 * D.
TEST(CliLas, LidarScenesAsLasGiveTheHOfTheirPly) {
    const std::string lidar = kSharedData + "/lidar";
    if (!std::filesystem::exists(lidar + "/FSite8_orig-utm.ply")) {
        GTEST_SKIP() << "no " << lidar << " (../shared/data beside the source tree)";
    }
    TempDir dir;
    constexpr double kScale = 0.001;
    const std::pair<const char*, const char*> scenes[] = {{"FSite8_orig-utm", "FSite8_red1-utm"},
                                                          {"CSite1_red1-utm", "CSite1_red2-utm"}};
    for (const auto& [nameA, nameB] : scenes) {
        SCOPED_TRACE(std::string(nameA) + " vs " + nameB);
        const std::string plyA = lidar + "/" + nameA + ".ply", plyB = lidar + "/" + nameB + ".ply";
        auto a = io::loadPointCloud(plyA);
        auto b = io::loadPointCloud(plyB);
        ASSERT_TRUE(a.ok() && b.ok());
        ASSERT_EQ(a->scalar, Scalar::kFloat32);  // the trap: float32 UTM
        glm::dvec3 lo(INFINITY);
        for (const io::PointCloud* c : {&*a, &*b})
            for (size_t i = 0; i < c->size(); ++i) lo = glm::min(lo, c->view().at(i));
        const glm::dvec3 offset = glm::floor(lo);
        const std::string lasA = dir.write(std::string(nameA) + ".las", toLas(*a, kScale, offset));
        const std::string lasB = dir.write(std::string(nameB) + ".las", toLas(*b, kScale, offset));

        const CliRun fromPly = runCli({"--backend", "cpu", "--json", plyA, plyB});
        ASSERT_EQ(fromPly.exitCode, 0) << fromPly;
        const CliRun fromLas = runCli({"--backend", "cpu", "--json", lasA, lasB});
        ASSERT_EQ(fromLas.exitCode, 0) << fromLas;
        const nlohmann::json j = parseJson(fromLas);
        EXPECT_EQ(j["precision"]["a"], "float64");
        EXPECT_EQ(j["points"]["a"].get<size_t>(), a->size());
        EXPECT_EQ(j["points"]["b"].get<size_t>(), b->size());
        const double tolerance = std::sqrt(3.0) * kScale + 2e-6 * unionDiagonal(*a, *b);
        std::printf("%s vs %s: H from PLY %.9f, from LAS %.9f, tolerance %.3g\n", nameA, nameB,
                    hausdorffOf(fromPly), hausdorffOf(fromLas), tolerance);
        EXPECT_GT(hausdorffOf(fromPly), 1.0);
        EXPECT_NEAR(hausdorffOf(fromLas), hausdorffOf(fromPly), tolerance);
    }
}

// ---- --las-classes ----------------------------------------------------------------

std::string classFixture(const TempDir& dir) {
    LasSpec s;
    s.format = 1;
    s.scale = {0.01, 0.01, 0.01};
    s.offset = {512000.0, 5400000.0, 0.0};
    // Ground (2) on a line at z = 0, a building (6) 10 m up, noise (7) 50 m up.
    s.points = {{{0, 0, 0}, 2}, {{100, 0, 0}, 2}, {{0, 0, 1000}, 6}, {{0, 0, 5000}, 7}};
    return dir.write("scan.las", lasBytes(s));
}

TEST(CliLas, ClassFilterSelectsThePoints) {
    TempDir dir;
    const std::string las = classFixture(dir);
    const std::string ref = dir.write("ref.xyz", "512000 5400000 0\n");
    const CliRun all = runCli({"--backend", "cpu", "--json", las, ref});
    ASSERT_EQ(all.exitCode, 0) << all;
    EXPECT_EQ(parseJson(all)["points"]["a"], 4);
    EXPECT_DOUBLE_EQ(hausdorffOf(all), 50.0);
    const CliRun ground = runCli({"--backend", "cpu", "--json", "--las-classes", "2", las, ref});
    ASSERT_EQ(ground.exitCode, 0) << ground;
    EXPECT_EQ(parseJson(ground)["points"]["a"], 2);
    EXPECT_DOUBLE_EQ(hausdorffOf(ground), 1.0);
    const CliRun two = runCli({"--backend", "cpu", "--json", "--las-classes=2,6", las, ref});
    ASSERT_EQ(two.exitCode, 0) << two;
    EXPECT_EQ(parseJson(two)["points"]["a"], 3);
    EXPECT_DOUBLE_EQ(hausdorffOf(two), 10.0);
}

TEST(CliLas, FilterKeepingNothingIsBadInput) {
    TempDir dir;
    const std::string las = classFixture(dir);
    const CliRun run = runCli({"--las-classes", "3,9", las, las});
    EXPECT_EQ(run.exitCode, 3) << run;
    EXPECT_NE(run.err.find(las + ": classification: none of the 4 points has class 3, 9"), std::string::npos)
        << run;
}

TEST(CliLas, BadClassListIsUsageError) {
    TempDir dir;
    const std::string las = classFixture(dir);
    for (const std::string bad : {"", "2,", ",2", "2,,6", "a", "256", "-1", "2;6", " 2"}) {
        SCOPED_TRACE("'" + bad + "'");
        const CliRun run = runCli({"--las-classes", bad, las, las});
        EXPECT_EQ(run.exitCode, 2) << run;
        EXPECT_NE(run.err.find("option '--las-classes' expects comma-separated integers in [0, 255]"),
                  std::string::npos)
            << run;
    }
    const CliRun missing = runCli({las, las, "--las-classes"});
    EXPECT_EQ(missing.exitCode, 2) << missing;
    EXPECT_NE(missing.err.find("option '--las-classes' needs a value"), std::string::npos) << missing;
}

TEST(CliLas, ClassesWithoutLasInputIsUsageError) {
    const CliRun run = runCli({"--las-classes", "2", kSampleA, kSampleB});
    EXPECT_EQ(run.exitCode, 2) << run;
    EXPECT_NE(run.err.find("neither input is .las"), std::string::npos) << run;
}

TEST(CliLas, HelpDocumentsTheOption) {
    const CliRun run = runCli({"--help"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("--las-classes LIST"), std::string::npos);
    EXPECT_NE(run.out.find(".las"), std::string::npos);
}

// ---- bad LAS: exit 3 naming file and place ------------------------------------------

TEST(CliLas, LazIsExit3WithHowToDecompress) {
    TempDir dir;
    const std::string laz = dir.write("scan.laz", "LASF");
    const CliRun run = runCli({laz, kSampleA});
    EXPECT_EQ(run.exitCode, 3) << run;
    EXPECT_NE(run.err.find(laz + ": file: compressed LAS (LAZ) is not read"), std::string::npos) << run;
    EXPECT_NE(run.err.find("laszip -i in.laz -o out.las"), std::string::npos) << run;
}

TEST(CliLas, DamagedLasIsExit3) {
    TempDir dir;
    LasSpec s;
    s.points = {{{1, 2, 3}}, {{4, 5, 6}}};
    std::string truncated = lasBytes(s);
    truncated.resize(truncated.size() - 1);
    s.scale[2] = 0.0;
    const std::string cases[][2] = {
        {dir.write("t.las", truncated), "byte offset 227: the header declares 2 points of 20 bytes"},
        {dir.write("s.las", lasBytes(s)), "byte offset 147: Z scale factor is 0"}};
    for (const auto& [path, where] : cases) {
        const CliRun run = runCli({path, kSampleA});
        EXPECT_EQ(run.exitCode, 3) << run;
        EXPECT_NE(run.err.find(path + ": " + where), std::string::npos) << run;
    }
}

// ---- double PLY at UTM: the README's example ------------------------------------------

std::string doublePly(const std::vector<glm::dvec3>& points) {
    io::test::ByteBuilder b;
    b.text("ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(points.size()) +
           "\nproperty double x\nproperty double y\nproperty double z\nend_header\n");
    for (const glm::dvec3& p : points) b.put(p.x).put(p.y).put(p.z);
    return b.str();
}

std::string floatPly(const std::vector<glm::dvec3>& points) {
    io::test::ByteBuilder b;
    b.text("ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(points.size()) +
           "\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    for (const glm::dvec3& p : points) b.put(float(p.x)).put(float(p.y)).put(float(p.z));
    return b.str();
}

// A 200 m site at x ~ 5.1e5, y ~ 5.4e6 with centimetre detail, two samplings
// (tests/common/geo_cases.cpp, utm_cm_3): the CLI on the double PLYs matches
// the double brute force within 1e-6 of the diagonal, and
// the same points stored as float32 PLYs (what earlier releases computed on)
// do not.
TEST(CliPrecision, DoublePlyAtUtmMatchesTheDoubleBruteForce) {
    const std::vector<test::GeoCase> cases = test::makeGeoCases();
    const test::GeoCase& c = cases[3];
    ASSERT_EQ(c.name, "utm_cm_3");
    TempDir dir;
    const std::string a = dir.write("a.ply", doublePly(c.a)), b = dir.write("b.ply", doublePly(c.b));
    const std::string fa = dir.write("fa.ply", floatPly(c.a)), fb = dir.write("fb.ply", floatPly(c.b));
    const double truth = std::max(test::bruteForceDirectedDouble(c.a, c.b).distance,
                                  test::bruteForceDirectedDouble(c.b, c.a).distance);
    io::PointCloud ca{Scalar::kFloat64, {}, {c.a.begin(), c.a.end()}};
    io::PointCloud cb{Scalar::kFloat64, {}, {c.b.begin(), c.b.end()}};
    const double tolerance = 1e-6 * unionDiagonal(ca, cb);
    SCOPED_TRACE("seed " + std::to_string(c.seed) + ", brute force H " + std::to_string(truth));
    const CliRun rounded = runCli({"--backend", "cpu", "--json", fa, fb});
    ASSERT_EQ(rounded.exitCode, 0) << rounded;
    // The GPU backends on the same cases: tests/core/precision_test.cpp.
    std::printf("utm_cm_3 (seed %llu): double brute force H %.9f, float32 PLYs give %.9f\n",
                static_cast<unsigned long long>(c.seed), truth, hausdorffOf(rounded));
    for (const std::string backend : {"cpu", "auto"}) {
        SCOPED_TRACE(backend);
        const CliRun run = runCli({"--backend", backend, "--json", "--verify", a, b});
        ASSERT_EQ(run.exitCode, 0) << run;
        const nlohmann::json j = parseJson(run);
        EXPECT_EQ(j["precision"]["a"], "float64");
        EXPECT_EQ(j["precision"]["b"], "float64");
        EXPECT_NEAR(j["hausdorff"].get<double>(), truth, tolerance);
    }
    EXPECT_EQ(parseJson(rounded)["precision"]["a"], "float32");
    EXPECT_GT(std::abs(hausdorffOf(rounded) - truth), 100 * tolerance) << "float32 UTM should miss the truth";
}

// ---- coordinates past the float search's limits (issue 36) -------------------------

// Exit 3 naming the file and every word of `words`, on every backend; never a
// signal, never a distance.
void expectLimitExit3(const std::vector<std::string>& files, const std::vector<std::string>& words) {
    for (const std::string backend : {"cpu", "ray-query", "rt-pipeline"}) {
        SCOPED_TRACE(backend);
        std::vector<std::string> args = {"--backend", backend, "--json"};
        args.insert(args.end(), files.begin(), files.end());
        const CliRun run = runCli(args);
        if (backend != "cpu" && run.exitCode == 4) GTEST_SKIP() << "no device for " << backend << "\n" << run;
        EXPECT_EQ(run.exitCode, 3) << run;
        EXPECT_TRUE(run.out.empty()) << run;
        for (const std::string& w : words) EXPECT_NE(run.err.find(w), std::string::npos) << w << "\n" << run;
    }
}

TEST(CliInputLimits, XyzPastFloatRangeIsExit3) {
    TempDir dir;
    const std::string big = dir.write("big.xyz", "1e308 0 0\n0.1 0 0\n");
    const std::string small = dir.write("small.xyz", "0 0 0\n1 0 0\n");
    expectLimitExit3({big, small}, {"point set A (" + big + ")", "point 0", "x = 1e+308", "3.40282347e+38"});
    expectLimitExit3({big, big}, {big, "x = 1e+308", "float32's largest value"});
    // A few strays among many points: refused before any search.
    std::string many;
    for (int i = 0; i < 2000; ++i) many += std::to_string(i % 37) + " " + std::to_string(i % 11) + " 0.5\n";
    const std::string strays = dir.write("strays.xyz", many + "-1e308 0 0\n0 1e308 0\n");
    expectLimitExit3({small, strays}, {"point set B (" + strays + ")", "point 2000", "x = -1e+308"});
}

TEST(CliInputLimits, XyzBelowFloatNormalsIsExit3) {
    TempDir dir;
    const std::string tiny = dir.write("tiny.xyz", "1e-160 0 0\n0 2e-160 0\n");
    const std::string zero = dir.write("zero.xyz", "0 0 0\n");
    expectLimitExit3({tiny, zero},
                     {"point sets A and B (" + tiny + ", " + zero + ")", "1e-160", "1.17549435e-38"});
}

TEST(CliInputLimits, LasScaleOrOffsetPastFloatRangeIsExit3) {
    TempDir dir;
    LasSpec s;
    s.points = {{{1, 2, 3}}, {{4, 5, 6}}};
    s.scale = {1e300, 0.01, 0.01};
    const std::string scaled = dir.write("scale.las", lasBytes(s));
    ASSERT_EQ(std::filesystem::file_size(scaled), 267u);
    expectLimitExit3({scaled, scaled}, {"point set A (" + scaled + ")", "x = 4e+300", "3.40282347e+38"});
    s.scale = {0.01, 0.01, 0.01};
    s.offset = {0.0, 1e308, 0.0};
    const std::string offset = dir.write("offset.las", lasBytes(s));
    expectLimitExit3({kSampleA, offset}, {"point set B (" + offset + ")", "y = 1e+308", "3.40282347e+38"});
}

// Far from the origin but close together: exact, whatever the magnitude.
TEST(CliInputLimits, LasFarButSmallIsExact) {
    TempDir dir;
    LasSpec s;
    s.offset = {1e300, 0.0, -1e307};  // y varies: 1e300 + 1 is 1e300 in double
    s.points = {{{0, 0, 0}}, {{0, 100, 0}}};
    const std::string a = dir.write("a.las", lasBytes(s));
    s.points = {{{0, 500, 0}}};
    const std::string b = dir.write("b.las", lasBytes(s));
    for (const std::string backend : {"cpu", "ray-query", "rt-pipeline"}) {
        SCOPED_TRACE(backend);
        const CliRun run = runCli({"--backend", backend, "--json", a, b});
        if (backend != "cpu" && run.exitCode == 4) GTEST_SKIP() << "no device for " << backend << "\n" << run;
        ASSERT_EQ(run.exitCode, 0) << run;
        EXPECT_EQ(hausdorffOf(run), 5.0) << run;
    }
}

}  // namespace
}  // namespace rthdist::cli_test
