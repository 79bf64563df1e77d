// rthdist-load-bench: how fast the loaders turn a file into points, from the
// page cache (issue 14's "loaders at disk speed").
//
//   rthdist-load-bench FILE... [--runs 7] [--warmup 2] [--threads N] [--floats] [--las-classes 2,6]
//
// Per file: --warmup untimed loads (they also bring the file into the page
// cache), then --runs timed rthdist::io::loadPointCloud calls (what the CLI
// calls, on --threads parsing threads, 0 every hardware thread; --floats:
// loadPoints, rounded to float32). Alongside, the same
// number of plain read()s of the whole file into one buffer: what the page
// cache itself delivers on this machine. Prints one JSON object per file
// (times in seconds, MB = 1e6 bytes of the file as stored on disk;
// cpu_median_s: user + system CPU seconds of a load, all threads: what a
// load costs whatever else runs on the machine).
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "rthdist/io.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// CPU seconds (user + system, every thread) this process has used so far.
double cpuSeconds() {
    rusage u{};
    ::getrusage(RUSAGE_SELF, &u);
    auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * t.tv_usec; };
    return seconds(u.ru_utime) + seconds(u.ru_stime);
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    if (v.empty()) return 0.0;
    const size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Settings {
    int runs = 7;
    int warmup = 2;
    bool floats = false;
    unsigned threads = 0;
    std::vector<int> lasClasses;
};

// One load; the point count and precision, or the loader's error.
struct Loaded {
    size_t points = 0;
    std::string precision;
    std::string error;
};

Loaded loadOnce(const std::string& path, const Settings& s) {
    if (s.floats) {
        auto r = rthdist::io::loadPoints(path);
        if (!r) return {0, "", r.error().message};
        return {r->size(), "float32", ""};
    }
    rthdist::io::LoadOptions options;
    options.lasClasses = s.lasClasses;
    options.threads = s.threads;
    auto r = rthdist::io::loadPointCloud(path, options);
    if (!r) return {0, "", r.error().message};
    return {r->size(), r->scalar == rthdist::Scalar::kFloat64 ? "float64" : "float32", ""};
}

// Seconds to read() the whole file into a buffer allocated beforehand.
double readSeconds(const std::string& path, std::vector<char>& buffer) {
    const Clock::time_point t0 = Clock::now();
    const int fd = ::open(path.c_str(), O_RDONLY);
    if (fd < 0) return -1.0;
    size_t got = 0;
    ssize_t n = 0;
    while (got < buffer.size() && (n = ::read(fd, buffer.data() + got, buffer.size() - got)) > 0) got += n;
    ::close(fd);
    return got == buffer.size() ? secondsSince(t0) : -1.0;
}

nlohmann::ordered_json benchFile(const std::string& path, const Settings& s) {
    const double bytes = static_cast<double>(std::filesystem::file_size(path));
    Loaded loaded;
    for (int i = 0; i < s.warmup; ++i) loaded = loadOnce(path, s);
    std::vector<double> load;
    std::vector<double> cpu;
    std::vector<double> read;
    std::vector<char> buffer(static_cast<size_t>(bytes));
    for (int i = 0; i < s.runs; ++i) {
        const double cpu0 = cpuSeconds();
        const Clock::time_point t0 = Clock::now();
        loaded = loadOnce(path, s);
        load.push_back(secondsSince(t0));
        cpu.push_back(cpuSeconds() - cpu0);
        read.push_back(readSeconds(path, buffer));
        if (!loaded.error.empty()) break;
    }
    const double t = median(load);
    nlohmann::ordered_json j = {{"file", path},
                                {"bytes", bytes},
                                {"points", loaded.points},
                                {"precision", loaded.precision},
                                {"entry", s.floats ? "loadPoints" : "loadPointCloud"},
                                {"hardware_threads", std::thread::hardware_concurrency()},
                                {"threads", s.threads},
                                {"runs", load.size()},
                                {"warmup", s.warmup},
                                {"median_s", t},
                                {"min_s", *std::min_element(load.begin(), load.end())},
                                {"max_s", *std::max_element(load.begin(), load.end())},
                                {"mb_per_s", bytes / 1e6 / t},
                                {"points_per_s", static_cast<double>(loaded.points) / t},
                                {"cpu_median_s", median(cpu)},
                                {"read_median_s", median(read)},
                                {"read_mb_per_s", bytes / 1e6 / median(read)}};
    if (!loaded.error.empty()) j["error"] = loaded.error;
    return j;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"rthdist-load-bench: loader throughput from the page cache, as JSON"};
    std::vector<std::string> files;
    Settings s;
    app.add_option("files", files, "point files")->required()->check(CLI::ExistingFile);
    app.add_option("--runs", s.runs, "timed loads per file")->check(CLI::Range(1, 1000));
    app.add_option("--warmup", s.warmup, "untimed loads first")->check(CLI::Range(0, 100));
    app.add_option("--threads", s.threads, "parsing threads per load (0: every hardware thread)")
        ->check(CLI::Range(0, 4096));
    app.add_flag("--floats", s.floats, "time loadPoints (float32) instead of loadPointCloud");
    app.add_option("--las-classes", s.lasClasses, "LAS classification filter")->delimiter(',');
    CLI11_PARSE(app, argc, argv);
    int status = 0;
    for (const std::string& f : files) {
        const nlohmann::ordered_json j = benchFile(f, s);
        if (j.contains("error")) status = 1;
        std::cout << j.dump() << std::endl;
    }
    return status;
}
