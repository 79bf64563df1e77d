#include "cli/verify.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/common.hpp>

namespace rthdist::cli {

Result<Verification> verifyAgainstCpu(PointView a, PointView b, const Options& options,
                                      const HausdorffResult& result) {
    Options cpuOptions = options;
    cpuOptions.backend = Backend::kCpu;
    cpuOptions.validation = false;
    cpuOptions.deviceIndex = -1;
    cpuOptions.devices.clear();
    Result<HausdorffResult> cpu = hausdorff(a, b, cpuOptions);
    if (!cpu)
        return Error{cpu.error().code, "verification run on the cpu backend failed: " + cpu.error().message};

    Verification v;
    v.cpu = std::move(cpu).value();
    // Both backends are exact in double (their certificates): equal values.
    v.tolerance = 0.0;
    const char* name = backendName(result.backend);
    auto compare = [&](const char* what, double got, double want) {
        const double diff = std::abs(got - want);
        v.maxAbsDiff = std::max(v.maxAbsDiff, std::isnan(diff) ? INFINITY : diff);
        if (!(diff <= v.tolerance)) {
            char line[256];
            std::snprintf(line, sizeof line, "%s: %s %.17g vs cpu %.17g (|diff| %.3g > tolerance %.3g)", what,
                          name, got, want, diff, v.tolerance);
            v.mismatches.emplace_back(line);
            v.ok = false;
        }
    };
    compare("H(A,B)", result.hausdorff, v.cpu.hausdorff);
    compare("h(A,B)", result.aToB.distance, v.cpu.aToB.distance);
    if (!result.directedOnly) compare("h(B,A)", result.bToA.distance, v.cpu.bToA.distance);
    return v;
}

}  // namespace rthdist::cli
