// The certificate of a direction on the device (core/certificate.hpp, issue
// 32): the self-check appends the band, every query within 2e of the float
// maximum (check_queries.comp); the band queries that can still decide the
// maximum get their nearest target by a brute force over every target of the
// direction (cert_scan.comp: one read of the targets for up to
// RTHDIST_CERT_ENTRIES queries), settled in double on the host from the
// candidates within their bounds. The proof then fixes the direction's
// value and witness (exact in double) or says why it does not hold.
#pragma once

#include "core/certificate.hpp"
#include "gpu_algo/direction.hpp"
#include "gpu_algo/query_check.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

// Queries one direction's band holds (8 bytes each, host memory); a larger
// band (a maximum below the rounding slack over more queries, e.g. a set
// against a copy of itself) leaves the proof to the engine's recomputation.
inline constexpr uint32_t kBandCapacity = uint32_t(1) << 18;
// Candidates one brute force holds (8 bytes each, host memory).
inline constexpr uint32_t kCandidateCapacity = uint32_t(1) << 16;
// Targets the witness's brute force with the self-check holds (4 bytes
// each, after the band in its buffer); more leave the witness to a brute
// force of its own.
inline constexpr uint32_t kWitnessCapacity = uint32_t(1) << 12;

// The certificate's e of d as the shaders take it: float, rounded up (the
// band, the kill margin and the witness's bound all use this one value).
[[nodiscard]] float deviceSlack(const DirectionRun& d);

// Records cert_witness.comp (the witness's brute force) beside the
// direction's check recorded at `at`, with the same early exit: it runs
// where the check runs whole, once per direction.
void cmdScanWitness(Workspace& ws, VkCommandBuffer cmd, const DirectionRun& d, CheckAt at);

class CertificatePass {
public:
    CertificatePass(Workspace& workspace, QueryCheck& check) : m_ws(workspace), m_check(check) {}

    // Before the direction's checks: its band emptied, the slack e set from
    // both sets' boxes (search units).
    void startDirection(DirectionRun& d, size_t direction);

    // After the direction's final check (QueryCheck::finishDirection): the
    // proof on the coordinates the host reads (SetPoints::original, search
    // units). Proven: `out` takes the proof's witness, value and
    // certificate; else out.certificate stays unconfirmed. Returns the band
    // (with the device's candidates) for a proof from other coordinates.
    core::DirectionBand prove(DirectionRun& d, Directed& out);

private:
    // The brute force of `batch` over d's targets on the device.
    bool bruteForce(DirectionRun& d, core::DirectionBand& band, std::span<core::BandNearest> batch);
    // One cert_scan.comp pass over d's targets (its entries and candidates
    // in the certificate scratch), in its own submission.
    void scan(DirectionRun& d, uint32_t entries, uint32_t capacity, uint32_t mode);

    Workspace& m_ws;
    QueryCheck& m_check;
};

}  // namespace rthdist::gpu_algo
