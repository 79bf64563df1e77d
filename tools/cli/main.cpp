// rthdist — command-line front end of the library: loads two point files,
// computes the exact Hausdorff distance and prints a summary or JSON.
// Every failure ends in "rthdist: <message>" on stderr and an exit code
// (cli/args.hpp, rthdist/result.hpp exitCodeFor); nothing escapes main().
#include <chrono>
#include <cstdio>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/per_point_outputs.hpp"
#include "cli/progress_meter.hpp"
#include "cli/report.hpp"
#include "cli/verify.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::cli {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

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

// Loads one input; the message always names the file.
Result<std::vector<glm::vec3>> load(const std::string& path) {
    Result<std::vector<glm::vec3>> points = io::loadPoints(path);
    if (!points) {
        Error e = points.error();
        if (e.message.find(path) == std::string::npos) e.message = path + ": " + e.message;
        return e;
    }
    if (points->empty()) return Error{ErrorCode::kBadInput, path + ": no points"};
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

    const Clock::time_point loadStart = Clock::now();
    Result<std::vector<glm::vec3>> a = load(args.pathA);
    if (!a) return failWith(a.error());
    Result<std::vector<glm::vec3>> b = load(args.pathB);
    if (!b) return failWith(b.error());
    const double loadMs = msSince(loadStart);

    // Progress only on a terminal, for runs longer than a second, and never with --quiet.
    ProgressMeter meter(!args.quiet && ProgressMeter::stderrIsTerminal());
    Options options = args.options;
    options.progress = [&meter](const char* stage, double fraction) { meter.update(stage, fraction); };
    Result<HausdorffResult> result = hausdorff(*a, *b, options);
    meter.finish();
    if (!result) return failWith(result.error());

    std::optional<HausdorffStats> stats;
    if (args.perPoint) {
        Result<HausdorffStats> s = hausdorffStats(*result, *a, *b, statsOptionsFrom(args));
        if (!s) {
            return fail(kExitInternal, std::string("the ") + backendName(result->backend) +
                                           " backend returned no per-point distances: " + s.error().message);
        }
        stats = std::move(s).value();
        meter.update("output", 0.0);
        Result<bool> written = writePerPointOutputs(args, *a, *b, *result, *stats);
        meter.finish();
        if (!written) return fail(kExitOutput, written.error().message);
    }

    std::optional<Verification> verification;
    if (args.verify) {
        Result<Verification> v = verifyAgainstCpu(*a, *b, args.options, *result);
        if (!v) return failWith(v.error());
        verification = std::move(v).value();
    }

    RunReport report;
    report.args = &args;
    report.pointsA = a->size();
    report.pointsB = b->size();
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
