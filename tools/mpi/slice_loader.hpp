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
    // A 64-bit digest of every point of the whole file as read (its scalar
    // type and coordinate bytes): ranks compare it before any work, so that
    // ranks that read different contents (a file changed between reads, node-
    // local copies that differ) fail instead of computing a mixture.
    uint64_t checksum = 0;
};

// The digest of LoadedSlice::checksum over a cloud's points. Local.
[[nodiscard]] uint64_t pointsChecksum(const io::PointCloud& cloud);

// Local (no MPI). Errors name the file; an empty file is kBadInput "<path>: no points", as in rthdist.
[[nodiscard]] Result<LoadedSlice> loadSlice(const std::string& path, const io::LoadOptions& options, int rank,
                                            int size);

}  // namespace rthdist::cli
