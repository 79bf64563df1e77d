// rthdist-mpi against rthdist: `mpirun -np N rthdist-mpi A B --json` prints
// the JSON object `rthdist A B --json` prints, but for timings_ms and the
// work counters (summed over ranks; counters.*.queries must match), and
// `bits` in spatial mode (each rank indexes its own slab); the same summary
// lines; the same exit codes and "rthdist: " messages. N = 1, 2, 3.
#include <gtest/gtest.h>

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

TEST_P(MpiCliJson, DirectedSameAsRthdist) {
    expectSameJson({kSampleB, kSampleA, "--json", "--directed", "--backend", GetParam()}, "spatial");
}

INSTANTIATE_TEST_SUITE_P(Backends, MpiCliJson, testing::Values("cpu", "ray-query"),
                         [](const testing::TestParamInfo<std::string>& info) {
                             return info.param == "cpu" ? std::string("Cpu") : std::string("RayQuery");
                         });

// The summary's lines but for timings and counters (work per rank).
std::string stableSummary(const std::string& text) {
    std::istringstream in(text);
    std::string line, out;
    while (std::getline(in, line)) {
        if (line.starts_with("time (ms)") || line.starts_with("counters") ||
            line.starts_with("           B->A"))
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

}  // namespace
}  // namespace rthdist::cli_test
