// cpu-index-bench: times the CPU backend's index build stage by stage (each
// set's adaptive order, then its target index) on two point files, and prints
// a hash of everything the build produced, so two builds of the library can
// be compared for identical output as well as for time. Not a test: no
// thresholds. Prints one JSON object (medians in ms, and every run).
//
//   cpu-index-bench A B [--threads T] [--runs N] [--bits K]
//
// The scale is the one rule of the backend (core::exactScale over both sets);
// the hash covers the order (keys and input indices), the gathered
// coordinates, the identical runs, and the index's arrays and BVH boxes.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "bench_median.hpp"
#include "core/index_space.hpp"
#include "core/stopwatch.hpp"
#include "cpu/target_index.hpp"
#include "rthdist/io.hpp"

using namespace rthdist;

namespace {

using core::Clock;
using core::msSince;

// User + system CPU time of the whole process (all threads), ms.
double cpuMs() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    auto ms = [](const timeval& t) { return double(t.tv_sec) * 1e3 + double(t.tv_usec) * 1e-3; };
    return ms(u.ru_utime) + ms(u.ru_stime);
}

// FNV-1a over raw bytes: identical builds give identical hashes.
struct Hash {
    uint64_t h = 1469598103934665603ull;
    template <class Vector>
    void add(const Vector& v) {
        const auto* p = reinterpret_cast<const unsigned char*>(v.data());
        for (size_t i = 0, n = v.size() * sizeof(v[0]); i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
        const uint64_t n = v.size();
        for (int i = 0; i < 8; ++i) h = (h ^ ((n >> (8 * i)) & 0xff)) * 1099511628211ull;
    }
};

uint64_t hashOf(const cpu::SetOrder& o, const cpu::TargetIndex& t) {
    Hash h;
    const size_t n = o.keyed.size();  // the order's coordinates without their padding
    h.add(o.keyed), h.add(std::span(o.x.data(), n)), h.add(std::span(o.y.data(), n));
    h.add(std::span(o.z.data(), n)), h.add(o.identical);
    h.add(t.x), h.add(t.y), h.add(t.z), h.add(t.original), h.add(t.bucketOf), h.add(t.cellKey);
    h.add(t.cellFirst), h.add(t.cellLo), h.add(t.cellHi), h.add(t.bucketFirst);
    for (const cpu::BoxLevel& level : t.levels) h.add(level.boxes);
    return h.h;
}

struct SetTimes {
    std::vector<double> order, index, cpu;  // wall of each stage, CPU time of both
    uint64_t hash = 0;
};

void printSet(const char* name, const SetTimes& s, bool last) {
    std::printf(
        "\"%s\":{\"order_ms\":%.3f,\"index_ms\":%.3f,\"cpu_ms\":%.3f,\"hash\":\"%016llx\",\"order_all\":[",
        name, median(s.order), median(s.index), median(s.cpu), static_cast<unsigned long long>(s.hash));
    for (size_t i = 0; i < s.order.size(); ++i) std::printf("%s%.3f", i ? "," : "", s.order[i]);
    std::printf("],\"index_all\":[");
    for (size_t i = 0; i < s.index.size(); ++i) std::printf("%s%.3f", i ? "," : "", s.index[i]);
    std::printf("]}%s", last ? "" : ",");
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> files;
    int threads = 0, runs = 5, bits = 0;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if ((arg == "--threads" || arg == "--runs" || arg == "--bits") && i + 1 < argc) {
            const int v = std::atoi(argv[++i]);
            (arg == "--threads" ? threads : arg == "--runs" ? runs : bits) = v;
        } else if (!arg.empty() && arg[0] != '-') {
            files.push_back(arg);
        } else {
            files.clear();
            break;
        }
    }
    if (files.size() != 2 || runs < 1) {
        std::fprintf(stderr, "usage: cpu-index-bench A B [--threads T] [--runs N] [--bits K]\n");
        return 2;
    }
    std::vector<std::vector<glm::vec3>> sets;
    for (const std::string& f : files) {
        auto loaded = io::loadPoints(f);
        if (!loaded || loaded.value().empty()) {
            std::fprintf(stderr, "cpu-index-bench: cannot use %s\n", f.c_str());
            return 1;
        }
        sets.push_back(std::move(loaded.value()));
    }
    const double scale =
        core::exactScale(std::max(core::largestMagnitude(sets[0]), core::largestMagnitude(sets[1])));
    SetTimes times[2];
    for (int r = 0; r < runs; ++r) {
        for (int s = 0; s < 2; ++s) {
            const double cpuStart = cpuMs();
            auto start = Clock::now();
            const cpu::SetOrder order = cpu::orderSet(sets[size_t(s)], scale, bits, threads);
            times[s].order.push_back(msSince(start));
            start = Clock::now();
            const cpu::TargetIndex index = cpu::buildTargetIndex(scale, order, threads);
            times[s].index.push_back(msSince(start));
            times[s].cpu.push_back(cpuMs() - cpuStart);
            if (r == 0) times[s].hash = hashOf(order, index);
        }
    }
    std::printf("{\"a\":\"%s\",\"b\":\"%s\",\"points\":[%zu,%zu],\"threads\":%d,\"runs\":%d,",
                files[0].c_str(), files[1].c_str(), sets[0].size(), sets[1].size(), threads, runs);
    printSet("set_a", times[0], false);
    printSet("set_b", times[1], true);
    std::printf("}\n");
    return 0;
}
