#include "cli/args.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "cli/command_line.hpp"

namespace rthdist::cli {

namespace {

Error usageError(std::string message) { return Error{ErrorCode::kInvalidArgument, std::move(message)}; }

// Documented ranges of the numeric options (README "Usage", --help).
//
// --radius-growth: the candidate search starts at a radius of 2 cells and
// gives up after 4096 iterations (kMaxIterations in src/gpu_algo/radius_schedule.hpp),
// so growth^4096 must cover the largest possible ratio of a nearest distance
// to a cell: at most 2^130 (float range, sqrt(3) across) over 2^-157 (a
// subnormal extent split into 2^8 cells), 2^287 in all. 1.05^4096 = 2^288
// would leave no room for the iterations that re-run a radius with a larger
// pair buffer; 1.1^4096 = 2^563 leaves half the iterations spare. Above 16
// every ray reports most boxes from its second radius on: slower, no gain.
constexpr double kMinRadiusGrowth = 1.1;
constexpr double kMaxRadiusGrowth = 16.0;
// --bits: the library's largest index bit count (kMaxBits in
// src/core/index_space.hpp; the library rejects more, with exit code 3).
constexpr int kMaxBitsOption = 8;
constexpr int kMaxDeviceIndex = 1023;
constexpr int kMaxThreads = 1024;
// --memory-budget in MiB: up to 2^30 MiB (1 PiB) fits EngineOptions::memoryBudget.
constexpr int kMaxMemoryBudgetMib = 1 << 30;
constexpr int kMaxHistogramBins = 10000;
// LAS classification values are one byte (formats 0-5 use 0..31 of them).
constexpr int kMaxLasClass = 255;

std::string rangeText(double lo, double hi) {
    char text[64];
    std::snprintf(text, sizeof text, "[%g, %g]", lo, hi);
    return text;
}

// Whole-string integer in [lo, hi]; no sign other than a leading '-'.
std::optional<int> parseInt(std::string_view text, int lo, int hi) {
    int v = 0;
    const char* end = text.data() + text.size();
    const auto res = std::from_chars(text.data(), end, v);
    if (text.empty() || res.ec != std::errc() || res.ptr != end || v < lo || v > hi) return std::nullopt;
    return v;
}

// Whole-string finite number (from_chars: no leading '+', no spaces).
std::optional<double> parseNumber(std::string_view text) {
    double v = 0.0;
    const char* end = text.data() + text.size();
    const auto res = std::from_chars(text.data(), end, v);
    if (text.empty() || res.ec != std::errc() || res.ptr != end || !std::isfinite(v)) return std::nullopt;
    return v;
}

// "2,6,9": comma-separated integers in [0, kMaxLasClass], at least one.
// Comma-separated integers, each in [lo, hi].
std::optional<std::vector<int>> parseIntList(std::string_view text, int lo, int hi) {
    std::vector<int> values;
    for (;;) {
        const size_t comma = text.find(',');
        const auto n = parseInt(text.substr(0, comma), lo, hi);
        if (!n) return std::nullopt;
        values.push_back(*n);
        if (comma == std::string_view::npos) return values;
        text.remove_prefix(comma + 1);
    }
}

// Comma-separated finite numbers > 0, at least one.
std::optional<std::vector<double>> parsePositiveList(std::string_view text) {
    std::vector<double> values;
    for (;;) {
        const size_t comma = text.find(',');
        const auto v = parseNumber(text.substr(0, comma));
        if (!v || !(*v > 0.0)) return std::nullopt;
        values.push_back(*v);
        if (comma == std::string_view::npos) return values;
        text.remove_prefix(comma + 1);
    }
}

// A LAS file by its name: ".las", optionally ".gz" (case-insensitive).
bool isLasPath(std::string path) {
    for (char& c : path) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (path.ends_with(".gz")) path.resize(path.size() - 3);
    return path.ends_with(".las");
}

}  // namespace

std::string usageText() {
    return R"(Usage: rthdist [options] A B
       rthdist --list-devices [--json]

Exact Hausdorff distance H(A,B) = max(h(A,B), h(B,A)) between two 3-D point
sets, h(A,B) = max over a in A of the distance to its nearest point of B.
Inputs: .ply .xyz .txt .obj .gltf .glb .stl .off .pcd .las (optionally .gz);
compressed LAS (.laz) must be decompressed first (laszip, pdal translate).

Options:
  --json              print one JSON object instead of the summary
  --directed          compute only h(A,B)
  --backend NAME      auto | ray-query | rt-pipeline | cpu   (default auto: ray-query,
                      else rt-pipeline, on a hardware RT device; else cpu)
  --device N          Vulkan device index from --list-devices, 0..1023
                      (default: first usable)
  --devices LIST      several GPUs: comma-separated device indices (e.g. 0,1),
                      each once, at most 16, or all (every hardware RT
                      device, the first 16); a pair past the
                      memory budget spreads its pieces over them (the result
                      is one device's); a pair that fits runs on the first
  --bits K            index-space bit count 0..8, 0 = choose from the data (default 0)
  --radius-growth F   candidate-search radius factor per iteration, 1.1..16 (default 2)
  --threads N         host threads (the cpu backend, and every backend's passes over the
                      points) 0..1024, 0 = all hardware threads (default 0)
  --memory-budget MIB memory one backend call may hold, in MiB, 0..2^30; larger
                      inputs are computed exactly in query chunks and target
                      tiles (default 0: 3/4 of the device's budget; cpu: none)
  --verify            also run the CPU backend and compare (exit 1 on mismatch)
  --validation        enable the Vulkan validation layer, count its messages
  --list-devices      list Vulkan devices, the paths each supports, and why not
  --quiet             no progress on stderr (progress is shown only on a terminal)
  --surface SIDE      a | b: the exact distance from the other file's points to
                      the triangles of SIDE's mesh (obj, ply, off, stl, gltf,
                      glb), directed only: --surface b is h(A, surface of B);
                      the per-point options below give the points' side's
                      distances (exact on the cpu backend, which auto picks;
                      within the JSON's per_point.tolerance on a GPU one),
                      their files named for that side alone (--surface b:
                      PREFIX_a.*);
                      both: certified bounds [lower, upper] on H between the
                      surfaces of both meshes (--directed: h(A, B)), on the
                      cpu backend (auto picks it) or a GPU backend
  --tolerance T       --surface both: the largest width upper - lower, a
                      finite distance > 0 (default 1e-4 of the diagonal of
                      both meshes' box; at least ~4e-12 of their extent on
                      the cpu backend, ~6e-5 of their diagonal on a GPU one)
  --eval LIST         reconstruction evaluation, A the reconstruction and B the
                      ground truth: accuracy (A -> B) and completeness (B -> A)
                      mean and median, Chamfer, precision, recall and F-score
                      at each threshold of LIST (comma-separated, > 0; given
                      once); with --surface b, accuracy to B's triangles
  --eval-cap D        drop distances >= D from the means, medians and Chamfer
                      (DTU: 20 mm), D > 0 (default: no cap); precision and
                      recall keep them
  --eval-csv FILE     also write the summary as CSV, one row per threshold
  --las-classes LIST  read only the LAS points of these classification values,
                      comma-separated integers 0..255 (e.g. 2,6: ground and
                      buildings); needs a .las input, other formats are read whole

Per-point distances (each of these implies --per-point):
  --per-point         every point's nearest distance (exact for double input); statistics in the output
  --percentile P      also report the P-th percentile, 0..100, repeatable
                      (default 50 90 95 99; 95 is always reported: HD95)
  --histogram-bins N  histogram bins, 1..10000 (default 20)
  --range MIN MAX     fixed distance range of the colour ramp and histogram,
                      finite, 0 <= MIN < MAX (default 0 .. the largest distance)
  --out-ply PREFIX    write PREFIX_a.ply and PREFIX_b.ply: points with float
                      quality = distance and a red/green/blue colour ramp
  --out-csv PREFIX    write PREFIX_a.csv and PREFIX_b.csv: index,x,y,z,distance,nearest
                      (--surface a|b: index,x,y,z,distance,triangle, the closest
                      point closest_x,_y,_z and barycentric_0,_1,_2)
  --png FILE          picture of both sets coloured by distance, with the
                      Hausdorff segment
  --render NAME       vulkan | software: how --png draws the points (default
                      vulkan, headless; software when no Vulkan device works)
  --histogram-png FILE  bar chart of the distance histograms
  --help, -h          print this help
  --version           print the version

Output files are written to a temporary file beside them and renamed into
place when complete; an earlier file of the same name survives a failure.

Exit codes: 0 ok, 1 internal error or --verify mismatch, 2 usage error
            (unknown option, missing input, value out of range),
            3 bad input (unreadable/malformed file, empty set, NaN/Inf),
            4 no usable Vulkan device, 5 cannot write an output file.
)";
}

namespace {

[[noreturn]] void reject(std::string message) { throw UsageError{std::move(message)}; }

[[noreturn]] void outOfRange(const std::string& name, const std::string& value, const std::string& expected) {
    reject("option '" + name + "' expects " + expected + ", got '" + value + "'");
}

// The flags: --name alone, "--name=value" is an error.
void addFlags(CommandLine& line, CliArgs& out) {
    const std::pair<const char*, bool*> flags[] = {
        {"--json", &out.json},
        {"--directed", &out.options.directedOnly},
        {"--verify", &out.verify},
        {"--validation", &out.options.validation},
        {"--list-devices", &out.listDevices},
        {"--help", &out.help},  // and -h (parseArgs)
        {"--version", &out.version},
        {"--quiet", &out.quiet},
        {"--per-point", &out.perPoint},
    };
    for (const auto& [name, target] : flags) {
        line.flag(name, [name = std::string(name), target = target](bool withValue) {
            if (withValue) reject("option '" + name + "' takes no value");
            *target = true;
        });
    }
}

// An option with one value; `apply` checks and stores it.
void addValue(CommandLine& line, const std::string& name, std::function<void(const std::string&)> apply) {
    line.option(name, 1, [name, apply = std::move(apply)](const std::vector<std::string>& values, bool) {
        if (values.empty()) reject("option '" + name + "' needs a value");
        apply(values[0]);
    });
}

// An integer option in [lo, hi]; `expected` describes the range in messages.
void addInt(CommandLine& line, const std::string& name, int lo, int hi, const std::string& expected,
            int& target) {
    addValue(line, name, [=, &target](const std::string& v) {
        const auto n = parseInt(v, lo, hi);
        if (!n) outOfRange(name, v, expected);
        target = *n;
    });
}

void addComputeOptions(CommandLine& line, CliArgs& out) {
    addValue(line, "--backend", [&out](const std::string& v) {
        if (!parseBackend(v, out.options.backend))
            reject("unknown backend '" + v + "' (expected auto, ray-query, rt-pipeline or cpu)");
    });
    addInt(line, "--bits", 0, kMaxBitsOption, "an integer in " + rangeText(0, kMaxBitsOption) + " (0 = auto)",
           out.options.bits);
    addInt(line, "--device", 0, kMaxDeviceIndex, "a device index in " + rangeText(0, kMaxDeviceIndex),
           out.options.deviceIndex);
    addValue(line, "--devices", [&out](const std::string& v) {
        // A second --devices replaced the first list silently: one list.
        if (out.allDevices || !out.options.devices.empty())
            reject("option '--devices' is given twice; list every device in one (e.g. --devices 0,1)");
        if (v == "all") {
            out.allDevices = true;
            return;
        }
        const auto devices = parseIntList(v, 0, kMaxDeviceIndex);
        if (!devices)
            outOfRange(
                "--devices", v,
                "all, or comma-separated device indices in " + rangeText(0, kMaxDeviceIndex) + " (e.g. 0,1)");
        // Each device once (every entry opens a device), at most kMaxEngineDevices of them.
        if (devices->size() > kMaxEngineDevices)
            reject("option '--devices' lists " + std::to_string(devices->size()) + " devices; at most " +
                   std::to_string(kMaxEngineDevices));
        for (size_t i = 0; i < devices->size(); ++i) {
            if (std::find(devices->begin(), devices->begin() + std::ptrdiff_t(i), (*devices)[i]) !=
                devices->begin() + std::ptrdiff_t(i))
                reject("option '--devices' names device " + std::to_string((*devices)[i]) +
                       " twice; each device once");
        }
        out.options.devices = *devices;
    });
    addInt(line, "--threads", 0, kMaxThreads, "an integer in " + rangeText(0, kMaxThreads) + " (0 = all)",
           out.options.threads);
    addValue(line, "--memory-budget", [&out](const std::string& v) {
        const auto mib = parseInt(v, 0, kMaxMemoryBudgetMib);
        if (!mib) outOfRange("--memory-budget", v, "an integer number of MiB in [0, 2^30]");
        out.options.memoryBudget = uint64_t(*mib) << 20;
    });
    addValue(line, "--radius-growth", [&out](const std::string& v) {
        const auto f = parseNumber(v);
        if (!f || !(*f >= kMinRadiusGrowth && *f <= kMaxRadiusGrowth))
            outOfRange("--radius-growth", v, "a number in " + rangeText(kMinRadiusGrowth, kMaxRadiusGrowth));
        out.options.radiusGrowth = float(*f);
    });
    addValue(line, "--surface", [&out](const std::string& v) {
        if (v != "a" && v != "b" && v != "both")
            reject("option '--surface' expects a, b or both, got '" + v + "'");
        out.surface = v;
    });
    addValue(line, "--tolerance", [&out](const std::string& v) {
        const auto t = parseNumber(v);
        if (!t || !(*t > 0.0)) outOfRange("--tolerance", v, "a finite distance > 0");
        out.tolerance = *t;
    });
    addValue(line, "--eval", [&out](const std::string& v) {
        // A second --eval replaced the first's thresholds silently: one list.
        if (!out.evalThresholds.empty())
            reject("option '--eval' is given twice; list every threshold in one (e.g. --eval 0.01,0.02)");
        const auto list = parsePositiveList(v);
        if (!list) outOfRange("--eval", v, "comma-separated finite thresholds > 0 (e.g. 0.01,0.02)");
        out.evalThresholds = *list;
    });
    addValue(line, "--eval-cap", [&out](const std::string& v) {
        const auto d = parseNumber(v);
        // 0 is refused, not read as the library's "no cap" (EvalOptions::cap):
        // "drop distances >= 0" would drop them all; no --eval-cap is no cap.
        if (!d || !(*d > 0.0))
            outOfRange("--eval-cap", v, "a finite distance > 0 (no cap: leave --eval-cap out)");
        out.evalCap = *d;
    });
    addValue(line, "--eval-csv", [&out](const std::string& v) {
        if (v.empty()) reject("option '--eval-csv' needs a value");
        out.evalCsv = v;
    });
    addValue(line, "--las-classes", [&out](const std::string& v) {
        // A second --las-classes replaced the first list silently: one list.
        if (!out.lasClasses.empty())
            reject("option '--las-classes' is given twice; list every class in one (e.g. --las-classes 2,6)");
        const auto classes = parseIntList(v, 0, kMaxLasClass);
        if (!classes)
            outOfRange("--las-classes", v,
                       "comma-separated integers in " + rangeText(0, kMaxLasClass) + " (e.g. 2,6)");
        out.lasClasses = *classes;
    });
}

// The per-point options; each turns --per-point on.
void addPerPointOptions(CommandLine& line, CliArgs& out) {
    addValue(line, "--percentile", [&out](const std::string& v) {
        const auto p = parseNumber(v);
        if (!p || !(*p >= 0.0 && *p <= 100.0)) outOfRange("--percentile", v, "a number in [0, 100]");
        out.percentiles.push_back(*p);
        out.perPoint = true;
    });
    addValue(line, "--histogram-bins", [&out](const std::string& v) {
        const auto n = parseInt(v, 1, kMaxHistogramBins);
        if (!n) outOfRange("--histogram-bins", v, "an integer in " + rangeText(1, kMaxHistogramBins));
        out.histogramBins = *n;
        out.perPoint = true;
    });
    line.option("--range", 2, [&out](const std::vector<std::string>& v, bool inlineValue) {
        if (inlineValue) reject("option '--range' takes two values: --range MIN MAX");
        if (v.size() < 2) reject("option '--range' needs two values MIN MAX");
        // Distances are >= 0; finite bounds keep MAX - MIN and every bin finite.
        const auto lo = parseNumber(v[0]), hi = parseNumber(v[1]);
        if (!lo || !hi || !(*lo >= 0.0 && *hi > *lo))
            reject("option '--range' expects finite numbers 0 <= MIN < MAX, got '" + v[0] + "' '" + v[1] +
                   "'");
        out.hasRange = true;
        out.rangeLo = *lo;
        out.rangeHi = *hi;
        out.perPoint = true;
    });
    addValue(line, "--render", [&out](const std::string& v) {
        if (v != "vulkan" && v != "software")
            reject("unknown renderer '" + v + "' (expected vulkan or software)");
        out.softwareRender = v == "software";
        out.perPoint = true;  // as every per-point option (README: all but --quiet imply it)
    });
    for (auto [name, target] :
         {std::pair{"--out-ply", &out.outPly}, std::pair{"--out-csv", &out.outCsv},
          std::pair{"--png", &out.png}, std::pair{"--histogram-png", &out.histogramPng}}) {
        addValue(line, name, [name = std::string(name), target = target, &out](const std::string& v) {
            if (v.empty()) reject("option '" + name + "' needs a value");
            *target = v;
            out.perPoint = true;
        });
    }
}

// --surface reports the directed value alone (a|b) or certified bounds
// (both), on the cpu backend or on one device of a GPU backend, with
// per-point outputs for a|b: the options it cannot honour are refused,
// never ignored.
std::optional<Error> checkSurfaceOptions(const CliArgs& out) {
    if (out.tolerance > 0.0 && out.surface != "both")
        return usageError(
            "option '--tolerance' sets the width of surface-to-surface bounds: it needs --surface both");
    if (out.surface.empty()) return std::nullopt;
    if (out.perPoint && out.surface == "both")
        return usageError(
            "option '--surface both' gives certified bounds between two surfaces, not per-point distances: "
            "--per-point and its options need --surface a or b");
    if (out.verify)
        return usageError("option '--surface' proves its value itself: --verify has nothing to compare");
    if (!out.options.devices.empty() || out.allDevices)
        return usageError("option '--surface' runs on one device: --devices spreads work over GPUs");
    return std::nullopt;
}

// --eval: both directions' per-point distances, A the reconstruction, B
// the ground truth (points, or B's surface with --surface b).
std::optional<Error> checkEvalOptions(const CliArgs& out) {
    if (out.evalThresholds.empty()) {
        if (out.evalCap > 0.0)
            return usageError("option '--eval-cap' caps the distances of --eval: it needs --eval");
        if (!out.evalCsv.empty())
            return usageError("option '--eval-csv' writes the --eval summary: it needs --eval");
        return std::nullopt;
    }
    if (!out.surface.empty() && out.surface != "b")
        return usageError(
            "option '--eval' measures A (the reconstruction) to B (the ground truth): with a "
            "surface, only --surface b");
    if (out.options.directedOnly)
        return usageError("option '--eval' needs both directions: not with --directed");
    if (out.perPoint)
        return usageError("option '--eval' has no per-point outputs (--per-point and its options)");
    if (out.verify) return usageError("option '--eval': --verify compares Hausdorff values, not the summary");
    if (!out.options.devices.empty() || out.allDevices)
        return usageError("option '--eval' runs on one device: not with --devices");
    return std::nullopt;
}

}  // namespace

std::vector<int> everyRtDevice(Backend backend) {
    std::vector<int> devices;
    auto listed = listDevices();
    if (!listed) return devices;
    for (const DeviceInfo& d : listed.value()) {
        const bool runs = backend == Backend::kRayQuery     ? d.rayQuery
                          : backend == Backend::kRtPipeline ? d.rtPipeline
                                                            : d.rayQuery || d.rtPipeline;
        if (runs && d.type != "cpu") devices.push_back(d.index);
    }
    return devices;
}

Result<CliArgs> parseArgs(std::span<const std::string> args) {
    CliArgs out;
    std::vector<std::string> positional;
    // Operands are any argument that is not an option: "-" included, and
    // everything after "--".
    CommandLine line([&](const std::string& token, bool afterEnd) {
        if (afterEnd || token.size() < 2 || token[0] != '-') {
            positional.push_back(token);
        } else if (token == "-h") {
            out.help = true;
        } else if (token != "--") {
            const size_t eq = token.find('=');
            reject("unknown option '" + (token.rfind("--", 0) == 0 ? token.substr(0, eq) : token) + "'");
        }
    });
    addFlags(line, out);
    addComputeOptions(line, out);
    addPerPointOptions(line, out);
    if (auto error = line.parse(args)) return usageError(std::move(*error));

    if (out.help || out.version) return out;
    if (out.listDevices) {
        if (!positional.empty()) return usageError("--list-devices takes no input files");
        return out;
    }
    if (positional.size() != 2) {
        return usageError("expected two input files A and B, got " + std::to_string(positional.size()));
    }
    if (!out.lasClasses.empty() && !isLasPath(positional[0]) && !isLasPath(positional[1])) {
        return usageError("option '--las-classes' filters LAS files, but neither input is .las");
    }
    if ((!out.options.devices.empty() || out.allDevices) && out.options.backend == Backend::kCpu)
        return usageError("option '--devices' spreads the work over GPUs; the cpu backend uses --threads");
    if (auto error = checkEvalOptions(out)) return *error;
    if (auto error = checkSurfaceOptions(out)) return *error;
    out.options.perPointDistances = out.perPoint;
    out.pathA = positional[0];
    out.pathB = positional[1];
    return out;
}

io::LoadOptions loadOptionsOf(const CliArgs& args) {
    io::LoadOptions options;
    options.lasClasses = args.lasClasses;
    options.threads = unsigned(args.options.threads);
    return options;
}

}  // namespace rthdist::cli
