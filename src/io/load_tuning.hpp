// Internal knobs of loadPointCloud that the public LoadOptions do not show:
// the tests force the read() path and tiny chunks, to check that neither
// changes a point or an error.
#pragma once

#include <string>

#include "io/file_bytes.hpp"
#include "io/parallel_chunks.hpp"
#include "rthdist/io.hpp"

namespace rthdist::io {

struct LoadTuning {
    FileAccess access = FileAccess::kMap;
    size_t chunkBytes = 0;  // 0: kDefaultChunkBytes
};

// loadPointCloud with explicit tuning (loadPointCloud passes {}).
[[nodiscard]] Result<PointCloud> loadPointCloudTuned(const std::string& path, const LoadOptions& options,
                                                     const LoadTuning& tuning);

// loadMesh with explicit tuning (loadMesh passes {}).
[[nodiscard]] Result<TriangleMesh> loadMeshTuned(const std::string& path, const LoadOptions& options,
                                                 const LoadTuning& tuning);

}  // namespace rthdist::io
