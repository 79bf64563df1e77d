#include "cli/surface_pair_command.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <string>

#include "cli/exit_codes.hpp"
#include "cli/json_output.hpp"
#include "cli/report.hpp"
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

// The library names the meshes "surface A", "surface B" (or the set "A",
// "B"): the message gains the file name.
Error named(Error error, const CliArgs& args) {
    for (const auto& [subject, path] : {std::pair<std::string, std::string>{"surface A", args.pathA},
                                        {"surface B", args.pathB},
                                        {"point set A", args.pathA},
                                        {"point set B", args.pathB}}) {
        if (error.message.rfind(subject, 0) != 0) continue;
        error.message.insert(subject.size(), " (" + path + ")");
        break;
    }
    return error;
}

Json pointJson(const glm::dvec3& p) { return Json::array({p.x, p.y, p.z}); }

// One direction; q names the side of the witness point, s the other.
Json directedJson(const SurfaceBoundsDirected& d, const std::string& q, const std::string& s) {
    return {{"bounds", Json::array({d.lower, d.upper})},
            {"distance", d.distance},
            {q + "_triangle", d.fromTriangle},
            {q + "_point", pointJson(d.fromPoint)},
            {q + "_barycentric", pointJson(d.fromBarycentric)},
            {"triangle", d.toTriangle},
            {s + "_point", pointJson(d.toPoint)},
            {"barycentric", pointJson(d.toBarycentric)}};
}

Json countersJson(const SurfaceBoundsCounters& c) {
    return {{"queries", c.queries},
            {"patches", c.patches},
            {"splits", c.splits},
            {"rounds", c.rounds},
            {"max_depth", c.maxDepth}};
}

const char* precisionName(Scalar s) { return s == Scalar::kFloat64 ? "float64" : "float32"; }

struct Run {
    const CliArgs* args = nullptr;
    const io::TriangleMesh* a = nullptr;
    const io::TriangleMesh* b = nullptr;
    const SurfaceBoundsResult* result = nullptr;
    double loadMs = 0.0, wallMs = 0.0;
};

std::string jsonReport(const Run& run) {
    const SurfaceBoundsResult& r = *run.result;
    Json j = {{"version", versionString()},
              {"mode", "surface-to-surface"},
              {"surface", "both"},
              {"files", {{"a", run.args->pathA}, {"b", run.args->pathB}}},
              {"points", {{"a", run.a->vertices.size()}, {"b", run.b->vertices.size()}}},
              {"triangles", {{"a", run.a->triangleCount()}, {"b", run.b->triangleCount()}}},
              {"precision",
               {{"a", precisionName(run.a->vertices.scalar)}, {"b", precisionName(run.b->vertices.scalar)}}},
              {"backend", backendName(r.backend)},
              {"device", r.device},
              {"directed", r.directed},
              {"hausdorff", Json()},
              {"bounds", Json::array({r.lower, r.upper})},
              {"tolerance", r.tolerance},
              {"slack", r.slack},
              {"origin", pointJson(r.origin)},
              {"validation_messages", r.validationMessages}};
    j["a_to_b"] = directedJson(r.aToB, "a", "b");
    j["b_to_a"] = r.directed ? Json() : directedJson(r.bToA, "b", "a");
    j["timings_ms"] = {{"load", run.loadMs}, {"build", r.buildMs}, {"search", r.searchMs},
                       {"total", r.totalMs}, {"wall", run.wallMs}, {"setup", r.setupMs},
                       {"gpu", r.gpuMs}};
    j["counters"] = {{"a_to_b", countersJson(r.aToB.counters)},
                     {"b_to_a", r.directed ? Json() : countersJson(r.bToA.counters)}};
    return jsonText(j) + "\n";
}

std::string text(const glm::dvec3& p) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", p.x, p.y, p.z);
    return buf;
}

std::string summaryText(const Run& run) {
    const SurfaceBoundsResult& r = *run.result;
    std::string s;
    char line[1024];
    auto add = [&](int n) { s.append(line, size_t(std::max(0, std::min(n, int(sizeof line) - 1)))); };
    add(std::snprintf(line, sizeof line, "rthdist %s: backend %s on %s, surface to surface\n",
                      versionString(), backendName(r.backend), r.device.c_str()));
    add(std::snprintf(line, sizeof line, "A  %s  (surface: %zu triangles, %zu vertices)\n",
                      run.args->pathA.c_str(), run.a->triangleCount(), run.a->vertices.size()));
    add(std::snprintf(line, sizeof line, "B  %s  (surface: %zu triangles, %zu vertices)\n",
                      run.args->pathB.c_str(), run.b->triangleCount(), run.b->vertices.size()));
    add(std::snprintf(line, sizeof line, "%s in [%.17g, %.17g]   (width %.3g, tolerance %.3g)\n",
                      r.directed ? "h(surface A, surface B)" : "H(surface A, surface B)", r.lower, r.upper,
                      r.upper - r.lower, r.tolerance));
    auto direction = [&](const SurfaceBoundsDirected& d, const char* q, const char* o) {
        add(std::snprintf(line, sizeof line,
                          "  h(%s, %s) in [%.17g, %.17g]: %s triangle %u at %s -> %s triangle %u at %s\n", q,
                          o, d.lower, d.upper, q, d.fromTriangle, text(d.fromPoint).c_str(), o, d.toTriangle,
                          text(d.toPoint).c_str()));
    };
    direction(r.aToB, "A", "B");
    if (!r.directed) direction(r.bToA, "B", "A");
    add(std::snprintf(line, sizeof line,
                      "time (ms)  load %.2f | build %.2f | search %.2f | total %.2f | wall %.2f\n",
                      run.loadMs, r.buildMs, r.searchMs, r.totalMs, run.wallMs));
    const uint64_t queries = r.aToB.counters.queries + r.bToA.counters.queries;
    add(std::snprintf(line, sizeof line, "counters   queries %" PRIu64 ", splits %" PRIu64 "\n", queries,
                      r.aToB.counters.splits + r.bToA.counters.splits));
    return s;
}

}  // namespace

int surfacePairCommand(const CliArgs& args) {
    const Clock::time_point start = Clock::now();
    const io::LoadOptions loadOptions = loadOptionsOf(args);
    const Clock::time_point loadStart = Clock::now();
    Result<io::TriangleMesh> a = io::loadMesh(args.pathA, loadOptions);
    if (!a) return fail(a.error());
    Result<io::TriangleMesh> b = io::loadMesh(args.pathB, loadOptions);
    if (!b) return fail(b.error());
    const double loadMs = msSince(loadStart);

    SurfaceBoundsOptions options;
    options.backend = args.options.backend;
    options.threads = args.options.threads;
    options.deviceIndex = args.options.deviceIndex;
    options.validation = args.options.validation;
    options.tolerance = args.tolerance;
    options.directedOnly = args.options.directedOnly;
    Result<SurfaceBoundsResult> result = surfaceHausdorff(a->view(), b->view(), options);
    if (!result && result.error().message.rfind("tolerance", 0) == 0) {
        // The floor depends on the meshes: a usage error all the same.
        Error usage = result.error();
        usage.message = "option '--tolerance': " + usage.message;
        fail(usage);
        return kExitUsage;
    }
    if (!result) return fail(named(result.error(), args));

    const Run run{&args, &*a, &*b, &*result, loadMs, msSince(start)};
    const std::string out = args.json ? jsonReport(run) : summaryText(run);
    if (std::fwrite(out.data(), 1, out.size(), stdout) != out.size() || std::fflush(stdout) != 0)
        return fail(Error{ErrorCode::kInternal, "cannot write to stdout"});
    return kExitOk;
}

}  // namespace rthdist::cli
