#include "rank_device.hpp"

#include <vector>

#include "rthdist/rthdist.hpp"

namespace rthdist::cli {

namespace {

int nodeLocalRank(MPI_Comm comm) {
    MPI_Comm node = MPI_COMM_NULL;
    MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
    int rank = 0;
    MPI_Comm_rank(node, &rank);
    MPI_Comm_free(&node);
    return rank;
}

bool usable(const DeviceInfo& d, Backend backend) {
    switch (backend) {
        case Backend::kRayQuery: return d.rayQuery;
        case Backend::kRtPipeline: return d.rtPipeline;
        case Backend::kAuto: return d.type != "cpu" && (d.rayQuery || d.rtPipeline);
        case Backend::kCpu: return false;
    }
    return false;
}

}  // namespace

int deviceForRank(MPI_Comm comm, const Options& options) {
    const int localRank = nodeLocalRank(comm);  // collective: every rank takes part
    if (options.deviceIndex >= 0 || options.backend == Backend::kCpu) return options.deviceIndex;
    Result<std::vector<DeviceInfo>> devices = listDevices();
    if (!devices) return -1;  // the engine reports the lack of a device itself
    std::vector<int> candidates;
    for (const DeviceInfo& d : *devices)
        if (usable(d, options.backend)) candidates.push_back(d.index);
    if (candidates.size() < 2) return -1;
    return candidates[size_t(localRank) % candidates.size()];
}

}  // namespace rthdist::cli
