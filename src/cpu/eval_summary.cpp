// evaluationSummary (rthdist/eval.hpp): accuracy, completeness, the three
// Chamfer conventions and precision / recall / F-score at thresholds, from
// two lists of nearest distances. The definitions are the header's.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "rthdist/eval.hpp"

namespace rthdist {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

// NumPy's median: the middle value, or the mean of the two middle values.
double median(std::vector<double> v) {
    if (v.empty()) return kNaN;
    const size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(mid), v.end());
    const double upper = v[mid];
    if (v.size() % 2 == 1) return upper;
    const double lower = *std::max_element(v.begin(), v.begin() + std::ptrdiff_t(mid));
    return (lower + upper) / 2.0;
}

EvalDistances summarize(std::span<const double> d, double cap) {
    EvalDistances out;
    out.count = d.size();
    std::vector<double> kept;
    kept.reserve(d.size());
    double sum = 0.0, sumSquares = 0.0, max = kNaN;
    for (double v : d) {
        if (cap > 0.0 && !(v < cap)) continue;
        kept.push_back(v);
        sum += v;
        sumSquares += v * v;
        max = std::isnan(max) ? v : std::max(max, v);
    }
    out.kept = kept.size();
    out.mean = kept.empty() ? kNaN : sum / double(kept.size());
    out.meanSquared = kept.empty() ? kNaN : sumSquares / double(kept.size());
    out.max = max;
    out.median = median(std::move(kept));
    return out;
}

double fractionBelow(std::span<const double> d, double tau) {
    const auto n = std::count_if(d.begin(), d.end(), [tau](double v) { return v < tau; });
    return double(n) / double(d.size());
}

std::optional<Error> checkOptions(const EvalOptions& options) {
    for (size_t i = 0; i < options.thresholds.size(); ++i) {
        const double t = options.thresholds[i];
        if (!std::isfinite(t) || !(t > 0.0)) {
            return Error{ErrorCode::kInvalidArgument, "evaluation threshold " + std::to_string(i) + " is " +
                                                          number(t) + ": a finite distance > 0"};
        }
    }
    if (!std::isfinite(options.cap) || options.cap < 0.0)
        return Error{ErrorCode::kInvalidArgument,
                     "evaluation cap is " + number(options.cap) + ": a finite distance > 0 (0: none)"};
    return std::nullopt;
}

std::optional<Error> checkDistances(std::span<const double> d, const char* name) {
    if (d.empty()) return Error{ErrorCode::kInvalidArgument, std::string(name) + ": no distances"};
    const auto bad = std::find_if(d.begin(), d.end(), [](double v) { return !std::isfinite(v) || v < 0.0; });
    if (bad == d.end()) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument, std::string(name) + ": distance " +
                                                  std::to_string(bad - d.begin()) + " is " + number(*bad) +
                                                  " (a finite distance >= 0)"};
}

}  // namespace

Result<EvalSummary> evaluationSummary(std::span<const double> accuracy, std::span<const double> completeness,
                                      const EvalOptions& options) {
    if (auto err = checkOptions(options)) return *err;
    if (auto err = checkDistances(accuracy, "accuracy (reconstruction -> ground truth)")) return *err;
    if (auto err = checkDistances(completeness, "completeness (ground truth -> reconstruction)")) return *err;
    EvalSummary s;
    s.cap = options.cap;
    s.accuracy = summarize(accuracy, options.cap);
    s.completeness = summarize(completeness, options.cap);
    s.chamferSumOfMeans = s.accuracy.mean + s.completeness.mean;
    s.chamferMeanOfMeans = s.chamferSumOfMeans / 2.0;
    s.chamferSumOfMeanSquares = s.accuracy.meanSquared + s.completeness.meanSquared;
    for (double tau : options.thresholds) {
        EvalThreshold t;
        t.threshold = tau;
        t.precision = fractionBelow(accuracy, tau);
        t.recall = fractionBelow(completeness, tau);
        const double sum = t.precision + t.recall;
        t.fscore = sum > 0.0 ? 2.0 * t.precision * t.recall / sum : 0.0;
        s.thresholds.push_back(t);
    }
    return s;
}

}  // namespace rthdist
