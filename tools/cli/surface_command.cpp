#include "cli/surface_command.hpp"

#include <cinttypes>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli/exit_codes.hpp"
#include "cli/json_output.hpp"
#include "cli/per_point_outputs.hpp"
#include "cli/report.hpp"
#include "cli/surface_per_point.hpp"
#include "core/stopwatch.hpp"
#include "rthdist/io.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::cli {
namespace {

using core::Clock;
using core::msSince;

int fail(const Error& error) {
    std::fflush(stdout);
    std::fprintf(stderr, "rthdist: %s\n", error.message.c_str());
    return exitCodeFor(error.code);
}

// Which file is which: the points' side q and the surface's side s ("a"/"b").
struct Sides {
    std::string q, s;
    std::string pointsPath, surfacePath;
};

Json pointJson(const glm::dvec3& p) { return Json::array({p.x, p.y, p.z}); }

Json directedJson(const SurfaceDirected& d, const Sides& sides) {
    return {{"distance", d.distance},
            {sides.q + "_index", d.queryIndex},
            {"triangle", d.triangle},
            {sides.q + "_point", pointJson(d.queryPoint)},
            {sides.s + "_point", pointJson(d.surfacePoint)},
            {"barycentric", pointJson(d.barycentric)}};
}

Json countersJson(const SurfaceCounters& c) {
    return {{"queries", c.queries},
            {"triangles", c.triangles},
            {"bvh_nodes", c.bvhNodes},
            {"nodes_visited", c.nodesVisited},
            {"triangles_tested", c.trianglesTested},
            {"dominated", c.dominated},
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

const char* precisionName(Scalar s) { return s == Scalar::kFloat64 ? "float64" : "float32"; }

struct Run {
    const CliArgs* args = nullptr;
    Sides sides;
    const io::PointCloud* points = nullptr;
    const io::TriangleMesh* mesh = nullptr;
    const SurfaceResult* result = nullptr;
    const HausdorffStats* stats = nullptr;  // with per-point outputs
    double loadMs = 0.0, wallMs = 0.0;
};

std::string jsonReport(const Run& run) {
    const SurfaceResult& r = *run.result;
    const bool b = run.sides.s == "b";
    auto side = [&](auto pointsValue, auto meshValue) {
        return b ? Json{{"a", pointsValue}, {"b", meshValue}} : Json{{"a", meshValue}, {"b", pointsValue}};
    };
    Json j = {
        {"version", versionString()},
        {"mode", "point-to-surface"},
        {"surface", run.sides.s},
        {"files", {{"a", run.args->pathA}, {"b", run.args->pathB}}},
        {"points", side(run.points->size(), run.mesh->vertices.size())},
        {"triangles", side(Json(), run.mesh->triangleCount())},
        {"precision", side(precisionName(run.points->scalar), precisionName(run.mesh->vertices.scalar))},
        {"backend", backendName(r.backend)},
        {"device", r.device},
        {"directed", true},
        {"hausdorff", r.hausdorff},
        {"validation_messages", r.validationMessages}};
    j["a_to_b"] = b ? directedJson(r.directed, run.sides) : Json();
    j["b_to_a"] = b ? Json() : directedJson(r.directed, run.sides);
    if (run.stats != nullptr) {
        j["per_point"] = surfaceStatsJson(*run.stats, !b);
        // 0: every distance exact (cpu); a GPU backend's bound (rthdist/surface.hpp).
        j["per_point"]["tolerance"] = r.perPoint.tolerance;
    }
    const SurfaceStages& st = r.stages;
    j["timings_ms"] = {{"load", run.loadMs},
                       {"build", r.buildMs},
                       {"search", r.searchMs},
                       {"total", r.totalMs},
                       {"wall", run.wallMs},
                       {"stages",
                        {{"frame", st.frame},
                         {"upload", st.upload},
                         {"device", st.search},
                         {"readback", st.readback},
                         {"certify", st.certify},
                         {"gpu", r.gpuMs},
                         {"gpu_build", st.gpuBuild},
                         {"tail_build", st.tailBuild},
                         {"gpu_tail", st.gpuTail},
                         {"tail_host", st.tailHost},
                         {"per_point", st.perPoint}}}};
    j["counters"] = {{"a_to_b", b ? countersJson(r.directed.counters) : Json()},
                     {"b_to_a", b ? Json() : countersJson(r.directed.counters)}};
    return jsonText(j) + "\n";
}

std::string text(const glm::dvec3& p) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", p.x, p.y, p.z);
    return buf;
}

std::string summaryText(const Run& run) {
    const SurfaceResult& r = *run.result;
    const SurfaceDirected& d = r.directed;
    const std::string Q = run.sides.q == "a" ? "A" : "B", S = run.sides.s == "a" ? "A" : "B";
    std::string s;
    char line[1024];
    auto add = [&](int n) { s.append(line, size_t(std::max(0, std::min(n, int(sizeof line) - 1)))); };
    add(std::snprintf(line, sizeof line, "rthdist %s: backend %s on %s, point to surface\n", versionString(),
                      backendName(r.backend), r.device.c_str()));
    add(std::snprintf(line, sizeof line, "%s  %s  (%zu points)\n", Q.c_str(), run.sides.pointsPath.c_str(),
                      run.points->size()));
    add(std::snprintf(line, sizeof line, "%s  %s  (surface: %zu triangles, %zu vertices)\n", S.c_str(),
                      run.sides.surfacePath.c_str(), run.mesh->triangleCount(), run.mesh->vertices.size()));
    add(std::snprintf(line, sizeof line, "h(%s, surface %s) = %.10g   (directed)\n", Q.c_str(), S.c_str(),
                      d.distance));
    add(std::snprintf(line, sizeof line, "  %s[%" PRIu64 "] %s -> %s triangle %u at %s\n", Q.c_str(),
                      d.queryIndex, text(d.queryPoint).c_str(), S.c_str(), d.triangle,
                      text(d.surfacePoint).c_str()));
    if (run.stats != nullptr) {
        s += surfaceStatsText(*run.stats, run.sides.q == "b");
        if (r.perPoint.tolerance > 0.0)
            add(std::snprintf(line, sizeof line,
                              "  per-point distances within %.3g above the exact ones (the device's float "
                              "search; h and its witness exact)\n",
                              r.perPoint.tolerance));
    }
    add(std::snprintf(line, sizeof line,
                      "time (ms)  load %.2f | build %.2f | search %.2f | total %.2f | wall %.2f\n",
                      run.loadMs, r.buildMs, r.searchMs, r.totalMs, run.wallMs));
    const SurfaceCounters& c = d.counters;
    add(std::snprintf(line, sizeof line,
                      "counters   queries %" PRIu64 ", bvh nodes %" PRIu64 ", nodes visited %" PRIu64
                      ", triangles tested %" PRIu64 ", dominated %" PRIu64 "\n",
                      c.queries, c.bvhNodes, c.nodesVisited, c.trianglesTested, c.dominated));
    return s;
}

}  // namespace

int surfaceCommand(const CliArgs& args) {
    const Clock::time_point start = Clock::now();
    Sides sides{args.surface == "b" ? "a" : "b", args.surface, args.surface == "b" ? args.pathA : args.pathB,
                args.surface == "b" ? args.pathB : args.pathA};
    const io::LoadOptions loadOptions = loadOptionsOf(args);
    const Clock::time_point loadStart = Clock::now();
    Result<io::PointCloud> points = io::loadPointCloud(sides.pointsPath, loadOptions);
    if (!points) return fail(points.error());
    Result<io::TriangleMesh> mesh = io::loadMesh(sides.surfacePath, loadOptions);
    if (!mesh) return fail(mesh.error());
    const double loadMs = msSince(loadStart);

    SurfaceOptions options;
    options.backend = args.options.backend;
    options.threads = args.options.threads;
    options.deviceIndex = args.options.deviceIndex;
    options.validation = args.options.validation;
    options.perPointDistances = args.perPoint;
    Result<SurfaceResult> result = hausdorffToSurface(points->view(), mesh->view(), options);
    // The library names the points "A" and the surface "B".
    if (!result) return fail(withFileNames(result.error(), sides.pointsPath, sides.surfacePath));

    std::optional<HausdorffStats> stats;
    if (args.perPoint) {
        const std::vector<glm::vec3> floats = floatPoints(*points);
        const std::vector<glm::vec3> vertices = floatPoints(mesh->vertices);
        const SurfacePerPointRun perPoint{&args,
                                          sides.q == "b",
                                          floats,
                                          vertices,
                                          &*result,
                                          sides.pointsPath,
                                          sides.surfacePath,
                                          points->view(),
                                          mesh->vertices.view()};
        Result<HausdorffStats> s = surfaceStats(perPoint);
        if (!s) return fail(Error{ErrorCode::kInternal, s.error().message});
        stats = std::move(s).value();
        Result<bool> written = writeSurfacePerPointOutputs(perPoint, *stats);
        if (!written) {
            std::fflush(stdout);
            std::fprintf(stderr, "rthdist: %s\n", written.error().message.c_str());
            return kExitOutput;
        }
    }

    Run run{&args, sides, &*points, &*mesh, &*result, stats ? &*stats : nullptr, loadMs, msSince(start)};
    const std::string out = args.json ? jsonReport(run) : summaryText(run);
    if (std::fwrite(out.data(), 1, out.size(), stdout) != out.size() || std::fflush(stdout) != 0)
        return fail(Error{ErrorCode::kInternal, "cannot write to stdout"});
    return kExitOk;
}

}  // namespace rthdist::cli
