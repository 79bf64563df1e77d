#include "cli/stats_report.hpp"

#include <cstdio>

namespace rthdist::cli {
namespace {

double normalize(double v, double diagonal) { return diagonal > 0.0 ? v / diagonal : 0.0; }

Json percentilesJson(const std::vector<Percentile>& list, double diagonal) {
    Json out = Json::array();
    for (const Percentile& p : list) out.push_back({{"p", p.p}, {"value", normalize(p.value, diagonal)}});
    return out;
}

Json blockJson(const DistanceStats& s, double diagonal) {
    return {{"count", s.count},
            {"min", s.min},
            {"max", s.max},
            {"mean", s.mean},
            {"rms", s.rms},
            {"percentiles", percentilesJson(s.percentiles, 1.0)},
            {"normalized",
             {{"min", normalize(s.min, diagonal)},
              {"max", normalize(s.max, diagonal)},
              {"mean", normalize(s.mean, diagonal)},
              {"rms", normalize(s.rms, diagonal)},
              {"percentiles", percentilesJson(s.percentiles, diagonal)}}}};
}

// The symmetric percentiles: max of the directed ones and pooled (null with --directed).
Json symmetricJson(const HausdorffStats& s, bool directedOnly) {
    Json out = Json::array();
    for (size_t i = 0; i < s.symmetric.size(); ++i) {
        const double p = s.symmetric[i].p, mx = s.symmetric[i].value;
        const double pooled = directedOnly ? 0.0 : s.pooled.percentiles[i].value;
        out.push_back({{"p", p},
                       {"max", mx},
                       {"pooled", directedOnly ? Json() : Json(pooled)},
                       {"max_normalized", normalize(mx, s.diagonal)},
                       {"pooled_normalized", directedOnly ? Json() : Json(normalize(pooled, s.diagonal))}});
    }
    return out;
}

Json hd95Json(const HausdorffStats& s, bool directedOnly) {
    Json out = Json::object();
    double hdMax = 0.0, hdPooled = 0.0;
    if (percentileVariant(s, "max", 95.0, hdMax)) {
        out["max"] = hdMax;
        out["max_normalized"] = normalize(hdMax, s.diagonal);
    }
    if (!directedOnly && percentileVariant(s, "pooled", 95.0, hdPooled)) {
        out["pooled"] = hdPooled;
        out["pooled_normalized"] = normalize(hdPooled, s.diagonal);
    }
    return out;
}

Json histogramJson(const HausdorffStats& s, bool directedOnly) {
    const Histogram& h = s.aToB.histogram;
    Json out = {{"lo", h.lo},
                {"hi", h.hi},
                {"bins", h.counts.size()},
                {"a_to_b", s.aToB.histogram.counts},
                {"b_to_a", directedOnly ? Json() : Json(s.bToA.histogram.counts)},
                {"pooled", directedOnly ? Json() : Json(s.pooled.histogram.counts)}};
    for (const char* side : {"below", "above"}) {
        const bool below = side[0] == 'b';
        auto count = [&](const DistanceStats& d) { return below ? d.histogram.below : d.histogram.above; };
        Json& sideJson = out[side] = {{"a_to_b", count(s.aToB)}};
        if (!directedOnly) {
            sideJson["b_to_a"] = count(s.bToA);
            sideJson["pooled"] = count(s.pooled);
        }
    }
    return out;
}

}  // namespace

Json statsJson(const HausdorffStats& s, bool directedOnly) {
    return {{"diagonal", s.diagonal},
            {"diagonal_a", s.diagonalA},
            {"diagonal_b", s.diagonalB},
            {"a_to_b", blockJson(s.aToB, s.diagonal)},
            {"b_to_a", directedOnly ? Json() : blockJson(s.bToA, s.diagonal)},
            {"pooled", directedOnly ? Json() : blockJson(s.pooled, s.diagonal)},
            {"percentiles", symmetricJson(s, directedOnly)},
            {"hd95", hd95Json(s, directedOnly)},
            {"histogram", histogramJson(s, directedOnly)}};
}

std::string statsText(const HausdorffStats& s, bool directedOnly, const char* directedName) {
    std::string out;
    char line[512];
    auto block = [&](const char* name, const DistanceStats& d) {
        std::snprintf(line, sizeof line, "           %-6s min %.6g  mean %.6g  rms %.6g  max %.6g", name,
                      d.min, d.mean, d.rms, d.max);
        out += line;
        for (const Percentile& p : d.percentiles) {
            std::snprintf(line, sizeof line, "  P%g %.6g", p.p, p.value);
            out += line;
        }
        out += "\n";
    };
    std::snprintf(line, sizeof line, "per-point  distances (bbox diagonal of A+B %.6g)\n", s.diagonal);
    out += line;
    block(directedName, s.aToB);
    if (!directedOnly) {
        block("B->A", s.bToA);
        block("pooled", s.pooled);
    }
    double hd = 0.0, pooled = 0.0;
    if (percentileVariant(s, "max", 95.0, hd)) {
        std::snprintf(line, sizeof line, "HD95       %.10g (max of directed P95; %.4g%% of diagonal)", hd,
                      100.0 * (s.diagonal > 0 ? hd / s.diagonal : 0.0));
        out += line;
        if (!directedOnly && percentileVariant(s, "pooled", 95.0, pooled)) {
            std::snprintf(line, sizeof line, ", pooled P95 %.10g", pooled);
            out += line;
        }
        out += "\n";
    }
    return out;
}

}  // namespace rthdist::cli
