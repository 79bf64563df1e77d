#include "gpu_algo/certificate_pass.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rthdist::gpu_algo {
namespace {

// Groups of the brute force's grid-stride loop at most: enough to fill any
// device, few enough that each loads the band queries once per many targets.
constexpr uint32_t kCertGroups = 4096;

// The witness's brute force in d's band buffer (cert_witness.comp):
// uint ran, query, count, pad, then the targets.
VkDeviceSize witnessOffset(const DirectionRun& d) { return 8 + VkDeviceSize(d.bandCapacity) * 8; }

// Groups of a grid-stride pass over d's targets (cert_scan.comp, cert_witness.comp).
uint32_t targetScanGroups(const Workspace& ws, const DirectionRun& d) {
    return std::max<uint32_t>(
        1, std::min({gpu::groupsFor(d.T.n, RTHDIST_WG), kCertGroups, ws.ctx.limits().maxGroupsX}));
}

}  // namespace

float deviceSlack(const DirectionRun& d) { return float(d.slack * (1.0 + 0x1.0p-20)); }

void cmdScanWitness(Workspace& ws, VkCommandBuffer cmd, const DirectionRun& d, CheckAt at) {
    if (d.band == nullptr) return;
    const sh::CertWitnessPush push{d.T.sorted->address(),
                                   d.Q.sorted->address(),
                                   d.blk.device,
                                   d.band->address() + witnessOffset(d),
                                   d.T.n,
                                   d.Q.n,
                                   kWitnessCapacity,
                                   deviceSlack(d),
                                   at == CheckAt::kBehindCull ? 1u : 0u,
                                   0,
                                   0,
                                   0};
    if (at == CheckAt::kBehindSearch) {  // the check's groups: none while queries go on
        ws.pipelines.cmdDispatchIndirect(cmd, Kernel::kCertWitness, &push, sizeof(push),
                                         ws.hostSmall.handle(), d.blk.offset + RTHDIST_CTR_CHECK_ARGS);
        return;
    }
    ws.pipelines.cmdDispatch(cmd, Kernel::kCertWitness, &push, sizeof(push), targetScanGroups(ws, d));
}

void CertificatePass::startDirection(DirectionRun& d, size_t direction) {
    d.slack =
        core::searchSlack(std::max(core::largestMagnitude(d.Q.bounds), core::largestMagnitude(d.T.bounds)));
    DirectionBuffers& memory = m_ws.scratch.directions[direction];
    d.bandCapacity = std::min<uint32_t>(kBandCapacity, d.Q.n);  // the band holds at most every query
    d.band = &m_ws.grow(memory.band, witnessOffset(d) + 16 + VkDeviceSize(kWitnessCapacity) * 4,
                        d.name() + ".band", MemoryKind::kHost);
    std::memset(d.band->mapped(), 0, 8);
    std::memset(static_cast<char*>(d.band->mapped()) + witnessOffset(d), 0, 16);
    // The kill threshold's margin (common.glsl, deadThreshold): the band's e.
    const float killSlack = deviceSlack(d);
    std::memcpy(d.blk.host + RTHDIST_CTR_KILL_SLACK, &killSlack, 4);
}

core::DirectionBand CertificatePass::prove(DirectionRun& d, Directed& out) {
    core::DirectionBand band;
    band.present = true;
    band.slack = d.slack;
    const uint64_t packed = d.blk.fields().maxPacked;
    band.hf = std::sqrt(double(std::bit_cast<float>(uint32_t(packed >> 32))));
    band.witness = out.queryIndex;
    const auto* words = static_cast<const uint32_t*>(d.band->mapped());
    const uint32_t count = words[0];
    if (count > d.bandCapacity) {
        band.failure = "the band of " + std::to_string(count) + " queries within the rounding slack of the " +
                       "maximum is past its capacity of " + std::to_string(d.bandCapacity);
    } else {
        std::vector<uint32_t> queries(count), targets(count);
        band.queries.resize(count);
        for (uint32_t k = 0; k < count; ++k) {
            queries[k] = words[2 + 2 * k];
            targets[k] = words[3 + 2 * k];
            band.queries[k] = {queries[k], targets[k]};
        }
        // The witness's brute force, where it ran with the check and its
        // targets fit: the proof settles the witness from them.
        const auto* witness =
            reinterpret_cast<const uint32_t*>(static_cast<const char*>(d.band->mapped()) + witnessOffset(d));
        const uint32_t found = witness[2];
        if (witness[0] == 1 && found <= kWitnessCapacity &&
            std::any_of(queries.begin(), queries.end(), [&](uint32_t q) { return q == witness[1]; })) {
            std::vector<uint64_t> list;
            for (uint32_t k = 0; k < found; ++k) {
                if (witness[4 + k] >= d.T.n) continue;
                list.push_back(witness[4 + k]);
                targets.push_back(witness[4 + k]);
            }
            band.candidates.emplace_back(witness[1], std::move(list));
        }
        m_check.fetchPoints(d, queries, targets);
    }
    const core::PointAt query = [&d](uint64_t i) { return d.qPts.original(uint32_t(i)); };
    const core::PointAt target = [&d](uint64_t i) { return d.tPts.original(uint32_t(i)); };
    const core::BruteForce device = [&](std::span<core::BandNearest> batch) {
        return bruteForce(d, band, batch);
    };
    const core::DirectedProof proof = core::proveDirection(band, query, target, device);
    core::applyProof(out, proof, query, target);
    if (!proof.proven) band.failure = proof.failure;
    d.settled = proof.proven ? proof.settled : std::vector<core::BandNearest>{};
    return band;
}

void CertificatePass::scan(DirectionRun& d, uint32_t entries, uint32_t capacity, uint32_t mode) {
    const sh::CertScanPush push{d.T.sorted->address(),
                                m_ws.scratch.certificate.entries.address(),
                                m_ws.scratch.certificate.candidates.address(),
                                d.T.n,
                                entries,
                                capacity,
                                mode};
    VkCommandBuffer cmd = m_ws.ctx.begin();
    m_ws.pipelines.cmdDispatch(cmd, Kernel::kCertScan, &push, sizeof(push), targetScanGroups(m_ws, d));
    gpu::cmdHostReadBarrier(cmd);
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuCertificate += m_ws.ctx.lastGpuMs();
}

bool CertificatePass::bruteForce(DirectionRun& d, core::DirectionBand& band,
                                 std::span<core::BandNearest> batch) {
    if (batch.size() > RTHDIST_CERT_ENTRIES) return false;
    Buffer& entries = m_ws.grow(m_ws.scratch.certificate.entries, RTHDIST_CERT_ENTRIES * 16, "cert.entries",
                                MemoryKind::kHost);
    // At most every target per query, at most kCandidateCapacity.
    const auto capacity = uint32_t(std::min<uint64_t>(kCandidateCapacity, uint64_t(d.T.n) * batch.size()));
    Buffer& found =
        m_ws.grow(m_ws.scratch.certificate.candidates,
                  std::max<VkDeviceSize>(8 + VkDeviceSize(capacity) * 8, RTHDIST_CERT_ENTRIES * 8),
                  "cert.candidates", MemoryKind::kHost);
    auto* e = static_cast<float*>(entries.mapped());
    auto* words = static_cast<uint32_t*>(found.mapped());
    const auto n = uint32_t(batch.size());
    for (uint32_t k = 0; k < n; ++k) {
        const glm::vec3 q = d.qPts.searched(uint32_t(batch[k].query));
        // Every target within the query's bound U (its best so far, exact)
        // is within U + e in float; 3e and a relative 2^-20 leave room for a
        // proof from the caller's own coordinates (HausdorffResult::proofMaterial).
        const double bound = batch[k].distance + 3.0 * d.slack;
        e[4 * k + 0] = q.x;
        e[4 * k + 1] = q.y;
        e[4 * k + 2] = q.z;
        e[4 * k + 3] = float(bound * bound * (1.0 + core::kSlackPerMagnitude));
    }
    std::memset(words, 0, 8);
    scan(d, n, capacity, 0);
    if (words[0] > capacity) {
        // Too many targets within the bounds (a query that died on a far
        // point): each query's float nearest first, then every target within
        // it + 2e (where its nearest in double lies: design.md §10).
        auto* mins = reinterpret_cast<uint64_t*>(words);
        std::fill(mins, mins + n, ~uint64_t(0));
        scan(d, n, capacity, 1);
        for (uint32_t k = 0; k < n; ++k) {
            const double nearest = std::sqrt(double(std::bit_cast<float>(uint32_t(mins[k] >> 32))));
            const double bound = nearest + 3.0 * d.slack;
            e[4 * k + 3] = std::min(e[4 * k + 3], float(bound * bound * (1.0 + core::kSlackPerMagnitude)));
        }
        std::memset(words, 0, 8);
        scan(d, n, capacity, 0);
        if (words[0] > capacity) {
            // More targets than the candidates hold within the slack of the
            // nearest (e.g. a dense cluster seen from far away: its extent is
            // below e, so float cannot order its points): the host measures
            // every target in double (host arrays; device views cannot).
            if (d.tPts.onDevice()) return false;
            const core::PointAt query = [&d](uint64_t i) { return d.qPts.original(uint32_t(i)); };
            const core::PointAt target = [&d](uint64_t i) { return d.tPts.original(uint32_t(i)); };
            return core::hostBruteForce(query, target, d.T.n, m_ws.threads)(batch);
        }
    }
    const uint32_t count = words[0];
    std::vector<std::vector<uint64_t>> lists(n);
    std::vector<uint32_t> targets;
    for (uint32_t j = 0; j < count; ++j) {
        const uint32_t k = words[2 + 2 * j], t = words[3 + 2 * j];
        if (k >= n || t >= d.T.n) return false;
        lists[k].push_back(t);
        targets.push_back(t);
    }
    std::vector<uint32_t> queries;
    for (const core::BandNearest& b : batch) queries.push_back(uint32_t(b.query));
    m_check.fetchPoints(d, queries, targets);
    for (uint32_t k = 0; k < n; ++k) {
        const glm::dvec3 q = d.qPts.original(uint32_t(batch[k].query));
        for (uint64_t t : lists[k]) batch[k].offer(t, core::exactDistance(q, d.tPts.original(uint32_t(t))));
        band.candidates.emplace_back(batch[k].query, std::move(lists[k]));
    }
    return true;
}

}  // namespace rthdist::gpu_algo
