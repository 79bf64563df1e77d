#include "cli/report.hpp"

#include <charconv>
#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <utility>

#include "cli/json_output.hpp"
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
    // Appended in order: GCC 12 reads `"(" + std::string&&` (an insert at 0)
    // as an overlapping memcpy (-Wrestrict, GCC bug 105329).
    std::string text = "(";
    text += coordinateText(p.x);
    text += ", ";
    text += coordinateText(p.y);
    text += ", ";
    text += coordinateText(p.z);
    text += ")";
    return text;
}

Json pointJson(const glm::dvec3& p) { return Json::array({p.x, p.y, p.z}); }

Json countersJson(const Counters& c) {
    return {{"bits", c.bits},
            {"occupied_cells", c.occupiedCells},
            {"queries", c.queries},
            {"culled_by_neighbourhood", c.culledByNeighbourhood},
            {"surviving_queries", c.survivingQueries},
            {"iterations", c.iterations},
            {"rays", c.rays},
            {"candidate_pairs", c.candidatePairs},
            {"tail_scanned", c.tailScanned},
            {"query_chunks", c.queryChunks},
            {"target_tiles", c.targetTiles},
            {"cross_piece_queries", c.crossPieceQueries},
            {"narrowed_targets", c.narrowedTargets},
            {"per_point_mended", c.perPointMended}};
}

// One direction; `q`/`t` name the query and target sets ("a"/"b").
Json directedJson(const Directed& d, const std::string& q, const std::string& t) {
    return {{"distance", d.distance},
            {q + "_index", d.queryIndex},
            {t + "_index", d.targetIndex},
            {q + "_point", pointJson(d.queryPoint)},
            {t + "_point", pointJson(d.targetPoint)}};
}

// "hausdorff", "a_to_b", "b_to_a" (null with --directed) into `out`.
// The proof of one directed value (rthdist.hpp, Certificate).
Json certificateJson(const Certificate& c) {
    Json j = {{"confirmed", c.confirmed},
              {"query", c.query},
              {"nearest", c.nearest},
              {"distance", c.distance},
              {"band", c.band}};
    if (c.recomputed) {
        j["recomputed"] = true;
        j["failure"] = c.failure;
    } else if (!c.confirmed && !c.failure.empty()) {
        j["failure"] = c.failure;  // why the value is not proven in double (rthdist-mpi's double inputs)
    }
    return j;
}

void addDirectedResult(Json& out, const HausdorffResult& r) {
    out["hausdorff"] = r.hausdorff;
    out["a_to_b"] = directedJson(r.aToB, "a", "b");
    out["b_to_a"] = r.directedOnly ? Json() : directedJson(r.bToA, "b", "a");
    out["certificate"] = {{"a_to_b", certificateJson(r.aToB.certificate)},
                          {"b_to_a", r.directedOnly ? Json() : certificateJson(r.bToA.certificate)}};
}

std::string countersText(const Counters& c) {
    std::string s;
    appendf(s,
            "queries %llu, culled %llu, surviving %llu, iterations %u, rays %llu, candidate pairs %llu, "
            "occupied cells %llu",
            (unsigned long long)c.queries, (unsigned long long)c.culledByNeighbourhood,
            (unsigned long long)c.survivingQueries, c.iterations, (unsigned long long)c.rays,
            (unsigned long long)c.candidatePairs, (unsigned long long)c.occupiedCells);
    if (c.tailScanned > 0) appendf(s, ", tail scanned %llu", (unsigned long long)c.tailScanned);
    if (c.queryChunks > 1 || c.targetTiles > 1)
        appendf(s, ", out of core in %u query chunks x %u target tiles", c.queryChunks, c.targetTiles);
    if (c.crossPieceQueries > 0)
        appendf(s, ", %llu queries past their piece", (unsigned long long)c.crossPieceQueries);
    if (c.narrowedTargets > 0)
        appendf(s, ", targets narrowed to %llu", (unsigned long long)c.narrowedTargets);
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
    appendf(s, "  h(A,B) = %.10g   A[%" PRIu64 "] %s -> B[%" PRIu64 "] %s\n", r.aToB.distance,
            r.aToB.queryIndex, pointText(r.aToB.queryPoint).c_str(), r.aToB.targetIndex,
            pointText(r.aToB.targetPoint).c_str());
    if (!r.directedOnly) {
        appendf(s, "  h(B,A) = %.10g   B[%" PRIu64 "] %s -> A[%" PRIu64 "] %s\n", r.bToA.distance,
                r.bToA.queryIndex, pointText(r.bToA.queryPoint).c_str(), r.bToA.targetIndex,
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
    auto proof = [](const Certificate& c) {
        std::string text = c.confirmed ? "confirmed" : "not confirmed";
        appendf(text, " (band %llu)", (unsigned long long)c.band);
        if (c.recomputed) text += ", recomputed on the CPU backend: " + c.failure;
        if (!c.recomputed && !c.confirmed && !c.failure.empty()) text += ": " + c.failure;
        return text;
    };
    appendf(s, "certificate h(A,B) %s", proof(r.aToB.certificate).c_str());
    if (!r.directedOnly) appendf(s, ", h(B,A) %s", proof(r.bToA.certificate).c_str());
    s += "\n";
    appendf(s, "counters   A->B %s\n", countersText(r.aToB.counters).c_str());
    if (!r.directedOnly) appendf(s, "           B->A %s\n", countersText(r.bToA.counters).c_str());
    if (report.stats != nullptr) s += statsText(*report.stats, r.directedOnly);
    if (args.options.validation) {
        appendf(s, "validation messages: %llu\n", (unsigned long long)r.validationMessages);
    }
    if (const Verification* v = report.verification) {
        appendf(s, "verify     cpu H = %.10g, h(A,B) = %.10g", v->cpu.hausdorff, v->cpu.aToB.distance);
        if (!r.directedOnly) appendf(s, ", h(B,A) = %.10g", v->cpu.bToA.distance);
        appendf(s, "; max |diff| %.3g, tolerance %.3g: %s (cpu total %.2f ms)\n", v->maxAbsDiff, v->tolerance,
                v->ok ? "agree" : "MISMATCH", v->cpu.timings.total);
    }
    return s;
}

std::string jsonReport(const RunReport& report) {
    const CliArgs& args = *report.args;
    const HausdorffResult& r = *report.result;
    auto precision = [](Scalar s) { return s == Scalar::kFloat64 ? "float64" : "float32"; };
    const Timings& t = r.timings;
    Json j = {{"version", versionString()},
              {"files", {{"a", args.pathA}, {"b", args.pathB}}},
              {"points", {{"a", report.pointsA}, {"b", report.pointsB}}},
              {"precision", {{"a", precision(report.scalarA)}, {"b", precision(report.scalarB)}}},
              {"origin", pointJson(r.origin)},
              {"backend", backendName(r.backend)},
              {"device", r.device},
              {"bits", r.aToB.counters.bits},
              {"bits_requested", args.options.bits},
              {"directed", r.directedOnly}};
    addDirectedResult(j, r);
    j["timings_ms"] = {{"load", report.loadMs}, {"setup", t.setup}, {"upload", t.upload},
                       {"index", t.index},      {"cull", t.cull},   {"search", t.search},
                       {"refine", t.refine},    {"check", t.check}, {"certificate", t.certificate},
                       {"pieces", t.pieces},    {"total", t.total}, {"wall", report.wallMs}};
    if (r.backend != Backend::kCpu)  // device time per stage (timestamp queries)
        j["gpu_ms"] = {{"upload", t.gpuUpload}, {"index", t.gpuIndex},   {"cull", t.gpuCull},
                       {"search", t.gpuSearch}, {"refine", t.gpuRefine}, {"certificate", t.gpuCertificate}};
    j["counters"] = {{"a_to_b", countersJson(r.aToB.counters)},
                     {"b_to_a", r.directedOnly ? Json() : countersJson(r.bToA.counters)}};
    j["validation"] = args.options.validation;
    j["validation_messages"] = r.validationMessages;

    if (const Verification* v = report.verification) {
        Json cpu = Json::object();
        addDirectedResult(cpu, v->cpu);
        cpu["total_ms"] = v->cpu.timings.total;  // the CPU backend's call, beside this one
        j["verify"] = {{"ok", v->ok},
                       {"tolerance", v->tolerance},
                       {"max_abs_diff", v->maxAbsDiff},
                       {"cpu", std::move(cpu)},
                       {"mismatches", v->mismatches}};
    }
    if (report.stats != nullptr) j["per_point"] = statsJson(*report.stats, r.directedOnly);
    return jsonText(j) + "\n";
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
    Json list = Json::array();
    for (const DeviceInfo& d : devices) {
        Json& entry = list.emplace_back(Json::object());
        entry["index"] = d.index;
        entry["name"] = d.name;
        entry["type"] = d.type;
        entry["driver"] = d.driver;
        entry["ray_query"] = d.rayQuery;
        entry["rt_pipeline"] = d.rtPipeline;
        entry["missing"] = d.missing;
        Json& limits = entry["limits"] = Json::object();
        for (const auto& [name, value] : d.limits) limits[name] = value;
    }
    return jsonText(Json{{"devices", std::move(list)}}) + "\n";
}

Error withFileNames(Error error, const std::string& pathA, const std::string& pathB) {
    const std::pair<std::string, std::string> names[] = {
        {"point sets A and B", pathA + ", " + pathB}, {"point set A", pathA}, {"point set B", pathB}};
    for (const auto& [subject, files] : names) {
        if (error.message.rfind(subject, 0) != 0) continue;
        error.message.insert(subject.size(), " (" + files + ")");
        break;
    }
    return error;
}

}  // namespace rthdist::cli
