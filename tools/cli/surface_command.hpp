// `rthdist A B --surface a|b`: the exact distance from one file's points to
// the other file's triangles (rthdist/surface.hpp), directed only, on the
// CPU backend. --surface b: h(A, surface of B), reported as a_to_b with
// b_point the closest point of B's triangle `triangle`; --surface a: h(B,
// surface of A) as b_to_a. The other direction is null: B's vertices to
// A's points would be a different quantity from the surface's every point
// to A (surface to surface, issue 34's --surface both, comes later).
//
// JSON: version, mode "point-to-surface", surface, files {a, b},
//   points {a, b} (vertices of the mesh side), triangles {a, b} (null for
//   the points side), precision {a, b}, backend, device, directed (true),
//   hausdorff, a_to_b {distance, a_index, triangle, a_point, b_point,
//   barycentric} | null, b_to_a {distance, b_index, triangle, b_point,
//   a_point, barycentric} | null, timings_ms {load, build, search, total,
//   wall}, counters {a_to_b, b_to_a}.
#pragma once

#include "cli/args.hpp"

namespace rthdist::cli {

// Loads both files, computes and prints; returns the exit code (every
// failure printed as "rthdist: <message>" on stderr).
[[nodiscard]] int surfaceCommand(const CliArgs& args);

}  // namespace rthdist::cli
