// Command line of rthdist-mpi: rthdist's own (cli/args.hpp, parsed by the
// same code, so flags, ranges and messages are rthdist's) plus
// --mpi-mode auto|replicated|spatial; the options rthdist-mpi does not
// support (--verify and the per-point family) are usage errors naming the
// option. Pure: no I/O, no MPI.
#pragma once

#include <span>
#include <string>

#include "cli/args.hpp"
#include "rthdist/mpi.hpp"

namespace rthdist::cli {

struct MpiCliArgs {
    CliArgs cli;
    TargetMode mode = TargetMode::kAuto;  // --mpi-mode
};

// argv[1..]; errors are ErrorCode::kInvalidArgument (exit 2).
[[nodiscard]] Result<MpiCliArgs> parseMpiArgs(std::span<const std::string> args);

[[nodiscard]] std::string mpiUsageText();

}  // namespace rthdist::cli
