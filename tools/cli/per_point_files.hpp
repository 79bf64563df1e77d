// Per-point distance files of the CLI (--out-ply, --out-csv), written through
// writeOutputFile (cli/output_file.hpp): complete under their final name or
// not replaced at all.
//
// PLY: binary_little_endian 1.0, one `vertex` element per input point, in input
//   order: float x, y, z (the input floats), float quality (the exact NN
//   distance rounded to float; MeshLab shows it as vertex quality), uchar
//   red, green, blue (cli/colour_ramp.hpp Turbo ramp over `range`). No faces:
//   inputs are point sets. rthdist::io::loadPoints reads it back.
// CSV: header "index,x,y,z,distance,nearest"; one row per point in input
//   order; coordinates as the shortest decimal that reads back to the same
//   float, distance as the shortest decimal of the double, nearest = index of
//   the nearest point in the other set.
#pragma once

#include <glm/vec3.hpp>

#include <span>
#include <string>

#include "cli/colour_ramp.hpp"
#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cli {

[[nodiscard]] Result<bool> writeDistancePly(const std::string& path, std::span<const glm::vec3> points,
                                            const PerPoint& nearest, const ColourRange& range);

[[nodiscard]] Result<bool> writeDistanceCsv(const std::string& path, std::span<const glm::vec3> points,
                                            const PerPoint& nearest);

}  // namespace rthdist::cli
