// Command-line parsing for the rthdist CLI. Pure: no I/O, no exit(); the
// caller prints the usage error and picks the exit code (kExitUsage).
#pragma once

#include <span>
#include <string>

#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cli {

// Exit codes of the CLI. Errors from the library map through exitCodeFor()
// (3 bad input, 4 no usable device, 1 internal).
inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;
inline constexpr int kExitUsage = 2;

struct CliArgs {
    std::string pathA;
    std::string pathB;
    Options options;
    bool json = false;         // --json: one JSON object on stdout
    bool verify = false;       // --verify: re-run on the CPU backend and compare
    bool listDevices = false;  // --list-devices
    bool help = false;         // --help / -h
    bool version = false;      // --version
};

// Parses argv[1..]. Accepts "--flag value" and "--flag=value"; "--" ends the
// options. Errors (unknown flag, missing or malformed value, wrong number of
// input files) come back as ErrorCode::kInvalidArgument with a message.
[[nodiscard]] Result<CliArgs> parseArgs(std::span<const std::string> args);

// The --help text.
[[nodiscard]] std::string usageText();

}  // namespace rthdist::cli
