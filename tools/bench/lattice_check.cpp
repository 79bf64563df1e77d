// lattice-check: a large run whose answer is known without a nearest-neighbour
// search, so that sizes no brute force reaches (issue 14: 200 M points on the
// CPU backend) are checked against an independent answer, not against the
// library itself.
//
//   lattice-check N [--backend cpu|ray-query|rt-pipeline] [--threads T] [--three]
//                   [--memory-budget MIB] [--devices 0,1]                 (N in 2..4096)
//
// A is the integer lattice {0..N-1}^3 (N^3 points), B the same lattice moved
// by (1/2, 1/2, 1/2) plus one outlier o far outside both. Every coordinate is
// a float32 value (N <= 2^23), so the sets are exact as given.
// - h(A, B): every lattice point of A has its nearest points of B at the
//   corners of the unit cube around it that lie in B's lattice; the nearest
//   is at distance sqrt(3)/2 for every point of A (B's lattice spans
//   [1/2, N - 1/2] on each axis, so each point of A has at least one such
//   corner), and o is farther than that from all of A.
// - h(B, A): the lattice points of B are at sqrt(3)/2 from A too; o's nearest
//   point of A is, per axis, o's coordinate rounded to the nearest integer
//   and clamped to [0, N - 1] (o is chosen with no coordinate at a half), so
//   h(B, A) = |o - that point| > sqrt(3)/2, witnessed by o (the last point of
//   B) and that point of A.
// The check: H, both directed distances, the h(B, A) witness pair, and that
// the h(A, B) witness is a point of A with a point of B at sqrt(3)/2 from it.
//
// With --three, B is three points instead (issue 14: 300 M points against 3,
// out of core on lavapipe): h(B, A) is the largest distance from a point of B
// to its nearest lattice point (rounded and clamped, as above), witnessed by
// that point; h(A, B) is the brute force over A x B in double (3 N^3
// distances), and its witness pair must realize it with the target a nearest
// of the three to the query. --memory-budget MIB forces the out-of-core split;
// --devices spreads the queries over several GPUs (EngineOptions::devices).
//
// --write-ply PREFIX writes A and B as binary PLY files PREFIX_a.ply and
// PREFIX_b.ply instead of computing (for rthdist and rthdist-mpi runs on the
// same sets: the JSON printed gives the expected H, and h(B,A)'s witness is
// the last point of B).
// Prints one JSON object (sizes, times, peak memory, each check) and exits 0
// when every check holds, 1 when one fails, 2 on a usage error, 3 when the
// library refuses or fails the call.
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"

using namespace rthdist;

namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::ordered_json;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

double peakRssGiB() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / (1024.0 * 1024.0);  // ru_maxrss is in KiB
}

// The lattice {0..n-1}^3 moved by `shift`, x fastest; point (x, y, z) has index
// x + n * (y + n * z).
std::vector<glm::vec3> lattice(size_t n, float shift) {
    std::vector<glm::vec3> points(n * n * n);
    size_t i = 0;
    for (size_t z = 0; z < n; ++z)
        for (size_t y = 0; y < n; ++y)
            for (size_t x = 0; x < n; ++x) points[i++] = glm::vec3(float(x), float(y), float(z)) + shift;
    return points;
}

// The nearest point of the lattice {0..n-1}^3 to p (no coordinate of p at a half).
glm::dvec3 nearestLatticePoint(const glm::dvec3& p, size_t n) {
    const double top = double(n - 1);
    return glm::clamp(glm::round(p), glm::dvec3(0.0), glm::dvec3(top));
}

// h(A, B) of the lattice {0..n-1}^3 against a few points, by brute force in double.
double bruteLatticeToPoints(size_t n, const std::vector<glm::vec3>& b) {
    double worst = 0.0;
    for (size_t z = 0; z < n; ++z)
        for (size_t y = 0; y < n; ++y)
            for (size_t x = 0; x < n; ++x) {
                const glm::dvec3 p{double(x), double(y), double(z)};
                double best = INFINITY;
                for (const glm::vec3& t : b) best = std::min(best, glm::length(p - glm::dvec3(t)));
                worst = std::max(worst, best);
            }
    return worst;
}

// The checks of the lattice against its half-shifted copy plus an outlier.
Json shiftedChecks(size_t n, const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                   const HausdorffResult& r, double& expected) {
    const double half = std::sqrt(0.75);
    const glm::dvec3 o(b.back());
    const glm::dvec3 oNearest = nearestLatticePoint(o, n);
    const double hBA = glm::length(o - oNearest);
    expected = hBA;
    const uint64_t oNearestIndex =
        uint64_t(oNearest.x) + n * (uint64_t(oNearest.y) + n * uint64_t(oNearest.z));
    const Directed& ab = r.aToB;
    const Directed& ba = r.bToA;
    const glm::dvec3 abQuery(a[ab.queryIndex]);
    const glm::dvec3 abTarget(b[ab.targetIndex]);
    Json checks = Json::object();
    checks["H"] = r.hausdorff == hBA;
    checks["h(A,B) = sqrt(3)/2"] = ab.distance == half;
    checks["h(B,A) = |o - nearest lattice point|"] = ba.distance == hBA;
    checks["h(B,A) witness is o"] = ba.queryIndex == b.size() - 1;
    checks["h(B,A) witness target is o's nearest"] = ba.targetIndex == oNearestIndex;
    checks["h(A,B) witness pair at sqrt(3)/2"] = glm::length(abQuery - abTarget) == half;
    return checks;
}

// The checks of the lattice against three points (--three).
Json threeChecks(size_t n, const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                 const HausdorffResult& r, double& expected) {
    double hBA = 0.0;
    size_t hBAQuery = 0;
    for (size_t j = 0; j < b.size(); ++j) {
        const double d = glm::length(glm::dvec3(b[j]) - nearestLatticePoint(glm::dvec3(b[j]), n));
        if (d > hBA) {
            hBA = d;
            hBAQuery = j;
        }
    }
    const double hAB = bruteLatticeToPoints(n, b);
    expected = std::max(hAB, hBA);
    const Directed& ab = r.aToB;
    const Directed& ba = r.bToA;
    const glm::dvec3 baNearest = nearestLatticePoint(glm::dvec3(b[hBAQuery]), n);
    double abNearest = INFINITY;
    for (const glm::vec3& t : b)
        abNearest = std::min(abNearest, glm::length(glm::dvec3(a[ab.queryIndex]) - glm::dvec3(t)));
    Json checks = Json::object();
    checks["H"] = r.hausdorff == expected;
    checks["h(A,B) = brute force"] = ab.distance == hAB;
    checks["h(A,B) witness pair realizes it"] =
        glm::length(glm::dvec3(a[ab.queryIndex]) - glm::dvec3(b[ab.targetIndex])) == hAB && abNearest == hAB;
    checks["h(B,A) = farthest point of B from the lattice"] = ba.distance == hBA;
    checks["h(B,A) witness pair realizes it"] =
        glm::length(glm::dvec3(b[ba.queryIndex]) - glm::dvec3(a[ba.targetIndex])) == hBA &&
        glm::length(glm::dvec3(a[ba.targetIndex]) - baNearest) == 0.0 && ba.queryIndex == hBAQuery;
    return checks;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"lattice-check: a large run checked against an answer known without a search"};
    size_t n = 0;
    std::string backend = "cpu";
    Options options;
    app.add_option("N", n, "lattice side: N^3 points per set")->required()->check(CLI::Range(2, 4096));
    app.add_option("--backend", backend, "cpu, ray-query or rt-pipeline");
    app.add_option("--threads", options.threads, "host threads, 0 = all")->check(CLI::NonNegativeNumber);
    bool three = false;
    uint64_t budgetMib = 0;
    app.add_flag("--three", three, "B is three points (brute-force check of h(A,B))");
    std::string plyPrefix;
    app.add_option("--write-ply", plyPrefix, "write PREFIX_a.ply and PREFIX_b.ply instead of computing");
    app.add_option("--devices", options.devices, "device indices for several GPUs, e.g. 0,1")
        ->delimiter(',')
        ->check(CLI::NonNegativeNumber);
    app.add_option("--memory-budget", budgetMib, "MiB one backend call may hold, 0 = automatic")
        ->check(CLI::Range(uint64_t(0), uint64_t(1) << 30));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;  // --help: 0; anything else: a usage error
    }
    if (!parseBackend(backend, options.backend)) {
        std::fprintf(stderr, "lattice-check: unknown backend %s\n", backend.c_str());
        return 2;
    }

    auto start = Clock::now();
    const std::vector<glm::vec3> a = lattice(n, 0.0f);
    options.memoryBudget = budgetMib << 20;
    std::vector<glm::vec3> b;
    if (three) {
        // Inside the lattice's box, on no half: h(B, A) is below sqrt(3)/2; and one outside.
        const float m = float(n / 2);
        b = {glm::vec3(m + 0.125f, m - 0.25f, 0.375f),
             glm::vec3(float(n / 5) + 0.0625f, float(n) - 1.3125f, m),
             glm::vec3(-7.25f, float(n / 3) + 0.1875f, float(n) + 2.4375f)};
    } else {
        b = lattice(n, 0.5f);
        b.push_back(glm::vec3(float(n) + 100.25f, -40.375f, float(n / 3) + 0.125f));  // the outlier o
    }
    const double generateS = secondsSince(start);
    if (!plyPrefix.empty()) {
        start = Clock::now();
        for (const auto& [suffix, points] :
             {std::pair<const char*, const std::vector<glm::vec3>*>{"_a.ply", &a}, {"_b.ply", &b}}) {
            const Result<bool> written = io::writePlyPoints(plyPrefix + suffix, *points);
            if (!written) {
                std::fprintf(stderr, "lattice-check: %s\n", written.error().message.c_str());
                return 3;
            }
        }
        const glm::dvec3 o(b.back());
        Json out = {{"side", n},
                    {"points_a", a.size()},
                    {"points_b", b.size()},
                    {"write_s", secondsSince(start)},
                    {"expected_hausdorff", three ? -1.0 : glm::length(o - nearestLatticePoint(o, n))}};
        std::cout << out.dump(2) << "\n";
        return 0;
    }

    start = Clock::now();
    const Result<HausdorffResult> r = hausdorff(a, b, options);
    const double computeS = secondsSince(start);
    if (!r) {
        std::fprintf(stderr, "lattice-check: %s\n", r.error().message.c_str());
        return 3;
    }

    start = Clock::now();
    double expected = 0.0;
    Json checks = three ? threeChecks(n, a, b, *r, expected) : shiftedChecks(n, a, b, *r, expected);
    const double checkS = secondsSince(start);
    bool exact = true;
    for (const auto& [name, ok] : checks.items()) exact = exact && ok.get<bool>();

    Json out = Json::object();
    out["side"] = n;
    out["points_a"] = a.size();
    out["points_b"] = b.size();
    out["backend"] = backendName(r->backend);
    out["device"] = r->device;
    out["generate_s"] = generateS;
    out["compute_s"] = computeS;
    out["check_s"] = checkS;
    out["query_chunks_a_to_b"] = r->aToB.counters.queryChunks;
    out["target_tiles_b_to_a"] = r->bToA.counters.targetTiles;
    const Timings& t = r->timings;
    out["timings_ms"] = {{"setup", t.setup},   {"upload", t.upload}, {"index", t.index}, {"cull", t.cull},
                         {"search", t.search}, {"refine", t.refine}, {"check", t.check}, {"total", t.total}};
    out["peak_rss_gib"] = peakRssGiB();
    out["hausdorff"] = r->hausdorff;
    out["expected"] = expected;
    out["checks"] = std::move(checks);
    out["exact"] = exact;
    std::cout << out.dump(2) << "\n";
    return exact ? 0 : 1;
}
