// pieces-bench: times the out-of-core route's partition of a pair into pieces
// in space (api::SpatialPieces::partition) pass by pass, as a call under
// `--memory-budget MIB` on one device cuts it, and prints a hash of what it
// produced, so two builds (or two settings) can be compared for identical
// pieces as well as for time. Not a test: no thresholds. One JSON object:
// medians in ms and every run.
//
//   pieces-bench A B [--budget-mib M] [--threads T] [--runs N]
//
// The box and the scale are the Engine's (the exact box of both sets as
// given, core::exactScale of its largest magnitude); the pieces' order is
// the route's without per-point output (PieceOrder::kBlocks, no cells kept).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "api/out_of_core.hpp"
#include "api/spatial_pieces.hpp"
#include "bench_median.hpp"
#include "core/index_space.hpp"
#include "core/stopwatch.hpp"
#include "rthdist/io.hpp"

using namespace rthdist;

namespace {

// FNV-1a over 8-byte words (a tail byte-wise), with each array's length:
// identical partitions give identical hashes, at memory speed (a byte-wise
// pass took ~10 s a run at 700M points).
struct Hash {
    uint64_t h = 1469598103934665603ull;
    void mix(uint64_t w) { h = (h ^ w) * 1099511628211ull; }
    template <class Vector>
    void add(const Vector& v) {
        const auto* p = reinterpret_cast<const unsigned char*>(v.data());
        const size_t n = v.size() * sizeof(v[0]);
        size_t i = 0;
        for (; i + 8 <= n; i += 8) {
            uint64_t w;
            std::memcpy(&w, p + i, 8);
            mix(w);
        }
        for (; i < n; ++i) mix(p[i]);
        mix(uint64_t(v.size()));
    }
};

uint64_t hashOf(const api::SpatialPieces& p) {
    Hash h;
    for (int s = 0; s < 2; ++s) {
        const api::SpatialPieces::Set& set = p.set(s);
        h.add(set.points), h.add(set.input), h.add(set.start), h.add(set.blockStart);
    }
    return h.h;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> files;
    int threads = 0, runs = 3;
    uint64_t budgetMib = 22400;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if ((arg == "--threads" || arg == "--runs" || arg == "--budget-mib") && i + 1 < argc) {
            const long long v = std::atoll(argv[++i]);
            if (arg == "--threads") threads = int(v);
            if (arg == "--runs") runs = int(v);
            if (arg == "--budget-mib") budgetMib = uint64_t(v);
        } else if (!arg.empty() && arg[0] != '-') {
            files.push_back(arg);
        } else {
            files.clear();
            break;
        }
    }
    if (files.size() != 2 || runs < 1 || budgetMib == 0) {
        std::fprintf(stderr, "usage: pieces-bench A B [--budget-mib M] [--threads T] [--runs N]\n");
        return 2;
    }
    std::vector<std::vector<glm::vec3>> sets;
    for (const std::string& f : files) {
        auto loaded = io::loadPoints(f);
        if (!loaded || loaded.value().empty()) {
            std::fprintf(stderr, "pieces-bench: cannot use %s\n", f.c_str());
            return 1;
        }
        sets.push_back(std::move(loaded.value()));
    }
    // Both sets are non-empty (checked above).
    const core::Bounds boxA = core::boundsOf(sets[0]), boxB = core::boundsOf(sets[1]);
    const core::Bounds box{glm::min(boxA.lo, boxB.lo), glm::max(boxA.hi, boxB.hi)};
    const double scale = core::exactScale(core::largestMagnitude(box));
    // One lane's limits (api::computeWithin): a tile of half a call each.
    const uint64_t perCall = (budgetMib << 20) / api::kBytesPerPoint;
    const uint64_t tile = std::min(perCall / 2, api::kMaxCallPoints);
    const api::PieceLimits limits{tile, tile};

    std::vector<double> box_ms, keys, plan, scatter, total;
    uint64_t hash = 0;
    size_t pieces = 0;
    for (int r = 0; r < runs; ++r) {
        const core::Clock::time_point start = core::Clock::now();
        const api::SpatialPieces cut = api::SpatialPieces::partition(sets[0], sets[1], scale, limits, threads,
                                                                     api::PieceOrder::kBlocks, &box, false);
        total.push_back(core::msSince(start));
        const api::SpatialPieces::PassTimes& t = cut.passTimes();
        box_ms.push_back(t.box), keys.push_back(t.keys);
        plan.push_back(t.plan), scatter.push_back(t.scatter);
        const uint64_t h = hashOf(cut);
        if (r > 0 && h != hash) {
            std::fprintf(stderr, "pieces-bench: run %d's partition differs from run 1's\n", r + 1);
            return 1;
        }
        hash = h;
        pieces = cut.count();
    }
    const auto list = [](const std::vector<double>& v) {
        std::string s = "[";
        for (size_t i = 0; i < v.size(); ++i) {
            if (i > 0) s.push_back(',');
            s.append(std::to_string(v[i]));
        }
        s.push_back(']');
        return s;
    };
    std::printf(
        "{\"a\":\"%s\",\"b\":\"%s\",\"points\":[%zu,%zu],\"budget_mib\":%llu,\"pieces\":%zu,\"runs\":%d,"
        "\"hash\":\"%016llx\",\"median_ms\":{\"total\":%.3f,\"box\":%.3f,\"keys\":%.3f,"
        "\"plan\":%.3f,\"scatter\":%.3f},\"total_all\":%s,\"keys_all\":%s,\"scatter_all\":%s}\n",
        files[0].c_str(), files[1].c_str(), sets[0].size(), sets[1].size(), (unsigned long long)budgetMib,
        pieces, runs, (unsigned long long)hash, median(total), median(box_ms), median(keys), median(plan),
        median(scatter), list(total).c_str(), list(keys).c_str(), list(scatter).c_str());
    return 0;
}
