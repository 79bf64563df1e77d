// The per-point statistics in the CLI's outputs: the "per_point" JSON object
// and the summary lines (README "Per-point distances" documents both).
//
// JSON: per_point {
//   diagonal, diagonal_a, diagonal_b,           bbox diagonals (normalizer: diagonal of A ∪ B)
//   a_to_b | b_to_a | pooled: {count, min, max, mean, rms,
//       percentiles: [{p, value}], normalized: {min, max, mean, rms, percentiles: [{p, value}]}}
//       (b_to_a and pooled are null with --directed)
//   percentiles: [{p, max, pooled, max_normalized, pooled_normalized}]   symmetric and pooled
//   hd95: {max, pooled, max_normalized, pooled_normalized}
//   histogram: {lo, hi, bins, a_to_b: [...], b_to_a: [...] | null, pooled: [...] | null,
//               below: {a_to_b, b_to_a, pooled}, above: {...}} }
#pragma once

#include <string>

#include "cli/json_output.hpp"
#include "rthdist/stats.hpp"

namespace rthdist::cli {

// The "per_point" object.
[[nodiscard]] Json statsJson(const HausdorffStats& stats, bool directedOnly);

// Summary lines (each ends with '\n'). directedName: the label of the
// aToB block ("B->A" where the one direction measured runs from B, as for
// `--surface a`).
[[nodiscard]] std::string statsText(const HausdorffStats& stats, bool directedOnly,
                                    const char* directedName = "A->B");

}  // namespace rthdist::cli
