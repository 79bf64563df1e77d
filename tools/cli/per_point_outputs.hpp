// Writes every per-point output the command line asked for (--out-ply,
// --out-csv, --png, --histogram-png) from one finished run. The colour range
// is --range when given, else [0, the largest per-point distance] (= H).
#pragma once

#include <glm/vec3.hpp>

#include <span>
#include <vector>

#include "cli/args.hpp"
#include "rthdist/io.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::cli {

// The per-point outputs and their statistics work on float32 points: a
// double cloud is rounded (its distances stay those of the double input;
// past the float range a coordinate becomes an infinity).
[[nodiscard]] std::vector<glm::vec3> floatPoints(const io::PointCloud& cloud);

// Statistics options from the command line (95 always among the percentiles).
[[nodiscard]] StatsOptions statsOptionsFrom(const CliArgs& args);

struct RenderScene;

// --png: `scene` drawn (Vulkan unless --software-render; a software fallback
// or validation messages noted on stderr) and written to args.png.
[[nodiscard]] Result<bool> writeScenePng(const CliArgs& args, const RenderScene& scene);

// Every file goes through writeOutputFile (cli/output_file.hpp); each Error
// is an output that could not be written, its message naming the file and the
// reason, and the CLI exits kExitOutput with it. Files written before the
// failing one stay written.
// a, b: the float copies (the PLY's float x y z, the picture); givenA,
// givenB: the inputs as loaded (the CSV's coordinates).
[[nodiscard]] Result<bool> writePerPointOutputs(const CliArgs& args, std::span<const glm::vec3> a,
                                                std::span<const glm::vec3> b, const PointView& givenA,
                                                const PointView& givenB, const HausdorffResult& result,
                                                const HausdorffStats& stats);

}  // namespace rthdist::cli
