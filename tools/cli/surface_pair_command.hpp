// `rthdist A B --surface both [--tolerance T]`: certified bounds on the
// Hausdorff distance between the surfaces of two meshes (rthdist/surface.hpp,
// surfaceHausdorff; design.md §12), on the CPU backend. --directed: the
// bounds of h(surface A, surface B) alone.
//
// JSON: version, mode "surface-to-surface", surface "both", files {a, b},
//   points {a, b} (vertices), triangles {a, b}, precision {a, b}, backend,
//   device, directed, hausdorff (null: only bounds are known), bounds
//   [lower, upper] (of H, or of h(A, B) with --directed), tolerance, slack,
//   origin, a_to_b {bounds, distance, a_triangle, a_point, a_barycentric,
//   triangle, b_point, barycentric} (the witness of the lower bound: a point
//   of A's triangle a_triangle and its closest point b_point on B's
//   triangle `triangle`), b_to_a (the mirror image; null with --directed),
//   timings_ms {load, build, search, total, wall}, counters {a_to_b, b_to_a}
//   {queries, patches, splits, rounds, max_depth}.
#pragma once

#include "cli/args.hpp"

namespace rthdist::cli {

// Loads both meshes, computes and prints; returns the exit code (every
// failure printed as "rthdist: <message>" on stderr).
[[nodiscard]] int surfacePairCommand(const CliArgs& args);

}  // namespace rthdist::cli
