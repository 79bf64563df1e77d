#include "slice_loader.hpp"

#include <utility>
#include <vector>

namespace rthdist::cli {

namespace {

template <class T>
std::vector<T> sliceOf(std::vector<T>& all, int rank, int size) {
    const uint64_t n = all.size();
    const uint64_t begin = n * uint64_t(rank) / uint64_t(size), end = n * uint64_t(rank + 1) / uint64_t(size);
    std::vector<T> part(all.begin() + std::ptrdiff_t(begin), all.begin() + std::ptrdiff_t(end));
    std::vector<T>().swap(all);
    return part;
}

}  // namespace

Result<LoadedSlice> loadSlice(const std::string& path, const io::LoadOptions& options, int rank, int size) {
    Result<io::PointCloud> cloud = io::loadPointCloud(path, options);
    if (!cloud) {
        Error e = cloud.error();
        if (e.message.find(path) == std::string::npos) e.message = path + ": " + e.message;
        return e;
    }
    if (cloud->size() == 0) return Error{ErrorCode::kBadInput, path + ": no points"};
    LoadedSlice out;
    out.fileCount = cloud->size();
    out.points.scalar = cloud->scalar;
    if (cloud->scalar == Scalar::kFloat64) {
        out.points.doubles = sliceOf(cloud->doubles, rank, size);
    } else {
        out.points.floats = sliceOf(cloud->floats, rank, size);
    }
    return out;
}

}  // namespace rthdist::cli
