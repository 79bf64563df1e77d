// rthdist masks — Hausdorff distance, HD-p, ASSD/MSD and surface Dice between
// two segmentation masks (NIfTI-1/2 or NumPy volumes), exact, in the
// convention of a named tool (../shared/MASKS.md, README "Segmentation masks").
//
// Pipeline per label: select the label's voxels in each volume, extract the
// convention's point set (boundary voxels under a stated connectivity, or all
// foreground voxels), convert voxel centres to coordinates in double, then
// the exact engine (rthdist.hpp, per-point distances) for every point's
// nearest distance in the other set; the convention's percentile rule and
// combination of the two directions make the numbers.
//
// Conventions (Convention; conventionName/parseConvention):
//   rthdist     boundary = foreground voxels with a background (or outside
//               the volume) neighbour under `connectivity` (default 6);
//               coordinates = the voxel-to-world affine (a shear counts);
//               HD-p = max of the two directed nearest-rank percentiles
//               (rthdist/stats.hpp percentileNearestRank); empty -> status, no value.
//   monai       boundary = mask XOR erosion (6-connected cross); spacing only;
//               HD-p = max of the two directed linear percentiles
//               (torch.quantile: rank and weight in float32; p = 0 -> the
//               maximum); surface Dice counts float(d) <= float(tolerance)
//               (MaskOptions::monaiFloat32); empty: emptyValues.
//   medpy       boundary as monai (connectivity 6 by default); HD-p = linear
//               percentile of the POOLED distances of both directions;
//               HD = max; empty -> undefined (MedPy raises).
//   plastimatch boundary voxels (6-connected); HD-p per direction = the k-th
//               smallest, k = floor(f n - 1) clamped to [0, n-1], f = p/100;
//               HD-p = MEAN of the two; "average" = mean of the directed means;
//               both empty -> 0.
//   itk         ALL foreground voxels (HausdorffDistanceImageFilter): a voxel
//               inside the other mask counts 0; no percentile; "average" =
//               mean of the directed means (AverageHausdorffDistance).
//   deepmind    surface-distance (1f805ce): surfels = corners of the voxel grid
//               (voxel coordinates (i - 1/2, j - 1/2, k - 1/2)) whose 2x2x2
//               neighbour code is neither 0 nor 255, each with the area of its
//               marching-cubes piece (surfel_area.hpp); distance from each
//               surfel of X to the nearest surfel of Y; every statistic weighted
//               by area: HD-p per direction = d_i of the first i (sorted by
//               distance, then area) whose cumulative area / total >= p/100,
//               no interpolation; HD-p = max of the two ("robust HD");
//               directed mean = sum(a d) / sum(a); ASSD = both surfaces' sum(a d)
//               / both areas; MSD = mean of the directed means; surface overlap
//               = area within the tolerance / area, per direction; surface
//               Dice = (both areas within the tolerance) / (both areas).
//               Empty: HD and HD-p inf; surface Dice 0 (one empty) or NaN
//               (both); the empty side's mean NaN, the other's inf.
// Every convention but rthdist measures with the voxel spacing only (the
// column norms of the affine's 3x3 part), as those tools do; for an
// orthonormal direction matrix the distances equal the world ones. DeepMind
// takes only spacing_mm: an oblique affine's direction matrix is ignored
// (witness points are still reported in world coordinates).
//
// Precision: coordinates in double; distances are the engine's exact values
// (within 1e-6 of the union's bounding-box diagonal of the brute force in
// double, rthdist.hpp), so every order statistic is as well. deepmind
// recomputes each distance from the engine's nearest surfel with SciPy's EDT
// arithmetic, sqrt(((di sx)^2 + (dj sy)^2) + (dk sz)^2), and sums areas in
// NumPy's order (area_weighted.hpp), so its area-weighted percentiles pick
// the index DeepMind's own run picks, rounding included.
// Threading: extraction, the recomputed distances and the percentiles use
// options.threads (0 = all); the Engine passed in is not thread-safe (one per
// thread). Functions are otherwise reentrant.
// Limits: volumes up to 2^31 - 1 selected points per mask (engine limit);
// labels are int32 values (wider or non-integral values -> kBadInput).
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rthdist/result.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist::masks_gpu {
class BoundaryPass;
}

namespace rthdist::masks {

// A label volume on a grid: voxel (i, j, k) is labels[i + nx * (j + ny * k)]
// (NIfTI order, i fastest), its centre at voxelToWorld * (i, j, k, 1).
struct Volume {
    std::string path;  // the file it came from ("" for arrays)
    std::array<int64_t, 3> dims{0, 0, 0};
    glm::dmat4 voxelToWorld{1.0};       // column-major (glm): world = M * (i, j, k, 1)
    std::string transform = "spacing";  // "sform", "qform", "pixdim", "spacing", "affine"
    // The voxels' labels: exactly one of the two holds them. The loaders use
    // labels8 for 8-bit unsigned data (bool, uint8: a quarter of the bytes to
    // scan), labels otherwise.
    std::vector<int32_t> labels;
    std::vector<uint8_t> labels8;

    [[nodiscard]] size_t storedVoxels() const { return labels8.empty() ? labels.size() : labels8.size(); }

    [[nodiscard]] uint64_t voxelCount() const {
        return uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
    }
    // Column norms of the affine's 3x3 part (the spacing tools such as MONAI use).
    [[nodiscard]] glm::dvec3 spacing() const;
};

// What one volume file may make the loaders hold. maxVolumeBytes bounds a
// volume's voxel data both as stored in the file (inflated, for .nii.gz)
// and as held in memory (1 byte a voxel for bool/uint8 without scaling, 4
// for every other type); a file past it is kBadInput naming the file, its
// size and the limit, before anything is allocated or inflated (the CLI's
// --max-volume-mib raises it). The voxels are held once: read (inflated) in
// pieces straight into the Volume's labels.
inline constexpr uint64_t kDefaultMaxVolumeBytes = uint64_t{2} << 30;  // 2 GiB
struct VolumeLimits {
    uint64_t maxVolumeBytes = kDefaultMaxVolumeBytes;
};

// The geometry every volume must have (loaders, arrays, compareMasks and
// prepareReference check it): each voxel axis (a column norm of the
// affine's 3x3 part) at least kMinSpacing and at most kMaxCoordinate, the
// grid's corners within kMaxCoordinate of 0 in world and in spacing
// coordinates, the affine finite (a NaN origin is refused), last row
// 0 0 0 1, not singular. Within these the distances are exact; beyond them
// the engine's arithmetic is not (the engine works in float after centring:
// spacings below ~1.4e-45 and extents beyond ~3e38 gave wrong values).
inline constexpr double kMinSpacing = 1e-30;
inline constexpr double kMaxCoordinate = 1e30;

// Reads a NIfTI-1 or NIfTI-2 file (.nii, .nii.gz; nifti.cpp, in target
// rthdist_masks, not rthdist_masks_core) with rthdist's own reader: the
// header is validated field by field (README "Segmentation masks": dim,
// datatype, pixdim, vox_offset, scl_slope/scl_inter, qform/sform codes,
// quatern_b/c/d, qoffset, srow) before any value is used, then the voxels
// are read (inflated) in pieces into the Volume, within `limits`. The
// transform is the sform when sform_code > 0, else the qform when
// qform_code > 0, else diag(pixdim[1..3]) with origin 0. scl_slope/scl_inter
// are applied when the slope is finite and non-zero (as nibabel). A 4-D to
// 7-D file must have one volume. Only regular files are read (a FIFO or a
// device is refused before a byte is read). Errors (kBadInput) name the
// file and the field.
[[nodiscard]] Result<Volume> loadNifti(const std::string& path, const VolumeLimits& limits = {});

// Reads a NumPy .npy file (format 1.0, 2.0 or 3.0, read as NumPy's format
// specification says: npy_header.hpp; 3-D; bool, int8..int64,
// uint8..uint64, float32, float64, either byte order; C or Fortran order).
// Array axes 0, 1, 2 are i, j, k; the voxel spacing along them is `spacing`
// (origin 0) unless `affine` (a 4x4 whose last row is 0 0 0 1) is given.
// Regular files only; errors (kBadInput) name the file and the field.
[[nodiscard]] Result<Volume> loadNpy(const std::string& path, glm::dvec3 spacing,
                                     const std::optional<glm::dmat4>& affine = std::nullopt,
                                     const VolumeLimits& limits = {});

// Loads by extension: .nii / .nii.gz through loadNifti, .npy through loadNpy
// (rthdist_masks, as loadNifti).
[[nodiscard]] Result<Volume> loadVolume(const std::string& path, glm::dvec3 spacing = glm::dvec3(1.0),
                                        const std::optional<glm::dmat4>& affine = std::nullopt,
                                        const VolumeLimits& limits = {});

// kInvalidArgument naming v.path when v breaks the geometry rules above
// (kMinSpacing, kMaxCoordinate, a finite affine) or its labels do not
// match its dims.
[[nodiscard]] std::optional<Error> checkVolume(const Volume& v);

// A 3-D label array in memory (a NumPy array): C order ((i, j, k) at
// (i * n1 + j) * n2 + k) or, when `fortran`, i fastest; scalars of NumPy
// kind `kind` in the host's byte order: "b1", "u1", "i1", "u2", "i2", "u4",
// "i4", "u8", "i8", "f4" or "f8".
struct LabelArray {
    const void* data = nullptr;
    std::array<int64_t, 3> dims{0, 0, 0};
    bool fortran = false;
    std::string_view kind;
};

// A Volume holding a copy of the array's labels, as loadNpy reads them (the
// same types and checks: non-integral or non-int32 values are kBadInput),
// with `voxelToWorld` (finite, last row 0 0 0 1, not singular; else
// kInvalidArgument). `name` is the Volume's path: every error and grid
// mismatch names it; `transform` says where the affine came from.
[[nodiscard]] Result<Volume> volumeFromArray(const LabelArray& array, const glm::dmat4& voxelToWorld,
                                             const std::string& name,
                                             const std::string& transform = "affine");

// Empty when a and b share a grid (same dims, affines equal within 1e-5 of
// an entry's magnitude, at least 1e-6); else the reason, naming both files.
// Nothing is resampled.
[[nodiscard]] std::optional<Error> checkSameGrid(const Volume& a, const Volume& b);

// Sorted distinct non-zero labels present in the volume.
[[nodiscard]] std::vector<int32_t> labelsPresent(const Volume& v);

enum class Convention { kRthdist, kMonai, kMedpy, kPlastimatch, kItk, kDeepmind };
inline constexpr std::array<Convention, 6> kAllConventions{Convention::kRthdist, Convention::kMonai,
                                                           Convention::kMedpy,   Convention::kPlastimatch,
                                                           Convention::kItk,     Convention::kDeepmind};
[[nodiscard]] const char* conventionName(Convention c);
[[nodiscard]] bool parseConvention(const std::string& text, Convention& out);
// One line naming the point set, the metric, the percentile rule and the combination.
[[nodiscard]] const char* conventionRule(Convention c);

// Which voxels form a mask: label == value, or (anyNonZero) label != 0.
struct LabelSelect {
    int32_t value = 1;
    bool anyNonZero = true;
};

struct MaskOptions {
    Convention convention = Convention::kRthdist;
    // 6, 18 or 26; 0 = 6. Used by rthdist and medpy; monai and plastimatch
    // always use 6 (their tools take none), itk all voxels, deepmind surfels.
    int connectivity = 0;
    std::vector<double> percentiles{95.0};  // each in [0, 100]
    double tolerance = 1.0;                 // surface Dice tolerance, in mm (>= 0)
    int threads = 0;                        // extraction, distances, percentiles; 0 = all hardware threads
    // monai only: MONAI's float32 arithmetic (its distances are float32
    // tensors): a distance d is within the tolerance when float(d) <=
    // float(tolerance), and torch.quantile's rank p/100 (n - 1) and weight are
    // float32 (rank, weight and the two order statistics as torch takes them;
    // the interpolation in double). false: the same rules in double (d <= tolerance,
    // numpy's rank). Either way p = 0 is the maximum (MONAI's `if not percentile`).
    bool monaiFloat32 = true;
    // Extract boundaries on the host even when the MaskEngine has a device
    // pass (makeMaskEngine's devicePass; tests compare the two: the voxels
    // are the same).
    bool hostExtraction = false;
};

enum class EmptyStatus { kNone, kBothEmpty, kAEmpty, kBEmpty };
[[nodiscard]] const char* emptyStatusName(EmptyStatus s);  // "ok", "both_empty", "a_empty", "b_empty"

// What a convention's own tool reports for a row with an empty mask, one
// text per number of MaskResult: "nan", "inf", "0", "undefined" (the tool
// defines no such value) or "error" (the tool raises). emptyValues() below
// has each convention's rules.
struct EmptyDirected {
    std::string hd, mean, surfaceOverlap;
    std::vector<std::string> percentiles;  // per MaskOptions::percentiles
};
struct EmptyValues {
    std::string hd, assd, msd, surfaceDice;
    std::vector<std::string> hdPercentile;  // per MaskOptions::percentiles
    EmptyDirected aToB, bToA;
};

// The values convention c reports when A or B (or both) is empty, for the
// requested percentiles (none for itk):
//   rthdist, itk  "undefined" everywhere.
//   monai (d388d1c)  both: "nan" everywhere. One: every distance of both
//                 directions is inf (get_surface_distance), so HD, the
//                 directed HDs and means, ASSD and MSD "inf"; HD-p "nan"
//                 (torch.quantile interpolates inf - inf) except p = 0
//                 ("inf": the maximum); surface Dice and overlaps "0".
//   medpy         "error" everywhere (RuntimeError: no binary object).
//   plastimatch   both: "0" (its statistics stay 0) but surface Dice and
//                 overlaps "undefined"; one: "undefined".
//   deepmind (1f805ce)  HD, HD-p and every directed HD-p "inf"; a side
//                 without surfels: mean and overlap "nan" (0/0), the other
//                 side's "inf" and "0"; surface Dice "0" (one) or "nan"
//                 (both); ASSD "inf" (one) or "nan"; MSD "nan".
[[nodiscard]] EmptyValues emptyValues(Convention c, EmptyStatus s, const std::vector<double>& percentiles);

// One direction X -> Y.
struct DirectedMask {
    uint64_t points = 0;  // X's points under the convention (boundary voxels, all voxels or surfels);
                          // also with an empty mask (0 for the empty side only)
    double hd = 0.0;      // max over X of the nearest distance to Y
    double mean = 0.0;    // deepmind: area-weighted
    std::vector<double> percentiles;  // this direction's percentile per MaskOptions::percentiles
                                      // (the convention's rule; medpy: the pooled values)
    // The fraction of X's points within the tolerance of Y (deepmind: of X's
    // surfel area, its "surface overlap"); itk: not defined (NaN).
    double surfaceOverlap = 0.0;
    double area = 0.0;  // deepmind: X's total surfel area (mm²); 0 for the others
    // X's point realizing hd and its nearest point of Y, as grid indices: voxels,
    // or for deepmind surfel corners (corner (i, j, k) at voxel coordinates
    // (i - 1/2, j - 1/2, k - 1/2)).
    std::array<int64_t, 3> voxel{0, 0, 0};
    std::array<int64_t, 3> nearestVoxel{0, 0, 0};
    glm::dvec3 point{0.0}, nearestPoint{0.0};  // those two in world coordinates
};

struct MaskResult {
    Convention convention = Convention::kRthdist;
    int connectivity = 6;  // 0 for itk (all voxels) and deepmind (surfels)
    EmptyStatus empty = EmptyStatus::kNone;
    // With empty != kNone: no number below is valid (NaN) but the points
    // of both sides; `emptyValues` says what the convention itself reports.
    EmptyValues emptyValues;
    double hd = 0.0;
    std::vector<double> percentiles;   // the requested p values
    std::vector<double> hdPercentile;  // combined per the convention (empty for itk)
    double assd = 0.0;  // (sum of both directions' distances) / (n_a + n_b); deepmind: area-weighted
    double msd = 0.0;   // mean of the two directed means (itk/plastimatch "average HD")
    // (#{d_ab <= tol} + #{d_ba <= tol}) / (n_a + n_b); deepmind: areas instead
    // of counts; itk: not defined (NaN).
    double surfaceDice = 0.0;
    DirectedMask aToB, bToA;
    double extractMs = 0.0, distanceMs = 0.0, totalMs = 0.0;
    Timings engine;  // the engine calls' stages, summed over the calls (distanceMs is their wall time)
    // Where the boundary voxels were found: "device" (the compute pass of a
    // MaskEngine made with devicePass) or "host" (the default, itk's
    // foreground, deepmind's surfels, a box too large for the pass, or
    // MaskOptions::hostExtraction).
    std::string extraction = "host";
};

// The engine of compareMasks and, when asked for on a GPU backend, the
// boundary pass (masks_gpu/boundary_pass.hpp) opened on the same device
// index: boundary voxels are then found by a compute shader, the points'
// distances by the engine. Without it the host finds them (row_bits.hpp:
// one read of each label, then word arithmetic), which measured faster on
// the H100 machine (docs/bench/masks): the pass needs the same host read to
// find and stage the labels' box, then an upload and a read-back. Not
// thread-safe (one per thread), as Engine.
struct MaskEngine {
    Engine engine;
    std::shared_ptr<masks_gpu::BoundaryPass> boundaryPass;  // null: extraction on the host
};

// Compares label `selectA` of `a` with `selectB` of `b` (same grid: checked).
// The calls set their own options (per-point distances). Boundary
// conventions: one compute() call for both directions, on A's grid; itk and
// deepmind: one call per direction.
[[nodiscard]] Result<MaskResult> compareMasks(MaskEngine& engine, const Volume& a, LabelSelect selectA,
                                              const Volume& b, LabelSelect selectB,
                                              const MaskOptions& options);

// The Engine of `options` (backend, device, threads, validation) and, with
// devicePass on a GPU backend, the boundary pass on options.deviceIndex
// (a second Vulkan device of its own).
[[nodiscard]] Result<MaskEngine> makeMaskEngine(Options options, bool devicePass = false);

}  // namespace rthdist::masks
