// Output files of the CLI (--out-csv, --out-ply, --png, --histogram-png):
// written to a temporary file and renamed into place, so a failure or a
// signal never leaves a partial file under the final name nor destroys an
// earlier good one, and no *.tmp stays behind; a write failure exits 5 with
// the file and the system's reason. The tests run as root too, so every
// failure here is one that root cannot write through: a parent that is a
// regular file (ENOTDIR), /dev/full (ENOSPC), a file size limit (EFBIG).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cli_runner.hpp"

namespace rthdist::cli_test {
namespace {

namespace fs = std::filesystem;

constexpr char kA[] = "0 0 0\n1 0 0\n3 0 0\n";
constexpr char kB[] = "0 0 0\n0 2 0\n";
constexpr char kEarlier[] = "an earlier good file\n";

// The CLI's file size limit for the failing-write tests: 8 blocks of 512
// bytes (dash's unit), far below the sample's outputs. SIGXFSZ is ignored so
// that the write fails with EFBIG instead of killing the process.
const std::string kSmallFileLimit = "trap '' XFSZ; ulimit -f 8;";

class CliOutput : public ::testing::Test {
protected:
    TempDir m_dir;
    std::string m_a = m_dir.write("a.xyz", kA);
    std::string m_b = m_dir.write("b.xyz", kB);
    std::string path(const std::string& name) const { return (m_dir.path() / name).string(); }

    // Names of the files in the directory that end in ".tmp".
    std::vector<std::string> tempFiles() const {
        std::vector<std::string> found;
        for (const auto& e : fs::directory_iterator(m_dir.path())) {
            const std::string name = e.path().filename().string();
            if (name.size() >= 4 && name.compare(name.size() - 4, 4, ".tmp") == 0) found.push_back(name);
        }
        return found;
    }

    void expectOutputError(const CliRun& run, const std::string& file, const std::string& reason) {
        EXPECT_EQ(run.exitCode, 5) << run;
        EXPECT_TRUE(run.out.empty()) << run;
        EXPECT_EQ(run.err.rfind("rthdist: cannot write output '" + file + "'", 0), 0u) << run;
        EXPECT_NE(run.err.find(reason), std::string::npos) << run;
        EXPECT_EQ(tempFiles(), std::vector<std::string>()) << run;
    }
};

TEST_F(CliOutput, ParentIsARegularFile) {
    const std::string prefix = m_a + "/d";  // a.xyz is a file: ENOTDIR, also for root
    expectOutputError(runCli({"--backend", "cpu", "--out-csv", prefix, m_a, m_b}), prefix + "_a.csv",
                      "Not a directory");
}

TEST_F(CliOutput, MissingDirectory) {
    const std::string png = path("missing-dir/p.png");
    expectOutputError(runCli({"--backend", "cpu", "--png", png, "--render", "software", m_a, m_b}), png,
                      "No such file or directory");
}

// /dev/full is written in place (never replaced by a regular file) and fails.
TEST_F(CliOutput, FullDeviceIsReported) {
    expectOutputError(runCli({"--backend", "cpu", "--histogram-png", "/dev/full", m_a, m_b}), "/dev/full",
                      "No space left on device");
    struct stat st {};
    ASSERT_EQ(::stat("/dev/full", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
}

// A per-point file that is a link to /dev/full: the link is followed.
TEST_F(CliOutput, FullDeviceThroughASymlink) {
    fs::create_symlink("/dev/full", path("d_a.csv"));
    expectOutputError(runCli({"--backend", "cpu", "--out-csv", path("d"), m_a, m_b}), path("d_a.csv"),
                      "No space left on device");
    EXPECT_TRUE(fs::is_symlink(path("d_a.csv")));
}

// Each output in turn, over an earlier good file, with a file size limit the
// output exceeds: exit 5 naming it, the earlier file intact, no *.tmp.
TEST_F(CliOutput, EarlierFileSurvivesAFailedWrite) {
    struct Case {
        const char* option;
        std::string argument;
        std::string file;
    };
    const std::vector<Case> cases = {
        {"--out-csv", path("d"), path("d_a.csv")},
        {"--out-ply", path("d"), path("d_a.ply")},
        {"--png", path("p.png"), path("p.png")},
        {"--histogram-png", path("h.png"), path("h.png")},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.option);
        m_dir.write(fs::path(c.file).filename().string(), kEarlier);
        const CliRun run =
            runCli({"--backend", "cpu", "--render", "software", c.option, c.argument, kSampleA, kSampleB},
                   kSmallFileLimit);
        expectOutputError(run, c.file, "File too large");
        EXPECT_EQ(readFile(c.file), kEarlier);
    }
}

TEST_F(CliOutput, SuccessLeavesNoTempFilesAndUsualModes) {
    m_dir.write("d_b.csv", kEarlier);
    ASSERT_EQ(::chmod(path("d_b.csv").c_str(), 0600), 0);
    const CliRun run =
        runCli({"--backend", "cpu", "--render", "software", "--out-csv", path("d"), "--out-ply", path("d"),
                "--png", path("p.png"), "--histogram-png", path("h.png"), m_a, m_b},
               "umask 022;");
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_EQ(tempFiles(), std::vector<std::string>());
    for (const char* name : {"d_a.csv", "d_a.ply", "d_b.ply", "p.png", "h.png"}) {
        SCOPED_TRACE(name);
        EXPECT_EQ(fs::status(path(name)).permissions(), fs::perms(0644));  // as fopen would create it
    }
    EXPECT_EQ(fs::status(path("d_b.csv")).permissions(), fs::perms(0600));  // replaced, mode kept
    EXPECT_EQ(readFile(path("d_b.csv")), "index,x,y,z,distance,nearest\n0,0,0,0,0,0\n1,0,2,0,2,0\n");
}

TEST_F(CliOutput, SymlinkIsKeptAndItsTargetReplaced) {
    m_dir.write("real.csv", kEarlier);
    fs::create_symlink("real.csv", path("d_a.csv"));
    const CliRun run = runCli({"--backend", "cpu", "--out-csv", path("d"), m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_TRUE(fs::is_symlink(path("d_a.csv")));
    EXPECT_EQ(readFile(path("real.csv")),
              "index,x,y,z,distance,nearest\n0,0,0,0,0,0\n1,1,0,0,1,0\n2,3,0,0,3,0\n");
}

// The CSV's coordinates are the input's: a double file's as doubles (two
// points 2 cm apart at UTM coordinates were one float value apart).
TEST_F(CliOutput, CsvCoordinatesKeepTheInputsPrecision) {
    const std::string a =
        m_dir.write("utm_a.xyz", "512345.12 5412345.51 100.25\n512345.14 5412345.53 100.25\n");
    const std::string b = m_dir.write("utm_b.xyz", "512345.12 5412345.51 100.25\n");
    const CliRun run = runCli({"--backend", "cpu", "--out-csv", path("u"), a, b});
    ASSERT_EQ(run.exitCode, 0) << run;
    const std::string csv = readFile(path("u_a.csv"));
    EXPECT_NE(csv.find("\n0,512345.12,5412345.51,100.25,0,0\n"), std::string::npos) << csv;
    EXPECT_NE(csv.find("\n1,512345.14,5412345.53,100.25,"), std::string::npos) << csv;
}

// A link whose target does not exist yet (in an existing directory, through
// a second link): the target is created and the links kept, not replaced.
TEST_F(CliOutput, DanglingSymlinkCreatesItsTarget) {
    fs::create_directory(path("t"));
    fs::create_symlink("t/hop.csv", path("d_a.csv"));
    fs::create_symlink("new.csv", path("t/hop.csv"));
    const CliRun run = runCli({"--backend", "cpu", "--out-csv", path("d"), m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_TRUE(fs::is_symlink(path("d_a.csv")));
    EXPECT_TRUE(fs::is_symlink(path("t/hop.csv")));
    EXPECT_EQ(readFile(path("t/new.csv")),
              "index,x,y,z,distance,nearest\n0,0,0,0,0,0\n1,1,0,0,1,0\n2,3,0,0,3,0\n");
}

// The temporary name must still fit NAME_MAX (255) when the final one does.
TEST_F(CliOutput, LongestFileNameWorks) {
    const std::string name = std::string(251, 'p') + ".png";
    const CliRun run = runCli({"--backend", "cpu", "--histogram-png", path(name), m_a, m_b});
    ASSERT_EQ(run.exitCode, 0) << run;
    EXPECT_TRUE(fs::is_regular_file(path(name)));
    EXPECT_EQ(tempFiles(), std::vector<std::string>());
}

// A large input whose --out-csv is about 14 MB (A: 400,000 grid points in a
// fixed pattern; B: 4 points).
struct BigInput {
    std::string a, b;
};
BigInput writeBigInput(const TempDir& dir) {
    std::string big;
    big.reserve(400000 * 24);
    char line[64];
    for (int i = 0; i < 400000; ++i) {
        std::snprintf(line, sizeof line, "%d %d %d\n", i % 97, (i / 97) % 89, i / (97 * 89));
        big += line;
    }
    return {dir.write("big.xyz", big), dir.write("four.xyz", "0 0 0\n50 0 0\n0 50 0\n0 0 50\n")};
}

// SIGTERM delivered exactly when the CLI enters a system call of the output
// phase (strace's signal injection; the first write(2) of the run is the
// output's): the earlier file survives or the new one is complete, no *.tmp.
// Before the fix, SIGTERM at the first write left d_a.csv cut (truncated by
// fopen, half written).
TEST_F(CliOutput, SigtermAtEachOutputStep) {
    if (std::system("strace -o /dev/null true >/dev/null 2>&1") != 0) {
        GTEST_SKIP() << "strace (Debian package strace) missing or not permitted to trace";
    }
    const BigInput in = writeBigInput(m_dir);
    const std::vector<std::string> args = {"--out-csv", path("d"), "--backend", "cpu", "--quiet", in.a, in.b};
    const CliRun full = runCli(args);
    ASSERT_EQ(full.exitCode, 0) << full;
    const std::string complete = readFile(path("d_a.csv"));
    for (const char* call : {"write", "fsync", "rename"}) {
        SCOPED_TRACE(call);
        m_dir.write("d_a.csv", kEarlier);
        fs::remove(path("d_b.csv"));
        const std::string c = call;
        const CliRun run = runCli(
            args, "", "strace -f -o /dev/null -e trace=" + c + " -e inject=" + c + ":signal=TERM:when=1");
        EXPECT_EQ(run.exitCode, 128 + SIGTERM) << run;
        const std::string got = readFile(path("d_a.csv"));
        EXPECT_TRUE(got == kEarlier || got == complete) << "d_a.csv cut at " << got.size() << " bytes";
        EXPECT_FALSE(fs::exists(path("d_b.csv")));
        EXPECT_EQ(tempFiles(), std::vector<std::string>());
    }
}

// SIGTERM at several moments of the output phase of a large --out-csv: each
// file is afterwards absent, its complete content or the earlier file, never
// cut, and no *.tmp is left. The moments spread over the window between the
// end of the computation and the end of a full run, measured first.
TEST_F(CliOutput, SigtermNeverLeavesACutFile) {
    const BigInput in = writeBigInput(m_dir);
    const std::string a = in.a, b = in.b;
    const std::vector<std::string> computeOnly = {"--backend", "cpu", "--per-point", "--quiet", a, b};
    std::vector<std::string> withCsv = computeOnly;
    withCsv.insert(withCsv.begin(), {"--out-csv", path("d")});

    using Clock = std::chrono::steady_clock;
    auto timed = [](const std::vector<std::string>& args) {
        const Clock::time_point t0 = Clock::now();
        const CliRun run = runCli(args);
        EXPECT_EQ(run.exitCode, 0) << run;
        return std::chrono::duration<double>(Clock::now() - t0).count();
    };
    const double computeSeconds = timed(computeOnly);
    const double fullSeconds = timed(withCsv);
    const std::string completeA = readFile(path("d_a.csv")), completeB = readFile(path("d_b.csv"));
    ASSERT_GT(completeA.size(), 1000000u);

    constexpr int kMoments = 8;
    for (int k = 0; k < kMoments; ++k) {
        const double at = computeSeconds + (fullSeconds - computeSeconds) * (k + 0.5) / kMoments;
        char seconds[32];
        std::snprintf(seconds, sizeof seconds, "%.3f", std::max(at, 0.01));
        SCOPED_TRACE(std::string("SIGTERM after ") + seconds + " s");
        m_dir.write("d_a.csv", kEarlier);
        fs::remove(path("d_b.csv"));
        // `timeout` sends SIGTERM to the CLI and exits 124 when it fired.
        (void)runCli(withCsv, "", std::string("timeout -s TERM ") + seconds);
        const std::string gotA = readFile(path("d_a.csv"));
        EXPECT_TRUE(gotA == kEarlier || gotA == completeA) << "d_a.csv cut at " << gotA.size() << " bytes";
        if (fs::exists(path("d_b.csv"))) {
            const std::string gotB = readFile(path("d_b.csv"));
            EXPECT_EQ(gotB.size(), completeB.size()) << "d_b.csv cut";
        }
        EXPECT_EQ(tempFiles(), std::vector<std::string>());
    }
}

}  // namespace
}  // namespace rthdist::cli_test
