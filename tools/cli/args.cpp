#include "cli/args.hpp"

#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>
#include <vector>

namespace rthdist::cli {

namespace {

Error usageError(std::string message) { return Error{ErrorCode::kInvalidArgument, std::move(message)}; }

// Whole-string integer in [lo, hi]; no sign other than a leading '-'.
std::optional<int> parseInt(std::string_view text, int lo, int hi) {
    int v = 0;
    const char* end = text.data() + text.size();
    const auto res = std::from_chars(text.data(), end, v);
    if (text.empty() || res.ec != std::errc() || res.ptr != end || v < lo || v > hi) return std::nullopt;
    return v;
}

std::optional<float> parseFloat(std::string_view text) {
    double v = 0.0;
    const char* end = text.data() + text.size();
    const auto res = std::from_chars(text.data(), end, v);
    if (text.empty() || res.ec != std::errc() || res.ptr != end || !std::isfinite(v)) return std::nullopt;
    return static_cast<float>(v);
}

}  // namespace

std::string usageText() {
    return R"(Usage: rthdist [options] A B
       rthdist --list-devices [--json]

Exact Hausdorff distance H(A,B) = max(h(A,B), h(B,A)) between two 3-D point
sets, h(A,B) = max over a in A of the distance to its nearest point of B.
Inputs: .ply .xyz .txt .obj .gltf .glb .stl .off .pcd (optionally .gz).

Options:
  --json              print one JSON object instead of the summary
  --directed          compute only h(A,B)
  --backend NAME      auto | ray-query | rt-pipeline | cpu   (default auto: ray-query,
                      else rt-pipeline, on a hardware RT device; else cpu)
  --device N          Vulkan device index from --list-devices (default: first usable)
  --bits K            index-space bit count, 0 = choose from the data (default 0)
  --radius-growth F   candidate-search radius factor per iteration, > 1 (default 2)
  --threads N         CPU backend threads, 0 = all hardware threads (default 0)
  --verify            also run the CPU backend and compare (exit 1 on mismatch)
  --validation        enable the Vulkan validation layer, count its messages
  --list-devices      list Vulkan devices, the paths each supports, and why not
  --help, -h          print this help
  --version           print the version

Exit codes: 0 ok, 1 internal error or --verify mismatch, 2 usage error,
            3 bad input (unreadable/malformed file, empty set, NaN/Inf),
            4 no usable Vulkan device.
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
            const auto n = parseInt(*v, 0, 30);
            if (!n) return usageError("option '--bits' expects an integer in [0, 30], got '" + *v + "'");
            out.options.bits = *n;
        } else if (name == "--device") {
            const auto v = takeValue();
            if (!v) return usageError("option '--device' needs a value");
            const auto n = parseInt(*v, 0, 1 << 20);
            if (!n) return usageError("option '--device' expects a device index >= 0, got '" + *v + "'");
            out.options.deviceIndex = *n;
        } else if (name == "--threads") {
            const auto v = takeValue();
            if (!v) return usageError("option '--threads' needs a value");
            const auto n = parseInt(*v, 0, 1 << 16);
            if (!n) return usageError("option '--threads' expects an integer >= 0, got '" + *v + "'");
            out.options.threads = *n;
        } else if (name == "--radius-growth") {
            const auto v = takeValue();
            if (!v) return usageError("option '--radius-growth' needs a value");
            const auto f = parseFloat(*v);
            if (!f || !(*f > 1.0f)) {
                return usageError("option '--radius-growth' expects a number > 1, got '" + *v + "'");
            }
            out.options.radiusGrowth = *f;
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
    out.pathA = positional[0];
    out.pathB = positional[1];
    return out;
}

}  // namespace rthdist::cli
