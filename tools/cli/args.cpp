#include "cli/args.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string_view>
#include <vector>

namespace rthdist::cli {

namespace {

Error usageError(std::string message) { return Error{ErrorCode::kInvalidArgument, std::move(message)}; }

// Documented ranges of the numeric options (README "Usage", --help).
//
// --radius-growth: the candidate search starts at a radius of 2 cells and
// gives up after 4096 iterations (kMaxIterations in src/algo/gpu_hausdorff.cpp),
// so growth^4096 must cover the largest possible ratio of a nearest distance
// to a cell: at most 2^130 (float range, sqrt(3) across) over 2^-157 (a
// subnormal extent split into 2^8 cells), 2^287 in all. 1.05^4096 = 2^288
// would leave no room for the iterations that re-run a radius with a larger
// pair buffer; 1.1^4096 = 2^563 leaves half the iterations spare. Above 16
// every ray reports most boxes from its second radius on: slower, no gain.
constexpr double kMinRadiusGrowth = 1.1;
constexpr double kMaxRadiusGrowth = 16.0;
// --bits: the library's largest index bit count (kMaxBits in
// src/algo/index_space.hpp; the library rejects more, with exit code 3).
constexpr int kMaxBitsOption = 8;
constexpr int kMaxDeviceIndex = 1023;
constexpr int kMaxThreads = 1024;
constexpr int kMaxHistogramBins = 10000;
// LAS classification values are one byte (formats 0-5 use 0..31 of them).
constexpr int kMaxLasClass = 255;

std::string rangeText(double lo, double hi) {
    char text[64];
    std::snprintf(text, sizeof text, "[%g, %g]", lo, hi);
    return text;
}

Error outOfRange(const std::string& name, const std::string& value, const std::string& expected) {
    return usageError("option '" + name + "' expects " + expected + ", got '" + value + "'");
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
std::optional<std::vector<int>> parseClassList(std::string_view text) {
    std::vector<int> classes;
    for (;;) {
        const size_t comma = text.find(',');
        const auto n = parseInt(text.substr(0, comma), 0, kMaxLasClass);
        if (!n) return std::nullopt;
        classes.push_back(*n);
        if (comma == std::string_view::npos) return classes;
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
  --bits K            index-space bit count 0..8, 0 = choose from the data (default 0)
  --radius-growth F   candidate-search radius factor per iteration, 1.1..16 (default 2)
  --threads N         CPU backend threads 0..1024, 0 = all hardware threads (default 0)
  --verify            also run the CPU backend and compare (exit 1 on mismatch)
  --validation        enable the Vulkan validation layer, count its messages
  --list-devices      list Vulkan devices, the paths each supports, and why not
  --quiet             no progress on stderr (progress is shown only on a terminal)
  --las-classes LIST  read only the LAS points of these classification values,
                      comma-separated integers 0..255 (e.g. 2,6: ground and
                      buildings); needs a .las input, other formats are read whole

Per-point distances (each of these implies --per-point):
  --per-point         every point's exact nearest distance; statistics in the output
  --percentile P      also report the P-th percentile, 0..100, repeatable
                      (default 50 90 95 99; 95 is always reported: HD95)
  --histogram-bins N  histogram bins, 1..10000 (default 20)
  --range MIN MAX     fixed distance range of the colour ramp and histogram,
                      finite, 0 <= MIN < MAX (default 0 .. the largest distance)
  --out-ply PREFIX    write PREFIX_a.ply and PREFIX_b.ply: points with float
                      quality = distance and a red/green/blue colour ramp
  --out-csv PREFIX    write PREFIX_a.csv and PREFIX_b.csv: index,x,y,z,distance,nearest
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

Result<CliArgs> parseArgs(std::span<const std::string> args) {
    CliArgs out;
    std::vector<std::string> positional;
    bool optionsEnded = false;

    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& arg = args[i];
        if (optionsEnded || arg.size() < 2 || arg[0] != '-') {
            positional.push_back(arg);
            continue;
        }
        if (arg == "--") {
            optionsEnded = true;
            continue;
        }
        std::string name = arg;
        std::optional<std::string> inlineValue;
        if (const size_t eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
            name = arg.substr(0, eq);
            inlineValue = arg.substr(eq + 1);
        }
        // Fetches the option's value from "--name=value" or the next argument.
        auto takeValue = [&]() -> std::optional<std::string> {
            if (inlineValue) return inlineValue;
            if (i + 1 >= args.size()) return std::nullopt;
            return args[++i];
        };
        auto flag = [&](bool& target) -> std::optional<Error> {
            if (inlineValue) return usageError("option '" + name + "' takes no value");
            target = true;
            return std::nullopt;
        };

        std::optional<Error> error;
        if (name == "--json") {
            error = flag(out.json);
        } else if (name == "--directed") {
            error = flag(out.options.directedOnly);
        } else if (name == "--verify") {
            error = flag(out.verify);
        } else if (name == "--validation") {
            error = flag(out.options.validation);
        } else if (name == "--list-devices") {
            error = flag(out.listDevices);
        } else if (name == "--help" || name == "-h") {
            error = flag(out.help);
        } else if (name == "--version") {
            error = flag(out.version);
        } else if (name == "--backend") {
            const auto v = takeValue();
            if (!v) return usageError("option '--backend' needs a value");
            if (!parseBackend(*v, out.options.backend)) {
                return usageError("unknown backend '" + *v +
                                  "' (expected auto, ray-query, rt-pipeline or cpu)");
            }
        } else if (name == "--bits") {
            const auto v = takeValue();
            if (!v) return usageError("option '--bits' needs a value");
            const auto n = parseInt(*v, 0, kMaxBitsOption);
            if (!n)
                return outOfRange(name, *v, "an integer in " + rangeText(0, kMaxBitsOption) + " (0 = auto)");
            out.options.bits = *n;
        } else if (name == "--device") {
            const auto v = takeValue();
            if (!v) return usageError("option '--device' needs a value");
            const auto n = parseInt(*v, 0, kMaxDeviceIndex);
            if (!n) return outOfRange(name, *v, "a device index in " + rangeText(0, kMaxDeviceIndex));
            out.options.deviceIndex = *n;
        } else if (name == "--threads") {
            const auto v = takeValue();
            if (!v) return usageError("option '--threads' needs a value");
            const auto n = parseInt(*v, 0, kMaxThreads);
            if (!n) return outOfRange(name, *v, "an integer in " + rangeText(0, kMaxThreads) + " (0 = all)");
            out.options.threads = *n;
        } else if (name == "--radius-growth") {
            const auto v = takeValue();
            if (!v) return usageError("option '--radius-growth' needs a value");
            const auto f = parseNumber(*v);
            if (!f || !(*f >= kMinRadiusGrowth && *f <= kMaxRadiusGrowth)) {
                return outOfRange(name, *v, "a number in " + rangeText(kMinRadiusGrowth, kMaxRadiusGrowth));
            }
            out.options.radiusGrowth = float(*f);
        } else if (name == "--las-classes") {
            const auto v = takeValue();
            if (!v) return usageError("option '--las-classes' needs a value");
            const auto classes = parseClassList(*v);
            if (!classes) {
                return outOfRange(
                    name, *v, "comma-separated integers in " + rangeText(0, kMaxLasClass) + " (e.g. 2,6)");
            }
            out.lasClasses = *classes;
        } else if (name == "--quiet") {
            error = flag(out.quiet);
        } else if (name == "--per-point") {
            error = flag(out.perPoint);
        } else if (name == "--percentile") {
            const auto v = takeValue();
            if (!v) return usageError("option '--percentile' needs a value");
            const auto p = parseNumber(*v);
            if (!p || !(*p >= 0.0 && *p <= 100.0)) return outOfRange(name, *v, "a number in [0, 100]");
            out.percentiles.push_back(*p);
            out.perPoint = true;
        } else if (name == "--histogram-bins") {
            const auto v = takeValue();
            if (!v) return usageError("option '--histogram-bins' needs a value");
            const auto n = parseInt(*v, 1, kMaxHistogramBins);
            if (!n) return outOfRange(name, *v, "an integer in " + rangeText(1, kMaxHistogramBins));
            out.histogramBins = *n;
            out.perPoint = true;
        } else if (name == "--range") {
            if (inlineValue) return usageError("option '--range' takes two values: --range MIN MAX");
            if (i + 2 >= args.size()) return usageError("option '--range' needs two values MIN MAX");
            // Distances are >= 0; finite bounds keep MAX - MIN and every bin finite.
            const auto lo = parseNumber(args[i + 1]), hi = parseNumber(args[i + 2]);
            if (!lo || !hi || !(*lo >= 0.0 && *hi > *lo)) {
                return usageError("option '--range' expects finite numbers 0 <= MIN < MAX, got '" +
                                  args[i + 1] + "' '" + args[i + 2] + "'");
            }
            i += 2;
            out.hasRange = true;
            out.rangeLo = *lo;
            out.rangeHi = *hi;
            out.perPoint = true;
        } else if (name == "--render") {
            const auto v = takeValue();
            if (!v) return usageError("option '--render' needs a value");
            if (*v != "vulkan" && *v != "software")
                return usageError("unknown renderer '" + *v + "' (expected vulkan or software)");
            out.softwareRender = *v == "software";
        } else if (name == "--out-ply" || name == "--out-csv" || name == "--png" ||
                   name == "--histogram-png") {
            const auto v = takeValue();
            if (!v || v->empty()) return usageError("option '" + name + "' needs a value");
            std::string& target = name == "--out-ply"   ? out.outPly
                                  : name == "--out-csv" ? out.outCsv
                                  : name == "--png"     ? out.png
                                                        : out.histogramPng;
            target = *v;
            out.perPoint = true;
        } else {
            return usageError("unknown option '" + name + "'");
        }
        if (error) return *error;
    }

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
    out.options.perPointDistances = out.perPoint;
    out.pathA = positional[0];
    out.pathB = positional[1];
    return out;
}

}  // namespace rthdist::cli
