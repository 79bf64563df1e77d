#include "core/input_limits.hpp"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

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

ShiftedReach farthestShifted(const PointView& points, const glm::dvec3& origin) {
    ShiftedReach best;
    for (size_t i = 0; i < points.count; ++i) {
        const glm::dvec3 p = points.at(i);
        for (int k = 0; k < 3; ++k) {
            const double d = std::abs(p[k] - origin[k]);
            if (d <= kMaxShifted) continue;
            const std::pair<double, double> reach{std::isnan(d) ? INFINITY : d, std::abs(p[k])};
            if (reach > std::pair{best.distance, best.magnitude}) {
                best.distance = reach.first;
                best.magnitude = reach.second;
                best.index = i;
                best.axis = k;
            }
        }
    }
    return best;
}

std::optional<Error> checkShiftedRange(const PointView& points, const Bounds& box, const glm::dvec3& origin,
                                       const char* name, uint64_t firstIndex) {
    const glm::dvec3 far = farthest(box, origin);
    if (far.x <= kMaxShifted && far.y <= kMaxShifted && far.z <= kMaxShifted) return std::nullopt;
    // Past the limit (a second pass, on this path only): farthestShifted names the place.
    const ShiftedReach worstPoint = farthestShifted(points, origin);
    const size_t worst = worstPoint.index;
    const int axis = worstPoint.axis;
    if (axis < 0)
        return Error{ErrorCode::kBadInput, std::string("point set ") + name + ": coordinates past " +
                                               number(kMaxShifted) + " from the search origin"};
    const double v = points.at(worst)[axis];
    return Error{ErrorCode::kBadInput,
                 std::string("point set ") + name + ": point " + std::to_string(firstIndex + worst) +
                     " has " + axisName(axis) + " = " + number(v) + ", " +
                     number(std::abs(v - origin[axis])) + " from the search origin (" + axisName(axis) +
                     " = " + number(origin[axis]) + "): past " + number(kMaxShifted) +
                     " (float32's largest value), the most the float search takes after the shift; bring "
                     "the sets closer together or scale them down"};
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

bool checkBFirst(const Bounds& boxA, const Bounds& boxB, const glm::dvec3& origin) {
    // The set that reaches farther first; on a tie (the centre is as far from
    // both ends of an axis) the one of larger coordinates: a stray at 1e308,
    // rather than the points near 0 it is far from.
    auto reach = [&origin](const Bounds& box) {
        const glm::dvec3 f = farthest(box, origin);
        const glm::dvec3 m = glm::max(glm::abs(box.lo), glm::abs(box.hi));
        double magnitude = 0.0;
        for (int k = 0; k < 3; ++k)
            if (!(f[k] <= kMaxShifted)) magnitude = std::max(magnitude, m[k]);
        return std::pair{std::max({f.x, f.y, f.z}), magnitude};
    };
    return reach(boxB) > reach(boxA);
}

std::optional<Error> checkPairFrame(const PointView& a, const Bounds& boxA, bool floatExactA,
                                    const PointView& b, const Bounds& boxB, bool floatExactB,
                                    const glm::dvec3& origin) {
    if (floatExactA && floatExactB && origin == glm::dvec3(0.0)) return std::nullopt;
    const bool bFirst = checkBFirst(boxA, boxB, origin);
    if (auto e = bFirst ? checkShiftedRange(b, boxB, origin, "B") : checkShiftedRange(a, boxA, origin, "A"))
        return e;
    if (auto e = bFirst ? checkShiftedRange(a, boxA, origin, "A") : checkShiftedRange(b, boxB, origin, "B"))
        return e;
    const Bounds both{glm::min(boxA.lo, boxB.lo), glm::max(boxA.hi, boxB.hi)};
    return checkShiftedExtent(both, origin, "A and B");
}

}  // namespace rthdist::core
