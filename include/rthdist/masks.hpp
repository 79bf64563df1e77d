// rthdist masks — Hausdorff distance, HD-p, ASSD/MSD and surface Dice between
// two segmentation masks (NIfTI-1/2 or NumPy volumes), exact, in the
// convention of a named tool. The package's `masks` component:
// find_package(rthdist COMPONENTS masks) -> rthdist::masks (static builds;
// README "Segmentation masks", docs/masks.md).
//
// Pipeline per label: select the label's voxels in each volume, extract the
// convention's point set (boundary voxels under a stated connectivity, all
// foreground voxels, or surfels), convert voxel centres (corners) to
// coordinates in double, then the exact engine (rthdist.hpp, per-point
// distances) for every point's nearest distance in the other set; the
// convention's percentile rule and combination of the two directions make
// the numbers.
//
// Conventions: one row each in rthdist/mask_conventions.hpp (the point set,
// metric, connectivity, percentile rule, combination, tolerance arithmetic
// and empty-mask values), which the library reads; docs/masks.md explains
// each row and the tool it reproduces. In short:
//   rthdist     boundary voxels under `connectivity` (default 6), world
//               coordinates (the affine, a shear counts); HD-p = max of the
//               two directed nearest-rank percentiles; empty -> status, no value.
//   monai       mask XOR erosion (6-connected cross), spacing; HD-p = max of
//               the two directed linear percentiles (torch.quantile's float32
//               rank and weight: MaskOptions::monaiFloat32; p = 0 -> the
//               maximum); surface Dice counts float(d) <= float(tolerance).
//   medpy       boundary as monai (connectivity 6 by default); HD-p = linear
//               percentile of the POOLED distances of both directions.
//   plastimatch boundary voxels (6-connected); HD-p per direction = the k-th
//               smallest, k = floor(p/100 n - 1) clamped to [0, n-1]; HD-p =
//               MEAN of the two.
//   itk         ALL foreground voxels (a voxel inside the other mask counts
//               0); no percentile, no surface measures.
//   deepmind    surfels (corners of the half-voxel-shifted grid whose 2x2x2
//               code is neither 0 nor 255) weighted by their marching-cubes
//               areas; every statistic area-weighted; HD-p per direction =
//               the first distance whose cumulative area fraction >= p/100;
//               HD-p = max of the two ("robust HD").
// "average" (MaskResult::msd) is the mean of the two directed means for
// every convention. Every convention but rthdist measures with the voxel
// spacing only (the column norms of the affine's 3x3 part), as those tools
// do; for an orthonormal direction matrix the distances equal the world
// ones. DeepMind takes only spacing_mm: an oblique affine's direction matrix
// is ignored (witness points are still reported in world coordinates).
//
// Precision: coordinates in double; distances are the engine's exact values
// (within 1e-6 of the union's bounding-box diagonal of the brute force in
// double, rthdist.hpp), so every order statistic is as well. deepmind
// recomputes each distance from the engine's nearest surfel with SciPy's EDT
// arithmetic, sqrt(((di sx)^2 + (dj sy)^2) + (dk sz)^2), and sums areas in
// NumPy's order, so its area-weighted percentiles pick the index DeepMind's
// own run picks, rounding included.
// Threading: extraction, the recomputed distances and the percentiles use
// options.threads (0 = all); a MaskEngine (and a PreparedReference, which
// belongs to one) is not thread-safe: one per thread, as Engine. Functions
// are otherwise reentrant.
// Limits: up to 2^31 - 1 selected points per mask (engine limit); labels are
// int32 values (wider or non-integral values -> kBadInput); a volume file's
// voxel data within VolumeLimits; geometry within kMinSpacing and
// kMaxCoordinate (below).
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

#include "rthdist/mask_conventions.hpp"
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

// Reads a NIfTI-1 or NIfTI-2 file (.nii, .nii.gz) with rthdist's own reader: the
// header is validated field by field (README "Segmentation masks": dim,
// datatype, pixdim, vox_offset, scl_slope/scl_inter, qform/sform codes,
// quatern_b/c/d, qoffset, srow) before any value is used, then the voxels
// are read (inflated) in pieces into the Volume, within `limits`. A gzip
// stream is read to its end: a missing, cut or corrupt trailer (CRC-32,
// ISIZE), inflated bytes after the voxels and bytes after the stream other
// than zero padding are refused (at most one byte past the voxels is
// inflated); a plain .nii's bytes after the voxels are not read. The
// transform is the sform when sform_code > 0, else the qform when
// qform_code > 0, else diag(pixdim[1..3]) with origin 0. scl_slope/scl_inter
// are applied when the slope is finite and non-zero (as nibabel). A 4-D to
// 7-D file must have one volume. Only regular files are read (a FIFO or a
// device is refused before a byte is read). Errors (kBadInput) name the
// file and the field.
[[nodiscard]] Result<Volume> loadNifti(const std::string& path, const VolumeLimits& limits = {});

// Reads a NumPy .npy file (format 1.0, 2.0 or 3.0, read as NumPy's format
// specification says; 3-D; bool, int8..int64,
// uint8..uint64, float32, float64, either byte order; C or Fortran order).
// Array axes 0, 1, 2 are i, j, k; the voxel spacing along them is `spacing`
// (origin 0) unless `affine` (a 4x4 whose last row is 0 0 0 1) is given.
// Regular files only; errors (kBadInput) name the file and the field.
[[nodiscard]] Result<Volume> loadNpy(const std::string& path, glm::dvec3 spacing,
                                     const std::optional<glm::dmat4>& affine = std::nullopt,
                                     const VolumeLimits& limits = {});

// Loads by extension: .nii / .nii.gz through loadNifti, .npy through loadNpy.
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
// Voxels whose label is not 0: every label's points lie among them.
[[nodiscard]] uint64_t nonzeroVoxels(const Volume& v);

// Convention (the enum, kAllConventions and each one's rules): rthdist/mask_conventions.hpp.
// Its row's name and one-line rule ("?" for a value outside the table).
[[nodiscard]] const char* conventionName(Convention c);
[[nodiscard]] const char* conventionRule(Convention c);
// The convention named `text` (a row's name) into `out`; false when none is.
[[nodiscard]] bool parseConvention(const std::string& text, Convention& out);
// Every convention's name, in table order, joined by ", " ("rthdist, monai, ...").
[[nodiscard]] std::string conventionNames();
// The point set and metric as the CLI's JSON names them: "boundary_voxels",
// "voxels" or "surfels"; "world" or "spacing".
[[nodiscard]] const char* pointSetName(PointSet p);
[[nodiscard]] const char* metricName(Metric m);

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
// requested percentiles (none for a convention without HD-p): its row's
// bothEmpty or oneEmpty texts (rthdist/mask_conventions.hpp), each HD-p at
// p = 0 from the percentileAt0 text. In short: rthdist, itk "undefined";
// monai (d388d1c) "nan" for both, with one empty every distance inf (HD-p
// "nan" but at p = 0, Dice "0"); medpy "error" (it raises); plastimatch "0"
// for both (no Dice); deepmind (1f805ce) inf HDs, "nan" means and Dice of two
// empty masks.
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
// boundary pass (a compute shader, src/masks_gpu) opened on the same device
// index: boundary voxels are then found by a compute shader, the points'
// distances by the engine. Without it the host finds them (one read of each label, then word arithmetic),
// which measured faster on the H100 machine (docs/bench/masks): the pass needs the same host read to find and
// stage the labels' box, then an upload and a read-back. Not thread-safe (one per thread), as Engine.
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

// The backend of a one-shot comparison of a and b (one MaskEngine for this
// pair only: the CLI with one prediction, Python's compare_masks) under
// `conventions`: oneShotBackendFor (rthdist.hpp) of the run's points, which
// are at most the volumes' nonzero voxels (boundary or foreground; DeepMind's
// surfels, corners of them, eight a voxel) summed over the conventions, the
// labels splitting those voxels. Under auto the CPU backend for small masks,
// which answers before a GPU has opened its device; options.backend otherwise.
[[nodiscard]] Backend oneShotMaskBackend(const Options& options, const Volume& a, const Volume& b,
                                         const std::vector<Convention>& conventions);

// PreparedReference: a reference (ground-truth) mask prepared once and compared with many
// predictions (models, epochs, raters): its point set is extracted and
// indexed on the MaskEngine once instead of at every compareMasks call.
//
// Contract: compareMasks(engine, prepareReference(engine, ref, sel, o),
// prediction, sel, o) returns the MaskResult of compareMasks(engine, ref,
// sel, prediction, sel, o), the reference as A: every value (hd, HD-p per
// direction and combined, ASSD, MSD, surface overlaps and Dice, points,
// area, witness voxels/corners and world points, empty status and the
// convention's empty values) is the same double, bit for bit; only the
// timings and `extraction` (where the prediction's boundary was found)
// differ. It holds because both calls send the engine the same float
// coordinates in the same order (every convention searches in A's frame), the engine's per-point nearest
// point depends on those alone (the smallest target index among float ties), and the numbers are then made by
// the same code.
//
// What is kept, per convention (PreparedReference::points()):
//   rthdist, monai, medpy, plastimatch  the boundary voxels under the
//       convention's connectivity, and the engine's PreparedSet of them (A's
//       frame: world for rthdist, spacing otherwise); each comparison
//       prepares the prediction's boundary and runs ONE engine call on the
//       two prepared sets.
//   itk       the selection as one bit per voxel (the
//       voxels inside the reference are at 0 in both directions) and its
//       6-connected boundary with its PreparedSet: the prediction's voxels
//       outside the reference query it (prepared, then one call on the two
//       sets); the reference's voxels outside the prediction query the
//       prediction's boundary in a one-shot call.
//   deepmind  the surfels (corners, codes) only: both directions stay
//       one-shot calls, as in compareMasks. Each direction queries a subset
//       that depends on the prediction, and a PreparedSet of the reference's
//       surfels needs the prediction's queries prepared too (indexed, which a
//       one-shot directed call does not do): 0.73x on the CPU backend when
//       tried (docs/bench/masks). What it saves is the reference's surfels.
// Options: the convention's point set is fixed at preparation: a comparison
// whose options need another set (convention with other points or metric,
// another connectivity) is refused with kInvalidArgument naming both; it is
// not recomputed (the labels are not kept). The conventions that share a
// set share a prepared reference: monai and plastimatch (6-connected
// boundary, spacing metric), and medpy with the same connectivity.
// Percentiles, tolerance, threads and hostExtraction are free per call.
// Grids: the prediction must share the reference's grid (checkSameGrid: the
// same error as compareMasks, naming both files); an empty reference or
// prediction gives compareMasks's empty statuses.
//
// Precision: compareMasks's (above): distances recomputed in double from
// the voxel (corner) indices of the engine's nearest pair.
// Memory: the point lists (8 bytes a point; deepmind 9), itk's bits (one per
// voxel) and the PreparedSet (on the engine's device, plus its host copy);
// hostBytes()/deviceBytes() report them; everything is released with the
// last copy of the object (copies share it).
// Threading: a PreparedReference belongs to the MaskEngine that prepared it
// (its engine's device) and is used by that engine's calls, one at a time,
// as MaskEngine itself; comparing it on another MaskEngine is refused.
// Limits: as compareMasks; a prepared set holds at most 2^31 - 1 points.

class PreparedReference {
public:
    // The reference's grid: path, dims, affine and transform (no labels).
    [[nodiscard]] const Volume& grid() const;
    [[nodiscard]] LabelSelect select() const;
    // What it was prepared for: the convention asked and its effective
    // connectivity (0 for itk and deepmind, as MaskResult::connectivity).
    [[nodiscard]] Convention convention() const;
    [[nodiscard]] int connectivity() const;
    // Its selected voxels, and its point count under the convention (what
    // MaskResult::aToB.points reports: boundary voxels, foreground voxels
    // (itk) or surfels (deepmind)).
    [[nodiscard]] uint64_t selectedVoxels() const;
    [[nodiscard]] uint64_t points() const;
    // Memory held now: host (point lists, bits, the PreparedSet's host part)
    // and device (the PreparedSet's buffers; 0 on the CPU backend).
    [[nodiscard]] uint64_t hostBytes() const;
    [[nodiscard]] uint64_t deviceBytes() const;
    // The preparation's wall time, and where its boundary was found
    // ("device" or "host", as MaskResult::extraction).
    [[nodiscard]] double prepareMs() const;
    [[nodiscard]] const std::string& extraction() const;

    struct State;

private:
    friend Result<PreparedReference> prepareReference(MaskEngine&, const Volume&, LabelSelect,
                                                      const MaskOptions&);
    friend Result<MaskResult> compareMasks(MaskEngine&, const PreparedReference&, const Volume&, LabelSelect,
                                           const MaskOptions&);
    explicit PreparedReference(std::shared_ptr<const State> state);
    std::shared_ptr<const State> m_state;
};

// Extracts label `select` of `reference` under options.convention (and
// connectivity) and prepares its points on the engine. Errors: compareMasks's
// checks of the volume and options (kInvalidArgument), the engine's.
[[nodiscard]] Result<PreparedReference> prepareReference(MaskEngine& engine, const Volume& reference,
                                                         LabelSelect select, const MaskOptions& options);

// compareMasks(engine, reference's volume, its select, prediction, select,
// options) through the prepared reference (the contract above).
[[nodiscard]] Result<MaskResult> compareMasks(MaskEngine& engine, const PreparedReference& reference,
                                              const Volume& prediction, LabelSelect select,
                                              const MaskOptions& options);

}  // namespace rthdist::masks
