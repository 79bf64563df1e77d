// Output of the CLI: the human-readable summary, the --json object and the
// --list-devices listing. Pure formatting: every function returns text.
//
// JSON schema of a run (README.md "JSON output" documents it for users):
//   version, files {a, b}, points {a, b}, backend, device, bits,
//   bits_requested, directed, hausdorff,
//   a_to_b {distance, a_index, b_index, a_point, b_point},
//   b_to_a {distance, b_index, a_index, b_point, a_point} | null,
//   timings_ms {load, setup, upload, index, cull, search, refine, total, wall},
//   counters {a_to_b {...}, b_to_a {...} | null}, validation_messages,
//   verify {...} (only with --verify),
//   per_point {...} (only with --per-point; cli/stats_report.hpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cli/args.hpp"
#include "cli/verify.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::cli {

struct RunReport {
    const CliArgs* args = nullptr;
    size_t pointsA = 0;
    size_t pointsB = 0;
    Scalar scalarA = Scalar::kFloat32;  // the precision each file was read in
    Scalar scalarB = Scalar::kFloat32;
    double loadMs = 0.0;  // both files, measured by the CLI
    double wallMs = 0.0;  // the whole command up to printing
    const HausdorffResult* result = nullptr;
    const Verification* verification = nullptr;  // null without --verify
    const HausdorffStats* stats = nullptr;       // null without --per-point
};

[[nodiscard]] std::string summaryText(const RunReport& report);
[[nodiscard]] std::string jsonReport(const RunReport& report);

// A library error about "point set A", "point set B" or "point sets A and
// B" (the input checks, core/input_limits.hpp) with the files' names added.
[[nodiscard]] Error withFileNames(Error error, const std::string& pathA, const std::string& pathB);

[[nodiscard]] std::string devicesText(const std::vector<DeviceInfo>& devices);
[[nodiscard]] std::string devicesJson(const std::vector<DeviceInfo>& devices);

}  // namespace rthdist::cli
