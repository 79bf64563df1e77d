// `rthdist A B --surface a|b`: the exact distance from one file's points to
// the other file's triangles (rthdist/surface.hpp), directed only, on the
// CPU backend or, with --backend ray-query | rt-pipeline, a device's search
// proven on the host. --surface b: h(A, surface of B), reported as a_to_b
// with b_point the closest point of B's triangle `triangle`; --surface a:
// h(B, surface of A) as b_to_a. The other direction is null: B's vertices to
// A's points would be a different quantity from the surface's every point
// to A (surface to surface is --surface both, cli/surface_pair_command.hpp).
//
// JSON: version, mode "point-to-surface", surface, files {a, b},
//   points {a, b} (vertices of the mesh side), triangles {a, b} (null for
//   the points side), precision {a, b}, backend, device, directed (true),
//   hausdorff, a_to_b {distance, a_index, triangle, a_point, b_point,
//   barycentric} | null, b_to_a {distance, b_index, triangle, b_point,
//   a_point, barycentric} | null, per_point (with --per-point and its
//   options: the points' side's statistics, cli/surface_per_point.hpp),
//   timings_ms {load, build, search, total, wall}, counters {a_to_b,
//   b_to_a}.
// Per-point outputs (--per-point, --percentile, --histogram-bins, --range,
//   --out-ply, --out-csv, --png, --histogram-png): cli/surface_per_point.hpp,
//   on the cpu backend (auto picks it); a GPU backend proves the directed
//   maximum only, so the command line refuses them there (exit 2).
#pragma once

#include "cli/args.hpp"

namespace rthdist::cli {

// Loads both files, computes and prints; returns the exit code (every
// failure printed as "rthdist: <message>" on stderr).
[[nodiscard]] int surfaceCommand(const CliArgs& args);

}  // namespace rthdist::cli
