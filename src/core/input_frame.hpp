// From the caller's point views to the float32 sets the backends search, and
// back (design.md §8): one pass per set checks every coordinate and takes the
// bounding box in double; when an input is double the origin is the centre
// of the union's box and both sets are shifted by it and rounded to float
// (the error bound is in rthdist.hpp); packed float inputs are searched in
// place. Afterwards witnesses and per-point distances are taken from the
// original coordinates in double.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/index_space.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::core {

struct SetSummary {
    Bounds box;
    // Every coordinate is a float32 value (always for float views; for a
    // double view, e.g. text written from floats): searched without a shift.
    bool floatExact = true;
};

// Points per set of a one-shot call: sets past the backends' 32-bit indices
// (api::kMaxCallPoints) run in pieces (api/out_of_core.hpp) and report
// 64-bit witness indices. The bound keeps every byte offset within size_t.
inline constexpr uint64_t kMaxSetPoints = uint64_t(1) << 40;

// The view's shape alone (no pass over the points): the error for an empty
// set, more than kMaxSetPoints points, a stride that cannot hold a point, a
// view past the address space, or a null pointer.
[[nodiscard]] std::optional<Error> checkShape(const PointView& points, const char* name);

// Box and precision of one set, or the error naming the first bad point
// (NaN/Inf, an empty set, a stride that cannot hold a point, too many points).
// The passes over the points of this file run on `threads` threads, as
// EngineOptions::threads (0: every hardware thread).
[[nodiscard]] Result<SetSummary> summarizeSet(const PointView& points, const char* name, int threads = 0);

// The origin subtracted before the float search: zero when every coordinate
// of both sets is a float32 value (their differences are then as exact as
// the float search can be, whatever the magnitude), else the centre of the
// union of both boxes.
[[nodiscard]] glm::dvec3 searchOrigin(const SetSummary& a, const SetSummary& b);

// The origin of a set prepared alone (Engine::prepare): zero when every
// coordinate is a float32 value, else `wanted` or the centre of its box.
[[nodiscard]] glm::dvec3 preparedOrigin(const SetSummary& set, const std::optional<glm::dvec3>& wanted);

// Whether two sets shifted by one origin and rounded to float keep the
// contract's bound (rthdist.hpp): float-exact sets are not rounded (origin
// 0); the others' coordinates move by at most 2^-24 m, m the largest
// |p - origin| over their boxes, so a reported h moves by at most
// 2 sqrt(3) 2^-24 m, within 1e-6 D when m <= 4 D (D: the union's diagonal).
[[nodiscard]] bool frameKeepsBound(const SetSummary& a, const SetSummary& b, const glm::dvec3& origin);

// The largest coordinate magnitude of the set as searched (shifted by
// `origin`, rounded to float): the maxAbs of exactScale (index_space.hpp),
// from the box alone. Rounding p - origin is monotone in p, so the extremes
// of the rounded points are the rounded corners of the box: no pass over the
// points.
[[nodiscard]] double searchMagnitude(const SetSummary& set, const glm::dvec3& origin);

// Points shifted by `origin` and rounded to float, in a vector of their own.
[[nodiscard]] std::vector<glm::vec3> roundedCopy(const PointView& points, const glm::dvec3& origin,
                                                 int threads = 0);

// The float32 points a backend searches: the caller's memory when it is
// packed float and the origin is zero, else a shifted, rounded copy.
class FloatSet {
public:
    FloatSet(const PointView& points, const glm::dvec3& origin, int threads = 0);
    [[nodiscard]] std::span<const glm::vec3> span() const { return m_span; }

private:
    std::vector<glm::vec3> m_copy;
    std::span<const glm::vec3> m_span;
};

// Replaces a backend's witnesses and per-point distances (float coordinates
// after the shift) by those of the original coordinates, in double. A
// per-point array without distances (CallOptions::perPointNearestOnly)
// stays without them.
void restoreOriginal(HausdorffResult& r, const PointView& a, const PointView& b, int threads = 0);

}  // namespace rthdist::core
