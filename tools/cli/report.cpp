#include "cli/report.hpp"

#include <charconv>
#include <cstdarg>
#include <cstdio>

#include "cli/json_writer.hpp"
#include "cli/stats_report.hpp"

namespace rthdist::cli {

namespace {

[[gnu::format(printf, 2, 3)]] void appendf(std::string& out, const char* format, ...) {
    va_list ap;
    va_start(ap, format);
    va_list again;
    va_copy(again, ap);
    const int n = std::vsnprintf(nullptr, 0, format, ap);
    va_end(ap);
    if (n > 0) {
        const size_t at = out.size();
        out.resize(at + static_cast<size_t>(n) + 1);
        std::vsnprintf(out.data() + at, static_cast<size_t>(n) + 1, format, again);
        out.resize(at + static_cast<size_t>(n));
    }
    va_end(again);
}

// The shortest decimal that reads back as the coordinate: as a float when
// the value is one (float inputs), else as a double.
std::string coordinateText(double v) {
    char buf[64];
    const float f = float(v);
    const auto res =
        double(f) == v ? std::to_chars(buf, buf + sizeof buf, f) : std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, res.ptr);
}

std::string pointText(const glm::dvec3& p) {
    return "(" + coordinateText(p.x) + ", " + coordinateText(p.y) + ", " + coordinateText(p.z) + ")";
}

void writePoint(JsonWriter& w, const glm::dvec3& p) {
    w.beginArray(true).value(p.x).value(p.y).value(p.z).endArray();
}

void writeCounters(JsonWriter& w, const Counters& c) {
    w.beginObject()
        .field("bits", c.bits)
        .field("occupied_cells", c.occupiedCells)
        .field("queries", c.queries)
        .field("culled_by_neighbourhood", c.culledByNeighbourhood)
        .field("surviving_queries", c.survivingQueries)
        .field("iterations", c.iterations)
        .field("rays", c.rays)
        .field("candidate_pairs", c.candidatePairs)
        .endObject();
}

// One direction; `q`/`t` name the query and target sets ("a"/"b").
void writeDirected(JsonWriter& w, const Directed& d, const char* q, const char* t) {
    const std::string qs(q), ts(t);
    w.beginObject()
        .field("distance", d.distance)
        .field(qs + "_index", d.queryIndex)
        .field(ts + "_index", d.targetIndex);
    w.key(qs + "_point");
    writePoint(w, d.queryPoint);
    w.key(ts + "_point");
    writePoint(w, d.targetPoint);
    w.endObject();
}

void writeDirectedResult(JsonWriter& w, const HausdorffResult& r) {
    w.field("hausdorff", r.hausdorff);
    w.key("a_to_b");
    writeDirected(w, r.aToB, "a", "b");
    w.key("b_to_a");
    if (r.directedOnly) {
        w.null();
    } else {
        writeDirected(w, r.bToA, "b", "a");
    }
}

std::string countersText(const Counters& c) {
    std::string s;
    appendf(s,
            "queries %llu, culled %llu, surviving %llu, iterations %u, rays %llu, candidate pairs %llu, "
            "occupied cells %llu",
            (unsigned long long)c.queries, (unsigned long long)c.culledByNeighbourhood,
            (unsigned long long)c.survivingQueries, c.iterations, (unsigned long long)c.rays,
            (unsigned long long)c.candidatePairs, (unsigned long long)c.occupiedCells);
    return s;
}

}  // namespace

std::string summaryText(const RunReport& report) {
    const CliArgs& args = *report.args;
    const HausdorffResult& r = *report.result;
    std::string s;
    appendf(s, "rthdist %s: backend %s on %s\n", versionString(), backendName(r.backend), r.device.c_str());
    appendf(s, "A  %s  (%zu points)\n", args.pathA.c_str(), report.pointsA);
    appendf(s, "B  %s  (%zu points)\n", args.pathB.c_str(), report.pointsB);
    if (r.directedOnly) {
        appendf(s, "h(A,B) = %.10g   (directed only)\n", r.aToB.distance);
    } else {
        appendf(s, "H(A,B) = %.10g\n", r.hausdorff);
    }
    appendf(s, "  h(A,B) = %.10g   A[%u] %s -> B[%u] %s\n", r.aToB.distance, r.aToB.queryIndex,
            pointText(r.aToB.queryPoint).c_str(), r.aToB.targetIndex, pointText(r.aToB.targetPoint).c_str());
    if (!r.directedOnly) {
        appendf(s, "  h(B,A) = %.10g   B[%u] %s -> A[%u] %s\n", r.bToA.distance, r.bToA.queryIndex,
                pointText(r.bToA.queryPoint).c_str(), r.bToA.targetIndex,
                pointText(r.bToA.targetPoint).c_str());
    }
    if (r.directedOnly) {
        appendf(s, "bits       A->B %u\n", r.aToB.counters.bits);
    } else {
        appendf(s, "bits       A->B %u, B->A %u\n", r.aToB.counters.bits, r.bToA.counters.bits);
    }
    const Timings& t = r.timings;
    appendf(s,
            "time (ms)  load %.2f | setup %.2f | upload %.2f | index %.2f | cull %.2f | search %.2f | "
            "refine %.2f | check %.2f | total %.2f | wall %.2f\n",
            report.loadMs, t.setup, t.upload, t.index, t.cull, t.search, t.refine, t.check, t.total,
            report.wallMs);
    appendf(s, "counters   A->B %s\n", countersText(r.aToB.counters).c_str());
    if (!r.directedOnly) appendf(s, "           B->A %s\n", countersText(r.bToA.counters).c_str());
    if (report.stats != nullptr) s += statsText(*report.stats, r.directedOnly);
    if (args.options.validation) {
        appendf(s, "validation messages: %llu\n", (unsigned long long)r.validationMessages);
    }
    if (const Verification* v = report.verification) {
        appendf(s, "verify     cpu H = %.10g, h(A,B) = %.10g", v->cpu.hausdorff, v->cpu.aToB.distance);
        if (!r.directedOnly) appendf(s, ", h(B,A) = %.10g", v->cpu.bToA.distance);
        appendf(s, "; max |diff| %.3g, tolerance %.3g: %s\n", v->maxAbsDiff, v->tolerance,
                v->ok ? "agree" : "MISMATCH");
    }
    return s;
}

std::string jsonReport(const RunReport& report) {
    const CliArgs& args = *report.args;
    const HausdorffResult& r = *report.result;
    JsonWriter w;
    w.beginObject();
    w.field("version", versionString());
    w.key("files").beginObject().field("a", args.pathA).field("b", args.pathB).endObject();
    w.key("points")
        .beginObject()
        .field("a", uint64_t(report.pointsA))
        .field("b", uint64_t(report.pointsB))
        .endObject();
    auto precision = [](Scalar s) { return s == Scalar::kFloat64 ? "float64" : "float32"; };
    w.key("precision")
        .beginObject()
        .field("a", precision(report.scalarA))
        .field("b", precision(report.scalarB))
        .endObject();
    w.key("origin");
    writePoint(w, r.origin);
    w.field("backend", backendName(r.backend));
    w.field("device", r.device);
    w.field("bits", r.aToB.counters.bits);
    w.field("bits_requested", args.options.bits);
    w.field("directed", r.directedOnly);
    writeDirectedResult(w, r);

    const Timings& t = r.timings;
    w.key("timings_ms")
        .beginObject()
        .field("load", report.loadMs)
        .field("setup", t.setup)
        .field("upload", t.upload)
        .field("index", t.index)
        .field("cull", t.cull)
        .field("search", t.search)
        .field("refine", t.refine)
        .field("check", t.check)
        .field("total", t.total)
        .field("wall", report.wallMs)
        .endObject();

    w.key("counters").beginObject();
    w.key("a_to_b");
    writeCounters(w, r.aToB.counters);
    w.key("b_to_a");
    if (r.directedOnly) {
        w.null();
    } else {
        writeCounters(w, r.bToA.counters);
    }
    w.endObject();
    w.field("validation", args.options.validation);
    w.field("validation_messages", r.validationMessages);

    if (const Verification* v = report.verification) {
        w.key("verify").beginObject();
        w.field("ok", v->ok).field("tolerance", v->tolerance).field("max_abs_diff", v->maxAbsDiff);
        w.key("cpu").beginObject();
        writeDirectedResult(w, v->cpu);
        w.endObject();
        w.key("mismatches").beginArray();
        for (const std::string& m : v->mismatches) w.value(m);
        w.endArray();
        w.endObject();
    }
    if (report.stats != nullptr) writeStatsJson(w, *report.stats, r.directedOnly);
    w.endObject();
    return w.str() + "\n";
}

std::string devicesText(const std::vector<DeviceInfo>& devices) {
    std::string s;
    if (devices.empty()) s += "no Vulkan devices\n";
    for (const DeviceInfo& d : devices) {
        appendf(s, "[%d] %s\n", d.index, d.name.c_str());
        appendf(s, "    type %s, driver %s\n", d.type.c_str(), d.driver.c_str());
        appendf(s, "    ray-query: %s, rt-pipeline: %s\n", d.rayQuery ? "yes" : "no",
                d.rtPipeline ? "yes" : "no");
        for (const std::string& why : d.missing) appendf(s, "    - %s\n", why.c_str());
        std::string limits;
        for (const auto& [name, value] : d.limits)
            appendf(limits, " %s %llu", name.c_str(), (unsigned long long)value);
        if (!limits.empty()) appendf(s, "    limits:%s\n", limits.c_str());
    }
    return s;
}

std::string devicesJson(const std::vector<DeviceInfo>& devices) {
    JsonWriter w;
    w.beginObject().key("devices").beginArray();
    for (const DeviceInfo& d : devices) {
        w.beginObject()
            .field("index", d.index)
            .field("name", d.name)
            .field("type", d.type)
            .field("driver", d.driver)
            .field("ray_query", d.rayQuery)
            .field("rt_pipeline", d.rtPipeline);
        w.key("missing").beginArray();
        for (const std::string& why : d.missing) w.value(why);
        w.endArray();
        w.key("limits").beginObject();
        for (const auto& [name, value] : d.limits) w.field(name.c_str(), value);
        w.endObject().endObject();
    }
    w.endArray().endObject();
    return w.str() + "\n";
}

}  // namespace rthdist::cli
