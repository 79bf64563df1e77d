// The per-point outputs of `rthdist A B --surface a|b` (README "Point to
// surface"): every point of the points' side measured to the other file's
// triangles (rthdist/surface.hpp, SurfacePerPoint), and what the point
// sets' per-point options make of such distances: the statistics (JSON
// "per_point", the summary lines, HD95 and the other percentiles), the
// colour PLY, a CSV with the triangle, closest point and barycentric
// coordinates, the picture and the histogram.
//
// Directed only: the points' side alone has per-point values (the
// surface's every point to the other file would be surface to surface).
// The statistics are those of the point sets with --directed
// (cli/stats_report.hpp): one block, for --surface b named a_to_b
// ("A->B"), for --surface a b_to_a ("B->A"); b_to_a / a_to_b and pooled
// null, diagonal of both files' points and vertices.
// Files: --out-ply PREFIX and --out-csv PREFIX write the points' side only,
//   PREFIX_a.* for --surface b, PREFIX_b.* for --surface a
//   (cli/per_point_files.hpp: writeDistancePly, writeSurfaceCsv); --png
//   draws the points coloured by distance, the mesh's vertices grey and the
//   witness segment; --histogram-png one histogram.
#pragma once

#include <glm/vec3.hpp>

#include <span>
#include <string>

#include "cli/args.hpp"
#include "cli/json_output.hpp"
#include "rthdist/stats.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::cli {

struct SurfacePerPointRun {
    const CliArgs* args = nullptr;
    bool fromB = false;                   // --surface a: the points are B's
    std::span<const glm::vec3> points;    // the points' side, rounded to float (floatPoints)
    std::span<const glm::vec3> vertices;  // the surface's vertices, rounded to float
    const SurfaceResult* result = nullptr;
    std::string pointsPath, surfacePath;
    // Both sides as loaded (double where the files are): the statistics'
    // diagonals are theirs.
    PointView pointsAsGiven, verticesAsGiven;
};

// The statistics of run.result->perPoint.distance (statsOptionsFrom(args));
// kInvalidArgument when the result has no per-point distances.
[[nodiscard]] Result<HausdorffStats> surfaceStats(const SurfacePerPointRun& run);

// The "per_point" object, keys named for the points' side.
[[nodiscard]] Json surfaceStatsJson(const HausdorffStats& stats, bool fromB);

// Summary lines (each ends with '\n').
[[nodiscard]] std::string surfaceStatsText(const HausdorffStats& stats, bool fromB);

// Every file the command line asked for (the point sets' rules: written
// through writeOutputFile; an Error names the file, and the CLI exits
// kExitOutput).
[[nodiscard]] Result<bool> writeSurfacePerPointOutputs(const SurfacePerPointRun& run,
                                                       const HausdorffStats& stats);

}  // namespace rthdist::cli
