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

}  // namespace

void CertificatePass::startDirection(DirectionRun& d, size_t direction) {
    d.slack =
        core::searchSlack(std::max(core::largestMagnitude(d.Q.bounds), core::largestMagnitude(d.T.bounds)));
    DirectionBuffers& memory = m_ws.scratch.directions[direction];
    d.band =
        &m_ws.grow(memory.band, 8 + VkDeviceSize(kBandCapacity) * 8, d.name() + ".band", MemoryKind::kHost);
    std::memset(d.band->mapped(), 0, 8);
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
    if (count > kBandCapacity) {
        band.failure = "the band of " + std::to_string(count) + " queries within the rounding slack of the " +
                       "maximum is past its capacity of " + std::to_string(kBandCapacity);
    } else {
        std::vector<uint32_t> queries(count), targets(count);
        band.queries.resize(count);
        for (uint32_t k = 0; k < count; ++k) {
            queries[k] = words[2 + 2 * k];
            targets[k] = words[3 + 2 * k];
            band.queries[k] = {queries[k], targets[k]};
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
    return band;
}

bool CertificatePass::bruteForce(DirectionRun& d, core::DirectionBand& band,
                                 std::span<core::BandNearest> batch) {
    if (batch.size() > RTHDIST_CERT_ENTRIES) return false;
    Buffer& entries = m_ws.grow(m_ws.scratch.certificate.entries, RTHDIST_CERT_ENTRIES * 16, "cert.entries",
                                MemoryKind::kHost);
    Buffer& found = m_ws.grow(m_ws.scratch.certificate.candidates, 8 + VkDeviceSize(kCandidateCapacity) * 8,
                              "cert.candidates", MemoryKind::kHost);
    auto* e = static_cast<float*>(entries.mapped());
    for (size_t k = 0; k < batch.size(); ++k) {
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
    std::memset(found.mapped(), 0, 8);
    const sh::CertScanPush push{d.T.sorted->address(),
                                entries.address(),
                                found.address(),
                                d.T.n,
                                uint32_t(batch.size()),
                                kCandidateCapacity,
                                0u};
    const uint32_t groups = std::max<uint32_t>(
        1, std::min({gpu::groupsFor(d.T.n, RTHDIST_WG), kCertGroups, m_ws.ctx.limits().maxGroupsX}));
    VkCommandBuffer cmd = m_ws.ctx.begin();
    m_ws.pipelines.cmdDispatch(cmd, Kernel::kCertScan, &push, sizeof(push), groups);
    gpu::cmdHostReadBarrier(cmd);
    m_ws.ctx.submitAndWait(cmd);
    m_ws.timings->gpuCertificate += m_ws.ctx.lastGpuMs();
    const auto* words = static_cast<const uint32_t*>(found.mapped());
    const uint32_t count = words[0];
    if (count > kCandidateCapacity) return false;
    std::vector<std::vector<uint64_t>> lists(batch.size());
    std::vector<uint32_t> targets;
    for (uint32_t j = 0; j < count; ++j) {
        const uint32_t k = words[2 + 2 * j], t = words[3 + 2 * j];
        if (k >= batch.size() || t >= d.T.n) return false;
        lists[k].push_back(t);
        targets.push_back(t);
    }
    std::vector<uint32_t> queries;
    for (const core::BandNearest& b : batch) queries.push_back(uint32_t(b.query));
    m_check.fetchPoints(d, queries, targets);
    for (size_t k = 0; k < batch.size(); ++k) {
        const glm::dvec3 q = d.qPts.original(uint32_t(batch[k].query));
        for (uint64_t t : lists[k]) batch[k].offer(t, core::exactDistance(q, d.tPts.original(uint32_t(t))));
        band.candidates.emplace_back(batch[k].query, std::move(lists[k]));
    }
    return true;
}

}  // namespace rthdist::gpu_algo
