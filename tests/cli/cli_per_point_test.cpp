// CLI per-point outputs on the cpu backend: the per_point JSON statistics on
// an exact fixture, the PLY/CSV files read back (PLY through
// rthdist::io::loadPoints), PNG signatures and sizes, usage errors of the new
// flags, and progress: absent when stderr is a file, shown on a terminal
// (a pseudo-terminal from `script`), absent with --quiet.
#include <gtest/gtest.h>

#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"
#include "rthdist/io.hpp"

namespace rthdist::cli_test {
namespace {

using Json = nlohmann::json;

// A: 0, 1, 3 on the x axis; B: the origin and (0, 2, 0).
// d_A = {0, 1, 3} (nearest 0, 0, 0); d_B = {0, 2} (nearest 0, 0).
constexpr char kA[] = "0 0 0\n1 0 0\n3 0 0\n";
constexpr char kB[] = "0 0 0\n0 2 0\n";

class CliPerPoint : public ::testing::Test {
protected:
    TempDir m_dir;
    std::string m_a = m_dir.write("a.xyz", kA);
    std::string m_b = m_dir.write("b.xyz", kB);
    std::string path(const std::string& name) const { return (m_dir.path() / name).string(); }
};

double percentileOf(const Json& list, double p) {
    for (const Json& e : list) {
        if (e["p"].get<double>() == p) return e["value"].get<double>();
    }
    ADD_FAILURE() << "percentile " << p << " missing";
    return -1;
}

TEST_F(CliPerPoint, JsonStatistics) {
    const CliRun run = runCli({"--backend", "cpu", "--json", "--per-point", "--percentile", "50",
                               "--percentile", "100", "--histogram-bins", "3", m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_TRUE(run.err.empty()) << run;
    const Json j = parseJson(run);
    const Json& pp = j["per_point"];
    ASSERT_TRUE(pp.is_object()) << run;
    EXPECT_EQ(pp["a_to_b"]["count"], 3);
    EXPECT_EQ(pp["a_to_b"]["min"], 0.0);
    EXPECT_EQ(pp["a_to_b"]["max"], 3.0);
    EXPECT_DOUBLE_EQ(pp["a_to_b"]["mean"].get<double>(), 4.0 / 3.0);
    EXPECT_DOUBLE_EQ(pp["a_to_b"]["rms"].get<double>(), std::sqrt(10.0 / 3.0));
    EXPECT_EQ(percentileOf(pp["a_to_b"]["percentiles"], 50), 1.0);  // rank ceil(1.5) = 2
    EXPECT_EQ(percentileOf(pp["b_to_a"]["percentiles"], 50), 0.0);  // rank 1
    EXPECT_EQ(percentileOf(pp["b_to_a"]["percentiles"], 95), 2.0);
    EXPECT_EQ(percentileOf(pp["pooled"]["percentiles"], 50), 1.0);  // {0,0,1,2,3}: rank 3
    EXPECT_EQ(pp["pooled"]["count"], 5);
    EXPECT_DOUBLE_EQ(pp["pooled"]["mean"].get<double>(), 6.0 / 5.0);
    EXPECT_EQ(pp["hd95"]["max"], 3.0);     // max(P95 A->B = 3, P95 B->A = 2)
    EXPECT_EQ(pp["hd95"]["pooled"], 3.0);  // rank ceil(4.75) = 5
    // Union box (0,0,0)-(3,2,0): diagonal sqrt(13).
    EXPECT_DOUBLE_EQ(pp["diagonal"].get<double>(), std::sqrt(13.0));
    EXPECT_DOUBLE_EQ(pp["a_to_b"]["normalized"]["max"].get<double>(), 3.0 / std::sqrt(13.0));
    EXPECT_DOUBLE_EQ(pp["hd95"]["max_normalized"].get<double>(), 3.0 / std::sqrt(13.0));
    const Json& h = pp["histogram"];
    EXPECT_EQ(h["lo"], 0.0);
    EXPECT_EQ(h["hi"], 3.0);
    EXPECT_EQ(h["a_to_b"], Json::parse("[1, 1, 1]"));
    EXPECT_EQ(h["b_to_a"], Json::parse("[1, 0, 1]"));  // 2 = hi goes to the last bin
    EXPECT_EQ(h["pooled"], Json::parse("[2, 1, 2]"));
    ASSERT_EQ(pp["percentiles"].size(), 3u);  // 50, 100 and the always-reported 95
    EXPECT_EQ(j["hausdorff"], 3.0);
}

TEST_F(CliPerPoint, WithoutFlagNoPerPointObject) {
    const CliRun run = runCli({"--backend", "cpu", "--json", m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_FALSE(parseJson(run).contains("per_point"));
}

TEST_F(CliPerPoint, DirectedHasNoBToA) {
    const CliRun run = runCli({"--backend", "cpu", "--json", "--directed", "--per-point", m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = parseJson(run);
    EXPECT_TRUE(j["per_point"]["b_to_a"].is_null());
    EXPECT_TRUE(j["per_point"]["pooled"].is_null());
    EXPECT_EQ(j["per_point"]["hd95"]["max"], 3.0);
}

TEST_F(CliPerPoint, SummaryShowsHd95) {
    const CliRun run = runCli({"--backend", "cpu", "--per-point", m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("HD95       3 "), std::string::npos) << run;
    EXPECT_NE(run.out.find("pooled"), std::string::npos) << run;
}

TEST_F(CliPerPoint, PlyReadsBackWithQualityAndColours) {
    const CliRun run = runCli({"--backend", "cpu", "--out-ply", path("d"), "--range", "0", "2", m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    for (auto [name, text, count] : {std::tuple{"d_a.ply", kA, 3}, std::tuple{"d_b.ply", kB, 2}}) {
        SCOPED_TRACE(name);
        Result<std::vector<glm::vec3>> back = io::loadPoints(path(name));
        ASSERT_TRUE(back.ok()) << back.error().message;
        ASSERT_EQ(back->size(), size_t(count));
        std::istringstream in(text);
        for (const glm::vec3& p : *back) {
            float x, y, z;
            in >> x >> y >> z;
            EXPECT_EQ(p, glm::vec3(x, y, z));
        }
        const std::string bytes = readFile(path(name));
        const size_t end = bytes.find("end_header\n");
        ASSERT_NE(end, std::string::npos);
        const std::string header = bytes.substr(0, end);
        EXPECT_NE(header.find("property float quality"), std::string::npos);
        EXPECT_NE(header.find("property uchar red\nproperty uchar green\nproperty uchar blue"),
                  std::string::npos);
        const size_t body = end + std::strlen("end_header\n");
        ASSERT_EQ(bytes.size(), body + size_t(count) * 19);
    }
    // A's quality values 0, 1, 3; colours: 0 -> low end, 2 and 3 (clamped) -> the same high end.
    const std::string bytes = readFile(path("d_a.ply"));
    const size_t body = bytes.find("end_header\n") + std::strlen("end_header\n");
    auto quality = [&](int i) {
        float q;
        std::memcpy(&q, bytes.data() + body + size_t(i) * 19 + 12, 4);
        return q;
    };
    auto colour = [&](int i) { return bytes.substr(body + size_t(i) * 19 + 16, 3); };
    EXPECT_EQ(quality(0), 0.0f);
    EXPECT_EQ(quality(1), 1.0f);
    EXPECT_EQ(quality(2), 3.0f);
    EXPECT_NE(colour(0), colour(2));
    EXPECT_NE(colour(1), colour(2));
    EXPECT_GT(uint8_t(colour(2)[0]), uint8_t(colour(2)[2]));  // far is red, not blue
    EXPECT_LT(int(uint8_t(colour(0)[0])) + uint8_t(colour(0)[1]) + uint8_t(colour(0)[2]),
              150);  // near is dark
}

TEST_F(CliPerPoint, CsvRows) {
    const CliRun run = runCli({"--backend", "cpu", "--out-csv", path("d"), m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_EQ(readFile(path("d_a.csv")),
              "index,x,y,z,distance,nearest\n0,0,0,0,0,0\n1,1,0,0,1,0\n2,3,0,0,3,0\n");
    EXPECT_EQ(readFile(path("d_b.csv")), "index,x,y,z,distance,nearest\n0,0,0,0,0,0\n1,0,2,0,2,0\n");
}

// PNG signature and the IHDR width/height (big endian at bytes 16 and 20).
void expectPng(const std::string& file, uint32_t width, uint32_t height) {
    const std::string bytes = readFile(file);
    ASSERT_GE(bytes.size(), 33u) << file;
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    auto be32 = [&](size_t at) {
        return uint32_t(uint8_t(bytes[at])) << 24 | uint32_t(uint8_t(bytes[at + 1])) << 16 |
               uint32_t(uint8_t(bytes[at + 2])) << 8 | uint32_t(uint8_t(bytes[at + 3]));
    };
    EXPECT_EQ(be32(16), width);
    EXPECT_EQ(be32(20), height);
}

TEST_F(CliPerPoint, PngFiles) {
    const CliRun run = runCli(
        {"--backend", "cpu", "--png", path("p.png"), "--histogram-png", path("h.png"), kSampleA, kSampleB});
    ASSERT_EQ(run.exitCode, 0) << run;
    expectPng(path("p.png"), 1600, 1000);
    expectPng(path("h.png"), 1000, 560);
}

// Output failures are exit 5, not 3 (bad input); cli_output_test has the rest.
TEST_F(CliPerPoint, UnwritableOutputIsAnError) {
    const CliRun run = runCli({"--backend", "cpu", "--out-csv", path("missing-dir/d"), m_a, m_b});
    EXPECT_EQ(run.exitCode, 5) << run;
    EXPECT_NE(run.err.find("missing-dir/d_a.csv"), std::string::npos) << run;
}

TEST_F(CliPerPoint, UsageErrors) {
    const std::vector<std::vector<std::string>> cases = {
        {"--percentile", "101"}, {"--percentile", "-1"}, {"--percentile", "x"}, {"--histogram-bins", "0"},
        {"--range", "2", "1"},   {"--range", "0"},       {"--out-ply", ""},     {"--png"},
    };
    for (const auto& c : cases) {
        std::vector<std::string> args{m_a, m_b};
        args.insert(args.end(), c.begin(), c.end());
        SCOPED_TRACE(c[0]);
        const CliRun run = runCli(args);
        EXPECT_EQ(run.exitCode, 2) << run;
        EXPECT_NE(run.err.find(c[0]), std::string::npos) << run;
    }
}

// Progress: stderr redirected to a file (runCli) shows none, even per-point
// with the delay forced to 0.
TEST_F(CliPerPoint, NoProgressWhenStderrIsAFile) {
    setenv("RTHDIST_PROGRESS_DELAY_MS", "0", 1);
    const CliRun run = runCli({"--backend", "cpu", "--json", "--per-point", kSampleA, kSampleB});
    unsetenv("RTHDIST_PROGRESS_DELAY_MS");
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_TRUE(run.err.empty()) << run;
    parseJson(run);
}

// Runs the CLI under `script` (a pseudo-terminal for stdout and stderr) and
// returns everything the terminal received.
std::string runOnTerminal(const std::vector<std::string>& args) {
    std::string command = "RTHDIST_PROGRESS_DELAY_MS=0 " + shellQuote(kCli);
    for (const std::string& a : args) command += " " + shellQuote(a);
    const std::string outer = "script -qec " + shellQuote(command) + " /dev/null </dev/null";
    FILE* pipe = popen(outer.c_str(), "r");
    if (pipe == nullptr) return {};
    std::string out;
    char buf[4096];
    size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
    pclose(pipe);
    return out;
}

TEST_F(CliPerPoint, ProgressOnATerminalUnlessQuiet) {
    if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "util-linux `script` missing";
    const std::string shown = runOnTerminal({"--backend", "cpu", "--per-point", kSampleA, kSampleB});
    // Stage names and percentages (the 100 ms throttle may skip some stages).
    EXPECT_NE(shown.find("\rrthdist: index"), std::string::npos) << shown;
    EXPECT_NE(shown.find("%"), std::string::npos) << shown;
    EXPECT_NE(shown.find("H(A,B) = "), std::string::npos) << shown;
    const std::string quiet =
        runOnTerminal({"--backend", "cpu", "--per-point", "--quiet", kSampleA, kSampleB});
    EXPECT_EQ(quiet.find("rthdist: "), std::string::npos) << quiet;
    EXPECT_NE(quiet.find("H(A,B) = "), std::string::npos) << quiet;
}

}  // namespace
}  // namespace rthdist::cli_test
