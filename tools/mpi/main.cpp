// rthdist-mpi — rthdist over MPI ranks (`mpirun -np N rthdist-mpi A B`):
// every rank reads its slice of both files (tools/mpi/slice_loader.hpp),
// hausdorffMpi computes H exactly over the ranks (rthdist/mpi.hpp), and rank 0
// prints rthdist's summary or --json object (tools/cli/report.hpp). Every
// failure ends in "rthdist: <message>" on rank 0's stderr and the same exit
// code on every rank (cli/exit_codes.hpp): errors are agreed on before any
// collective that could block; an unexpected exception aborts the job
// (MPI_Abort) rather than leave the other ranks waiting. Before any work the
// ranks agree on their command line (exit 2 when one differs) and on each
// input file as read (points, precision, checksum: exit 3 when one differs).
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "cli/exit_codes.hpp"
#include "cli/report.hpp"
#include "core/stopwatch.hpp"
#include "mpi_args.hpp"
#include "rank_device.hpp"
#include "rthdist/mpi.hpp"
#include "slice_loader.hpp"

namespace rthdist::cli {
namespace {

using core::Clock;
using core::msSince;

struct Rank {
    MPI_Comm comm = MPI_COMM_WORLD;
    int rank = 0;
    int size = 1;
    [[nodiscard]] bool root() const { return rank == 0; }
};

// Rank 0 reports; every rank returns the same code.
int fail(const Rank& r, int code, const std::string& message) {
    if (r.root()) {
        std::fflush(stdout);
        std::fprintf(stderr, "rthdist: %s\n", message.c_str());
    }
    return code;
}

int failWith(const Rank& r, const Error& error) { return fail(r, exitCodeFor(error.code), error.message); }

// Rank 0 writes; its success decides every rank's exit code.
int writeFromRoot(const Rank& r, const std::string& text) {
    int ok = 1;
    if (r.root())
        ok = std::fwrite(text.data(), 1, text.size(), stdout) == text.size() && std::fflush(stdout) == 0;
    MPI_Bcast(&ok, 1, MPI_INT, 0, r.comm);
    return ok ? kExitOk : fail(r, kExitInternal, "cannot write to stdout");
}

int listDevicesCommand(const Rank& r, const CliArgs& args) {
    std::optional<Error> error;
    std::string text;
    if (r.root()) {
        Result<std::vector<DeviceInfo>> devices = rthdist::listDevices();
        if (devices)
            text = args.json ? devicesJson(*devices) : devicesText(*devices);
        else
            error = devices.error();
    }
    if (auto agreed = agreeOnError(r.comm, error)) return failWith(r, *agreed);
    return writeFromRoot(r, text);
}

// Every rank's command line is rank 0's, compared before parsing: a rank
// started with another (an option on one rank only) would take other
// collectives and hang the job, or answer another question. A difference
// is a usage error (exit 2) on every rank.
std::optional<std::string> commandLineDifference(const Rank& r, const std::vector<std::string>& argv) {
    std::string mine;
    for (const std::string& a : argv) mine += std::to_string(a.size()) + ":" + a;
    uint64_t size = mine.size();
    MPI_Bcast(&size, 1, MPI_UINT64_T, 0, r.comm);
    std::string root = r.root() ? mine : std::string(size_t(size), '\0');
    for (uint64_t done = 0; done < size;) {  // in pieces of at most 2^30 bytes (MPI counts are int)
        const int piece = int(std::min<uint64_t>(size - done, uint64_t(1) << 30));
        MPI_Bcast(root.data() + done, piece, MPI_CHAR, 0, r.comm);
        done += uint64_t(piece);
    }
    int first = root == mine ? r.size : r.rank;  // the lowest rank that differs
    MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, r.comm);
    if (first == r.size) return std::nullopt;
    return "rank " + std::to_string(first) +
           " was started with other arguments than rank 0; every rank of rthdist-mpi needs the same "
           "command line";
}

// Every rank read the same file: the same number of points, precision and
// checksum of the whole file (slice_loader.hpp), compared before any work. A
// difference (a file changed between the ranks' reads, node-local copies
// that differ) is kBadInput (exit 3) on every rank, naming the ranks.
std::optional<Error> fileDifference(const Rank& r, const std::string& path, const LoadedSlice& slice) {
    const uint64_t mine[3] = {slice.fileCount, uint64_t(slice.points.scalar), slice.checksum};
    std::vector<uint64_t> all(3 * size_t(r.size));
    MPI_Allgather(mine, 3, MPI_UINT64_T, all.data(), 3, MPI_UINT64_T, r.comm);
    auto describe = [&all](int rank) {
        const uint64_t* v = all.data() + 3 * size_t(rank);
        char sum[32];
        std::snprintf(sum, sizeof(sum), "%016llx", static_cast<unsigned long long>(v[2]));
        return "rank " + std::to_string(rank) + " read " + std::to_string(v[0]) + " points (" +
               (v[1] == uint64_t(Scalar::kFloat64) ? "float64" : "float32") + ", checksum " + sum + ")";
    };
    for (int rank = 1; rank < r.size; ++rank) {
        if (std::equal(all.begin(), all.begin() + 3, all.begin() + 3 * rank)) continue;
        return Error{ErrorCode::kBadInput, path + ": the ranks read different contents: " + describe(0) +
                                               ", " + describe(rank) +
                                               "; every rank must read the same file"};
    }
    return std::nullopt;
}

int compute(const Rank& r, const MpiCliArgs& parsed, Clock::time_point start) {
    const CliArgs& args = parsed.cli;
    const Clock::time_point loadStart = Clock::now();
    io::LoadOptions loadOptions;
    loadOptions.lasClasses = args.lasClasses;
    Result<LoadedSlice> a = loadSlice(args.pathA, loadOptions, r.rank, r.size);
    std::optional<Error> error = a ? std::nullopt : std::optional<Error>(a.error());
    if (auto agreed = agreeOnError(r.comm, error)) return failWith(r, *agreed);
    if (auto differ = fileDifference(r, args.pathA, *a)) return failWith(r, *differ);
    Result<LoadedSlice> b = loadSlice(args.pathB, loadOptions, r.rank, r.size);
    error = b ? std::nullopt : std::optional<Error>(b.error());
    if (auto agreed = agreeOnError(r.comm, error)) return failWith(r, *agreed);
    if (auto differ = fileDifference(r, args.pathB, *b)) return failWith(r, *differ);
    double loadMs = msSince(loadStart);
    MPI_Allreduce(MPI_IN_PLACE, &loadMs, 1, MPI_DOUBLE, MPI_MAX, r.comm);

    Options options = args.options;
    options.deviceIndex = deviceForRank(r.comm, options);
    MpiOptions mpiOptions;
    mpiOptions.mode = parsed.mode;
    Result<HausdorffResult> result =
        hausdorffMpi(r.comm, a->points.view(), b->points.view(), options, mpiOptions);
    if (!result) return failWith(r, withFileNames(result.error(), args.pathA, args.pathB));

    RunReport report;
    report.args = &args;
    report.pointsA = a->fileCount;
    report.pointsB = b->fileCount;
    report.scalarA = a->points.scalar;
    report.scalarB = b->points.scalar;
    report.loadMs = loadMs;
    report.result = &*result;
    report.wallMs = msSince(start);
    return writeFromRoot(r,
                         r.root() ? (args.json ? jsonReport(report) : summaryText(report)) : std::string());
}

int run(const Rank& r, const std::vector<std::string>& argv) {
    const Clock::time_point start = Clock::now();
    if (auto differ = commandLineDifference(r, argv))
        return fail(r, kExitUsage, *differ + "\nTry 'rthdist-mpi --help'.");
    Result<MpiCliArgs> parsed = parseMpiArgs(argv);  // the same on every rank
    if (!parsed) return fail(r, kExitUsage, parsed.error().message + "\nTry 'rthdist-mpi --help'.");
    const CliArgs& args = parsed->cli;
    if (args.help) return writeFromRoot(r, mpiUsageText());
    if (args.version) return writeFromRoot(r, std::string("rthdist-mpi ") + versionString() + "\n");
    if (args.listDevices) return listDevicesCommand(r, args);
    return compute(r, *parsed, start);
}

}  // namespace
}  // namespace rthdist::cli

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    rthdist::cli::Rank r;
    MPI_Comm_rank(r.comm, &r.rank);
    MPI_Comm_size(r.comm, &r.size);
    int code = rthdist::cli::kExitInternal;
    try {
        const std::vector<std::string> args(argv + (argc > 0 ? 1 : 0), argv + argc);
        code = rthdist::cli::run(r, args);
    } catch (const std::bad_alloc&) {
        std::fprintf(stderr, "rthdist: out of host memory (rank %d)\n", r.rank);
        MPI_Abort(r.comm, rthdist::cli::kExitInternal);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rthdist: internal error (rank %d): %s\n", r.rank, e.what());
        MPI_Abort(r.comm, rthdist::cli::kExitInternal);
    }
    MPI_Finalize();
    return code;
}
