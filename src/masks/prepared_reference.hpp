// A reference (ground-truth) mask prepared once and compared with many
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
// coordinates in the same order (every convention searches in A's frame:
// voxel_metric.hpp), the engine's per-point nearest point depends on those
// alone (the smallest target index among float ties), and the numbers are
// then made by the same code (directions.hpp, deepmind.hpp).
//
// What is kept, per convention (PreparedReference::points()):
//   rthdist, monai, medpy, plastimatch  the boundary voxels under the
//       convention's connectivity, and the engine's PreparedSet of them (A's
//       frame: world for rthdist, spacing otherwise); each comparison
//       prepares the prediction's boundary and runs ONE engine call on the
//       two prepared sets.
//   itk       the selection as one bit per voxel (selection_bits.hpp: the
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
// Precision: compareMasks's (masks.hpp): distances recomputed in double from
// the voxel (corner) indices of the engine's nearest pair.
// Memory: the point lists (8 bytes a point; deepmind 9), itk's bits (one per
// voxel) and the PreparedSet (on the engine's device, plus its host copy);
// hostBytes()/deviceBytes() report them; everything is released with the
// last copy of the object (copies share it).
// Threading: a PreparedReference belongs to the MaskEngine that prepared it
// (its engine's device) and is used by that engine's calls, one at a time,
// as MaskEngine itself; comparing it on another MaskEngine is refused.
// Limits: as compareMasks; a prepared set holds at most 2^31 - 1 points.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "masks/masks.hpp"

namespace rthdist::masks {

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
