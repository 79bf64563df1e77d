// x/y/z of fixed-size binary records (binary PLY vertices without list
// properties, binary PCD rows) converted in parallel chunks straight into
// the cloud: no copy of the file, no per-value type switch when the three
// coordinates share a type.
#pragma once

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>

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

// out holds layout.count points. Values are those of loadScalar: doubles
// as stored, floats rounded by narrowToFloat (a double beyond the float
// range becomes an infinity; the caller's finiteness check reports it).
void convertRecords(const RecordLayout& layout, glm::vec3* out, const ChunkPlan& plan);
void convertRecords(const RecordLayout& layout, glm::dvec3* out, const ChunkPlan& plan);

}  // namespace rthdist::io
