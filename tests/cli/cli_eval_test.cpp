// `rthdist A B --eval ...` end to end (cli/eval_command.hpp): tiny point
// sets and a square mesh whose nearest distances are known by hand, so
// every number of the summary (means, medians, the three Chamfer
// conventions, precision, recall, F-score, the cap) is checked in the JSON
// and the CSV; the refusals: malformed or out-of-range values and
// combinations that cannot be honoured (exit 2 naming the option), an
// unwritable CSV (exit 5).
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace rthdist::cli_test {
namespace {

using Json = nlohmann::json;

class CliEval : public ::testing::Test {
protected:
    void SetUp() override {
        // Accuracy (A -> B): 0.5, 0, 2. Completeness (B -> A): 0.5, 0.
        m_a = m_dir.write("recon.xyz", "0 0 0\n1 0 0\n3 0 0\n");
        m_b = m_dir.write("truth.xyz", "0 0 0.5\n1 0 0\n");
        // A unit square at z = 0 and points 1 above its centre and on it.
        m_square = m_dir.write("square.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
        m_above = m_dir.write("above.xyz", "0.5 0.5 1\n0 0 0\n");
    }

    TempDir m_dir;
    std::string m_a, m_b, m_square, m_above;
};

TEST_F(CliEval, PointTargetsSummaryWithACap) {
    const std::string csv = (m_dir.path() / "eval.csv").string();
    const CliRun run = runCli({m_a, m_b, "--eval", "0.6,3", "--eval-cap", "1", "--eval-csv", csv, "--json"});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = Json::parse(run.out);
    EXPECT_EQ(j["mode"], "eval");
    EXPECT_EQ(j["target"], "points");
    const Json& e = j["eval"];
    EXPECT_EQ(e["reconstruction"], "a");
    EXPECT_EQ(e["ground_truth"], "b");
    EXPECT_EQ(e["cap"].get<double>(), 1.0);
    EXPECT_EQ(e["accuracy"]["count"].get<int>(), 3);
    EXPECT_EQ(e["accuracy"]["kept"].get<int>(), 2);  // 2 >= cap is dropped
    EXPECT_EQ(e["accuracy"]["mean"].get<double>(), 0.25);
    EXPECT_EQ(e["accuracy"]["median"].get<double>(), 0.25);
    EXPECT_EQ(e["accuracy"]["max"].get<double>(), 0.5);
    EXPECT_EQ(e["completeness"]["mean"].get<double>(), 0.25);
    EXPECT_EQ(e["chamfer"]["mean_of_means"].get<double>(), 0.25);
    EXPECT_EQ(e["chamfer"]["sum_of_means"].get<double>(), 0.5);
    EXPECT_EQ(e["chamfer"]["sum_of_mean_squares"].get<double>(), 0.25);
    ASSERT_EQ(e["thresholds"].size(), 2u);
    EXPECT_EQ(e["thresholds"][0]["threshold"].get<double>(), 0.6);
    EXPECT_DOUBLE_EQ(e["thresholds"][0]["precision"].get<double>(),
                     2.0 / 3.0);  // 2 is not < 0.6, despite the cap
    EXPECT_EQ(e["thresholds"][0]["recall"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(e["thresholds"][0]["fscore"].get<double>(), 0.8);
    EXPECT_EQ(e["thresholds"][1]["precision"].get<double>(), 1.0);

    std::ifstream in(csv);
    std::string header, row;
    ASSERT_TRUE(std::getline(in, header));
    EXPECT_EQ(header.rfind("threshold,precision,recall,fscore,accuracy_mean,", 0), 0u) << header;
    ASSERT_TRUE(std::getline(in, row));
    EXPECT_EQ(row.rfind("0.59999999999999998,0.66666666666666663,1,0.8", 0), 0u) << row;
    EXPECT_EQ(row.substr(row.rfind(',') + 1), "1");  // the cap
    ASSERT_TRUE(std::getline(in, row));
    EXPECT_FALSE(std::getline(in, row));
}

TEST_F(CliEval, SurfaceTargetMeasuresToTheTriangles) {
    const CliRun run = runCli({m_above, m_square, "--surface", "b", "--eval", "0.5", "--json"});
    ASSERT_EQ(run.exitCode, 0) << run;
    const Json j = Json::parse(run.out);
    EXPECT_EQ(j["target"], "surface");
    EXPECT_EQ(j["triangles"]["b"].get<int>(), 2);
    const Json& e = j["eval"];
    // Accuracy: 1 (above the centre; 1.2247 to the nearest vertex) and 0.
    EXPECT_EQ(e["accuracy"]["mean"].get<double>(), 0.5);
    EXPECT_EQ(e["accuracy"]["max"].get<double>(), 1.0);
    // Completeness: the four corners to A's points: 0, 1, 1 and 1.2247 (sorted).
    EXPECT_EQ(e["completeness"]["count"].get<int>(), 4);
    EXPECT_EQ(e["completeness"]["median"].get<double>(), 1.0);
    EXPECT_EQ(e["thresholds"][0]["recall"].get<double>(), 0.25);
    EXPECT_TRUE(e["cap"].is_null());
}

// The same on each GPU backend (lavapipe here), the validation layer on:
// the surface's per-point distances within their tolerance (these are
// exact: a vertex and a point above a face's centre), both directions on
// one device.
TEST_F(CliEval, SurfaceTargetOnEveryGpuBackend) {
    for (const char* backend : {"ray-query", "rt-pipeline"}) {
        const CliRun run = runCli({m_above, m_square, "--surface", "b", "--eval", "0.5", "--json",
                                   "--backend", backend, "--validation"});
        ASSERT_EQ(run.exitCode, 0) << run;
        const Json e = Json::parse(run.out)["eval"];
        EXPECT_NEAR(e["accuracy"]["mean"].get<double>(), 0.5, 1e-6) << backend;
        EXPECT_EQ(e["accuracy"]["max"].get<double>(), 1.0) << backend;
        EXPECT_EQ(e["completeness"]["count"].get<int>(), 4) << backend;
        EXPECT_NEAR(e["completeness"]["median"].get<double>(), 1.0, 1e-6) << backend;
        EXPECT_EQ(e["thresholds"][0]["recall"].get<double>(), 0.25) << backend;
        // The device named is the one opened (none: exit 4 naming it).
        const CliRun none = runCli(
            {m_above, m_square, "--surface", "b", "--eval", "0.5", "--backend", backend, "--device", "99"});
        EXPECT_EQ(none.exitCode, 4) << none;
        EXPECT_NE(none.err.find("device 99"), std::string::npos) << none;
    }
}

TEST_F(CliEval, SummaryText) {
    const CliRun run = runCli({m_a, m_b, "--eval", "0.6"});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_NE(run.out.find("reconstruction A  " + m_a), std::string::npos) << run;
    EXPECT_NE(run.out.find("F-score 0.800000"), std::string::npos) << run;
}

TEST_F(CliEval, BadValuesAreUsageErrorsNamingTheOption) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"--eval", "0"}, "'--eval'"},
        {{"--eval", "0.1,x"}, "'--eval'"},
        {{"--eval", "0.1,"}, "'--eval'"},
        {{"--eval", "inf"}, "'--eval'"},
        {{"--eval", "0.1", "--eval-cap", "-1"}, "'--eval-cap'"},
        {{"--eval", "0.1", "--eval-cap", "nan"}, "'--eval-cap'"},
        // 0 is not "no cap" here (that is no --eval-cap): "drop d >= 0" would drop every distance.
        {{"--eval", "0.1", "--eval-cap", "0"}, "leave --eval-cap out"},
        // A second list replaced the first silently.
        {{"--eval", "0.1", "--eval", "0.2"}, "'--eval' is given twice"},
        {{"--eval-cap", "1"}, "'--eval-cap'"},
        {{"--eval-csv", "x.csv"}, "'--eval-csv'"},
        {{"--eval", "0.1", "--surface", "a"}, "'--eval'"},
        {{"--eval", "0.1", "--surface", "both"}, "'--eval'"},
        {{"--eval", "0.1", "--directed"}, "'--eval'"},
        {{"--eval", "0.1", "--per-point"}, "'--eval'"},
    };
    for (const auto& [options, name] : cases) {
        std::vector<std::string> argv{m_a, m_b};
        argv.insert(argv.end(), options.begin(), options.end());
        const CliRun run = runCli(argv);
        EXPECT_EQ(run.exitCode, 2) << options[0] << " " << options[1] << run;
        EXPECT_NE(run.err.find(name), std::string::npos) << run;
        EXPECT_TRUE(run.out.empty()) << run;
    }
}

TEST_F(CliEval, UnwritableCsvIsExit5) {
    const CliRun run =
        runCli({m_a, m_b, "--eval", "0.6", "--eval-csv", (m_dir.path() / "missing" / "e.csv").string()});
    EXPECT_EQ(run.exitCode, 5) << run;
    EXPECT_NE(run.err.find("cannot write output"), std::string::npos) << run;
}

}  // namespace
}  // namespace rthdist::cli_test
