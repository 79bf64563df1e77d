// x/y/z of fixed-size binary records (binary PLY vertices without list
// properties, binary PCD rows) converted in parallel chunks straight into
// the cloud: no copy of the file, no per-value type switch when the three
// coordinates share a type, each chunk of the cloud first touched by the
// thread that converts it and checked for NaN/Inf while it is in cache.
#pragma once

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "io/parallel_chunks.hpp"
#include "io/scalar_type.hpp"

namespace rthdist::io {

struct RecordLayout {
    const char* first = nullptr;  // the first record
    size_t stride = 0;            // bytes per record
    uint64_t count = 0;           // records (the caller checked they fit the file)
    std::array<size_t, 3> offset{};
    std::array<ScalarType, 3> type{};
    bool bigEndian = false;
};

// out holds room for layout.count points (written, never read, before
// they are converted). Values are those of loadScalar: doubles as stored,
// floats rounded by narrowToFloat (a double beyond the float range becomes
// an infinity). Returns the error naming the first record with a NaN or
// infinite coordinate (non_finite.hpp: "vertex i: coordinate y is NaN",
// record i being vertex i of path); the records after its chunk may then be
// left unconverted.
[[nodiscard]] std::optional<Error> convertRecords(const RecordLayout& layout, glm::vec3* out,
                                                  const ChunkPlan& plan, const std::string& path);
[[nodiscard]] std::optional<Error> convertRecords(const RecordLayout& layout, glm::dvec3* out,
                                                  const ChunkPlan& plan, const std::string& path);

}  // namespace rthdist::io
