// Replicated targets: allgather T as float32 (in global order, so its
// indices are the global ones), then each rank's slice of Q against it.
#include <numeric>
#include <vector>

#include "mpi/collectives.hpp"
#include "mpi/directed_pass.hpp"
#include "rthdist/mpi.hpp"

namespace rthdist::mpi {

Result<PassOutcome> replicatedPass(MPI_Comm comm, Engine& engine, const GlobalSet& q, const GlobalSet& t,
                                   const CallOptions& call, bool perPoint) {
    std::vector<uint32_t> targetIds, queryIds;
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        targetIds.resize(t.total());
        queryIds.resize(q.local.count);
        std::iota(targetIds.begin(), targetIds.end(), 0u);
        std::iota(queryIds.begin(), queryIds.end(), uint32_t(q.offset()));
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    Result<std::vector<glm::vec3>> targets = allgatherRecords(comm, t.floats);
    if (!targets) return targets.error();

    Result<PassOutcome> out = Error{};
    local = guarded([&]() -> std::optional<Error> {
        out = searchLocal(engine, q.floats, queryIds, *targets, targetIds, call, perPoint);
        return out ? std::nullopt : std::optional<Error>(out.error());
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return out;
}

}  // namespace rthdist::mpi
