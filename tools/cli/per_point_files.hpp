// Per-point distance files of the CLI (--out-ply, --out-csv), written through
// writeOutputFile (cli/output_file.hpp): complete under their final name or
// not replaced at all.
//
// PLY: binary_little_endian 1.0, one `vertex` element per input point, in input
//   order: float x, y, z (the input floats), float quality (the exact NN
//   distance rounded to float; MeshLab shows it as vertex quality), uchar
//   red, green, blue (cli/colour_ramp.hpp Turbo ramp over `range`). No faces:
//   inputs are point sets. rthdist::io::loadPoints reads it back.
//   Point to surface (`--surface a|b`): the same layout, quality the exact
//   distance to the nearest point of the other file's triangles.
// CSV: header "index,x,y,z,distance,nearest"; one row per point in input
//   order; coordinates as the input holds them (the shortest decimal that
//   reads back to the same float for float inputs, to the same double for
//   double ones), distance as the shortest decimal of the double, nearest =
//   index of the nearest point in the other set.
// Surface CSV (writeSurfaceCsv, `--surface a|b`): header "index,x,y,z,
//   distance,triangle,closest_x,closest_y,closest_z,barycentric_0,
//   barycentric_1,barycentric_2": x, y, z and distance as above, triangle =
//   index of the nearest triangle of the surface (in the file's face order,
//   polygons fan-triangulated), closest_* its closest point and
//   barycentric_* that point's coordinates w.r.t. the triangle's vertices
//   in index order, each the shortest decimal of the double
//   (rthdist/surface.hpp, SurfacePerPoint).
#pragma once

#include <glm/vec3.hpp>

#include <span>
#include <string>

#include "cli/colour_ramp.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/surface.hpp"

namespace rthdist::cli {

// distance: one per point; quality: what it is, for the header's comment.
[[nodiscard]] Result<bool> writeDistancePly(
    const std::string& path, std::span<const glm::vec3> points, std::span<const double> distance,
    const ColourRange& range,
    const std::string& quality = "exact distance to the nearest point of the other set");

// points: the input as loaded (its precision is the coordinates' columns').
[[nodiscard]] Result<bool> writeDistanceCsv(const std::string& path, const PointView& points,
                                            const PerPoint& nearest);

[[nodiscard]] Result<bool> writeSurfaceCsv(const std::string& path, const PointView& points,
                                           const SurfacePerPoint& nearest);

}  // namespace rthdist::cli
