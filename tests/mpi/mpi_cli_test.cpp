// rthdist-mpi against rthdist: `mpirun -np N rthdist-mpi A B --json` prints
// the JSON object `rthdist A B --json` prints, but for timings_ms and the
// work counters (summed over ranks; counters.*.queries must match), and
// `bits` in spatial mode (each rank indexes its own slab); the same summary
// lines; the same exit codes and "rthdist: " messages. N = 1, 2, 3.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <filesystem>
#include <utility>

#include "cli/cli_runner.hpp"

namespace rthdist::cli_test {
namespace {

const std::string kMpiCli = RTHDIST_MPI_CLI_PATH;
const std::string kMpirun = RTHDIST_MPIEXEC;

// Runs argv[0] with the rest as arguments; stdout and stderr captured.
CliRun runArgv(const std::vector<std::string>& argv) { return runShell("exec" + quotedWords(argv)); }

CliRun runMpi(int np, const std::vector<std::string>& args) {
    std::vector<std::string> argv = {kMpirun, "--allow-run-as-root", "--oversubscribe",
                                     "-np",   std::to_string(np),    kMpiCli};
    argv.insert(argv.end(), args.begin(), args.end());
    return runArgv(argv);
}

// The JSON minus what legitimately differs between one process and N ranks.
nlohmann::json comparable(nlohmann::json j, bool spatial) {
    j.erase("timings_ms");
    j.erase("gpu_ms");  // device times (rthdist-mpi reports none)
    // The band's size depends on how the queries were split (its proof is the same).
    for (const char* d : {"a_to_b", "b_to_a"})
        if (j["certificate"][d].is_object()) j["certificate"][d].erase("band");
    for (const char* d : {"a_to_b", "b_to_a"}) {
        if (j["counters"][d].is_object()) j["counters"][d] = {{"queries", j["counters"][d]["queries"]}};
    }
    if (spatial) j.erase("bits");
    return j;
}

// A double XYZ pair at UTM-like coordinates (origin != 0 in both tools),
// millimetre jitter from a fixed LCG so that no two pairs tie: the GPU
// backends keep their own witness among exact ties (mpi_oracle_test.cpp).
std::pair<std::string, std::string> doubleFiles(const TempDir& dir) {
    uint64_t state = 0x2545F4914F6CDD1Dull;
    auto jitter = [&state] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double((state >> 33) % 500) * 0.001;
    };
    std::string a, b;
    for (int i = 0; i < 400; ++i) {
        char line[128];
        std::snprintf(line, sizeof line, "%.3f %.3f %.3f\n", 512000.0 + (i % 20) * 1.013 + jitter(),
                      5400000.0 + (i / 20) * 0.987 + jitter(), 100.0 + jitter());
        a += line;
        if (i % 3 == 0) {
            std::snprintf(line, sizeof line, "%.3f %.3f %.3f\n", 512000.5 + (i % 20) * 1.013 + jitter(),
                          5400000.0 + (i / 20) * 0.987 + jitter(), 100.25 + jitter());
            b += line;
        }
    }
    return {dir.write("a.xyz", a), dir.write("b.xyz", b)};
}

void expectSameJson(const std::vector<std::string>& args, const std::string& mode) {
    const CliRun one = runArgv([&] {
        std::vector<std::string> v = {kCli};
        v.insert(v.end(), args.begin(), args.end());
        return v;
    }());
    ASSERT_EQ(one.exitCode, 0) << one;
    const bool spatial = mode == "spatial";
    for (int np : {1, 2, 3}) {
        SCOPED_TRACE("np " + std::to_string(np) + " mode " + mode);
        std::vector<std::string> mpiArgs = args;
        mpiArgs.push_back("--mpi-mode=" + mode);
        const CliRun mpi = runMpi(np, mpiArgs);
        ASSERT_EQ(mpi.exitCode, 0) << mpi;
        EXPECT_EQ(comparable(parseJson(mpi), spatial), comparable(parseJson(one), spatial))
            << mpi.out << one.out;
    }
}

class MpiCliJson : public testing::TestWithParam<std::string> {};

TEST_P(MpiCliJson, SampleSameAsRthdist) {
    for (const char* mode : {"replicated", "spatial"})
        expectSameJson({kSampleA, kSampleB, "--json", "--backend", GetParam()}, mode);
}

TEST_P(MpiCliJson, DoubleInputSameAsRthdist) {
    const TempDir dir;
    const auto [a, b] = doubleFiles(dir);
    for (const char* mode : {"replicated", "spatial"})
        expectSameJson({a, b, "--json", "--backend", GetParam()}, mode);
}

// Two double pairs at UTM coordinates 3 m apart whose maximum the shifted
// frame's floats order the other way (a differential check, session 24:
// rthdist-mpi reported 2.9999994 confirmed, the exact H is 3.0000013): the
// ranks' near-maximum queries are settled in double, as one process does.
TEST_P(MpiCliJson, NearTiesOfDoublesAsRthdist) {
    const TempDir dir;
    const std::string a = dir.write("a.xyz",
                                    "512344.9999992 5403209.9999943 230.0000174\n"
                                    "512545.0000021 5403209.9999899 229.9999921\n");
    const std::string b = dir.write("b.xyz",
                                    "512347.9999986 5403210.0000173 230.00001559999998\n"
                                    "512548.0000034 5403209.999995 229.99999169999998\n");
    for (const char* mode : {"replicated", "spatial"})
        expectSameJson({a, b, "--json", "--backend", GetParam()}, mode);
    // The double brute force: each direction's largest nearest distance.
    const double pa[2][3] = {{512344.9999992, 5403209.9999943, 230.0000174},
                             {512545.0000021, 5403209.9999899, 229.9999921}};
    const double pb[2][3] = {{512347.9999986, 5403210.0000173, 230.00001559999998},
                             {512548.0000034, 5403209.999995, 229.99999169999998}};
    auto dist = [](const double* x, const double* y) {
        const double dx = x[0] - y[0], dy = x[1] - y[1], dz = x[2] - y[2];
        return std::sqrt(dx * dx + dy * dy + dz * dz);
    };
    double h = 0.0;
    for (int i = 0; i < 2; ++i) {
        h = std::max(h, std::min(dist(pa[i], pb[0]), dist(pa[i], pb[1])));
        h = std::max(h, std::min(dist(pb[i], pa[0]), dist(pb[i], pa[1])));
    }
    const nlohmann::json mpi = parseJson(runMpi(3, {a, b, "--json", "--backend", GetParam()}));
    EXPECT_EQ(mpi["hausdorff"].get<double>(), h);
    EXPECT_TRUE(mpi["certificate"]["a_to_b"]["confirmed"].get<bool>());
}

TEST_P(MpiCliJson, DirectedSameAsRthdist) {
    expectSameJson({kSampleB, kSampleA, "--json", "--directed", "--backend", GetParam()}, "spatial");
}

INSTANTIATE_TEST_SUITE_P(Backends, MpiCliJson, testing::Values("cpu", "ray-query"),
                         [](const testing::TestParamInfo<std::string>& info) {
                             return info.param == "cpu" ? std::string("Cpu") : std::string("RayQuery");
                         });

// The summary's lines but for timings, counters (work per rank) and the
// certificate (its band depends on the split; rthdist-mpi prints none).
std::string stableSummary(const std::string& text) {
    std::istringstream in(text);
    std::string line, out;
    while (std::getline(in, line)) {
        if (line.starts_with("time (ms)") || line.starts_with("counters") ||
            line.starts_with("           B->A") || line.starts_with("certificate"))
            continue;
        out += line + "\n";
    }
    return out;
}

TEST(MpiCli, SummarySameAsRthdist) {
    const CliRun one = runArgv({kCli, kSampleA, kSampleB, "--backend", "cpu"});
    ASSERT_EQ(one.exitCode, 0) << one;
    const CliRun mpi = runMpi(2, {kSampleA, kSampleB, "--backend", "cpu"});
    ASSERT_EQ(mpi.exitCode, 0) << mpi;
    EXPECT_EQ(stableSummary(mpi.out), stableSummary(one.out));
    EXPECT_NE(stableSummary(one.out).find("H(A,B) = "), std::string::npos);
}

// Exit code and the "rthdist: " line on stderr, as rthdist gives them.
void expectSameFailure(const std::vector<std::string>& args, int code) {
    std::vector<std::string> v = {kCli};
    v.insert(v.end(), args.begin(), args.end());
    const CliRun one = runArgv(v);
    ASSERT_EQ(one.exitCode, code) << one;
    const std::string firstLine = one.err.substr(0, one.err.find('\n'));
    ASSERT_TRUE(firstLine.starts_with("rthdist: ")) << one;
    for (int np : {1, 3}) {
        const CliRun mpi = runMpi(np, args);
        EXPECT_EQ(mpi.exitCode, code) << mpi;
        EXPECT_NE(mpi.err.find(firstLine), std::string::npos) << "expected: " << firstLine << "\n" << mpi;
        EXPECT_TRUE(mpi.out.empty()) << mpi;
    }
}

TEST(MpiCli, ExitCodesAndMessagesAsRthdist) {
    const TempDir dir;
    const std::string nan = dir.write("nan.xyz", "0 0 0\n1 1 1\n2 nan 2\n3 3 3\n");
    const std::string empty = dir.write("empty.xyz", "");
    expectSameFailure({kSampleA, (dir.path() / "missing.ply").string()}, 3);
    expectSameFailure({kSampleA, nan, "--backend", "cpu"}, 3);
    expectSameFailure({empty, kSampleA}, 3);
    expectSameFailure({kSampleA}, 2);
    expectSameFailure({kSampleA, kSampleB, "--bits", "9"}, 2);
    expectSameFailure({kSampleA, kSampleB, "--bogus"}, 2);
}

TEST(MpiCli, UnsupportedOptionsAreUsageErrors) {
    for (const std::vector<std::string>& extra : {std::vector<std::string>{"--verify"},
                                                  {"--per-point"},
                                                  {"--png", "x.png"},
                                                  {"--out-csv=p"},
                                                  {"--devices", "0,1"}}) {
        std::vector<std::string> args = {kSampleA, kSampleB};
        args.insert(args.end(), extra.begin(), extra.end());
        const CliRun mpi = runMpi(2, args);
        EXPECT_EQ(mpi.exitCode, 2) << mpi;
        const std::string name = extra[0].substr(0, extra[0].find('='));
        EXPECT_NE(mpi.err.find("rthdist: option '" + name + "' is not supported by rthdist-mpi"),
                  std::string::npos)
            << mpi;
    }
    const CliRun bad = runMpi(1, {kSampleA, kSampleB, "--mpi-mode", "halo"});
    EXPECT_EQ(bad.exitCode, 2) << bad;
    EXPECT_NE(bad.err.find("unknown MPI mode 'halo'"), std::string::npos) << bad;
}

// ---- ranks that disagree, inputs past the float search's limits (issue 36) ----------

// mpirun with one rank group per entry of `groups` ({ranks, working directory,
// arguments}: MPMD, `a : b`), bounded by `timeout` so that a hang fails the
// test (exit 124) instead of stalling it.
struct RankGroup {
    int ranks = 1;
    std::string dir;
    std::vector<std::string> args;
};

CliRun runGroups(const std::vector<RankGroup>& groups) {
    std::vector<std::string> argv = {"timeout",        "-s", "KILL", "120", kMpirun, "--allow-run-as-root",
                                     "--oversubscribe"};
    for (size_t g = 0; g < groups.size(); ++g) {
        if (g > 0) argv.push_back(":");
        argv.insert(argv.end(), {"-np", std::to_string(groups[g].ranks), "-wdir", groups[g].dir, kMpiCli});
        argv.insert(argv.end(), groups[g].args.begin(), groups[g].args.end());
    }
    return runArgv(argv);
}

class MpiAgreement : public testing::TestWithParam<std::string> {};

// The same relative path names other contents on the last rank(s): exit 3 on
// every rank naming the file and the ranks, never an H (it was 0 with an H of
// neither input). Before any engine: one backend.
TEST(MpiAgreementCpu, DifferentFileContentsAreExit3) {
    const TempDir dir;
    std::filesystem::create_directories(dir.path() / "one");
    std::filesystem::create_directories(dir.path() / "two");
    const std::string one = (dir.path() / "one").string(), two = (dir.path() / "two").string();
    dir.write("one/b.xyz", "0 0 0\n1 0 0\n2 0 0\n");
    dir.write("two/b.xyz", "0 0 0\n1 0 0\n2 0 7\n");  // same count, other values
    dir.write("one/c.xyz", "0 0 0\n1 0 0\n");
    dir.write("two/c.xyz", "0 0 0\n1 0 0\n2 0 0\n");  // another count
    for (int np : {2, 3}) {
        for (const std::string file : {"b.xyz", "c.xyz"}) {
            SCOPED_TRACE("np " + std::to_string(np) + " " + file);
            const std::vector<std::string> args = {"--backend", "cpu", "--json", kSampleA, file};
            const CliRun run = runGroups({{np - 1, one, args}, {1, two, args}});
            EXPECT_EQ(run.exitCode, 3) << run;
            EXPECT_TRUE(run.out.empty()) << run;
            EXPECT_NE(run.err.find("rthdist: " + file + ": the ranks read different contents: rank 0 read "),
                      std::string::npos)
                << run;
            EXPECT_NE(run.err.find("rank " + std::to_string(np - 1) + " read "), std::string::npos) << run;
        }
    }
}

// An option on one rank only (the last): exit 2 on every rank, never a hang.
// Before any engine: one backend.
TEST(MpiAgreementCpu, OptionOnOneRankIsExit2) {
    const TempDir dir;
    const std::string cwd = dir.path().string();
    const std::vector<std::string> args = {"--backend", "cpu", kSampleA, kSampleB};
    for (int np : {2, 3}) {
        for (const std::string extra : {"--json", "--help"}) {
            SCOPED_TRACE("np " + std::to_string(np) + " " + extra);
            std::vector<std::string> more = args;
            more.push_back(extra);
            const CliRun run = runGroups({{np - 1, cwd, args}, {1, cwd, more}});
            EXPECT_EQ(run.exitCode, 2) << run;
            EXPECT_TRUE(run.out.empty()) << run;
            EXPECT_NE(run.err.find("rthdist: rank " + std::to_string(np - 1) +
                                   " was started with other arguments than rank 0"),
                      std::string::npos)
                << run;
        }
    }
}

// Coordinates past the float search's limits: exit 3 naming the file and the
// limit, as rthdist (core/input_limits.hpp), on every rank count.
TEST_P(MpiAgreement, InputLimitsAsRthdist) {
    const TempDir dir;
    const std::string big = dir.write("big.xyz", "1e308 0 0\n0.1 0 0\n");
    const std::string small = dir.write("small.xyz", "0 0 0\n1 0 0\n2 0 0\n");
    const std::string tiny = dir.write("tiny.xyz", "1e-160 0 0\n0 2e-160 0\n");
    const std::string zero = dir.write("zero.xyz", "0 0 0\n");
    for (int np : {2, 3}) {
        SCOPED_TRACE("np " + std::to_string(np));
        for (const auto& [files, words] :
             {std::pair{std::vector{big, small},
                        std::vector<std::string>{"rthdist: point set A (" + big + ")", "x = 1e+308",
                                                 "3.40282347e+38"}},
              std::pair{std::vector{tiny, zero},
                        std::vector<std::string>{"rthdist: point sets A and B (" + tiny + ", " + zero + ")",
                                                 "1.17549435e-38"}}}) {
            const CliRun run =
                runGroups({{np, dir.path().string(), {"--backend", GetParam(), files[0], files[1]}}});
            EXPECT_EQ(run.exitCode, 3) << run;
            EXPECT_TRUE(run.out.empty()) << run;
            for (const std::string& w : words)
                EXPECT_NE(run.err.find(w), std::string::npos) << w << "\n" << run;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, MpiAgreement, testing::Values("cpu", "ray-query"),
                         [](const testing::TestParamInfo<std::string>& info) {
                             return info.param == "cpu" ? std::string("Cpu") : std::string("RayQuery");
                         });

}  // namespace
}  // namespace rthdist::cli_test
