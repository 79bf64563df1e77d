// rthdist-surface-bench: point-to-surface calls on a kept device (issue 34;
// Engine::hausdorffToSurface) beside the one-shot call (hausdorffToSurface,
// which creates its device per call, as the CLI does), on one backend.
//
//   rthdist-surface-bench POINTS MESH [--backend B] [--runs N] [--warmup W]
//                         [--one-shot N] [--threads T] [--name NAME] [--no-verify]
//                         [--per-point [--distances-only] [--recycle]]
// POINTS: any point input (a mesh's vertices); MESH: a file with faces.
// One Engine is created (setup_ms); its first --warmup calls are timed apart
// (warmup_ms: the first call also compiles what the driver compiles on first
// use), then --runs calls give the medians of every stage (SurfaceResult:
// total, search, frame, upload, device, readback, certify, gpu, gpu_build,
// tail_build, gpu_tail, tail_host)
// and the wall clock of the call. --one-shot N more calls of the free
// function (a device per call) give one_shot medians (total, build = the
// device and its pipelines). --no-verify skips the CPU backend's call that
// checks value and witness (==: both are exact). --per-point: every call
// asks per-point distances (SurfaceCallOptions::perPointDistances; with
// --distances-only, perPointDistancesOnly), the stage per_point is timed
// too, and the check also compares every point's distance with the CPU
// backend's per-point call: equal, or within the call's tolerance above it
// (per_point_within); --recycle hands each call's result back to the
// Engine (Engine::recycle) but the last's. Prints one JSON object.
// Not a test: no thresholds.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "core/stopwatch.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/surface.hpp"

namespace {

using rthdist::SurfaceResult;
using rthdist::core::Clock;
using rthdist::core::msSince;

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Settings {
    std::string points, mesh, name, backend = "rt-pipeline";
    int runs = 7, warmup = 2, oneShot = 0, threads = 0;
    bool verify = true, perPoint = false, distancesOnly = false, recycle = false;
    double surfaces = -1.0;  // >= 0: surface to surface (surfaceHausdorff) at this tolerance (0: default)
};

// The series of one kind of call: every stage's milliseconds per call.
struct Series {
    std::vector<double> wall, total, build, search, frame, upload, device, readback, certify, gpu, gpuBuild,
        tailBuild, gpuTail, tailHost, perPoint;

    void add(const SurfaceResult& r, double wallMs) {
        wall.push_back(wallMs);
        total.push_back(r.totalMs);
        build.push_back(r.buildMs);
        search.push_back(r.searchMs);
        frame.push_back(r.stages.frame);
        upload.push_back(r.stages.upload);
        device.push_back(r.stages.search);
        readback.push_back(r.stages.readback);
        certify.push_back(r.stages.certify);
        gpu.push_back(r.gpuMs);
        gpuBuild.push_back(r.stages.gpuBuild);
        tailBuild.push_back(r.stages.tailBuild);
        gpuTail.push_back(r.stages.gpuTail);
        tailHost.push_back(r.stages.tailHost);
        perPoint.push_back(r.stages.perPoint);
    }
    [[nodiscard]] nlohmann::json medians() const {
        return {
            {"wall", median(wall)},        {"total", median(total)},        {"build", median(build)},
            {"search", median(search)},    {"frame", median(frame)},        {"upload", median(upload)},
            {"device", median(device)},    {"readback", median(readback)},  {"certify", median(certify)},
            {"gpu", median(gpu)},          {"gpu_build", median(gpuBuild)}, {"tail_build", median(tailBuild)},
            {"gpu_tail", median(gpuTail)}, {"tail_host", median(tailHost)}, {"per_point", median(perPoint)}};
    }
};

nlohmann::json countersJson(const rthdist::SurfaceCounters& c) {
    return {{"queries", c.queries},
            {"triangles", c.triangles},
            {"radii", c.radii},
            {"rays", c.rays},
            {"submissions", c.submissions},
            {"tail_queries", c.tailQueries},
            {"tail_host_queries", c.tailHostQueries},
            {"tail_tree_reused", c.tailTreeReused},
            {"tail_lanes", c.tailLanes},
            {"band", c.band},
            {"host_triangles", c.hostTriangles},
            {"cpu_recomputed", c.cpuRecomputed}};
}

int fail(const std::string& what, const rthdist::Error& e) {
    std::fprintf(stderr, "rthdist-surface-bench: %s: %s\n", what.c_str(), e.message.c_str());
    return 1;
}

nlohmann::json boundsCounters(const rthdist::SurfaceBoundsCounters& c) {
    return {{"queries", c.queries},
            {"patches", c.patches},
            {"splits", c.splits},
            {"rounds", c.rounds},
            {"max_depth", c.maxDepth}};
}

// --surfaces: surfaceHausdorff (a one-shot call: no Engine keeps it) run
// warm-up + runs times in this process, its stages' medians.
int surfacePairs(const Settings& s, rthdist::Backend backend, const rthdist::MeshView& a,
                 const rthdist::MeshView& b, double loadMs) {
    rthdist::SurfaceBoundsOptions o;
    o.backend = backend;
    o.threads = s.threads;
    o.tolerance = s.surfaces;
    std::vector<double> wall, total, build, search, setup, gpu;
    rthdist::SurfaceBoundsResult last;
    for (int r = 0; r < s.warmup + s.runs; ++r) {
        const auto t0 = Clock::now();
        auto res = rthdist::surfaceHausdorff(a, b, o);
        const double ms = msSince(t0);
        if (!res) return fail("surface to surface", res.error());
        if (r >= s.warmup) {
            wall.push_back(ms);
            total.push_back(res->totalMs);
            build.push_back(res->buildMs);
            search.push_back(res->searchMs);
            setup.push_back(res->setupMs);
            gpu.push_back(res->gpuMs);
        }
        last = *res;
    }
    const nlohmann::json j = {
        {"case", s.name.empty() ? s.points + " | " + s.mesh : s.name},
        {"backend", rthdist::backendName(last.backend)},
        {"device", last.device},
        {"threads", s.threads},
        {"bounds", {last.lower, last.upper}},
        {"tolerance", last.tolerance},
        {"load_ms", loadMs},
        {"runs", s.runs},
        {"median_ms",
         {{"wall", median(wall)},
          {"total", median(total)},
          {"build", median(build)},
          {"search", median(search)},
          {"setup", median(setup)},
          {"gpu", median(gpu)}}},
        {"total_ms_all", total},
        {"counters",
         {{"a_to_b", boundsCounters(last.aToB.counters)}, {"b_to_a", boundsCounters(last.bToA.counters)}}}};
    std::cout << j.dump() << "\n";
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Settings s;
    CLI::App app{"rthdist-surface-bench: point-to-surface calls on a kept Engine and one-shot"};
    app.add_option("points", s.points, "point input (a mesh's vertices)")->required();
    app.add_option("mesh", s.mesh, "mesh with faces")->required();
    app.add_option("--backend", s.backend, "ray-query, rt-pipeline, cpu or auto");
    app.add_option("--runs", s.runs, "timed calls on the Engine")->check(CLI::PositiveNumber);
    app.add_option("--warmup", s.warmup, "calls before the timed ones")->check(CLI::NonNegativeNumber);
    app.add_option("--one-shot", s.oneShot, "timed one-shot calls (a device each)")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--threads", s.threads, "host threads (0: all)")->check(CLI::NonNegativeNumber);
    app.add_option("--name", s.name, "the case's name in the output");
    app.add_flag("!--no-verify", s.verify, "skip the CPU backend's reference call");
    app.add_flag("--per-point", s.perPoint, "every call asks per-point distances");
    app.add_flag("--distances-only", s.distancesOnly, "with --per-point: distances and triangles only");
    app.add_flag("--recycle", s.recycle, "hand each call's result back to the Engine");
    app.add_option("--surfaces", s.surfaces,
                   "surface to surface instead (surfaceHausdorff, a one-shot call a run) at this "
                   "absolute tolerance (0: the default)")
        ->check(CLI::NonNegativeNumber);
    CLI11_PARSE(app, argc, argv);

    rthdist::EngineOptions engineOptions;
    if (!rthdist::parseBackend(s.backend, engineOptions.backend)) {
        std::fprintf(stderr, "rthdist-surface-bench: unknown backend %s\n", s.backend.c_str());
        return 2;
    }
    engineOptions.threads = s.threads;
    auto t0 = Clock::now();
    auto points = rthdist::io::loadPointCloud(s.points);
    if (!points) return fail(s.points, points.error());
    auto mesh = rthdist::io::loadMesh(s.mesh);
    if (!mesh) return fail(s.mesh, mesh.error());
    const double loadMs = msSince(t0);
    if (s.surfaces >= 0.0) {
        auto meshA = rthdist::io::loadMesh(s.points);
        if (!meshA) return fail(s.points, meshA.error());
        return surfacePairs(s, engineOptions.backend, meshA->view(), mesh->view(), loadMs);
    }
    const rthdist::PointView query = points->view();
    const rthdist::MeshView surface = mesh->view();

    t0 = Clock::now();
    auto engine = rthdist::Engine::create(engineOptions);
    if (!engine) return fail("engine", engine.error());
    const double setupMs = msSince(t0);

    std::vector<double> warmup;
    Series kept, once;
    SurfaceResult last;
    rthdist::SurfaceCallOptions call;
    call.perPointDistances = s.perPoint;
    call.perPointDistancesOnly = s.distancesOnly;
    for (int r = 0; r < s.warmup + s.runs; ++r) {
        t0 = Clock::now();
        auto res = engine->hausdorffToSurface(query, surface, call);
        const double wall = msSince(t0);
        if (!res) return fail("engine call", res.error());
        if (r < s.warmup) {
            warmup.push_back(wall);
            if (s.recycle) engine->recycle(std::move(res.value()));
            continue;
        }
        kept.add(*res, wall);
        if (s.recycle && r + 1 < s.warmup + s.runs) {
            engine->recycle(std::move(res.value()));
            continue;
        }
        last = std::move(res.value());
    }
    rthdist::SurfaceOptions oneShot;
    static_cast<rthdist::SurfaceCallOptions&>(oneShot) = call;
    oneShot.backend = engineOptions.backend;
    oneShot.threads = s.threads;
    for (int r = 0; r < s.oneShot; ++r) {
        t0 = Clock::now();
        auto res = rthdist::hausdorffToSurface(query, surface, oneShot);
        const double wall = msSince(t0);
        if (!res) return fail("one-shot call", res.error());
        once.add(*res, wall);
    }

    bool agree = true;
    nlohmann::json reference;
    if (s.verify) {
        rthdist::SurfaceOptions cpu;
        static_cast<rthdist::SurfaceCallOptions&>(cpu) = call;
        cpu.backend = rthdist::Backend::kCpu;
        cpu.threads = s.threads;
        t0 = Clock::now();
        auto ref = rthdist::hausdorffToSurface(query, surface, cpu);
        const double cpuMs = msSince(t0);
        if (!ref) return fail("cpu reference", ref.error());
        agree = ref->hausdorff == last.hausdorff && ref->directed.queryIndex == last.directed.queryIndex &&
                ref->directed.triangle == last.directed.triangle;
        reference = {{"hausdorff", ref->hausdorff}, {"wall_ms", cpuMs}, {"total_ms", ref->totalMs}};
        if (s.perPoint) {
            const std::vector<double>&want = ref->perPoint.distance, &got = last.perPoint.distance;
            uint64_t exact = 0, within = want.size() == got.size() ? 0 : UINT64_MAX;
            for (size_t i = 0; i < want.size() && within != UINT64_MAX; ++i) {
                exact += got[i] == want[i] ? 1 : 0;
                within += got[i] >= want[i] && got[i] <= want[i] + last.perPoint.tolerance ? 1 : 0;
            }
            reference["per_point_equal"] = exact;
            reference["per_point_within"] = within;
            reference["tolerance"] = last.perPoint.tolerance;
            agree = agree && within == want.size();
        }
    }

    nlohmann::json j = {{"case", s.name.empty() ? s.points + " > " + s.mesh : s.name},
                        {"points", query.count},
                        {"triangles", surface.triangleCount()},
                        {"backend", rthdist::backendName(last.backend)},
                        {"device", last.device},
                        {"threads", s.threads},
                        {"hausdorff", last.hausdorff},
                        {"query", last.directed.queryIndex},
                        {"triangle", last.directed.triangle},
                        {"load_ms", loadMs},
                        {"setup_ms", setupMs},
                        {"warmup_ms", warmup},
                        {"runs", s.runs},
                        {"kept_median_ms", kept.medians()},
                        {"kept_wall_ms_all", kept.wall},
                        {"kept_total_ms_all", kept.total},
                        {"counters", countersJson(last.directed.counters)},
                        {"one_shot_runs", s.oneShot},
                        {"cpu_reference", reference},
                        {"agree", agree}};
    if (s.oneShot > 0) {
        j["one_shot_median_ms"] = once.medians();
        j["one_shot_total_ms_all"] = once.total;
        j["one_shot_wall_ms_all"] = once.wall;
    }
    std::cout << j.dump() << "\n";
    return agree ? 0 : 1;
}
