// Runs the rthdist binary as a child process and captures its exit code,
// stdout and stderr; writes fixture files into a private temp directory.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rthdist::cli_test {

inline const std::string kCli = RTHDIST_CLI_PATH;
inline const std::string kDataDir = RTHDIST_DATA_DIR;
inline const std::string kSampleA = kDataDir + "/bunny.ply";
inline const std::string kSampleB = kDataDir + "/bunny_res2.ply";

// Single-quotes for /bin/sh: every byte literal, ' written as '\''.
inline std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) {
        if (c == '\'') {
            out += "'\\''";
        } else {
            out += c;
        }
    }
    return out + "'";
}

inline std::string readFile(const std::filesystem::path& path) {
    std::ifstream f(path, std::ios::binary);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

// A fresh directory under $TMPDIR, removed with everything in it.
class TempDir {
public:
    TempDir() {
        std::string pattern = (std::filesystem::temp_directory_path() / "rthdist-cli-XXXXXX").string();
        if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
        m_path = pattern;
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(m_path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const { return m_path; }

    // Writes `bytes` to a file in the directory and returns its path.
    std::string write(const std::string& name, const std::string& bytes) const {
        const std::filesystem::path p = m_path / name;
        std::ofstream f(p, std::ios::binary);
        f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        return p.string();
    }

private:
    std::filesystem::path m_path;
};

struct CliRun {
    int exitCode = -1;
    std::string out;
    std::string err;
};

inline std::ostream& operator<<(std::ostream& os, const CliRun& r) {
    return os << "exit " << r.exitCode << "\n--- stdout ---\n" << r.out << "--- stderr ---\n" << r.err;
}

// Runs a /bin/sh command line with stdin closed; its stdout, stderr and exit
// code (128 + the signal when a signal ended it).
inline CliRun runShell(std::string command) {
    static int counter = 0;
    static const TempDir errDir;
    const std::string errPath = (errDir.path() / ("stderr-" + std::to_string(counter++))).string();
    command += " 2>" + shellQuote(errPath) + " </dev/null";

    CliRun run;
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) throw std::runtime_error("popen failed");
    char buf[4096];
    size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) run.out.append(buf, n);
    const int status = pclose(pipe);
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    run.err = readFile(errPath);
    return run;
}

// The words, each quoted for /bin/sh, each after a space.
inline std::string quotedWords(const std::vector<std::string>& words) {
    std::string out;
    for (const std::string& w : words) out += " " + shellQuote(w);
    return out;
}

// `shellPrefix` runs in the same /bin/sh before the CLI (e.g. "ulimit -f 8;");
// `wrapper` is a command that runs the CLI (e.g. "timeout -s TERM 2").
inline CliRun runCli(const std::vector<std::string>& args, const std::string& shellPrefix = "",
                     const std::string& wrapper = "") {
    return runShell(shellPrefix + " exec " + wrapper + " " + shellQuote(kCli) + quotedWords(args));
}

// Parses stdout as one JSON document; a test failure (and null) when it is not.
inline nlohmann::json parseJson(const CliRun& run) {
    nlohmann::json j = nlohmann::json::parse(run.out, nullptr, /*allow_exceptions=*/false);
    EXPECT_FALSE(j.is_discarded()) << "stdout is not valid JSON\n" << run;
    return j.is_discarded() ? nlohmann::json() : j;
}

// Exact brute force over float input in double, for small fixtures.
inline double directedBrute(const std::vector<std::array<float, 3>>& q,
                            const std::vector<std::array<float, 3>>& t) {
    double h = 0.0;
    for (const auto& a : q) {
        double best = INFINITY;
        for (const auto& b : t) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k) s += (double(a[k]) - double(b[k])) * (double(a[k]) - double(b[k]));
            best = std::min(best, s);
        }
        h = std::max(h, std::sqrt(best));
    }
    return h;
}

}  // namespace rthdist::cli_test
