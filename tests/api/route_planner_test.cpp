// The route table (src/api/route_planner.hpp) without a device: every route
// from the shapes, options, budgets and backend capabilities that lead to it,
// and the edges between neighbouring routes.
#include <gtest/gtest.h>

#include <cstdint>

#include "api/route_planner.hpp"

namespace rthdist::api {
namespace {

// A GPU backend's capabilities (the limits of small_pairs.hpp on a GPU).
BackendCaps gpuCaps(int lanes = 1) {
    BackendCaps caps;
    caps.scan = core::ScanLimits{uint64_t(1) << 22, uint64_t(1) << 28};
    caps.ingestPoints = uint64_t(1) << 25;
    caps.lanes = lanes;
    caps.piecesOnOutOfMemory = true;
    return caps;
}

// The CPU backend's: no scan, no ingest, no device views.
BackendCaps cpuCaps() {
    BackendCaps caps;
    caps.noDeviceViews = "device views need a GPU backend";
    return caps;
}

MemoryBudget budgetOf(uint64_t points) {
    MemoryBudget budget;
    budget.bytes = points * kBytesPerPoint;
    budget.source = "test";
    return budget;
}

PairShape hostViews(uint64_t a, uint64_t b, bool packedFloat = true) {
    PairShape s;
    s.input = PairShape::Input::kHostViews;
    s.a = a;
    s.b = b;
    s.packedFloat = packedFloat;
    return s;
}

PairShape preparedSets(uint64_t a, uint64_t b) {
    PairShape s;
    s.input = PairShape::Input::kPreparedSets;
    s.a = a;
    s.b = b;
    s.oneOrigin = true;
    s.oneScale = true;
    return s;
}

PairShape deviceViews(uint64_t a, uint64_t b) {
    PairShape s;
    s.input = PairShape::Input::kDeviceViews;
    s.a = a;
    s.b = b;
    return s;
}

constexpr uint64_t kLarge = 1'000'000;  // past the scan's work limit, within the ingest's

TEST(RoutePlanner, SmallHostPairIsScannedWhole) {
    const Plan plan = planRoute(hostViews(1000, 2000), CallOptions{}, MemoryBudget{}, gpuCaps());
    EXPECT_EQ(plan.route, Route::kSmallPairScan);
    EXPECT_TRUE(plan.piecesOnOutOfMemory);
}

TEST(RoutePlanner, ExplicitBitsAskForTheIndex) {
    CallOptions call;
    call.bits = 6;
    EXPECT_EQ(planRoute(hostViews(1000, 2000), call, MemoryBudget{}, gpuCaps()).route, Route::kDeviceIngest);
    EXPECT_EQ(planRoute(hostViews(1000, 2000, false), call, MemoryBudget{}, gpuCaps()).route,
              Route::kOneCall);
}

TEST(RoutePlanner, PackedFloatsAreIngested) {
    EXPECT_EQ(planRoute(hostViews(kLarge, kLarge), CallOptions{}, MemoryBudget{}, gpuCaps()).route,
              Route::kDeviceIngest);
}

TEST(RoutePlanner, IngestNeedsPackedFloatsSizeAndBudget) {
    const BackendCaps caps = gpuCaps();
    // Doubles (or strided views) are checked and framed on the host.
    EXPECT_EQ(planRoute(hostViews(kLarge, kLarge, false), CallOptions{}, MemoryBudget{}, caps).route,
              Route::kOneCall);
    // Past the ingest's size, one call of host staging.
    const uint64_t half = caps.ingestPoints / 2;
    EXPECT_EQ(planRoute(hostViews(half, half), CallOptions{}, MemoryBudget{}, caps).route,
              Route::kDeviceIngest);
    EXPECT_EQ(planRoute(hostViews(half, half + 1), CallOptions{}, MemoryBudget{}, caps).route,
              Route::kOneCall);
    // Past the budget: pieces, never the ingest.
    EXPECT_EQ(planRoute(hostViews(kLarge, kLarge), CallOptions{}, budgetOf(kLarge), caps).route,
              Route::kPieces);
}

TEST(RoutePlanner, OneCallOnTheCpuBackend) {
    const Plan plan = planRoute(hostViews(1000, 2000), CallOptions{}, MemoryBudget{}, cpuCaps());
    EXPECT_EQ(plan.route, Route::kOneCall);
    EXPECT_FALSE(plan.piecesOnOutOfMemory);  // a caller's budget, or none
    EXPECT_EQ(planRoute(hostViews(kLarge, kLarge), CallOptions{}, MemoryBudget{}, cpuCaps()).route,
              Route::kOneCall);
}

TEST(RoutePlanner, PastTheBudgetInPieces) {
    for (const BackendCaps& caps : {cpuCaps(), gpuCaps()}) {
        const Plan plan = planRoute(hostViews(5000, 6000, false), CallOptions{}, budgetOf(10000), caps);
        EXPECT_EQ(plan.route, Route::kPieces);
        EXPECT_EQ(plan.pieces.bytes, budgetOf(10000).bytes);
        EXPECT_EQ(plan.pieces.maxPiecePoints, UINT64_MAX);
    }
    // Exactly the budget: one call.
    EXPECT_EQ(planRoute(hostViews(4000, 6000, false), CallOptions{}, budgetOf(10000), cpuCaps()).route,
              Route::kOneCall);
}

TEST(RoutePlanner, SetsPastThe32BitLimitGoInPieces) {
    const Plan plan =
        planRoute(hostViews(kMaxCallPoints + 1, 10, false), CallOptions{}, MemoryBudget{}, cpuCaps());
    EXPECT_EQ(plan.route, Route::kPieces);
}

TEST(RoutePlanner, SeveralDevicesTakeAShareOfTheQueriesWithAllTheTargets) {
    MemoryBudget budget = budgetOf(10000);
    budget.maxPiecePoints = 3000;
    // Each device's share (half the queries and all the targets) fits: targets whole.
    const Plan plan = planRoute(hostViews(8000, 4000, false), CallOptions{}, budget, gpuCaps(2));
    EXPECT_EQ(plan.route, Route::kSeveralDevices);
    EXPECT_EQ(plan.pieces.maxPiecePoints, UINT64_MAX);
    EXPECT_EQ(plan.pieces.bytes, budget.bytes);
    // A share that does not fit: pieces spread over the devices.
    const Plan pieces = planRoute(hostViews(30000, 30000, false), CallOptions{}, budget, gpuCaps(2));
    EXPECT_EQ(pieces.route, Route::kPieces);
    EXPECT_EQ(pieces.pieces.maxPiecePoints, 3000u);
    // A pair that fits stays on one device.
    CallOptions indexed;
    indexed.bits = 5;  // not scanned whole
    EXPECT_EQ(planRoute(hostViews(4000, 5000, false), indexed, budget, gpuCaps(2)).route, Route::kOneCall);
}

TEST(RoutePlanner, SmallPiecesAreScannedWhole) {
    EXPECT_EQ(planFramedCall(500, 700, CallOptions{}, MemoryBudget{}, gpuCaps()).route,
              Route::kSmallPairScan);
    EXPECT_EQ(planFramedCall(500, 700, CallOptions{}, MemoryBudget{}, cpuCaps()).route, Route::kOneCall);
    EXPECT_EQ(planFramedCall(kLarge, kLarge, CallOptions{}, MemoryBudget{}, gpuCaps()).route,
              Route::kOneCall);
}

TEST(RoutePlanner, ScanLimitsBothDirections) {
    BackendCaps caps = gpuCaps();
    caps.scan.maxWork = 1000;
    EXPECT_EQ(planFramedCall(10, 100, CallOptions{}, MemoryBudget{}, caps).route, Route::kSmallPairScan);
    EXPECT_EQ(planFramedCall(10, 101, CallOptions{}, MemoryBudget{}, caps).route, Route::kOneCall);
    caps.scan.maxWork = 0;  // Tuning::smallPairWork 0: none scanned whole
    EXPECT_EQ(planFramedCall(1, 1, CallOptions{}, MemoryBudget{}, caps).route, Route::kOneCall);
    caps.scan = core::ScanLimits{100, UINT64_MAX};
    EXPECT_EQ(planFramedCall(100, 1, CallOptions{}, MemoryBudget{}, caps).route, Route::kSmallPairScan);
    EXPECT_EQ(planFramedCall(101, 1, CallOptions{}, MemoryBudget{}, caps).route, Route::kOneCall);
}

TEST(RoutePlanner, PreparedSetsOfOneFrameUseTheirIndexes) {
    EXPECT_EQ(planRoute(preparedSets(kLarge, kLarge), CallOptions{}, MemoryBudget{}, gpuCaps()).route,
              Route::kPrepared);
    EXPECT_EQ(planRoute(preparedSets(100, 100), CallOptions{}, MemoryBudget{}, cpuCaps()).route,
              Route::kPrepared);
    // The budget does not split prepared sets.
    EXPECT_EQ(planRoute(preparedSets(kLarge, kLarge), CallOptions{}, budgetOf(10), cpuCaps()).route,
              Route::kPrepared);
}

TEST(RoutePlanner, SmallPreparedSetsAreScannedWhole) {
    PairShape s = preparedSets(1000, 1000);
    EXPECT_EQ(planRoute(s, CallOptions{}, MemoryBudget{}, gpuCaps()).route, Route::kSmallPairScan);
    // Scales may differ (the scan brings both to the smaller), the origin may not.
    s.oneScale = false;
    EXPECT_EQ(planRoute(s, CallOptions{}, MemoryBudget{}, gpuCaps()).route, Route::kSmallPairScan);
    s.oneOrigin = false;
    EXPECT_EQ(planRoute(s, CallOptions{}, MemoryBudget{}, gpuCaps()).route, Route::kReframe);
    // Bits were the sets' own choice: a prepared pair is scanned whatever the call's bits.
    CallOptions call;
    call.bits = 5;
    EXPECT_EQ(planRoute(preparedSets(1000, 1000), call, MemoryBudget{}, gpuCaps()).route,
              Route::kSmallPairScan);
}

TEST(RoutePlanner, PreparedSetsOfDifferentFramesAreReframed) {
    PairShape s = preparedSets(kLarge, kLarge);
    s.oneScale = false;
    EXPECT_EQ(planRoute(s, CallOptions{}, MemoryBudget{}, gpuCaps()).route, Route::kReframe);
    s = preparedSets(100, 100);
    s.oneOrigin = false;
    EXPECT_EQ(planRoute(s, CallOptions{}, MemoryBudget{}, cpuCaps()).route, Route::kReframe);
}

TEST(RoutePlanner, PreparedSetsOfAnotherEngineAreRefused) {
    PairShape s = preparedSets(100, 100);
    s.sameEngine = false;
    const Plan plan = planRoute(s, CallOptions{}, MemoryBudget{}, gpuCaps());
    EXPECT_EQ(plan.route, Route::kRefused);
    EXPECT_EQ(plan.code, ErrorCode::kInvalidArgument);
    EXPECT_NE(plan.reason.find("another Engine"), std::string::npos);
}

TEST(RoutePlanner, DeviceViewSetsMeetOnlySetsOfTheirFrame) {
    PairShape s = preparedSets(100, 100);
    s.onDevice = true;
    // Never scanned whole (no host copy): their own indexes.
    EXPECT_EQ(planRoute(s, CallOptions{}, MemoryBudget{}, gpuCaps()).route, Route::kPrepared);
    for (int k = 0; k < 3; ++k) {
        PairShape bad = s;
        if (k == 0) bad.oneOrigin = false;
        if (k == 1) bad.oneScale = false;
        if (k == 2) bad.hostCopies = true;
        const Plan plan = planRoute(bad, CallOptions{}, MemoryBudget{}, gpuCaps());
        EXPECT_EQ(plan.route, Route::kRefused) << k;
        EXPECT_NE(plan.reason.find("keeps no host copy"), std::string::npos) << k;
    }
}

TEST(RoutePlanner, DeviceViewsRunOnTheDevice) {
    EXPECT_EQ(planRoute(deviceViews(kLarge, kLarge), CallOptions{}, MemoryBudget{}, gpuCaps()).route,
              Route::kDeviceViews);
    // Small ones too: the host cannot read them to scan them.
    EXPECT_EQ(planRoute(deviceViews(10, 10), CallOptions{}, MemoryBudget{}, gpuCaps()).route,
              Route::kDeviceViews);
}

TEST(RoutePlanner, DeviceViewsAreRefusedWithoutSupportOrPastTheBudget) {
    const Plan cpu = planRoute(deviceViews(10, 10), CallOptions{}, MemoryBudget{}, cpuCaps());
    EXPECT_EQ(cpu.route, Route::kRefused);
    EXPECT_EQ(cpu.code, ErrorCode::kInvalidArgument);
    EXPECT_EQ(cpu.reason, cpuCaps().noDeviceViews);
    const Plan big = planRoute(deviceViews(6000, 6000), CallOptions{}, budgetOf(10000), gpuCaps());
    EXPECT_EQ(big.route, Route::kRefused);
    EXPECT_EQ(big.code, ErrorCode::kOutOfMemory);
    EXPECT_NE(big.reason.find("not split into pieces"), std::string::npos);
}

TEST(RoutePlanner, SurfacesRunOnTheBackendNamed) {
    EXPECT_EQ(planSurfaceRoute(Backend::kCpu).route, Route::kSurfaceCpu);
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto).route, Route::kSurfaceCpu);
    // (Per-point distances too: the GPU route gives them within its tolerance.)
    for (Backend gpu : {Backend::kRayQuery, Backend::kRtPipeline})
        EXPECT_EQ(planSurfaceRoute(gpu).route, Route::kSurfaceGpu);
    // A named backend is never exchanged, whatever the call's shape.
    SurfaceShape few;
    few.queries = 10;
    few.triangles = 1000000;
    few.keptDevice = true;
    few.perPoint = true;
    EXPECT_EQ(planSurfaceRoute(Backend::kRtPipeline, few).route, Route::kSurfaceGpu);
    SurfaceShape many;
    many.queries = 10000000;
    many.triangles = 10;
    EXPECT_EQ(planSurfaceRoute(Backend::kCpu, many).route, Route::kSurfaceCpu);
}

TEST(RoutePlanner, AnAutoEngineWithADeviceSearchesManyQueriesOnIt) {
    SurfaceShape shape;
    shape.keptDevice = true;
    shape.queries = kAutoSurfaceGpuQueries;
    shape.triangles = kAutoSurfaceGpuQueries;
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto, shape).route, Route::kSurfaceGpu);
    // Fewer queries than triangles: the CPU backend's kept tree.
    shape.triangles = kAutoSurfaceGpuQueries + 1;
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto, shape).route, Route::kSurfaceCpu);
    // Fewer than kAutoSurfaceGpuQueries queries, however few the triangles.
    shape.queries = kAutoSurfaceGpuQueries - 1;
    shape.triangles = 1;
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto, shape).route, Route::kSurfaceCpu);
    // Per-point distances stay on the CPU backend (exact entries, one contract for auto).
    shape.queries = 1000000;
    shape.perPoint = true;
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto, shape).route, Route::kSurfaceCpu);
    // No kept device (one-shot, or an Engine on the CPU backend): the CPU backend.
    shape.perPoint = false;
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto, shape).route, Route::kSurfaceGpu);
    shape.keptDevice = false;
    EXPECT_EQ(planSurfaceRoute(Backend::kAuto, shape).route, Route::kSurfaceCpu);
}

TEST(RoutePlanner, SurfacePairsRunOnTheBackendNamed) {
    EXPECT_EQ(planSurfacePairRoute(Backend::kCpu).route, Route::kSurfaceCpu);
    EXPECT_EQ(planSurfacePairRoute(Backend::kAuto).route, Route::kSurfaceCpu);
    // A GPU backend the caller named runs on the device, never on the CPU in its place.
    for (Backend gpu : {Backend::kRayQuery, Backend::kRtPipeline})
        EXPECT_EQ(planSurfacePairRoute(gpu).route, Route::kSurfaceGpu);
}

TEST(RoutePlanner, SmallOneShotPairsUnderAutoRunOnTheCpu) {
    const uint64_t perThread = kOneShotCpuPointsPerThread;
    // At most kOneShotCpuPointsPerThread (2^18) points a host thread: the CPU backend.
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, 1, 1), Backend::kCpu);
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, perThread, 1), Backend::kCpu);
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, 16 * perThread, 16), Backend::kCpu);
    // One point more, or fewer threads: as asked.
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, perThread + 1, 1), Backend::kAuto);
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, 16 * perThread, 15), Backend::kAuto);
    // Threads past kOneShotCpuThreads (32) do not raise the bound.
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, 32 * perThread, 128), Backend::kCpu);
    EXPECT_EQ(oneShotBackend(Backend::kAuto, false, 32 * perThread + 1, 128), Backend::kAuto);
    // A device named, or a backend named: never chosen by size.
    EXPECT_EQ(oneShotBackend(Backend::kAuto, true, 1, 16), Backend::kAuto);
    for (Backend named : {Backend::kRayQuery, Backend::kRtPipeline, Backend::kCpu})
        EXPECT_EQ(oneShotBackend(named, false, 1, 16), named);
}

TEST(RoutePlanner, OneShotBackendForReadsTheOptions) {
    EngineOptions o;
    o.threads = 2;
    EXPECT_EQ(oneShotBackendFor(2 * kOneShotCpuPointsPerThread, o), Backend::kCpu);
    EXPECT_EQ(oneShotBackendFor(2 * kOneShotCpuPointsPerThread + 1, o), Backend::kAuto);
    o.deviceIndex = 0;  // a device named keeps the Vulkan path
    EXPECT_EQ(oneShotBackendFor(1, o), Backend::kAuto);
    o.deviceIndex = -1;
    o.devices = {0};
    EXPECT_EQ(oneShotBackendFor(1, o), Backend::kAuto);
    o.devices.clear();
    o.validation = true;  // the Vulkan validation layer asked for: the Vulkan path
    EXPECT_EQ(oneShotBackendFor(1, o), Backend::kAuto);
    o.validation = false;
    EXPECT_EQ(oneShotBackendFor(1, o), Backend::kCpu);
    o.backend = Backend::kRtPipeline;
    EXPECT_EQ(oneShotBackendFor(1, o), Backend::kRtPipeline);
}

TEST(RoutePlanner, EveryRouteHasAName) {
    for (Route r : {Route::kRefused, Route::kSmallPairScan, Route::kDeviceIngest, Route::kOneCall,
                    Route::kSeveralDevices, Route::kPieces, Route::kReframe, Route::kPrepared,
                    Route::kDeviceViews, Route::kSurfaceCpu, Route::kSurfaceGpu})
        EXPECT_STRNE(routeName(r), "?");
}

}  // namespace
}  // namespace rthdist::api
