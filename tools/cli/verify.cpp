#include "cli/verify.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/common.hpp>

namespace rthdist::cli {

double bboxDiagonal(const PointView& points) {
    if (points.empty()) return 0.0;
    glm::dvec3 lo(points.at(0)), hi(points.at(0));
    for (size_t i = 0; i < points.size(); ++i) {
        const glm::dvec3 p = points.at(i);
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::dvec3 d = hi - lo;
    return std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
}

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
    v.tolerance = 1e-6 * std::max(bboxDiagonal(a), bboxDiagonal(b));
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
