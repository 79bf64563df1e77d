// rthdist — reconstruction evaluation (issue 34): accuracy, completeness,
// Chamfer distances, precision, recall and F-score at thresholds, in one
// call, from the per-point nearest distances of the engine (point targets)
// or of the point-to-surface search (surface targets).
//
// Roles: the FIRST input is the reconstruction R, the SECOND the ground
//   truth G (the CLI's A and B).
//   accuracy distances:     every point of R to G (R -> G)
//   completeness distances: every point of G to R (G -> R)
//   Point targets (evaluatePoints): both are point sets; the distances are
//   the nearest-neighbour distances of hausdorff() with
//   Options::perPointDistances (exact for double inputs; for float32
//   inputs at most a relative 2^-21 above the exact ones). Surface target (evaluateToSurface): G is a
//   mesh; accuracy is every point of R to G's triangles (hausdorffToSurface:
//   exact on the CPU backend, within SurfacePerPoint::tolerance on a GPU
//   backend); completeness is every vertex a triangle of G uses (each
//   once) to R's points (a point set has no surface to measure to).
//   Per-point distances of a GPU backend are within its rounding of the
//   exact ones (README "Precision"; rthdist/surface.hpp), so a distance
//   that close to a threshold or the cap may fall on either side of it.
//
// Definitions (evaluationSummary; the README repeats them):
//   cap: with cap > 0, distances d >= cap are dropped from the means,
//     medians and Chamfer values (DTU's rule, 20 mm there: `d < cap` kept);
//     kept counts them. Precision, recall and F-score use every distance.
//   mean = sum / kept; median as NumPy's (the middle value, or the mean of
//     the two middle values for an even count); meanSquared = sum d^2 / kept;
//     max over the kept distances. NaN (JSON null) when nothing is kept.
//   Chamfer, three conventions, each named for what it is:
//     chamferMeanOfMeans       = (accuracy.mean + completeness.mean) / 2
//                                (DTU's "overall")
//     chamferSumOfMeans        = accuracy.mean + completeness.mean
//                                ("Chamfer-L1" in many papers)
//     chamferSumOfMeanSquares  = accuracy.meanSquared + completeness.meanSquared
//                                (squared distances, PyTorch3D's
//                                chamfer_distance with point_reduction "mean")
//   At each threshold tau (Tanks and Temples' rule, strict):
//     precision = #{accuracy d < tau} / |R|, recall = #{completeness d < tau} / |G|,
//     fscore = 2 precision recall / (precision + recall), 0 when both are 0.
//
// Inputs: thresholds finite and > 0 (any number, in the order given); cap
//   finite and >= 0 (0: no cap); violations are kInvalidArgument naming the
//   value. Threading: evaluationSummary is a pure function (reentrant); the
//   others run on the options' threads. Precision: sums in double, in point
//   order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/mesh.hpp"
#include "rthdist/options.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"
#include "rthdist/surface.hpp"

namespace rthdist {

struct EvalOptions {
    std::vector<double> thresholds;  // tau, each finite and > 0
    double cap = 0.0;                // > 0: drop d >= cap from means and medians; 0: none
};

// One direction's distances after the cap.
struct EvalDistances {
    uint64_t count = 0;  // every distance
    uint64_t kept = 0;   // below the cap (all without one)
    double mean = 0.0, median = 0.0, meanSquared = 0.0, max = 0.0;
};

struct EvalThreshold {
    double threshold = 0.0;
    double precision = 0.0, recall = 0.0, fscore = 0.0;
};

struct EvalSummary {
    EvalDistances accuracy;      // reconstruction -> ground truth
    EvalDistances completeness;  // ground truth -> reconstruction
    double chamferMeanOfMeans = 0.0;
    double chamferSumOfMeans = 0.0;
    double chamferSumOfMeanSquares = 0.0;
    double cap = 0.0;
    std::vector<EvalThreshold> thresholds;
};

// The summary of two lists of distances (definitions above); both non-empty.
[[nodiscard]] RTHDIST_API Result<EvalSummary> evaluationSummary(std::span<const double> accuracy,
                                                                std::span<const double> completeness,
                                                                const EvalOptions& options = {});

// Point targets: the distances from hausdorff(reconstruction, groundTruth)
// with per-point distances (options.perPointDistances and directedOnly are
// set by the call).
[[nodiscard]] RTHDIST_API Result<EvalSummary> evaluatePoints(PointView reconstruction, PointView groundTruth,
                                                             const EvalOptions& eval,
                                                             const Options& options = {});

// Surface target: accuracy to groundTruth's triangles, completeness from
// its (used) vertices to the reconstruction's points (roles above).
// options.perPointDistances is set by the call; options.backend and threads
// apply to both searches (a GPU backend: one Engine on options.deviceIndex
// runs both, so the device opens once).
[[nodiscard]] RTHDIST_API Result<EvalSummary> evaluateToSurface(PointView reconstruction,
                                                                MeshView groundTruth, const EvalOptions& eval,
                                                                const SurfaceOptions& options = {});

}  // namespace rthdist
