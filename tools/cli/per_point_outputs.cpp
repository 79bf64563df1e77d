#include "cli/per_point_outputs.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "cli/histogram_plot.hpp"
#include "cli/per_point_files.hpp"
#include "cli/point_render.hpp"

namespace rthdist::cli {
namespace {

std::string baseName(const std::string& path) {
    const size_t slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

std::vector<glm::vec3> floatPoints(const io::PointCloud& cloud) {
    if (cloud.scalar == Scalar::kFloat32) return {cloud.floats.begin(), cloud.floats.end()};
    constexpr double kMax = std::numeric_limits<float>::max();
    auto narrow = [](double v) {  // beyond the float range: an infinity, not undefined behaviour
        return v > kMax ? INFINITY : v < -kMax ? -INFINITY : static_cast<float>(v);
    };
    std::vector<glm::vec3> out(cloud.doubles.size());
    for (size_t i = 0; i < out.size(); ++i) {
        const glm::dvec3& p = cloud.doubles[i];
        out[i] = glm::vec3(narrow(p.x), narrow(p.y), narrow(p.z));
    }
    return out;
}

StatsOptions statsOptionsFrom(const CliArgs& args) {
    StatsOptions o;
    if (!args.percentiles.empty()) o.percentiles = args.percentiles;
    if (std::find(o.percentiles.begin(), o.percentiles.end(), 95.0) == o.percentiles.end()) {
        o.percentiles.push_back(95.0);
    }
    o.histogramBins = args.histogramBins;
    if (args.hasRange) {
        o.rangeLo = args.rangeLo;
        o.rangeHi = args.rangeHi;
    }
    return o;
}

Result<bool> writeScenePng(const CliArgs& args, const RenderScene& scene) {
    RenderOptions renderOptions;
    renderOptions.vulkan = !args.softwareRender;
    renderOptions.deviceIndex = args.options.deviceIndex;
    renderOptions.validation = args.options.validation;
    RenderInfo info;
    Result<bool> ok = renderPicture(scene, renderOptions, &info).writePng(args.png);
    if (!ok) return ok;
    if (!info.fallbackReason.empty()) {
        std::fprintf(stderr, "rthdist: note: --png drawn in software, Vulkan could not: %s\n",
                     info.fallbackReason.c_str());
    }
    if (info.validationMessages > 0) {
        std::fprintf(stderr, "rthdist: note: the --png render raised %llu validation message(s)\n",
                     static_cast<unsigned long long>(info.validationMessages));
    }
    return true;
}

Result<bool> writePerPointOutputs(const CliArgs& args, std::span<const glm::vec3> a,
                                  std::span<const glm::vec3> b, const PointView& givenA,
                                  const PointView& givenB, const HausdorffResult& r,
                                  const HausdorffStats& stats) {
    ColourRange range{stats.aToB.histogram.lo, stats.aToB.histogram.hi};
    const bool withB = !r.directedOnly;
    if (!args.outPly.empty()) {
        Result<bool> ok = writeDistancePly(args.outPly + "_a.ply", a, r.aNearest.distance, range);
        if (!ok) return ok;
        if (withB) {
            ok = writeDistancePly(args.outPly + "_b.ply", b, r.bNearest.distance, range);
            if (!ok) return ok;
        }
    }
    if (!args.outCsv.empty()) {
        Result<bool> ok = writeDistanceCsv(args.outCsv + "_a.csv", givenA, r.aNearest);
        if (!ok) return ok;
        if (withB) {
            ok = writeDistanceCsv(args.outCsv + "_b.csv", givenB, r.bNearest);
            if (!ok) return ok;
        }
    }
    if (!args.histogramPng.empty()) {
        Result<bool> ok = plotHistogram(stats, r.hausdorff, r.directedOnly).writePng(args.histogramPng);
        if (!ok) return ok;
    }
    if (!args.png.empty()) {
        // The segment of H: the direction that realizes the maximum.
        const bool fromB = withB && r.bToA.distance > r.aToB.distance;
        const Directed& d = fromB ? r.bToA : r.aToB;
        RenderScene scene;
        scene.a = a;
        scene.b = withB ? b : std::span<const glm::vec3>();
        scene.aDistance = r.aNearest.distance;
        scene.bDistance = withB ? std::span<const double>(r.bNearest.distance) : std::span<const double>();
        scene.range = range;
        scene.segmentFrom = d.queryPoint;
        scene.segmentTo = d.targetPoint;
        scene.hausdorff = r.hausdorff;
        char line[256];
        std::snprintf(line, sizeof line, "A %s (%zu points)   B %s (%zu points)",
                      baseName(args.pathA).c_str(), a.size(), baseName(args.pathB).c_str(), b.size());
        scene.caption.push_back(line);
        double hd95 = 0.0;
        (void)percentileVariant(stats, "max", 95.0, hd95);
        std::snprintf(line, sizeof line,
                      "%s = %.6g (%s[%" PRIu64 "] -> %s[%" PRIu64 "])   HD95 = %.6g   %s backend",
                      r.directedOnly ? "h(A,B)" : "H", r.hausdorff, fromB ? "B" : "A", d.queryIndex,
                      fromB ? "A" : "B", d.targetIndex, hd95, backendName(r.backend));
        scene.caption.push_back(line);
        if (Result<bool> ok = writeScenePng(args, scene); !ok) return ok;
    }
    return true;
}

}  // namespace rthdist::cli
