// rthdist-masks — HD, HD-p, ASSD/MSD and surface Dice between two
// segmentation masks (NIfTI-1/2 .nii/.nii.gz, NumPy .npy) in a named tool's
// convention (include/rthdist/masks.hpp; README "Segmentation masks").
//
//   rthdist-masks A B [B2 ...] [--label N | --labels all] [--convention NAME|all]
//                 [--percentile P]... [--connectivity 6|18|26] [--tolerance MM]
//                 [--monai-precision float32|double]
//                 [--spacing X,Y,Z | --affine 12 numbers] [--max-volume-mib N]
//                 [--backend B] [--device N]
//                 [--threads N] [--device-extraction [--host-extraction]] [--repeat N]
//                 [--unprepared] [--json | --csv]
//
// With more than one B, A is a reference compared with each B in turn
// through a prepared reference (rthdist/masks.hpp PreparedReference: A extracted
// and indexed once per label and convention); one row per (B, label,
// convention), each naming its B.
// A separate executable from `rthdist` (tools/cli/main.cpp), with its own
// options on the same CLI11 front end (cli/command_line.hpp). Exit codes are
// the point CLI's (cli/exit_codes.hpp): 0 ok, 1 internal, 2 usage, 3 bad
// input (unreadable file, grids that differ), 4 no device. Every error names
// the file it concerns.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <map>
#include <new>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/matrix.hpp>

#include "cli/command_line.hpp"
#include "cli/exit_codes.hpp"
#include "cli/json_output.hpp"
#include "rthdist/masks.hpp"

namespace rthdist::cli {
namespace {

using masks::Convention;
using masks::MaskResult;

struct MasksArgs {
    std::string pathA;
    std::vector<std::string> pathsB;  // one, or several predictions of the reference A
    std::optional<int32_t> label;     // --label N (both volumes)
    bool allLabels = false;           // --labels all
    std::vector<Convention> conventions{Convention::kRthdist};
    std::vector<double> percentiles;
    int connectivity = 0;
    double tolerance = 1.0;
    bool monaiFloat32 = true;  // --monai-precision float32 (default) | double
    glm::dvec3 spacing{1.0};
    std::optional<glm::dmat4> affine;  // --affine: voxel-to-world of .npy inputs
    masks::VolumeLimits limits;        // --max-volume-mib
    Options options;
    bool json = false, csv = false, help = false, version = false;
    bool deviceExtraction = false;  // --device-extraction: the boundary pass on a GPU backend
    bool hostExtraction = false;    // --host-extraction: the host all the same (tests compare)
    bool unprepared = false;        // --unprepared: several Bs without a prepared reference
    int repeat = 1;                 // --repeat N: each comparison N times (benchmarks)
};

// The --help text; the conventions' names come from their table.
std::string usageText() {
    std::string names = masks::conventionNames();
    names.insert(names.find(',') == std::string::npos ? names.size() : names.find(','), " (default)");
    return "usage: rthdist-masks A B [B2 ...] [options]\n"
           "Hausdorff distance, HD-p, ASSD/MSD and surface Dice between two segmentation masks\n"
           "(.nii, .nii.gz: NIfTI-1/2 with sform, else qform, else pixdim; .npy with --spacing).\n"
           "With several Bs, A is a reference compared with each (one row per B, label and\n"
           "convention), extracted and indexed once per label and convention.\n"
           "  --label N            compare label N in both volumes (default: every non-zero voxel)\n"
           "  --labels all         one row per label present in either volume\n"
           "  --convention NAME    " +
           names +
           ",\n"
           "                       or all (one row each)\n"
           "  --percentile P       HD-p to report, repeatable (default 95)\n"
           "  --connectivity C     boundary connectivity 6, 18 or 26 (default 6; itk uses all voxels,\n"
           "                       deepmind surfels)\n"
           "  --tolerance MM       surface Dice tolerance in mm (default 1)\n"
           "  --monai-precision float32|double  monai: compare distances with the tolerance and\n"
           "                       compute torch.quantile's rank in float32 as MONAI does (default),\n"
           "                       or in double\n"
           "  --spacing X,Y,Z      voxel spacing of .npy inputs along axes 0,1,2 (default 1,1,1)\n"
           "  --affine R00,R01,R02,T0,R10,...,T2  voxel-to-world of .npy inputs: 3x4, row-major\n"
           "  --max-volume-mib N   the most voxel data one volume may have, in MiB, as stored\n"
           "                       (inflated) and as held (1 byte a voxel for uint8/bool, else 4);\n"
           "                       default 2048; a larger file is refused (exit 3) before reading\n"
           "  --backend B          auto, cpu, ray-query, rt-pipeline (default auto)\n"
           "  --device N           Vulkan device index;  --threads N  CPU threads (0 = all)\n"
           "  --device-extraction  GPU backends: find boundary voxels with a compute shader\n"
           "                       (default: on the host, which measured faster)\n"
           "  --host-extraction    with --device-extraction: the host all the same (tests)\n"
           "  --repeat N           run each comparison N times in this process (benchmarks: JSON\n"
           "                       lists every run's time; the numbers are the last run's)\n"
           "  --unprepared         several Bs: extract and index A again for each (benchmarks;\n"
           "                       the same numbers)\n"
           "  --json | --csv       output format (default: text)\n"
           "Exit codes: 0 ok, 1 internal error, 2 usage, 3 bad input or different grids, 4 no device.\n";
}

Error usage(const std::string& m) { return Error{ErrorCode::kInvalidArgument, m}; }

std::optional<double> number(std::string_view t) {
    double v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size() || !std::isfinite(v))
        return std::nullopt;
    return v;
}

std::optional<int64_t> integer(std::string_view t) {
    int64_t v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
    return v;
}

[[noreturn]] void reject(std::string message) { throw UsageError{std::move(message)}; }

// "X,Y,Z": three positive numbers.
glm::dvec3 parseSpacing(const std::string& v) {
    double s[3];
    size_t at = 0;
    for (int k = 0; k < 3; ++k) {
        const size_t end = k < 2 ? v.find(',', at) : v.size();
        if (end == std::string::npos) reject("--spacing expects X,Y,Z, got '" + v + "'");
        const auto x = number(std::string_view(v).substr(at, end - at));
        if (!x || *x <= 0) reject("--spacing expects three positive numbers, got '" + v + "'");
        s[k] = *x;
        at = end + 1;
    }
    return {s[0], s[1], s[2]};
}

// 12 comma-separated numbers: the 3x4 voxel-to-world matrix, row-major.
glm::dmat4 parseAffine(const std::string& v) {
    glm::dmat4 m(1.0);
    size_t at = 0;
    for (int k = 0; k < 12; ++k) {
        const size_t end = k < 11 ? v.find(',', at) : v.size();
        if (end == std::string::npos) reject("--affine expects 12 comma-separated numbers");
        const auto x = number(std::string_view(v).substr(at, end - at));
        if (!x) reject("--affine expects 12 comma-separated numbers, got '" + v + "'");
        m[k % 4][k / 4] = *x;  // row k / 4, column k % 4 (glm is column-major)
        at = end + 1;
    }
    if (glm::determinant(glm::dmat3(m)) == 0.0) reject("--affine is singular");
    return m;
}

// An integer option in [lo, hi]; `message` + " got '<value>'" when it is not.
int64_t integerIn(const std::string& v, int64_t lo, int64_t hi, const std::string& message) {
    const auto n = integer(v);
    if (!n || *n < lo || *n > hi) reject(message + ", got '" + v + "'");
    return *n;
}

// The options that say what to compare and how.
void addMeasureOptions(CommandLine& line, MasksArgs& a, bool& conventionSet) {
    auto value = [&line](const std::string& name, std::function<void(const std::string&)> apply) {
        line.option(name, 1, [name, apply = std::move(apply)](const std::vector<std::string>& v, bool) {
            if (v.empty()) reject("option '" + name + "' needs a value");
            apply(v[0]);
        });
    };
    value("--label", [&a](const std::string& v) {
        a.label = int32_t(integerIn(v, INT32_MIN, INT32_MAX, "--label expects an int32"));
    });
    value("--labels", [&a](const std::string& v) {
        if (v != "all") reject("--labels expects 'all', got '" + v + "'");
        a.allLabels = true;
    });
    value("--convention", [&a, &conventionSet](const std::string& v) {
        if (!conventionSet) a.conventions.clear();
        conventionSet = true;
        Convention c;
        if (v == "all") {
            a.conventions.assign(masks::kAllConventions.begin(), masks::kAllConventions.end());
        } else if (masks::parseConvention(v, c)) {
            a.conventions.push_back(c);
        } else {
            reject("--convention expects " + masks::conventionNames() + " or all, got '" + v + "'");
        }
    });
    value("--percentile", [&a](const std::string& v) {
        const auto p = number(v);
        if (!p || *p < 0 || *p > 100) reject("--percentile expects a number in [0, 100], got '" + v + "'");
        a.percentiles.push_back(*p);
    });
    value("--connectivity", [&a](const std::string& v) {
        const auto n = integer(v);
        if (!n || (*n != 6 && *n != 18 && *n != 26))
            reject("--connectivity expects 6, 18 or 26, got '" + v + "'");
        a.connectivity = int(*n);
    });
    value("--tolerance", [&a](const std::string& v) {
        const auto t = number(v);
        if (!t || *t < 0) reject("--tolerance expects a number >= 0, got '" + v + "'");
        a.tolerance = *t;
    });
    value("--monai-precision", [&a](const std::string& v) {
        if (v != "float32" && v != "double")
            reject("--monai-precision expects float32 or double, got '" + v + "'");
        a.monaiFloat32 = v == "float32";
    });
    value("--spacing", [&a](const std::string& v) { a.spacing = parseSpacing(v); });
    value("--affine", [&a](const std::string& v) { a.affine = parseAffine(v); });
    value("--backend", [&a](const std::string& v) {
        if (!parseBackend(v, a.options.backend))
            reject("--backend expects auto, cpu, ray-query or rt-pipeline, got '" + v + "'");
    });
    value("--device", [&a](const std::string& v) {
        a.options.deviceIndex = int(integerIn(v, 0, 1023, "--device expects an index in [0, 1023]"));
    });
    value("--threads", [&a](const std::string& v) {
        a.options.threads = int(integerIn(v, 0, 1024, "--threads expects [0, 1024]"));
    });
    value("--max-volume-mib", [&a](const std::string& v) {
        a.limits.maxVolumeBytes =
            uint64_t(integerIn(v, 1, int64_t(1) << 30, "--max-volume-mib expects [1, 2^30] MiB")) << 20;
    });
    value("--repeat", [&a](const std::string& v) {
        a.repeat = int(integerIn(v, 1, 1000, "--repeat expects [1, 1000]"));
    });
}

Result<MasksArgs> parse(std::span<const std::string> argv) {
    MasksArgs a;
    std::vector<std::string> files;
    bool conventionSet = false;
    // Any argument that starts with '-' and is not an option is an error, "--" too.
    CommandLine line([&](const std::string& token, bool) {
        if (token == "-h") {
            a.help = true;
        } else if (token.size() > 1 && token[0] == '-') {
            const size_t eq = token.find('=');
            reject("unknown option '" + (token.rfind("--", 0) == 0 ? token.substr(0, eq) : token) + "'");
        } else {
            files.push_back(token);
        }
    });
    // Flags ignore a value ("--json=x" is --json).
    for (auto [name, target] :
         {std::pair{"--help", &a.help}, std::pair{"--version", &a.version}, std::pair{"--json", &a.json},
          std::pair{"--csv", &a.csv}, std::pair{"--host-extraction", &a.hostExtraction},
          std::pair{"--device-extraction", &a.deviceExtraction}, std::pair{"--unprepared", &a.unprepared}}) {
        line.flag(name, [target = target](bool) { *target = true; });
    }
    addMeasureOptions(line, a, conventionSet);
    if (auto error = line.parse(argv)) return usage(*error);

    if (a.help || a.version) return a;
    if (files.size() < 2)
        return usage("expected two mask files A B (or a reference A and several B), got " +
                     std::to_string(files.size()));
    if (a.label && a.allLabels) return usage("--label and --labels all exclude each other");
    if (a.json && a.csv) return usage("--json and --csv exclude each other");
    if (a.affine && a.spacing != glm::dvec3(1.0)) return usage("--spacing and --affine exclude each other");
    a.pathA = files[0];
    a.pathsB.assign(files.begin() + 1, files.end());
    if (a.percentiles.empty()) a.percentiles.push_back(95.0);
    return a;
}

struct Row {
    std::string b;                 // the B compared (several Bs only; else "")
    std::string label;             // "nonzero" or the label value
    MaskResult r;                  // the last run's
    std::vector<double> totalsMs;  // --repeat: every run's total
};

std::string num(double v) {
    if (std::isnan(v)) return "";
    char t[64];
    std::snprintf(t, sizeof t, "%.17g", v);
    return t;
}

Json volumeJson(const masks::Volume& v) {
    Json affine = Json::array();
    for (int r = 0; r < 3; ++r) {
        affine.push_back(Json::array());
        for (int c = 0; c < 4; ++c) affine.back().push_back(v.voxelToWorld[c][r]);
    }
    const glm::dvec3 s = v.spacing();
    return {{"path", v.path},
            {"dims", v.dims},
            {"transform", v.transform},
            {"affine", std::move(affine)},
            {"spacing", Json::array({s.x, s.y, s.z})}};
}

Json directedJson(const masks::DirectedMask& d, const MaskResult& r, bool ok) {
    Json out = {{"points", d.points}};
    if (!ok) return out;
    Json percentiles = Json::array();
    for (size_t i = 0; i < d.percentiles.size(); ++i)
        percentiles.push_back({{"p", r.percentiles[i]}, {"value", d.percentiles[i]}});
    out["hd"] = d.hd;
    out["mean"] = d.mean;
    out["surface_overlap"] = d.surfaceOverlap;
    const bool corners = masks::conventionRules(r.convention).points == masks::PointSet::kSurfels;
    if (corners) out["area_mm2"] = d.area;
    out["percentiles"] = std::move(percentiles);
    // Surfels (deepmind) are corners: corner (i, j, k) at voxel coordinates (i - 1/2, ...).
    out[corners ? "corner" : "voxel"] = d.voxel;
    out["point"] = Json::array({d.point.x, d.point.y, d.point.z});
    out[corners ? "nearest_corner" : "nearest_voxel"] = d.nearestVoxel;
    out["nearest_point"] = Json::array({d.nearestPoint.x, d.nearestPoint.y, d.nearestPoint.z});
    return out;
}

Json percentileTexts(const std::vector<double>& p, const std::vector<std::string>& texts) {
    Json out = Json::array();
    for (size_t i = 0; i < texts.size() && i < p.size(); ++i)
        out.push_back({{"p", p[i]}, {"value", texts[i]}});
    return out;
}

Json emptyDirectedJson(const masks::EmptyDirected& d, const std::vector<double>& p) {
    return {{"hd", d.hd},
            {"mean", d.mean},
            {"surface_overlap", d.surfaceOverlap},
            {"percentiles", percentileTexts(p, d.percentiles)}};
}

// What the convention's tool reports for a row with an empty mask, as text.
Json emptyJson(const MaskResult& r) {
    const masks::EmptyValues& e = r.emptyValues;
    return {{"hd", e.hd},
            {"hd_percentile", percentileTexts(r.percentiles, e.hdPercentile)},
            {"assd", e.assd},
            {"msd", e.msd},
            {"surface_dice", e.surfaceDice},
            {"a_to_b", emptyDirectedJson(e.aToB, r.percentiles)},
            {"b_to_a", emptyDirectedJson(e.bToA, r.percentiles)}};
}

Json rowJson(const Row& row) {
    const MaskResult& r = row.r;
    const bool ok = r.empty == masks::EmptyStatus::kNone;
    Json out = Json::object();
    if (!row.b.empty()) out["b"] = row.b;
    out.update(Json{{"label", row.label},
                    {"convention", masks::conventionName(r.convention)},
                    {"rule", masks::conventionRule(r.convention)},
                    {"connectivity", r.connectivity},
                    {"geometry", masks::metricName(masks::conventionRules(r.convention).metric)},
                    {"points_are", masks::pointSetName(masks::conventionRules(r.convention).points)},
                    {"status", masks::emptyStatusName(r.empty)}});
    if (!ok) out["convention_value"] = emptyJson(r);
    Json hdPercentile = Json::array();
    for (size_t i = 0; i < r.hdPercentile.size(); ++i)
        hdPercentile.push_back({{"p", r.percentiles[i]}, {"value", r.hdPercentile[i]}});
    out["hd"] = r.hd;
    out["hd_percentile"] = std::move(hdPercentile);
    out["assd"] = r.assd;
    out["msd"] = r.msd;
    out["surface_dice"] = r.surfaceDice;
    out["a_to_b"] = directedJson(r.aToB, r, ok);
    out["b_to_a"] = directedJson(r.bToA, r, ok);
    out["extraction"] = r.extraction;
    out["timings_ms"] = {{"extract", r.extractMs}, {"distance", r.distanceMs}, {"total", r.totalMs}};
    if (row.totalsMs.size() > 1) out["repeat_total_ms"] = row.totalsMs;
    const Timings& e = r.engine;
    out["engine_ms"] = {{"upload", e.upload},    {"index", e.index},          {"cull", e.cull},
                        {"search", e.search},    {"refine", e.refine},        {"check", e.check},
                        {"total", e.total},      {"gpu_upload", e.gpuUpload}, {"gpu_index", e.gpuIndex},
                        {"gpu_cull", e.gpuCull}, {"gpu_search", e.gpuSearch}, {"gpu_refine", e.gpuRefine}};
    return out;
}

// A prepared reference of a run with several Bs, as the JSON reports it.
struct PreparedInfo {
    std::string label;
    Convention convention;
    uint64_t points = 0, hostBytes = 0, deviceBytes = 0;
    double prepareMs = 0.0;
    std::string extraction;
};

// The volumes compared with A: {"b": B} with one, {"predictions": [...]} with several.
struct Report {
    const masks::Volume* a = nullptr;
    std::vector<Json> bs;
    std::vector<PreparedInfo> prepared;
    std::vector<Row> rows;
};

Json preparedJson(const std::vector<PreparedInfo>& prepared) {
    Json out = Json::array();
    for (const PreparedInfo& p : prepared)
        out.push_back({{"label", p.label},
                       {"convention", masks::conventionName(p.convention)},
                       {"points", p.points},
                       {"host_bytes", p.hostBytes},
                       {"device_bytes", p.deviceBytes},
                       {"prepare_ms", p.prepareMs},
                       {"extraction", p.extraction}});
    return out;
}

std::string jsonReport(const MasksArgs& args, const Report& report, const Engine& engine) {
    Json results = Json::array();
    for (const Row& row : report.rows) results.push_back(rowJson(row));
    Json j = {{"tool", "rthdist-masks"}, {"version", versionString()}, {"a", volumeJson(*report.a)}};
    if (args.pathsB.size() == 1) {
        j["b"] = report.bs.front();
    } else {
        j["predictions"] = report.bs;
        j["prepared_reference"] = !args.unprepared;
        j["prepared"] = preparedJson(report.prepared);
    }
    j.update(Json{{"backend", backendName(engine.backend())},
                  {"device", engine.deviceName()},
                  {"tolerance_mm", args.tolerance},
                  {"monai_precision", args.monaiFloat32 ? "float32" : "double"},
                  {"results", std::move(results)}});
    return jsonText(j) + "\n";
}

std::string csvReport(const MasksArgs& args, const std::vector<Row>& rows) {
    const bool several = args.pathsB.size() > 1;
    std::string out = several ? "b,label,convention,status,hd" : "label,convention,status,hd";
    for (double p : args.percentiles) out += ",hd" + num(p);
    out += ",assd,msd,surface_dice,a_to_b_hd,b_to_a_hd,a_points,b_points,total_ms\n";
    for (const Row& row : rows) {
        const MaskResult& r = row.r;
        if (several) out += row.b + ",";
        out += row.label + "," + masks::conventionName(r.convention) + "," + masks::emptyStatusName(r.empty) +
               "," + num(r.hd);
        // Each field appended after its comma (GCC 12 misreads "," + std::string&&
        // as an overlapping memcpy: -Wrestrict, GCC bug 105329).
        const auto field = [&out](const std::string& v) {
            out += ',';
            out += v;
        };
        for (size_t i = 0; i < args.percentiles.size(); ++i)
            field(i < r.hdPercentile.size() ? num(r.hdPercentile[i]) : "");
        for (double v : {r.assd, r.msd, r.surfaceDice, r.aToB.hd, r.bToA.hd}) field(num(v));
        field(std::to_string(r.aToB.points));
        field(std::to_string(r.bToA.points));
        field(num(r.totalMs));
        out += "\n";
    }
    return out;
}

std::string textReport(const MasksArgs& args, const Engine& engine, const std::vector<Row>& rows) {
    std::string out =
        std::string("backend ") + backendName(engine.backend()) + " (" + engine.deviceName() + ")\n";
    char line[512];
    for (const Row& row : rows) {
        const MaskResult& r = row.r;
        if (!row.b.empty()) out += row.b + "  ";
        std::snprintf(line, sizeof line, "label %s  %-11s ", row.label.c_str(),
                      masks::conventionName(r.convention));
        out += line;
        if (r.empty != masks::EmptyStatus::kNone) {
            const masks::EmptyValues& e = r.emptyValues;
            out += std::string(masks::emptyStatusName(r.empty)) + ": the convention reports HD " + e.hd;
            for (size_t i = 0; i < e.hdPercentile.size(); ++i) {
                std::snprintf(line, sizeof line, "  HD%g ", args.percentiles[i]);
                out += line + e.hdPercentile[i];
            }
            out += "  ASSD " + e.assd + "  MSD " + e.msd + "  SurfDice " + e.surfaceDice;
            std::snprintf(line, sizeof line, "  (%llu / %llu points)\n", (unsigned long long)r.aToB.points,
                          (unsigned long long)r.bToA.points);
            out += line;
            continue;
        }
        std::snprintf(line, sizeof line, "HD %.6f", r.hd);
        out += line;
        for (size_t i = 0; i < r.hdPercentile.size(); ++i) {
            std::snprintf(line, sizeof line, "  HD%g %.6f", args.percentiles[i], r.hdPercentile[i]);
            out += line;
        }
        if (!std::isnan(r.assd)) {
            std::snprintf(line, sizeof line, "  ASSD %.6f", r.assd);
            out += line;
        }
        std::snprintf(line, sizeof line, "  MSD %.6f", r.msd);
        out += line;
        if (!std::isnan(r.surfaceDice)) {
            std::snprintf(line, sizeof line, "  SurfDice@%g %.6f", args.tolerance, r.surfaceDice);
            out += line;
        }
        std::snprintf(line, sizeof line, "  (%llu / %llu points, %.1f ms)\n",
                      (unsigned long long)r.aToB.points, (unsigned long long)r.bToA.points, r.totalMs);
        out += line;
    }
    return out;
}

int fail(int code, const std::string& message) {
    std::fflush(stdout);
    std::fprintf(stderr, "rthdist-masks: %s\n", message.c_str());
    return code;
}

using Selections = std::vector<std::pair<std::string, masks::LabelSelect>>;

// The rows' labels: every label present in A or B (--labels all), one
// label, or every non-zero voxel.
Selections selectionsOf(const MasksArgs& args, const masks::Volume& a, const masks::Volume& b) {
    Selections selections;
    if (args.allLabels) {
        std::set<int32_t> labels;
        for (int32_t l : masks::labelsPresent(a)) labels.insert(l);
        for (int32_t l : masks::labelsPresent(b)) labels.insert(l);
        for (int32_t l : labels) selections.push_back({std::to_string(l), masks::LabelSelect{l, false}});
        if (selections.empty()) selections.push_back({"nonzero", masks::LabelSelect{1, true}});
    } else if (args.label) {
        selections.push_back({std::to_string(*args.label), masks::LabelSelect{*args.label, false}});
    } else {
        selections.push_back({"nonzero", masks::LabelSelect{1, true}});
    }
    return selections;
}

masks::MaskOptions maskOptions(const MasksArgs& args, Convention c) {
    masks::MaskOptions mo;
    mo.convention = c;
    mo.connectivity = args.connectivity;
    mo.percentiles = args.percentiles;
    mo.tolerance = args.tolerance;
    mo.monaiFloat32 = args.monaiFloat32;
    mo.threads = args.options.threads;
    mo.hostExtraction = args.hostExtraction;
    return mo;
}

// A's prepared references of a run with several Bs, one per (label, convention).
using PreparedCache = std::map<std::pair<std::string, Convention>, masks::PreparedReference>;

// The comparison of A's `select` with B's, args.repeat times, as one row:
// through A's prepared reference (created on first use) when `cache` is given.
Result<Row> compareRow(const MasksArgs& args, masks::MaskEngine& engine, const masks::Volume& a,
                       const masks::Volume& b, const std::string& label, masks::LabelSelect select,
                       Convention c, PreparedCache* cache, Report& report) {
    const masks::MaskOptions mo = maskOptions(args, c);
    const masks::PreparedReference* prepared = nullptr;
    if (cache != nullptr) {
        auto it = cache->find({label, c});
        if (it == cache->end()) {
            Result<masks::PreparedReference> p = masks::prepareReference(engine, a, select, mo);
            if (!p) return p.error();
            report.prepared.push_back(
                {label, c, p->points(), p->hostBytes(), p->deviceBytes(), p->prepareMs(), p->extraction()});
            it = cache->emplace(std::pair{label, c}, std::move(*p)).first;
        }
        prepared = &it->second;
    }
    Row row{args.pathsB.size() > 1 ? b.path : "", label, {}, {}};
    for (int run = 0; run < args.repeat; ++run) {
        Result<MaskResult> r = prepared ? masks::compareMasks(engine, *prepared, b, select, mo)
                                        : masks::compareMasks(engine, a, select, b, select, mo);
        if (!r) return r.error();
        row.totalsMs.push_back(r->totalMs);
        row.r = std::move(*r);
    }
    return row;
}

// B read and checked against A's grid.
Result<masks::Volume> loadB(const MasksArgs& args, const masks::Volume& a, const std::string& path) {
    Result<masks::Volume> b = masks::loadVolume(path, args.spacing, args.affine, args.limits);
    if (!b) return b;
    if (auto e = masks::checkSameGrid(a, *b)) return *e;
    return b;
}

// Every B in turn (loaded one at a time; the first may be given), its rows
// appended to `report`; 0 or the exit code after the message.
int compareAll(const MasksArgs& args, masks::MaskEngine& engine, const masks::Volume& a,
               std::optional<masks::Volume> first, Report& report) {
    PreparedCache cache;
    const bool prepare = args.pathsB.size() > 1 && !args.unprepared;
    for (const std::string& path : args.pathsB) {
        Result<masks::Volume> b = first ? Result<masks::Volume>(std::move(*first)) : loadB(args, a, path);
        first.reset();
        if (!b) return fail(exitCodeFor(b.error().code), b.error().message);
        report.bs.push_back(volumeJson(*b));
        for (const auto& [name, select] : selectionsOf(args, a, *b)) {
            for (Convention c : args.conventions) {
                Result<Row> row =
                    compareRow(args, engine, a, *b, name, select, c, prepare ? &cache : nullptr, report);
                if (!row) {
                    const std::string where = args.pathsB.size() > 1 ? path + ": label " : "label ";
                    return fail(exitCodeFor(row.error().code), where + name + ": " + row.error().message);
                }
                report.rows.push_back(std::move(*row));
            }
        }
    }
    return kExitOk;
}

// One pair (one B) without device extraction: the backend of a one-shot
// comparison (masks::oneShotMaskBackend: the CPU for small masks under
// auto). Several predictions share one engine as asked.
Options engineOptions(const MasksArgs& args, const masks::Volume& a, const std::optional<masks::Volume>& b) {
    Options options = args.options;
    if (b && !args.deviceExtraction)
        options.backend = masks::oneShotMaskBackend(options, a, *b, args.conventions);
    return options;
}

int run(int argc, char** argv) {
    std::vector<std::string> list(argv + 1, argv + argc);
    Result<MasksArgs> parsed = parse(list);
    if (!parsed) return fail(kExitUsage, parsed.error().message + "\nTry 'rthdist-masks --help'.");
    const MasksArgs& args = *parsed;
    if (args.help) return std::fputs(usageText().c_str(), stdout) >= 0 ? kExitOk : kExitInternal;
    if (args.version) return std::printf("rthdist-masks %s\n", versionString()) > 0 ? kExitOk : kExitInternal;

    Result<masks::Volume> a = masks::loadVolume(args.pathA, args.spacing, args.affine, args.limits);
    if (!a) return fail(exitCodeFor(a.error().code), a.error().message);
    std::optional<masks::Volume> first;  // both files read and checked before the engine starts
    if (args.pathsB.size() == 1) {
        Result<masks::Volume> b = loadB(args, *a, args.pathsB[0]);
        if (!b) return fail(exitCodeFor(b.error().code), b.error().message);
        first = std::move(*b);
    }
    Result<masks::MaskEngine> engine =
        masks::makeMaskEngine(engineOptions(args, *a, first), args.deviceExtraction);
    if (!engine) return fail(exitCodeFor(engine.error().code), engine.error().message);
    Report report;
    report.a = &*a;
    if (const int code = compareAll(args, *engine, *a, std::move(first), report); code != kExitOk)
        return code;
    const std::string text = args.json  ? jsonReport(args, report, engine->engine)
                             : args.csv ? csvReport(args, report.rows)
                                        : textReport(args, engine->engine, report.rows);
    if (std::fwrite(text.data(), 1, text.size(), stdout) != text.size() || std::fflush(stdout) != 0)
        return fail(kExitInternal, "cannot write to stdout");
    return kExitOk;
}

}  // namespace
}  // namespace rthdist::cli

int main(int argc, char** argv) {
    try {
        return rthdist::cli::run(argc, argv);
    } catch (const std::bad_alloc&) {
        return rthdist::cli::fail(rthdist::cli::kExitInternal, "out of host memory");
    } catch (const std::exception& e) {
        return rthdist::cli::fail(rthdist::cli::kExitInternal, e.what());
    }
}
