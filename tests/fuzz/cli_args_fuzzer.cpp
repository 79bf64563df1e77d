// libFuzzer target for the CLI's argument parser (tools/cli/args.cpp and
// command_line.cpp on CLI11, compiled in): the input is split at NUL bytes
// into argv[1..] (so, like argv, no argument holds a NUL). Any input must
// give a CliArgs or a kInvalidArgument error, never a crash or an exception.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cli/args.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::vector<std::string> args(1);
    for (size_t i = 0; i < size; ++i) {
        if (data[i] == '\0') {
            args.emplace_back();
        } else {
            args.back().push_back(static_cast<char>(data[i]));
        }
    }
    if (size == 0) args.clear();
    (void)rthdist::cli::parseArgs(args);
    return 0;
}
