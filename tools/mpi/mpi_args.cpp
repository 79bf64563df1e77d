#include "mpi_args.hpp"

#include <string_view>
#include <vector>

namespace rthdist::cli {

namespace {

Error usageError(std::string message) { return Error{ErrorCode::kInvalidArgument, std::move(message)}; }

// rthdist's options that rthdist-mpi refuses rather than ignores.
constexpr std::string_view kUnsupported[] = {
    "--verify",  "--per-point", "--percentile", "--histogram-bins", "--range",  "--out-ply",
    "--out-csv", "--png",       "--render",     "--histogram-png",  "--devices"};

// The option a token names ("--png=x" names "--png"), or empty.
std::string_view optionName(std::string_view token) {
    if (!token.starts_with("--")) return {};
    return token.substr(0, token.find('='));
}

}  // namespace

Result<MpiCliArgs> parseMpiArgs(std::span<const std::string> args) {
    MpiCliArgs out;
    std::vector<std::string> rest;
    bool ended = false;
    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& token = args[i];
        const std::string_view name = ended ? std::string_view() : optionName(token);
        if (token == "--") ended = true;
        if (name == "--mpi-mode") {
            const bool inlineValue = token.size() > name.size();
            if (!inlineValue && i + 1 == args.size()) return usageError("option '--mpi-mode' needs a value");
            const std::string value = inlineValue ? token.substr(name.size() + 1) : args[++i];
            if (!parseTargetMode(value.c_str(), out.mode))
                return usageError("unknown MPI mode '" + value + "' (expected auto, replicated or spatial)");
            continue;
        }
        for (std::string_view refused : kUnsupported) {
            if (name == refused)
                return usageError("option '" + std::string(name) + "' is not supported by rthdist-mpi");
        }
        rest.push_back(token);
    }
    Result<CliArgs> cli = parseArgs(rest);
    if (!cli) return cli.error();
    out.cli = std::move(cli).value();
    return out;
}

std::string mpiUsageText() {
    return R"(Usage: mpirun -np N rthdist-mpi [options] A B
       rthdist-mpi --list-devices [--json]

rthdist over MPI ranks: the same exact H(A,B), summary, --json object and exit
codes as rthdist (double inputs: the queries near the maximum settled in
double across the ranks). Every rank reads its slice of A and B; rank 0 prints.

  --mpi-mode NAME     auto | replicated | spatial (default auto: every rank
                      holds the whole target set as float32 when both sets
                      fit 1 GiB, else each rank owns a slab of it plus an
                      exact halo)

Not supported (exit 2): --verify, the per-point options (--per-point,
--percentile, --histogram-bins, --range, --out-ply, --out-csv, --png,
--render, --histogram-png), and --devices (one rank per GPU instead).

Without --device, a GPU backend on a node with several usable devices gives
each rank of the node its own (node-local rank modulo the device count).

rthdist's options:

)" + usageText();
}

}  // namespace rthdist::cli
