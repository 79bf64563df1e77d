// Small MPI helpers shared by the passes of hausdorffMpi: rank and size,
// per-rank counts and global offsets, error agreement around fallible local
// work, and typed all-to-all exchanges of plain records.
//
// Every helper is collective over `comm` unless it says otherwise. Counts are
// passed to MPI as int in units of whole records (a contiguous datatype per
// record type), so no count exceeds 2^31 - 1 for sets within the library's
// 2^31 - 1 points.
#pragma once

#include <mpi.h>

#include <cstdint>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "rthdist/mpi.hpp"
#include "rthdist/result.hpp"

namespace rthdist::mpi {

[[nodiscard]] int rankOf(MPI_Comm comm);
[[nodiscard]] int sizeOf(MPI_Comm comm);

// Every rank's value of `local`, in rank order.
[[nodiscard]] std::vector<uint64_t> allgatherCounts(MPI_Comm comm, uint64_t local);
// Prefix sums of counts: offsets[r] = sum of counts[0..r), offsets[size] = total. Local.
[[nodiscard]] std::vector<uint64_t> offsetsOf(const std::vector<uint64_t>& counts);
// The rank whose [offsets[r], offsets[r+1]) holds global index g. Local.
[[nodiscard]] int ownerOf(const std::vector<uint64_t>& offsets, uint64_t g);

// Runs local work, turning exceptions into errors (bad_alloc: kOutOfMemory).
// Local, not collective.
template <class Fn>
[[nodiscard]] std::optional<Error> guarded(Fn&& fn) {
    try {
        return fn();
    } catch (const std::bad_alloc&) {
        return Error{ErrorCode::kOutOfMemory, "out of host memory"};
    } catch (const std::exception& e) {
        return Error{ErrorCode::kInternal, std::string("internal error: ") + e.what()};
    } catch (...) {
        return Error{ErrorCode::kInternal, "internal error"};
    }
}

// A contiguous datatype of `bytes` bytes, committed; freed with the object.
class RecordType {
public:
    explicit RecordType(int bytes);
    ~RecordType();
    RecordType(const RecordType&) = delete;
    RecordType& operator=(const RecordType&) = delete;
    [[nodiscard]] MPI_Datatype get() const { return m_type; }

private:
    MPI_Datatype m_type = MPI_DATATYPE_NULL;
};

// Collective: an allocation of `count` records that fails on one rank fails
// on all (kOutOfMemory agreed), so no rank enters a transfer alone.
template <class Record>
[[nodiscard]] Result<std::vector<Record>> allocateAgreed(MPI_Comm comm, uint64_t count);

// Sends outgoing[r] to rank r and returns what every rank sent here, in rank
// order. Record must be trivially copyable.
template <class Record>
[[nodiscard]] Result<std::vector<Record>> exchangeRecords(MPI_Comm comm,
                                                          const std::vector<std::vector<Record>>& outgoing) {
    const int size = sizeOf(comm);
    const size_t n = static_cast<size_t>(size);
    std::vector<int> sendCounts(n), sendOffsets(n), recvCounts(n), recvOffsets(n);
    std::vector<Record> send;
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        for (int r = 0; r < size; ++r) {
            sendOffsets[size_t(r)] = int(send.size());
            sendCounts[size_t(r)] = int(outgoing[size_t(r)].size());
            send.insert(send.end(), outgoing[size_t(r)].begin(), outgoing[size_t(r)].end());
        }
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    MPI_Alltoall(sendCounts.data(), 1, MPI_INT, recvCounts.data(), 1, MPI_INT, comm);
    int total = 0;
    for (int r = 0; r < size; ++r) {
        recvOffsets[size_t(r)] = total;
        total += recvCounts[size_t(r)];
    }
    Result<std::vector<Record>> received = allocateAgreed<Record>(comm, uint64_t(total));
    if (!received) return received;
    const RecordType type(int(sizeof(Record)));
    MPI_Alltoallv(send.data(), sendCounts.data(), sendOffsets.data(), type.get(), received->data(),
                  recvCounts.data(), recvOffsets.data(), type.get(), comm);
    return received;
}

// Every rank's `local` records concatenated in rank order.
template <class Record>
[[nodiscard]] Result<std::vector<Record>> allgatherRecords(MPI_Comm comm, const std::vector<Record>& local) {
    const int size = sizeOf(comm);
    const std::vector<uint64_t> counts = allgatherCounts(comm, local.size());
    const size_t n = static_cast<size_t>(size);
    std::vector<int> recvCounts(n), recvOffsets(n);
    uint64_t total = 0;
    for (int r = 0; r < size; ++r) {
        recvOffsets[size_t(r)] = int(total);
        recvCounts[size_t(r)] = int(counts[size_t(r)]);
        total += counts[size_t(r)];
    }
    Result<std::vector<Record>> all = allocateAgreed<Record>(comm, total);
    if (!all) return all;
    const RecordType type(int(sizeof(Record)));
    MPI_Allgatherv(local.data(), int(local.size()), type.get(), all->data(), recvCounts.data(),
                   recvOffsets.data(), type.get(), comm);
    return all;
}

template <class Record>
Result<std::vector<Record>> allocateAgreed(MPI_Comm comm, uint64_t count) {
    std::vector<Record> out;
    std::optional<Error> local = guarded([&]() -> std::optional<Error> {
        out.resize(count);
        return std::nullopt;
    });
    if (auto error = agreeOnError(comm, local)) return *error;
    return out;
}

// Broadcasts a string from `root`.
void broadcastString(MPI_Comm comm, int root, std::string& text);

}  // namespace rthdist::mpi
