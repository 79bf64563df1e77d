// Process exit codes of the command-line tools (rthdist, rthdist-masks,
// rthdist-bench; README "Exit codes"). The library reports errors as values
// (rthdist/result.hpp); how a process ends is decided here, once.
#pragma once

#include "rthdist/result.hpp"

namespace rthdist::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitInternal = 1;     // internal error, --verify mismatch, out of memory
inline constexpr int kExitUsage = 2;        // unknown option, missing input, malformed or out-of-range value
inline constexpr int kExitBadInput = 3;     // unreadable or malformed file, empty set, NaN/Inf
inline constexpr int kExitNoDevice = 4;     // no usable Vulkan device
inline constexpr int kExitOutput = 5;       // an output file cannot be written (cli/output_file.hpp)
inline constexpr int kExitCancelled = 130;  // 128 + SIGINT, as a shell reports an interrupted command

// The exit code for a library error.
[[nodiscard]] constexpr int exitCodeFor(ErrorCode code) {
    switch (code) {
        case ErrorCode::kInvalidArgument: return kExitBadInput;  // options the library rejected
        case ErrorCode::kBadInput: return kExitBadInput;
        case ErrorCode::kNoDevice: return kExitNoDevice;
        case ErrorCode::kOutOfMemory: return kExitInternal;
        case ErrorCode::kInternal: return kExitInternal;
        case ErrorCode::kCancelled: return kExitCancelled;
    }
    return kExitInternal;
}

}  // namespace rthdist::cli
