// The coordinates the float search can take (README "Precision" and "Known
// limitations"), checked in one place by every entry point (Engine::compute
// on views and on prepared sets of different frames, Engine::prepare, the
// Python module through them, hausdorffMpi), before any float copy is made.
//
// A set searched shifted (input_frame.hpp: every set unless both are float
// values and the origin is 0) is rounded to float32 as p - origin. Two rules
// keep that rounding within the contract's bound (rthdist.hpp) and every
// distance finite:
//   - every |p - origin| coordinate is at most kMaxShifted (float32's largest
//     value): beyond it the float copy is infinite (the CPU backend crashed,
//     a distance came back inf);
//   - the largest |p - origin| coordinate over both sets is 0 (every point
//     the same: H = 0) or at least kMinShifted (2^-126, float32's smallest
//     normal value): below it the rounding moves coordinates by more than
//     2^-24 of the extent and the squared distances vanish.
// Sets of float values searched unshifted (origin 0) take any finite float.
// Past a limit: ErrorCode::kBadInput naming the set, the point, the axis and
// the limit (exit 3, Python ValueError).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>

#include "core/index_space.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"

namespace rthdist::core {

inline constexpr double kMaxShifted = 3.4028234663852886e38;   // FLT_MAX
inline constexpr double kMinShifted = 1.1754943508222875e-38;  // FLT_MIN = 2^-126

// A caller's origin (PrepareOptions::origin): finite, or kInvalidArgument.
[[nodiscard]] std::optional<Error> checkOrigin(const glm::dvec3& origin, const char* what);

// The point of `points` past kMaxShifted from `origin` that names an error:
// the farthest from it, on a tie the one of larger magnitude (a stray at
// 1e308 rather than the points near 0 it is far from), then the first;
// axis -1 when none is past the limit.
struct ShiftedReach {
    double distance = -1.0;
    double magnitude = -1.0;
    size_t index = 0;
    int axis = -1;
};
[[nodiscard]] ShiftedReach farthestShifted(const PointView& points, const glm::dvec3& origin);

// The upper rule for one set of box `box` searched as p - origin: the error
// names farthestShifted's point (its index plus `firstIndex`, the
// set's offset in a larger one) and its axis.
[[nodiscard]] std::optional<Error> checkShiftedRange(const PointView& points, const Bounds& box,
                                                     const glm::dvec3& origin, const char* name,
                                                     uint64_t firstIndex = 0);

// The lower rule for the union box of the sets searched in one frame
// (`names`: "A and B", "to prepare").
[[nodiscard]] std::optional<Error> checkShiftedExtent(const Bounds& box, const glm::dvec3& origin,
                                                      const char* names);

// Whether the upper rule checks B before A: the set that reaches farther
// from the origin, on a tie the one of larger coordinates (a stray at 1e308
// rather than the points near 0 it is far from).
[[nodiscard]] bool checkBFirst(const Bounds& boxA, const Bounds& boxB, const glm::dvec3& origin);

// Both rules for a pair in one frame (the upper one in checkBFirst's order); nothing when neither set is
// shifted (both float values, origin 0).
[[nodiscard]] std::optional<Error> checkPairFrame(const PointView& a, const Bounds& boxA, bool floatExactA,
                                                  const PointView& b, const Bounds& boxB, bool floatExactB,
                                                  const glm::dvec3& origin);

}  // namespace rthdist::core
