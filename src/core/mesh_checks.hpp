// The triangle indices of a MeshView checked before any surface call reads
// them (point to surface, surface to surface): a whole number of triangles,
// at least one, 32-bit counts, every index in range. The vertices are
// checked as a point set (core::summarizeSet).
#pragma once

#include <optional>
#include <string>

#include "rthdist/mesh.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::core {

// The error naming `name` ("surface B") and, for an index out of range,
// the first bad triangle (whatever the thread count), or nullopt. The
// indices are read on the worker pool (threads as EngineOptions::threads),
// in chunks: one past a bad index found already stops.
[[nodiscard]] std::optional<Error> checkTriangles(const MeshView& mesh, const std::string& name, int threads);

}  // namespace rthdist::core
