// rthdist — command-line front end of the library: loads two point files,
// computes the exact Hausdorff distance and prints a summary or JSON.
// Every failure ends in "rthdist: <message>" on stderr and an exit code
// (cli/exit_codes.hpp); nothing escapes main().
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <future>
#include <limits>
#include <new>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "cli/args.hpp"
#include "cli/eval_command.hpp"
#include "cli/exit_codes.hpp"
#include "cli/per_point_outputs.hpp"
#include "cli/progress_meter.hpp"
#include "cli/report.hpp"
#include "cli/surface_command.hpp"
#include "cli/surface_pair_command.hpp"
#include "cli/verify.hpp"
#include "core/stopwatch.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::cli {
namespace {

using core::Clock;
using core::msSince;

int fail(int code, const std::string& message) {
    std::fflush(stdout);
    std::fprintf(stderr, "rthdist: %s\n", message.c_str());
    return code;
}

int failWith(const Error& error) { return fail(exitCodeFor(error.code), error.message); }

// Writes all of `text` to stdout; false when stdout is gone (closed pipe, full disk).
bool writeStdout(const std::string& text) {
    return std::fwrite(text.data(), 1, text.size(), stdout) == text.size() && std::fflush(stdout) == 0;
}

// At least as many points as two files can hold uncompressed (12 bytes a
// point, the least any format takes); the largest count when a size is
// unknown (a missing file: its load reports it).
uint64_t filePointsBound(const std::string& pathA, const std::string& pathB) {
    std::error_code ea, eb;
    const uintmax_t a = std::filesystem::file_size(pathA, ea), b = std::filesystem::file_size(pathB, eb);
    if (ea || eb) return UINT64_MAX;
    return uint64_t(a) / 12 + uint64_t(b) / 12;
}

// Loads one input in its file's precision; the message always names the file.
Result<io::PointCloud> load(const std::string& path, const io::LoadOptions& options) {
    Result<io::PointCloud> points = io::loadPointCloud(path, options);
    if (!points) {
        Error e = points.error();
        if (e.message.find(path) == std::string::npos) e.message = path + ": " + e.message;
        return e;
    }
    if (points->size() == 0) return Error{ErrorCode::kBadInput, path + ": no points"};
    return points;
}

int listDevicesCommand(const CliArgs& args) {
    Result<std::vector<DeviceInfo>> devices = rthdist::listDevices();
    if (!devices) return failWith(devices.error());
    const std::string text = args.json ? devicesJson(*devices) : devicesText(*devices);
    return writeStdout(text) ? kExitOk : fail(kExitInternal, "cannot write to stdout");
}

int run(const std::vector<std::string>& argv) {
    const Clock::time_point start = Clock::now();
    Result<CliArgs> parsed = parseArgs(argv);
    if (!parsed) return fail(kExitUsage, parsed.error().message + "\nTry 'rthdist --help'.");
    const CliArgs& args = *parsed;

    if (args.help) return writeStdout(usageText()) ? kExitOk : kExitInternal;
    if (args.version)
        return writeStdout(std::string("rthdist ") + versionString() + "\n") ? kExitOk : kExitInternal;
    if (args.listDevices) return listDevicesCommand(args);
    if (!args.evalThresholds.empty()) return evalCommand(args);
    if (args.surface == "both") return surfacePairCommand(args);
    if (!args.surface.empty()) return surfaceCommand(args);
    Options options = args.options;
    if (args.allDevices) {
        options.devices = everyRtDevice(options.backend);
        if (options.devices.size() > kMaxEngineDevices) options.devices.resize(kMaxEngineDevices);
        if (options.devices.empty())
            return fail(kExitNoDevice, "--devices all: no device with hardware ray tracing for the " +
                                           std::string(backendName(options.backend)) + " backend");
    }

    // The engine (a device and its pipelines: 0.2-0.75 s on a GPU) is
    // created while the files load, unless they are small enough for a
    // one-shot call to take the CPU backend (oneShotBackendFor; a file holds
    // at least 12 bytes a point unless compressed): those load first, and
    // the engine takes the backend for the points they hold.
    const auto createEngine = [](const EngineOptions& o) { return Engine::create(o); };
    const bool loadFirst =
        oneShotBackendFor(filePointsBound(args.pathA, args.pathB), options) != options.backend;
    std::future<Result<Engine>> engine;
    if (!loadFirst)
        engine = std::async(std::launch::async, createEngine, static_cast<const EngineOptions&>(options));
    const Clock::time_point loadStart = Clock::now();
    io::LoadOptions loadOptions;
    loadOptions.lasClasses = args.lasClasses;
    Result<io::PointCloud> a = load(args.pathA, loadOptions);
    if (!a) return failWith(a.error());
    Result<io::PointCloud> b = load(args.pathB, loadOptions);
    if (!b) return failWith(b.error());
    const double loadMs = msSince(loadStart);
    if (loadFirst) {
        EngineOptions chosen = options;
        chosen.backend = oneShotBackendFor(a->size() + b->size(), options);
        engine = std::async(std::launch::deferred, createEngine, chosen);
    }

    // Progress only on a terminal, for runs longer than a second, and never with --quiet.
    ProgressMeter meter(!args.quiet && ProgressMeter::stderrIsTerminal());
    options.progress = [&meter](const char* stage, double fraction) { meter.update(stage, fraction); };
    Result<HausdorffResult> result = [&]() -> Result<HausdorffResult> {
        Result<Engine> created = engine.get();
        // No engine: the one-shot call reports bad input first, then why.
        if (!created) return hausdorff(a->view(), b->view(), options);
        return created->compute(a->view(), b->view(), static_cast<const CallOptions&>(options));
    }();
    meter.finish();
    if (!result) return failWith(withFileNames(result.error(), args.pathA, args.pathB));

    std::optional<HausdorffStats> stats;
    if (args.perPoint) {
        const std::vector<glm::vec3> floatsA = floatPoints(*a);
        const std::vector<glm::vec3> floatsB = floatPoints(*b);
        Result<HausdorffStats> s = hausdorffStats(*result, a->view(), b->view(), statsOptionsFrom(args));
        if (!s) {
            return fail(kExitInternal, std::string("the ") + backendName(result->backend) +
                                           " backend returned no per-point distances: " + s.error().message);
        }
        stats = std::move(s).value();
        meter.update("output", 0.0);
        Result<bool> written =
            writePerPointOutputs(args, floatsA, floatsB, a->view(), b->view(), *result, *stats);
        meter.finish();
        if (!written) return fail(kExitOutput, written.error().message);
    }

    std::optional<Verification> verification;
    if (args.verify) {
        Result<Verification> v = verifyAgainstCpu(a->view(), b->view(), args.options, *result);
        if (!v) return failWith(v.error());
        verification = std::move(v).value();
    }

    RunReport report;
    report.args = &args;
    report.pointsA = a->size();
    report.pointsB = b->size();
    report.scalarA = a->scalar;
    report.scalarB = b->scalar;
    report.loadMs = loadMs;
    report.result = &*result;
    report.verification = verification ? &*verification : nullptr;
    report.stats = stats ? &*stats : nullptr;
    report.wallMs = msSince(start);
    if (!writeStdout(args.json ? jsonReport(report) : summaryText(report))) {
        return fail(kExitInternal, "cannot write to stdout");
    }

    if (verification && !verification->ok) {
        std::string message = std::string("--verify failed: the ") + backendName(result->backend) +
                              " backend disagrees with the cpu backend";
        for (const std::string& m : verification->mismatches) message += "\n  " + m;
        return fail(kExitInternal, message);
    }
    return kExitOk;
}

}  // namespace
}  // namespace rthdist::cli

int main(int argc, char** argv) {
    try {
        const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
        return rthdist::cli::run(args);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "rthdist: out of host memory\n");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rthdist: internal error: %s\n", e.what());
    } catch (...) {
        std::fprintf(stderr, "rthdist: internal error\n");
    }
    return rthdist::cli::kExitInternal;
}
