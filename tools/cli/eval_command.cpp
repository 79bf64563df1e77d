#include "cli/eval_command.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "cli/exit_codes.hpp"
#include "cli/json_output.hpp"
#include "cli/output_file.hpp"
#include "cli/report.hpp"
#include "core/stopwatch.hpp"
#include "rthdist/eval.hpp"
#include "rthdist/io.hpp"

namespace rthdist::cli {
namespace {

using core::Clock;
using core::msSince;

int fail(const Error& error, int code) {
    std::fflush(stdout);
    std::fprintf(stderr, "rthdist: %s\n", error.message.c_str());
    return code;
}

Json distancesJson(const EvalDistances& d) {
    return {{"count", d.count},
            {"kept", d.kept},
            {"mean", d.mean},
            {"median", d.median},
            {"mean_squared", d.meanSquared},
            {"max", d.max}};
}

Json evalJson(const EvalSummary& s) {
    Json thresholds = Json::array();
    for (const EvalThreshold& t : s.thresholds) {
        thresholds.push_back({{"threshold", t.threshold},
                              {"precision", t.precision},
                              {"recall", t.recall},
                              {"fscore", t.fscore}});
    }
    return {{"reconstruction", "a"},
            {"ground_truth", "b"},
            {"cap", s.cap > 0.0 ? Json(s.cap) : Json()},
            {"accuracy", distancesJson(s.accuracy)},
            {"completeness", distancesJson(s.completeness)},
            {"chamfer",
             {{"mean_of_means", s.chamferMeanOfMeans},
              {"sum_of_means", s.chamferSumOfMeans},
              {"sum_of_mean_squares", s.chamferSumOfMeanSquares}}},
            {"thresholds", thresholds}};
}

// A CSV number: %.17g, empty when not finite (nothing kept under the cap).
std::string cell(double v) {
    if (!std::isfinite(v)) return "";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

std::string csvText(const EvalSummary& s) {
    std::string out =
        "threshold,precision,recall,fscore,accuracy_mean,accuracy_median,completeness_mean,"
        "completeness_median,chamfer_mean_of_means,chamfer_sum_of_means,chamfer_sum_of_mean_squares,cap\n";
    for (const EvalThreshold& t : s.thresholds) {
        for (double v : {t.threshold, t.precision, t.recall, t.fscore, s.accuracy.mean, s.accuracy.median,
                         s.completeness.mean, s.completeness.median, s.chamferMeanOfMeans,
                         s.chamferSumOfMeans, s.chamferSumOfMeanSquares})
            out += cell(v) + ",";
        out += (s.cap > 0.0 ? cell(s.cap) : std::string()) + "\n";
    }
    return out;
}

std::string summaryText(const CliArgs& args, const EvalSummary& s, bool surface) {
    std::string out;
    char line[512];
    auto add = [&](int n) { out.append(line, size_t(std::max(0, std::min(n, int(sizeof line) - 1)))); };
    add(std::snprintf(line, sizeof line, "rthdist %s: reconstruction evaluation (%s target)\n",
                      versionString(), surface ? "surface" : "points"));
    add(std::snprintf(line, sizeof line, "reconstruction A  %s\nground truth   B  %s\n", args.pathA.c_str(),
                      args.pathB.c_str()));
    if (s.cap > 0.0)
        add(std::snprintf(line, sizeof line, "cap %.10g (distances >= cap dropped from means)\n", s.cap));
    auto side = [&](const char* name, const EvalDistances& d) {
        add(std::snprintf(line, sizeof line, "%-13s mean %.10g  median %.10g  (%llu of %llu kept)\n", name,
                          d.mean, d.median, static_cast<unsigned long long>(d.kept),
                          static_cast<unsigned long long>(d.count)));
    };
    side("accuracy", s.accuracy);
    side("completeness", s.completeness);
    add(std::snprintf(line, sizeof line,
                      "chamfer       mean of means %.10g | sum of means %.10g | sum of mean squares %.10g\n",
                      s.chamferMeanOfMeans, s.chamferSumOfMeans, s.chamferSumOfMeanSquares));
    for (const EvalThreshold& t : s.thresholds) {
        add(std::snprintf(line, sizeof line, "tau %-10.6g  precision %.6f  recall %.6f  F-score %.6f\n",
                          t.threshold, t.precision, t.recall, t.fscore));
    }
    return out;
}

struct Loaded {
    io::PointCloud reconstruction;
    std::optional<io::PointCloud> truthPoints;
    std::optional<io::TriangleMesh> truthMesh;
};

Result<Loaded> load(const CliArgs& args) {
    const io::LoadOptions options = loadOptionsOf(args);
    Result<io::PointCloud> a = io::loadPointCloud(args.pathA, options);
    if (!a) return a.error();
    Loaded out{std::move(*a), std::nullopt, std::nullopt};
    if (args.surface == "b") {
        Result<io::TriangleMesh> b = io::loadMesh(args.pathB, options);
        if (!b) return b.error();
        out.truthMesh = std::move(*b);
    } else {
        Result<io::PointCloud> b = io::loadPointCloud(args.pathB, options);
        if (!b) return b.error();
        out.truthPoints = std::move(*b);
    }
    return out;
}

Result<EvalSummary> evaluate(const CliArgs& args, const Loaded& in) {
    EvalOptions eval;
    eval.thresholds = args.evalThresholds;
    eval.cap = args.evalCap;
    if (in.truthMesh) {
        SurfaceOptions options;
        options.backend = args.options.backend;
        options.threads = args.options.threads;
        options.deviceIndex = args.options.deviceIndex;
        options.validation = args.options.validation;
        return evaluateToSurface(in.reconstruction.view(), in.truthMesh->view(), eval, options);
    }
    return evaluatePoints(in.reconstruction.view(), in.truthPoints->view(), eval, args.options);
}

}  // namespace

int evalCommand(const CliArgs& args) {
    const Clock::time_point start = Clock::now();
    Result<Loaded> in = load(args);
    if (!in) return fail(in.error(), exitCodeFor(in.error().code));
    const double loadMs = msSince(start);
    const Clock::time_point evalStart = Clock::now();
    Result<EvalSummary> s = evaluate(args, *in);
    if (!s) return fail(withFileNames(s.error(), args.pathA, args.pathB), exitCodeFor(s.error().code));
    const double evalMs = msSince(evalStart);
    if (!args.evalCsv.empty()) {
        Result<bool> written = writeOutputFile(args.evalCsv, csvText(*s));
        if (!written) return fail(written.error(), kExitOutput);
    }
    const bool surface = in->truthMesh.has_value();
    std::string out;
    if (args.json) {
        const size_t b = surface ? in->truthMesh->vertices.size() : in->truthPoints->size();
        Json j = {
            {"version", versionString()},
            {"mode", "eval"},
            {"target", surface ? "surface" : "points"},
            {"files", {{"a", args.pathA}, {"b", args.pathB}}},
            {"points", {{"a", in->reconstruction.size()}, {"b", b}}},
            {"triangles", {{"a", Json()}, {"b", surface ? Json(in->truthMesh->triangleCount()) : Json()}}},
            {"eval", evalJson(*s)},
            {"timings_ms", {{"load", loadMs}, {"evaluate", evalMs}, {"wall", msSince(start)}}}};
        out = jsonText(j) + "\n";
    } else {
        out = summaryText(args, *s, surface);
    }
    if (std::fwrite(out.data(), 1, out.size(), stdout) != out.size() || std::fflush(stdout) != 0)
        return fail(Error{ErrorCode::kInternal, "cannot write to stdout"}, kExitInternal);
    return kExitOk;
}

}  // namespace rthdist::cli
