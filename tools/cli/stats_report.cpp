#include "cli/stats_report.hpp"

#include <cstdio>

namespace rthdist::cli {
namespace {

double normalize(double v, double diagonal) { return diagonal > 0.0 ? v / diagonal : 0.0; }

void writePercentiles(JsonWriter& w, const std::vector<Percentile>& list, double diagonal) {
    w.beginArray();
    for (const Percentile& p : list) {
        w.beginObject().field("p", p.p).field("value", normalize(p.value, diagonal)).endObject();
    }
    w.endArray();
}

void writeBlock(JsonWriter& w, const DistanceStats& s, double diagonal) {
    w.beginObject()
        .field("count", s.count)
        .field("min", s.min)
        .field("max", s.max)
        .field("mean", s.mean)
        .field("rms", s.rms);
    w.key("percentiles");
    writePercentiles(w, s.percentiles, 1.0);
    w.key("normalized")
        .beginObject()
        .field("min", normalize(s.min, diagonal))
        .field("max", normalize(s.max, diagonal))
        .field("mean", normalize(s.mean, diagonal))
        .field("rms", normalize(s.rms, diagonal));
    w.key("percentiles");
    writePercentiles(w, s.percentiles, diagonal);
    w.endObject().endObject();
}

void writeCounts(JsonWriter& w, const Histogram& h) {
    w.beginArray(true);
    for (uint64_t c : h.counts) w.value(c);
    w.endArray();
}

}  // namespace

void writeStatsJson(JsonWriter& w, const HausdorffStats& s, bool directedOnly) {
    const double diag = s.diagonal;
    w.key("per_point").beginObject();
    w.field("diagonal", diag).field("diagonal_a", s.diagonalA).field("diagonal_b", s.diagonalB);
    w.key("a_to_b");
    writeBlock(w, s.aToB, diag);
    w.key("b_to_a");
    if (directedOnly) {
        w.null();
    } else {
        writeBlock(w, s.bToA, diag);
    }
    w.key("pooled");
    if (directedOnly) {
        w.null();
    } else {
        writeBlock(w, s.pooled, diag);
    }
    w.key("percentiles").beginArray();
    for (size_t i = 0; i < s.symmetric.size(); ++i) {
        const double p = s.symmetric[i].p, mx = s.symmetric[i].value;
        w.beginObject().field("p", p).field("max", mx);
        if (directedOnly) {
            w.key("pooled").null();
        } else {
            w.field("pooled", s.pooled.percentiles[i].value);
        }
        w.field("max_normalized", normalize(mx, diag));
        if (directedOnly) {
            w.key("pooled_normalized").null();
        } else {
            w.field("pooled_normalized", normalize(s.pooled.percentiles[i].value, diag));
        }
        w.endObject();
    }
    w.endArray();
    double hdMax = 0.0, hdPooled = 0.0;
    w.key("hd95").beginObject();
    if (percentileVariant(s, "max", 95.0, hdMax)) {
        w.field("max", hdMax).field("max_normalized", normalize(hdMax, diag));
    }
    if (!directedOnly && percentileVariant(s, "pooled", 95.0, hdPooled)) {
        w.field("pooled", hdPooled).field("pooled_normalized", normalize(hdPooled, diag));
    }
    w.endObject();

    const Histogram& h = s.aToB.histogram;
    w.key("histogram").beginObject();
    w.field("lo", h.lo).field("hi", h.hi).field("bins", uint64_t(h.counts.size()));
    w.key("a_to_b");
    writeCounts(w, s.aToB.histogram);
    w.key("b_to_a");
    if (directedOnly) {
        w.null();
    } else {
        writeCounts(w, s.bToA.histogram);
    }
    w.key("pooled");
    if (directedOnly) {
        w.null();
    } else {
        writeCounts(w, s.pooled.histogram);
    }
    for (const char* side : {"below", "above"}) {
        const bool below = side[0] == 'b';
        auto count = [&](const DistanceStats& d) { return below ? d.histogram.below : d.histogram.above; };
        w.key(side).beginObject().field("a_to_b", count(s.aToB));
        if (!directedOnly) w.field("b_to_a", count(s.bToA)).field("pooled", count(s.pooled));
        w.endObject();
    }
    w.endObject();
    w.endObject();
}

std::string statsText(const HausdorffStats& s, bool directedOnly) {
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
    block("A->B", s.aToB);
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
