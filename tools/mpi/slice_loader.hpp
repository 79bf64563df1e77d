// Each rank's slice of an input file for rthdist-mpi: points
// [rank * n / size, (rank + 1) * n / size) of the file's n points, in the
// file's precision. Known limit: every rank reads and parses the whole file
// with io::loadPointCloud (any format the CLI reads) and keeps only its
// slice, so each rank needs the whole file's memory while it loads; reading
// byte ranges of binary PLY/LAS/XYZ is left to the loaders' rewrite (issue 14).
#pragma once

#include <cstdint>
#include <string>

#include "rthdist/io.hpp"
#include "rthdist/result.hpp"

namespace rthdist::cli {

struct LoadedSlice {
    io::PointCloud points;   // this rank's slice
    uint64_t fileCount = 0;  // points in the whole file
};

// Local (no MPI). Errors name the file; an empty file is kBadInput "<path>: no points", as in rthdist.
[[nodiscard]] Result<LoadedSlice> loadSlice(const std::string& path, const io::LoadOptions& options, int rank,
                                            int size);

}  // namespace rthdist::cli
