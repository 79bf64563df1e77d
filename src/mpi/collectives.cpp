#include "mpi/collectives.hpp"

#include <algorithm>

#include "rthdist/mpi.hpp"

namespace rthdist::mpi {

int rankOf(MPI_Comm comm) {
    int rank = 0;
    MPI_Comm_rank(comm, &rank);
    return rank;
}

int sizeOf(MPI_Comm comm) {
    int size = 1;
    MPI_Comm_size(comm, &size);
    return size;
}

std::vector<uint64_t> allgatherCounts(MPI_Comm comm, uint64_t local) {
    std::vector<uint64_t> counts(size_t(sizeOf(comm)));
    MPI_Allgather(&local, 1, MPI_UINT64_T, counts.data(), 1, MPI_UINT64_T, comm);
    return counts;
}

std::vector<uint64_t> offsetsOf(const std::vector<uint64_t>& counts) {
    std::vector<uint64_t> offsets(counts.size() + 1, 0);
    for (size_t r = 0; r < counts.size(); ++r) offsets[r + 1] = offsets[r] + counts[r];
    return offsets;
}

int ownerOf(const std::vector<uint64_t>& offsets, uint64_t g) {
    // The last r with offsets[r] <= g (empty slices share an offset with the next rank).
    const auto it = std::upper_bound(offsets.begin(), offsets.end() - 1, g);
    return int(it - offsets.begin()) - 1;
}

RecordType::RecordType(int bytes) {
    MPI_Type_contiguous(bytes, MPI_BYTE, &m_type);
    MPI_Type_commit(&m_type);
}

RecordType::~RecordType() {
    if (m_type != MPI_DATATYPE_NULL) MPI_Type_free(&m_type);
}

void broadcastString(MPI_Comm comm, int root, std::string& text) {
    uint64_t length = text.size();
    MPI_Bcast(&length, 1, MPI_UINT64_T, root, comm);
    text.resize(length);
    if (length > 0) MPI_Bcast(text.data(), int(length), MPI_CHAR, root, comm);
}

}  // namespace rthdist::mpi

namespace rthdist {

std::optional<Error> agreeOnError(MPI_Comm comm, const std::optional<Error>& local) {
    const int size = mpi::sizeOf(comm);
    const int mine = local ? mpi::rankOf(comm) : size;
    int first = size;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
    if (first == size) return std::nullopt;
    Error agreed = local ? *local : Error{};
    int numbers[3] = {int(agreed.code), agreed.vkResult, int(agreed.details.size())};
    MPI_Bcast(numbers, 3, MPI_INT, first, comm);
    mpi::broadcastString(comm, first, agreed.message);
    agreed.details.resize(size_t(numbers[2]));
    for (std::string& reason : agreed.details) mpi::broadcastString(comm, first, reason);
    agreed.code = ErrorCode(numbers[0]);
    agreed.vkResult = numbers[1];
    return agreed;
}

}  // namespace rthdist
