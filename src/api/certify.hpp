// The last step of every call that reads the caller's coordinates: each
// direction's certificate (core/certificate.hpp) settled, or the direction
// recomputed where it does not hold (issue 32).
#pragma once

#include <optional>

#include "rthdist/rthdist.hpp"

namespace rthdist::api {

// For each direction of `r` (a backend's result on queries `a` and targets
// `b` as the caller gave them, frame origin r.origin):
//   - proven by the backend's band (the backend's own coordinates, or again
//     from a and b by core::restoreOriginal): kept;
//   - no band (a route that keeps none: small pairs scanned whole, pieces):
//     the witness query's nearest target by a brute force in double over all
//     of the targets must realize the reported value (certificate.band 0);
//   - otherwise, or when that check fails: the direction is recomputed on
//     the CPU backend, an independent search (its own index, traversal and
//     early break; no shader, no ray), and proven from a and b; the result
//     takes it with certificate.recomputed. Its proof failing too is
//     kInternal with both reasons, never a number.
// r.hausdorff is the larger directed value afterwards, proofMaterial empty.
// `canRecompute` false (device views: the host cannot read the points) makes
// an unconfirmed direction kInternal at once.
[[nodiscard]] std::optional<Error> settleCertificates(HausdorffResult& r, const PointView& a,
                                                      const PointView& b, int threads,
                                                      bool canRecompute = true);

}  // namespace rthdist::api
