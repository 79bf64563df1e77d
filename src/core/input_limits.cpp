#include "core/input_limits.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace rthdist::core {

namespace {

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.9g", v);
    return text;
}

const char* axisName(int k) { return k == 0 ? "x" : k == 1 ? "y" : "z"; }

// Largest |coordinate - origin| of the box per axis, in double (inf past
// the double range, NaN for a NaN origin: neither is within a limit).
glm::dvec3 farthest(const Bounds& box, const glm::dvec3& origin) {
    return glm::max(glm::abs(box.lo - origin), glm::abs(box.hi - origin));
}

}  // namespace

std::optional<Error> checkOrigin(const glm::dvec3& origin, const char* what) {
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(origin[k]))
            return Error{ErrorCode::kInvalidArgument, std::string(what) + ": coordinate " + axisName(k) +
                                                          " is " + number(origin[k]) +
                                                          "; an origin must be finite"};
    }
    return std::nullopt;
}

std::optional<Error> checkShiftedRange(const PointView& points, const Bounds& box, const glm::dvec3& origin,
                                       const char* name, uint64_t firstIndex) {
    const glm::dvec3 far = farthest(box, origin);
    if (far.x <= kMaxShifted && far.y <= kMaxShifted && far.z <= kMaxShifted) return std::nullopt;
    // Past the limit: the first point past it names the place (a second pass, on this path only).
    for (size_t i = 0; i < points.count; ++i) {
        const glm::dvec3 p = points.at(i);
        for (int k = 0; k < 3; ++k) {
            if (std::abs(p[k] - origin[k]) <= kMaxShifted) continue;
            return Error{ErrorCode::kBadInput,
                         std::string("point set ") + name + ": point " + std::to_string(firstIndex + i) +
                             " has " + axisName(k) + " = " + number(p[k]) + ", " +
                             number(std::abs(p[k] - origin[k])) + " from the search origin (" + axisName(k) +
                             " = " + number(origin[k]) + "): past " + number(kMaxShifted) +
                             " (float32's largest value), the most the float search takes after the "
                             "shift; bring the sets closer together or scale them down"};
        }
    }
    return Error{ErrorCode::kBadInput, std::string("point set ") + name + ": coordinates past " +
                                           number(kMaxShifted) +
                                           " from the search origin (float32's largest value)"};
}

std::optional<Error> checkShiftedExtent(const Bounds& box, const glm::dvec3& origin, const char* names) {
    const glm::dvec3 far = farthest(box, origin);
    const double m = std::max({far.x, far.y, far.z});
    if (m == 0.0 || m >= kMinShifted) return std::nullopt;
    return Error{ErrorCode::kBadInput,
                 std::string("point sets ") + names + ": every coordinate lies within " + number(m) +
                     " of the search origin but the points are not all equal: below " + number(kMinShifted) +
                     " (2^-126, float32's smallest normal value) the float search loses the distances; "
                     "scale the sets up (H scales with them)"};
}

std::optional<Error> checkPairFrame(const PointView& a, const Bounds& boxA, bool floatExactA,
                                    const PointView& b, const Bounds& boxB, bool floatExactB,
                                    const glm::dvec3& origin) {
    if (floatExactA && floatExactB && origin == glm::dvec3(0.0)) return std::nullopt;
    if (auto e = checkShiftedRange(a, boxA, origin, "A")) return e;
    if (auto e = checkShiftedRange(b, boxB, origin, "B")) return e;
    const Bounds both{glm::min(boxA.lo, boxB.lo), glm::max(boxA.hi, boxB.hi)};
    return checkShiftedExtent(both, origin, "A and B");
}

}  // namespace rthdist::core
