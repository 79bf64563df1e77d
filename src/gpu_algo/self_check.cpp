#include "gpu_algo/self_check.hpp"

#include <bit>
#include <cmath>

namespace rthdist::gpu_algo {

namespace {

float packedDist2(uint64_t packed) { return std::bit_cast<float>(uint32_t(packed >> 32)); }

// The shaders' dist2 (common.glsl): float differences, squares summed left
// to right, no fused multiply-add.
float shaderDist2(const glm::vec3& a, const glm::vec3& b) {
    const volatile float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
    const volatile float xx = dx * dx, yy = dy * dy, zz = dz * dz;
    const volatile float xy = xx + yy;
    return xy + zz;
}

bool sameFloat(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }

std::string describe(const SampledQuery& s) { return "query slot " + std::to_string(s.slot); }

std::string checkOne(const SampledQuery& s, const SetPoints& qPts, const SetPoints& tPts, float maxD2,
                     bool perPoint, float killFloor2) {
    const uint32_t qi = std::bit_cast<uint32_t>(s.sorted[3]);
    if (qi >= qPts.size())
        return describe(s) + " names query " + std::to_string(qi) + " of " + std::to_string(qPts.size());
    const glm::vec3 q = qPts.searched(qi);
    if (!sameFloat(q.x, s.sorted[0]) || !sameFloat(q.y, s.sorted[1]) || !sameFloat(q.z, s.sorted[2]))
        return describe(s) + " holds coordinates that are not query " + std::to_string(qi) + "'s";
    const bool belowFloor = perPoint && s.state.status == RTHDIST_DEAD;
    const bool settled = s.state.status == RTHDIST_EXACT ||
                         (s.state.status == RTHDIST_DEAD && (!perPoint || killFloor2 > 0.0f));
    if (!settled) return describe(s) + " ended with status " + std::to_string(s.state.status);
    const uint32_t ti = uint32_t(s.state.best & 0xffffffffu);
    if (ti >= tPts.size())
        return describe(s) + " names target " + std::to_string(ti) + " of " + std::to_string(tPts.size());
    const float stored = packedDist2(s.state.best);
    const float recomputed = shaderDist2(q, tPts.searched(ti));
    // Equal bit for bit where the driver rounds as the host does; a few ulps
    // of slack for drivers that reassociate the sum.
    if (!(std::fabs(stored - recomputed) <= 4e-7f * std::fabs(recomputed) + 1e-37f))
        return describe(s) + ": squared distance " + std::to_string(stored) + " on the device, " +
               std::to_string(recomputed) + " from the points it names";
    if (belowFloor && !(stored < killFloor2))
        return describe(s) + ": stopped at distance^2 " + std::to_string(stored) + ", not below the floor " +
               std::to_string(killFloor2);
    if (!belowFloor && !(stored <= maxD2))
        return describe(s) + ": distance^2 " + std::to_string(stored) + " above the maximum " +
               std::to_string(maxD2);
    return "";
}

}  // namespace

std::vector<uint32_t> sampleSlots(uint32_t n, uint32_t count) {
    std::vector<uint32_t> slots;
    if (n == 0 || count == 0) return slots;
    if (n <= count) {
        for (uint32_t i = 0; i < n; ++i) slots.push_back(i);
        return slots;
    }
    for (uint32_t k = 0; k < count; ++k)
        slots.push_back(uint32_t(uint64_t(n - 1) * k / std::max<uint32_t>(1, count - 1)));
    return slots;
}

std::string indexCheckFailure(uint64_t n, uint64_t badRecords, uint64_t indexSum, uint64_t expectedSum,
                              uint64_t cells, uint64_t cellCapacity) {
    if (badRecords != 0)
        return std::to_string(badRecords) + " of " + std::to_string(n) +
               " sorted points are off their cell or order";
    if (indexSum != expectedSum)
        return "the sorted points are not a permutation of the input (index sum " + std::to_string(indexSum) +
               ", expected " + std::to_string(expectedSum) + ")";
    if (cells == 0 || cells > cellCapacity)
        return std::to_string(cells) + " cells written, capacity " + std::to_string(cellCapacity);
    return "";
}

std::string sampledQueryFailure(std::span<const SampledQuery> samples, const SetPoints& qPts,
                                const SetPoints& tPts, uint64_t maxPacked, bool perPoint, float killFloor2) {
    const float maxD2 = packedDist2(maxPacked);
    const bool floor = perPoint && killFloor2 > 0.0f;
    // With a floor the last sample (the maximum's slot) may be no query's
    // maximum at all: every query of the call may lie below the floor.
    for (size_t k = 0; k + (floor ? 1 : 0) < samples.size(); ++k) {
        std::string why = checkOne(samples[k], qPts, tPts, maxD2, perPoint, killFloor2);
        if (!why.empty()) return why;
    }
    if (!samples.empty() && !floor) {
        const SampledQuery& witness = samples.back();
        if (witness.slot != uint32_t(maxPacked & 0xffffffffu) ||
            !sameFloat(packedDist2(witness.state.best), maxD2))
            return "the witness (" + describe(witness) + ") does not hold the maximum";
    }
    return "";
}

std::string witnessFailure(double distance, uint64_t maxPacked, double lowerBound) {
    const double device = std::sqrt(double(packedDist2(maxPacked)));
    // Float squared distances carry a few ulps (2^-24 relative) of rounding;
    // below 2^-60 (subnormal squares) only the absolute slack counts.
    if (!(std::fabs(distance - device) <= 1e-6 * std::max(distance, device) + 0x1p-60))
        return "the witness pair is " + std::to_string(distance) + " apart, the device's maximum is " +
               std::to_string(device);
    if (distance < lowerBound * (1.0 - 1e-5))
        return "h = " + std::to_string(distance) + " lies below its lower bound " +
               std::to_string(lowerBound);
    return "";
}

}  // namespace rthdist::gpu_algo
