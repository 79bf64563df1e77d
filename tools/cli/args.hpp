// Command-line parsing for the rthdist CLI, on CLI11 (cli/command_line.hpp).
// Pure: no I/O, no exit(); the caller prints the usage error and picks the
// exit code (kExitUsage).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "cli/exit_codes.hpp"
#include "rthdist/io.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cli {

struct CliArgs {
    std::string pathA;
    std::string pathB;
    Options options;
    bool json = false;         // --json: one JSON object on stdout
    bool verify = false;       // --verify: re-run on the CPU backend and compare
    bool listDevices = false;  // --list-devices
    bool help = false;         // --help / -h
    bool version = false;      // --version

    // Per-point distances and what is made of them (README "Per-point
    // distances"). Every flag below except --quiet turns perPoint on.
    bool perPoint = false;            // --per-point (sets options.perPointDistances)
    std::vector<double> percentiles;  // --percentile P, repeatable; empty = defaults
    int histogramBins = 20;           // --histogram-bins N
    bool hasRange = false;            // --range MIN MAX (colour ramp and histogram)
    double rangeLo = 0.0, rangeHi = 0.0;
    std::string outPly;           // --out-ply PREFIX -> PREFIX_a.ply, PREFIX_b.ply
    std::string outCsv;           // --out-csv PREFIX -> PREFIX_a.csv, PREFIX_b.csv
    std::string png;              // --png FILE (picture)
    bool softwareRender = false;  // --render software|vulkan: how --png splats (default vulkan)
    std::string histogramPng;     // --histogram-png FILE
    bool quiet = false;           // --quiet: no progress on stderr
    std::vector<int> lasClasses;  // --las-classes 2,6: LAS classification filter (empty = all)
    bool allDevices = false;      // --devices all (options.devices: everyRtDevice)
    // --surface a|b: the points of the other file to this file's triangles
    // (cli/surface_command.hpp); both: surface to surface
    // (cli/surface_pair_command.hpp); empty: point sets.
    std::string surface;
    // --tolerance T: the width of surface-to-surface bounds (--surface both),
    // absolute; 0: the library's default (1e-4 of the bounding diagonal).
    double tolerance = 0.0;
    // --eval TAU[,TAU...]: the reconstruction-evaluation summary (A the
    // reconstruction, B the ground truth; cli/eval_command.hpp) at these
    // thresholds; --eval-cap D drops distances >= D from means and medians;
    // --eval-csv FILE writes the summary as CSV.
    std::vector<double> evalThresholds;
    double evalCap = 0.0;
    std::string evalCsv;
};

// Parses argv[1..]. Accepts "--option value" and "--option=value"; "--" ends
// the options. Errors (unknown option, missing or malformed value, wrong
// number of input files) come back as ErrorCode::kInvalidArgument with a
// message; with several, the first in command-line order.
[[nodiscard]] Result<CliArgs> parseArgs(std::span<const std::string> args);

// The --help text.
[[nodiscard]] std::string usageText();

// The loaders' options of a surface or evaluation command: --las-classes,
// and --threads as the parsing threads.
[[nodiscard]] io::LoadOptions loadOptionsOf(const CliArgs& args);

// `--devices all`: the listDevices() indices of every device with a hardware
// RT path for `backend` (software devices such as lavapipe only when named).
[[nodiscard]] std::vector<int> everyRtDevice(Backend backend);

}  // namespace rthdist::cli
