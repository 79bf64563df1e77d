// --verify: re-runs the exact CPU backend on the same input and compares H
// and both directed distances within 1e-6 of the larger bounding-box
// diagonal (the library's exactness contract).
#pragma once

#include <glm/vec3.hpp>

#include <span>
#include <string>
#include <vector>

#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::cli {

struct Verification {
    HausdorffResult cpu;
    double tolerance = 0.0;   // 0: both backends are exact in double
    double maxAbsDiff = 0.0;  // over H and the directed distances compared
    bool ok = true;
    std::vector<std::string> mismatches;  // one line per value out of tolerance
};

// Length of the diagonal of the axis-aligned bounding box, in double (0 for
// no points).

// Runs the CPU backend with `options` and compares it with `result`. An Error
// only when the CPU run itself fails.
[[nodiscard]] Result<Verification> verifyAgainstCpu(PointView a, PointView b, const Options& options,
                                                    const HausdorffResult& result);

}  // namespace rthdist::cli
