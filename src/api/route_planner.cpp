#include "api/route_planner.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/input_limits.hpp"

namespace rthdist::api {

namespace {

Plan refused(ErrorCode code, std::string reason) {
    Plan plan;
    plan.route = Route::kRefused;
    plan.code = code;
    plan.reason = std::move(reason);
    return plan;
}

Plan routed(Route route) {
    Plan plan;
    plan.route = route;
    return plan;
}

// A pair past one call's budget: in pieces. A pair that fits stays on one
// device: split over several, every device would index all the targets and
// the host stages each set once per device (H200s, 300M x 300M points: 5.8 s
// on one, 20.7 s on two; README "Several GPUs"). With several devices, a pair
// whose every device's share (its queries and all targets) fits the bytes
// runs with the targets whole, past the pieces' maxMemoryAllocationSize
// bound, as one device tries the whole pair (a device short of memory then
// halves the budget: out_of_core.hpp).
Plan inPieces(uint64_t a, uint64_t b, const MemoryBudget& budget, const BackendCaps& caps) {
    const auto lanes = uint64_t(caps.lanes < 1 ? 1 : caps.lanes);
    const bool sharesFit =
        fitsOneCall(budget, (a + lanes - 1) / lanes, b) && fitsOneCall(budget, (b + lanes - 1) / lanes, a);
    Plan plan = routed(lanes > 1 && sharesFit ? Route::kSeveralDevices : Route::kPieces);
    plan.pieces = budget;
    if (plan.route == Route::kSeveralDevices) plan.pieces.maxPiecePoints = UINT64_MAX;
    return plan;
}

// Small pairs are scanned whole with the automatic bit count only: a call
// that sets bits asks for the index.
bool scannedWhole(uint64_t a, uint64_t b, const CallOptions& call, const BackendCaps& caps) {
    return call.bits == 0 && caps.scan.takesPair(a, b);
}

Plan planHostViews(const PairShape& shape, const CallOptions& call, const MemoryBudget& budget,
                   const BackendCaps& caps) {
    // Small pairs are scanned whole from the host's float copies: the points
    // are checked on the host, not ingested.
    if (shape.packedFloat && !scannedWhole(shape.a, shape.b, call, caps) && caps.ingestPoints > 0 &&
        shape.a + shape.b <= caps.ingestPoints && fitsOneCall(budget, shape.a, shape.b))
        return routed(Route::kDeviceIngest);
    return planFramedCall(shape.a, shape.b, call, budget, caps);
}

Plan planPreparedSets(const PairShape& shape, const BackendCaps& caps) {
    if (!shape.sameEngine)
        return refused(ErrorCode::kInvalidArgument, "a prepared set belongs to another Engine");
    const bool oneFrame = shape.oneOrigin && shape.oneScale;
    if (shape.onDevice && (!oneFrame || shape.hostCopies)) {
        return refused(
            ErrorCode::kInvalidArgument,
            "a set prepared from a device view keeps no host copy: it meets only sets of its frame "
            "(prepare both with one PrepareOptions::origin) whose coordinates are float values or "
            "also device views");
    }
    // One origin suffices for the scan: it brings both scales to the smaller, exactly.
    if (!shape.onDevice && shape.oneOrigin && caps.scan.takesPair(shape.a, shape.b))
        return routed(Route::kSmallPairScan);
    return routed(oneFrame ? Route::kPrepared : Route::kReframe);
}

Plan planDeviceViews(const PairShape& shape, const MemoryBudget& budget, const BackendCaps& caps) {
    if (!caps.noDeviceViews.empty()) return refused(ErrorCode::kInvalidArgument, caps.noDeviceViews);
    if (!fitsOneCall(budget, shape.a, shape.b)) {
        return refused(ErrorCode::kOutOfMemory, "device views of " + std::to_string(shape.a) + " and " +
                                                    std::to_string(shape.b) +
                                                    " points do not fit the memory budget of one call "
                                                    "(device input is not split into pieces)");
    }
    return routed(Route::kDeviceViews);
}

}  // namespace

const char* routeName(Route route) {
    switch (route) {
        case Route::kRefused: return "refused";
        case Route::kSmallPairScan: return "small-pair scan";
        case Route::kDeviceIngest: return "device ingest";
        case Route::kOneCall: return "one call";
        case Route::kSeveralDevices: return "several devices";
        case Route::kPieces: return "pieces";
        case Route::kReframe: return "reframe";
        case Route::kPrepared: return "prepared";
        case Route::kDeviceViews: return "device views";
        case Route::kSurfaceCpu: return "surface (cpu)";
        case Route::kSurfaceGpu: return "surface (gpu)";
    }
    return "?";
}

bool autoSurfaceOnGpu(const SurfaceShape& shape) {
    return shape.keptDevice && !shape.perPoint && shape.queries >= kAutoSurfaceGpuQueries &&
           shape.queries >= shape.triangles;
}

Plan planSurfaceRoute(Backend requested, const SurfaceShape& shape) {
    if (requested == Backend::kCpu) return routed(Route::kSurfaceCpu);
    if (requested == Backend::kAuto)
        return routed(autoSurfaceOnGpu(shape) ? Route::kSurfaceGpu : Route::kSurfaceCpu);
    return routed(Route::kSurfaceGpu);
}

Plan planSurfacePairRoute(Backend requested) {
    if (requested == Backend::kCpu || requested == Backend::kAuto) return routed(Route::kSurfaceCpu);
    return routed(Route::kSurfaceGpu);
}

bool narrowingPays(double wholeMagnitude, double narrowedMagnitude) {
    // A narrowed frame below float32's normals cannot be searched
    // (core::checkShiftedExtent refuses it): the pair stays whole.
    if (narrowedMagnitude > 0.0 && narrowedMagnitude < core::kMinShifted) return false;
    return std::ldexp(narrowedMagnitude, kNarrowGainLog2) <= wholeMagnitude;
}

Backend oneShotBackend(Backend requested, bool vulkanAsked, uint64_t points, int threads) {
    if (requested != Backend::kAuto || vulkanAsked || threads < 1) return requested;
    const auto counted = uint64_t(std::min(threads, kOneShotCpuThreads));
    return points <= kOneShotCpuPointsPerThread * counted ? Backend::kCpu : requested;
}

Plan planFramedCall(uint64_t a, uint64_t b, const CallOptions& call, const MemoryBudget& budget,
                    const BackendCaps& caps) {
    if (!fitsOneCall(budget, a, b)) return inPieces(a, b, budget, caps);
    Plan plan = routed(scannedWhole(a, b, call, caps) ? Route::kSmallPairScan : Route::kOneCall);
    plan.piecesOnOutOfMemory = caps.piecesOnOutOfMemory;
    plan.pieces = inPieces(a, b, budget, caps).pieces;  // after a kOutOfMemory
    return plan;
}

Plan planRoute(const PairShape& shape, const CallOptions& call, const MemoryBudget& budget,
               const BackendCaps& caps) {
    switch (shape.input) {
        case PairShape::Input::kHostViews: return planHostViews(shape, call, budget, caps);
        case PairShape::Input::kPreparedSets: return planPreparedSets(shape, caps);
        case PairShape::Input::kDeviceViews: return planDeviceViews(shape, budget, caps);
    }
    return refused(ErrorCode::kInternal, "unknown input");
}

}  // namespace rthdist::api
