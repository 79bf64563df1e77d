#include "cli/surface_per_point.hpp"

#include <cinttypes>
#include <cstdio>
#include <string>

#include "cli/histogram_plot.hpp"
#include "cli/per_point_files.hpp"
#include "cli/per_point_outputs.hpp"
#include "cli/point_render.hpp"
#include "cli/stats_report.hpp"

namespace rthdist::cli {
namespace {

std::string baseName(const std::string& path) {
    const size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

// The point sets' directed result that the statistics read: the points'
// distances as aNearest (a copy: 8 bytes per point).
HausdorffResult directedView(const SurfaceResult& r) {
    HausdorffResult h;
    h.hausdorff = r.hausdorff;
    h.directedOnly = true;
    h.aNearest.distance = r.perPoint.distance;
    h.backend = r.backend;
    h.device = r.device;
    return h;
}

// --surface a: the one direction runs from B, so the A-named keys of the
// point sets' layout become B's (and the other way round).
std::string mirrored(const std::string& key) {
    if (key == "a_to_b") return "b_to_a";
    if (key == "b_to_a") return "a_to_b";
    if (key == "diagonal_a") return "diagonal_b";
    if (key == "diagonal_b") return "diagonal_a";
    return key;
}

Json mirror(const Json& j) {
    if (j.is_object()) {
        Json out = Json::object();
        for (const auto& [key, value] : j.items()) out[mirrored(key)] = mirror(value);
        return out;
    }
    if (j.is_array()) {
        Json out = Json::array();
        for (const Json& v : j) out.push_back(mirror(v));
        return out;
    }
    return j;
}

}  // namespace

Result<HausdorffStats> surfaceStats(const SurfacePerPointRun& run) {
    if (run.result->perPoint.distance.size() != run.points.size())
        return Error{ErrorCode::kInvalidArgument, "the surface search returned no per-point distances"};
    return hausdorffStats(directedView(*run.result), run.pointsAsGiven, run.verticesAsGiven,
                          statsOptionsFrom(*run.args));
}

Json surfaceStatsJson(const HausdorffStats& stats, bool fromB) {
    const Json j = statsJson(stats, true);
    return fromB ? mirror(j) : j;
}

std::string surfaceStatsText(const HausdorffStats& stats, bool fromB) {
    return statsText(stats, true, fromB ? "B->A" : "A->B");
}

Result<bool> writeSurfacePerPointOutputs(const SurfacePerPointRun& run, const HausdorffStats& stats) {
    const CliArgs& args = *run.args;
    const SurfaceResult& r = *run.result;
    const std::string side = run.fromB ? "_b" : "_a";
    const ColourRange range{stats.aToB.histogram.lo, stats.aToB.histogram.hi};
    if (!args.outPly.empty()) {
        Result<bool> ok =
            writeDistancePly(args.outPly + side + ".ply", run.points, r.perPoint.distance, range,
                             "exact distance to the nearest point of the other file's triangles");
        if (!ok) return ok;
    }
    if (!args.outCsv.empty()) {
        Result<bool> ok = writeSurfaceCsv(args.outCsv + side + ".csv", run.pointsAsGiven, r.perPoint);
        if (!ok) return ok;
    }
    const std::string Q = run.fromB ? "B" : "A", S = run.fromB ? "A" : "B";
    if (!args.histogramPng.empty()) {
        HistogramLabels labels;
        labels.aToB = Q + "->surface " + S;
        labels.axis = "distance to the surface";
        Result<bool> ok = plotHistogram(stats, r.hausdorff, true, labels).writePng(args.histogramPng);
        if (!ok) return ok;
    }
    if (!args.png.empty()) {
        const SurfaceDirected& d = r.directed;
        RenderScene scene;
        scene.a = run.points;
        scene.b = run.vertices;  // grey: the surface has no per-point values
        scene.aDistance = r.perPoint.distance;
        scene.range = range;
        scene.segmentFrom = glm::vec3(d.queryPoint);
        scene.segmentTo = glm::vec3(d.surfacePoint);
        scene.hausdorff = r.hausdorff;
        scene.title = "rthdist: per-point distance to the surface";
        char line[256];
        std::snprintf(line, sizeof line, "%s %s (%zu points)   %s %s (surface: %zu vertices, grey)",
                      Q.c_str(), baseName(run.pointsPath).c_str(), run.points.size(), S.c_str(),
                      baseName(run.surfacePath).c_str(), run.vertices.size());
        scene.caption.push_back(line);
        double hd95 = 0.0;
        (void)percentileVariant(stats, "max", 95.0, hd95);
        std::snprintf(line, sizeof line,
                      "h(%s, surface %s) = %.6g (%s[%" PRIu64 "] -> triangle %u)   HD95 = %.6g   %s backend",
                      Q.c_str(), S.c_str(), r.hausdorff, Q.c_str(), d.queryIndex, d.triangle, hd95,
                      backendName(r.backend));
        scene.caption.push_back(line);
        if (Result<bool> ok = writeScenePng(args, scene); !ok) return ok;
    }
    return true;
}

}  // namespace rthdist::cli
