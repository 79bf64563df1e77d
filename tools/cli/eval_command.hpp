// `rthdist A B --eval TAU[,TAU...] [--eval-cap D] [--eval-csv FILE]
// [--surface b]`: the reconstruction-evaluation summary (rthdist/eval.hpp),
// A the reconstruction, B the ground truth. Point targets: both files' points
// and the engine's exact per-point distances; --surface b: accuracy to B's
// triangles, completeness from B's used vertices to A's points.
//
// JSON: version, mode "eval", target ("points" | "surface"), files {a, b},
//   points {a, b}, triangles {a: null, b: count | null}, eval {
//   reconstruction "a", ground_truth "b", cap (null: none), accuracy and
//   completeness {count, kept, mean, median, mean_squared, max}, chamfer
//   {mean_of_means, sum_of_means, sum_of_mean_squares}, thresholds
//   [{threshold, precision, recall, fscore}]}, timings_ms {load, evaluate,
//   wall}. Values with nothing kept under the cap are null.
// CSV (--eval-csv): a header and one row per threshold: threshold,
//   precision, recall, fscore, accuracy_mean, accuracy_median,
//   completeness_mean, completeness_median, chamfer_mean_of_means,
//   chamfer_sum_of_means, chamfer_sum_of_mean_squares, cap (empty: none).
#pragma once

#include "cli/args.hpp"

namespace rthdist::cli {

[[nodiscard]] int evalCommand(const CliArgs& args);

}  // namespace rthdist::cli
