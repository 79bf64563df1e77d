#include "gpu_algo/gpu_hausdorff.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/index_space.hpp"
#include "core/input_frame.hpp"
#include "core/parallel.hpp"
#include "core/search_mutant.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/candidate_search.hpp"
#include "gpu_algo/certificate_pass.hpp"
#include "gpu_algo/device_input.hpp"
#include "gpu_algo/direction.hpp"
#include "gpu_algo/index_build.hpp"
#include "gpu_algo/neighbourhood_pass.hpp"
#include "gpu_algo/per_point_hand_back.hpp"
#include "gpu_algo/point_index.hpp"
#include "gpu_algo/query_check.hpp"
#include "gpu_algo/refinement.hpp"
#include "gpu_algo/self_check.hpp"
#include "gpu_algo/small_pairs.hpp"
#include "gpu_algo/workspace.hpp"

namespace rthdist::gpu_algo {

using core::exactScale;
using core::largestMagnitude;

static_assert(sizeof(sh::QueryState) == 16 && offsetof(sh::QueryState, rLo) == 8);
static_assert(sizeof(sh::SearchPush) <= 128 && sizeof(sh::CullPush) <= 128 && sizeof(sh::RefinePush) <= 128);

namespace {

// One-shot sets of at most this many points together are uploaded and
// indexed in one submission, each with scratch buffers of its own.
constexpr size_t kFusedBuildPoints = size_t(1) << 25;

// Float copies of the points multiplied by a power of two in double (exact:
// the rule keeps every product a normal float or zero).
std::vector<glm::vec3> scaledCopy(std::span<const glm::vec3> pts, double scale, int threads) {
    std::vector<glm::vec3> out(pts.size());
    threads = core::resolveThreads(threads, pts.size() / kHostChunk + 1);
    core::parallelChunks(pts.size(), kHostChunk, threads, [&](size_t begin, size_t end, int) {
        for (size_t i = begin; i < end; ++i) out[i] = core::scaled(pts[i], scale);
    });
    return out;
}

}  // namespace

// The stages on one workspace, and the calls that run them in order: a pair
// indexed (host staging or device ingest), both directions culled together,
// each direction's search and self-check, the result.
struct GpuHausdorff::State {
    State(gpu::Context& ctx, const std::string& cacheDir, int threads, const Tuning& tuning)
        : ws(ctx, cacheDir, threads, tuning),
          index(ws),
          check(ws),
          cull(ws, check),
          refine(ws),
          search(ws, index, refine, check),
          certificate(ws, check),
          deviceIngest(ws, index),
          smallPairs(ws),
          surface(ws) {}

    Workspace ws;
    PerPoint spare;   // recyclePerPoint: the next per-point result's h(A,B) arrays
    PerPoint spareB;  // and its h(B,A) arrays
    // Bit k: this call (or the call that failed last) has called
    // CallOptions::perPointReady for direction k (GpuHausdorff::handedBack).
    uint32_t handedBack = 0;
    IndexBuild index;
    QueryCheck check;
    NeighbourhoodPass cull;
    Refinement refine;
    CandidateSearch search;
    CertificatePass certificate;
    DeviceIngest deviceIngest;
    SmallPairScan smallPairs;
    SurfaceSearch surface;  // kept between calls: its buffers only grow

    // The search of a direction that has survivors, then its self-check
    // (in the search's last submission where it folds into it, else one
    // more); returns the checked witness.
    SampledQuery searchAndCheck(DirectionRun& d, uint32_t survivors, const CallOptions& options,
                                double progressFrom, double progressTo) {
        search.runSearch(d, survivors, options, progressFrom, progressTo);
        const auto t0 = Clock::now();
        if (!check.foldsIntoSearch(d)) {
            VkCommandBuffer cmd = ws.ctx.begin();
            check.cmdCheckQueries(cmd, d, CheckAt::kFinal);
            ws.ctx.submitAndWait(cmd);
        }
        SampledQuery witness = check.finishCheck(d);
        ws.timings->check += msSince(t0);
        return witness;
    }

    // Stages `input` (float, before the scale) as set `name` for an index
    // build in `scratch`: its index in the workspace's `shared` buffers
    // (one-shot) or, shared null, in buffers of its own (owned: a prepared
    // set). The host pass counts as upload time.
    void stageSet(DeviceSet& set, std::span<const glm::vec3> input, double scale, int bits,
                  const std::string& name, BuildScratch& scratch, SetBuffers* shared) {
        const auto t0 = Clock::now();
        set.input = input;
        set.scale = scale;
        if (scale != 1.0) set.scaledCopy = scaledCopy(input, scale, ws.threads);
        set.points = scale != 1.0 ? std::span<const glm::vec3>(set.scaledCopy) : input;
        set.place(name, scratch, shared);
        set.pts.useHost(set.points);
        index.stageIndex(set.ix, set.points, bits);
        ws.timings->upload += msSince(t0);
    }

    // One-shot H of two packed float host arrays through the ingest path:
    // one submission uploads and ingests both (and gathers the bit count's
    // samples on a device without shaderFloat64), the host reads their
    // bounds, chooses both grids (DeviceIngest::chooseGrids: one more
    // submission for the probe of the automatic bit count), and a last
    // submission builds both indexes.
    // kHostPath, having done nothing else, when the sets need the exact
    // power-of-two scale (index_space.hpp), which the host path applies;
    // kLeft when `leave` took the bounds and ended the call.
    enum class Ingested { kIndexed, kHostPath, kLeft };
    Ingested ingestPair(DeviceSet& da, DeviceSet& db, std::span<const glm::vec3> a,
                        std::span<const glm::vec3> b, const CallOptions& options,
                        const std::function<bool(const core::Bounds&, const core::Bounds&)>& leave) {
        const auto t0 = Clock::now();
        std::array<DeviceSet*, 2> sets = {&da, &db};
        std::array<std::span<const glm::vec3>, 2> inputs = {a, b};
        for (size_t k = 0; k < 2; ++k) {
            DeviceSet& set = *sets[k];
            set.input = set.points = inputs[k];
            set.pts.useHost(inputs[k]);
            set.place(k == 0 ? "A" : "B", ws.scratch.builds[k], &ws.oneShot[k]);
            index.stageSource(set.ix, inputs[k]);
        }
        VkCommandBuffer cmd = ws.ctx.begin();
        for (DeviceSet* set : sets) index.cmdUploadSource(cmd, set->ix);
        const uint32_t uploaded = ws.ctx.cmdMark(cmd);
        ws.barrier(cmd);
        for (size_t k = 0; k < 2; ++k) index.cmdIngest(cmd, sets[k]->ix, ws.blocks[k]);
        const std::array<PointIndex*, 2> indexes = {&da.ix, &db.ix};
        deviceIngest.cmdBitCountSamples(cmd, indexes, options.bits);
        ws.ctx.submitAndWait(cmd);
        ws.imports.clear();  // the device has read the caller's arrays
        const double uploadMs = ws.ctx.gpuMsBetween(0, uploaded);
        ws.timings->upload += msSince(t0) - (ws.ctx.lastGpuMs() - uploadMs);
        ws.timings->gpuUpload += uploadMs;
        ws.timings->gpuIndex += ws.ctx.lastGpuMs() - uploadMs;
        for (size_t k = 0; k < 2; ++k) index.finishIngest(sets[k]->ix, ws.blocks[k]);
        const double magnitude = std::max(largestMagnitude(da.ix.bounds), largestMagnitude(db.ix.bounds));
        if (exactScale(magnitude) != 1.0) return Ingested::kHostPath;
        if (leave && leave(da.ix.bounds, db.ix.bounds)) return Ingested::kLeft;
        const auto t1 = Clock::now();
        deviceIngest.chooseGrids(indexes, options.bits);
        ws.timings->index += msSince(t1);
        index.buildIndexes(std::array{&da.ix, &db.ix}, /*uploaded=*/true);
        return Ingested::kIndexed;
    }

    // One-shot H of two float sets through the host path: each staged by
    // the host (vec4 copy, bounds, bit count), uploaded and indexed. Small
    // sets: both in one submission (scratch of their own). Large ones: one
    // after the other in the same scratch (a submission is then cheap beside
    // the work, and the device holds one set's scratch, not two).
    void hostPair(std::span<const glm::vec3> a, std::span<const glm::vec3> b, double scale,
                  const CallOptions& options, HausdorffResult& res, const core::PerPointFloor& floor = {}) {
        DeviceSet da, db;
        const bool together = a.size() + b.size() <= kFusedBuildPoints;
        std::array<BuildScratch, 2>& builds = ws.scratch.builds;
        if (together) {
            stageSet(da, a, scale, options.bits, "A", builds[0], &ws.oneShot[0]);
            stageSet(db, b, scale, options.bits, "B", builds[1], &ws.oneShot[1]);
            reportProgress(options, "index", 0.05);
            index.buildIndexes(std::array{&da.ix, &db.ix});
        } else {
            // One after the other in one scratch, the larger set first: the
            // shared scratch is allocated once (device allocations cost ~20 ms
            // per GiB on an H200), not grown again for the second set.
            const bool bFirst = b.size() > a.size();
            DeviceSet& first = bFirst ? db : da;
            DeviceSet& second = bFirst ? da : db;
            stageSet(first, bFirst ? b : a, scale, options.bits, bFirst ? "B" : "A", builds[0],
                     &ws.oneShot[bFirst ? 1 : 0]);
            index.buildIndexes(std::array{&first.ix});
            reportProgress(options, "index", 0.05);
            stageSet(second, bFirst ? a : b, scale, options.bits, bFirst ? "A" : "B", builds[0],
                     &ws.oneShot[bFirst ? 0 : 1]);
            index.buildIndexes(std::array{&second.ix});
        }
        reportProgress(options, "index", 0.1);
        runPair(da, db, options, res, 0.1, floor);
    }

    // Device input: refuses a frame whose searched magnitudes need the exact
    // power-of-two scale (the host path applies it; vulkan_interop.hpp).
    static void requireUnitScale(double magnitude) {
        if (exactScale(magnitude) != 1.0)
            throw InputRejected{Error{ErrorCode::kInvalidArgument,
                                      "device input: searched coordinates of magnitude " +
                                          std::to_string(magnitude) +
                                          " need the exact power-of-two scale (past 2^40 or all below "
                                          "2^-40), which only the host-array path applies"}};
    }

    // Device input: both views ingested into da, db (one submission when
    // they fit kFusedBuildPoints together, else one after the other in one
    // scratch) and indexed. Double views first have their boxes reduced on
    // the device for the origin. Returns the origin.
    glm::dvec3 devicePair(DeviceSet& da, DeviceSet& db, const DeviceInput& a, const DeviceInput& b,
                          const CallOptions& options) {
        const std::array<DeviceInput, 2> views = {a, b};
        glm::dvec3 origin(0.0);
        const bool doubles = a.scalar == Scalar::kFloat64 || b.scalar == Scalar::kFloat64;
        if (doubles) {
            const std::array<std::string, 2> names = {"A", "B"};
            const std::array<core::SetSummary, 2> sums = deviceIngest.summarize(views, names);
            origin = core::searchOrigin(sums[0], sums[1]);
            requireUnitScale(
                std::max(core::searchMagnitude(sums[0], origin), core::searchMagnitude(sums[1], origin)));
        }
        const bool together = size_t(a.n) + b.n <= kFusedBuildPoints;
        da.place("A", ws.scratch.builds[0], &ws.oneShot[0]);
        db.place("B", ws.scratch.builds[together ? 1 : 0], &ws.oneShot[1]);
        if (together) {
            deviceIngest.ingest(std::array{&da.ix, &db.ix}, views, origin, options.bits, !doubles);
        } else {
            deviceIngest.ingest(std::array{&da.ix}, std::span(views).first(1), origin, options.bits,
                                !doubles);
        }
        if (!doubles)
            requireUnitScale(std::max(largestMagnitude(da.ix.bounds), largestMagnitude(db.ix.bounds)));
        if (together) {
            index.buildIndexes(std::array{&da.ix, &db.ix}, /*ingested=*/true);
        } else {
            index.buildIndexes(std::array{&da.ix}, true);
            deviceIngest.ingest(std::array{&db.ix}, std::span(views).last(1), origin, options.bits, false);
            if (!doubles) requireUnitScale(largestMagnitude(db.ix.bounds));
            index.buildIndexes(std::array{&db.ix}, true);
        }
        da.pts.useDevice(ws.ctx, a, origin, da.ix);
        db.pts.useDevice(ws.ctx, b, origin, db.ix);
        return origin;
    }

    // Device input prepared: the view ingested and indexed into buffers of
    // the set's own, with a copy of the view's bytes that its witnesses and
    // self-checks read from then on.
    void deviceSet(GpuHausdorff::PreparedDevice& out, const DeviceInput& view,
                   const std::optional<glm::dvec3>& wanted, int bits, const std::string& name) {
        DeviceSet& set = *out.set;
        set.place(name, ws.scratch.builds[0], nullptr);
        const bool isDouble = view.scalar == Scalar::kFloat64;
        if (isDouble) {
            const std::array<std::string, 1> names = {name};
            out.summary = deviceIngest.summarize(std::span(&view, 1), names)[0];
            out.origin = core::preparedOrigin(out.summary, wanted);
            requireUnitScale(core::searchMagnitude(out.summary, out.origin));
        }
        deviceIngest.ingest(std::array{&set.ix}, std::span(&view, 1), out.origin, bits, !isDouble);
        if (!isDouble) {
            out.summary.box = set.ix.bounds;  // float bounds: exact in double
            out.summary.floatExact = true;
            requireUnitScale(largestMagnitude(set.ix.bounds));
        }
        DeviceInput copy = view;
        const VkDeviceSize bytes = VkDeviceSize(view.n - 1) * view.stride + view.pointBytes();
        set.inputCopy = Buffer(ws.ctx, bytes, gpu::kStorageUsage, MemoryKind::kDevice);
        VkCommandBuffer cmd = ws.ctx.begin();
        const VkBufferCopy region{view.offset, 0, bytes};
        vkCmdCopyBuffer(cmd, view.buffer, set.inputCopy.handle(), 1, &region);
        ws.ctx.submitAndWait(cmd);
        copy.buffer = set.inputCopy.handle();
        copy.address = set.inputCopy.address();
        copy.offset = 0;
        index.buildIndexes(std::array{&set.ix}, /*ingested=*/true);
        set.own.releaseUnused(set.ix);
        set.pts.useDevice(ws.ctx, copy, out.origin, set.ix);
    }

    // H (or h) of two indexed sets of one scale into `res`; progress covers
    // [from, 1] of the call.
    // `floor`: honoured in per-point calls of nearest targets only (the
    // read-back's distances and restoreOriginal's need every query's); the
    // result then holds the per-point arrays and counters only.
    void runPair(DeviceSet& a, DeviceSet& b, const CallOptions& options, HausdorffResult& res, double from,
                 const core::PerPointFloor& given = {}) {
        const bool pp = options.perPointDistances;
        const core::PerPointFloor floor =
            pp && options.perPointNearestOnly && !options.perPointReady ? given : core::PerPointFloor{};
        if (pp) {  // filled whole: the read-back writes every entry
            res.aNearest = std::move(spare);
            if (!options.directedOnly) res.bNearest = std::move(spareB);
        }
        spare = spareB = PerPoint{};
        ws.recycleBuildScratch();  // every index of the call is built
        const double mid = options.directedOnly ? 1.0 : from + 0.5 * (1.0 - from);
        DirectionRun ab{a.ix, b.ix, a.pts, b.pts, ws.blocks[0], pp ? &res.aNearest : nullptr};
        DirectionRun ba{b.ix, a.ix, b.pts, a.pts, ws.blocks[1], pp ? &res.bNearest : nullptr};
        ab.perPointDistances = ba.perPointDistances = !options.perPointNearestOnly;
        ab.killFloor2 = floor.kill2(0);
        ba.killFloor2 = floor.kill2(1);
        cull.startDirection(ab, 0);
        certificate.startDirection(ab, 0);
        if (!options.directedOnly) {
            cull.startDirection(ba, 1);
            certificate.startDirection(ba, 1);
        }
        auto material = std::make_shared<detail::ProofMaterial>();
        auto aboveFloor = std::make_shared<detail::AboveFloor>();
        // Both culls (and their checks) in one submission; a direction with
        // survivors searches, then checks again.
        std::array<uint32_t, 2> survivors{};
        if (options.directedOnly)
            survivors[0] = cull.runCulls(std::array{&ab})[0];
        else
            survivors = cull.runCulls(std::array{&ab, &ba});
        reportProgress(options, "cull", from + 0.2 * (1.0 - from));
        struct Step {
            DirectionRun* run;
            uint32_t survivors;
            Directed* out;
            int direction;
        };
        std::array<Step, 2> steps{Step{&ab, survivors[0], &res.aToB, 0},
                                  Step{&ba, survivors[1], &res.bToA, 1}};
        const size_t count = options.directedOnly ? 1 : 2;
        const bool handBack = pp && options.perPointReady != nullptr;
        // Handed back: the direction with more queries first, its caller's
        // work (proportional to them) then overlaps the other's search.
        if (handBack && count == 2 && ba.Q.n > ab.Q.n) std::swap(steps[0], steps[1]);
        PerPointHandBack handing(options, check, handedBack);
        for (size_t i = 0; i < count; ++i) {
            const Step& s = steps[i];
            const double lo = i == 0 ? from : mid, hi = i + 1 == count ? 1.0 : mid;
            const SampledQuery witness = s.survivors > 0
                                             ? searchAndCheck(*s.run, s.survivors, options, lo, hi)
                                             : check.finishCheck(*s.run);
            auto t0 = Clock::now();
            if (floor.any()) {  // counters only: no witness, no proof
                *s.out = s.run->out;
            } else {
                *s.out = check.finishDirection(*s.run, witness);
                const auto tc = Clock::now();
                core::DirectionBand& band = s.direction == 0 ? material->aToB : material->bToA;
                band = certificate.prove(*s.run, *s.out);
                band.scale = a.scale;  // the caller's units to the search's (both sets share it)
                ws.timings->certificate += msSince(tc);
            }
            ws.timings->check += msSince(t0);
            if (handBack && i + 1 < count) {  // read back beside the next direction's search: not timed
                handing.handBeside(*s.run, *s.run->perPoint, s.direction);
                continue;
            }
            t0 = Clock::now();
            std::optional<std::vector<detail::QueryNearest>> above;
            if (s.run->above != nullptr) above = check.readAboveFloor(*s.run, size_t(s.direction));
            if (above) {  // sparse: the arrays stay empty
                s.run->perPoint->distance.clear();
                s.run->perPoint->nearest.clear();
                aboveFloor->of[s.direction] = std::move(above);
            } else if (pp) {
                check.readPerPoint(*s.run, *s.run->perPoint);
            }
            ws.timings->check += msSince(t0);
            if (handBack) handing.handHere(*s.run->perPoint, s.direction);
        }
        handing.join();
        if (floor.any()) {
            res.hausdorff = 0.0;
            res.aboveFloor = std::move(aboveFloor);
            return;
        }
        res.hausdorff =
            options.directedOnly ? res.aToB.distance : std::max(res.aToB.distance, res.bToA.distance);
        res.proofMaterial = std::move(material);
        // Witnesses and per-point distances from the unscaled inputs, in double.
        if (a.scale != 1.0) core::restoreOriginal(res, PointView(a.input), PointView(b.input), ws.threads);
    }

    // A scan of small pairs (small_pairs.hpp) under the guard: each pair's
    // result with its witnesses and per-point distances in double from its
    // inputs (`inputs[i]`), or its self-check failure, or the scan's error.
    template <class Scan>
    std::vector<Result<HausdorffResult>> scanPairs(std::span<const std::pair<PointView, PointView>> inputs,
                                                   const CallOptions& options, Scan&& scan) {
        SmallPairScan::Outcome outcome;
        Timings timings;
        auto err = guarded(timings, [&] {
            reportProgress(options, "search", 0.0);  // the scan is the search; honours the cancel flag
            outcome = scan(emptyResult(options));
        });
        std::vector<Result<HausdorffResult>> out;
        for (size_t i = 0; i < inputs.size(); ++i) {
            if (err) {
                out.emplace_back(*err);
            } else if (!outcome.failed[i].empty()) {
                out.emplace_back(Error{ErrorCode::kInternal, "self-check failed: " + outcome.failed[i]});
            } else {
                HausdorffResult& r = outcome.results[i];
                core::restoreOriginal(r, inputs[i].first, inputs[i].second, ws.threads);
                out.emplace_back(std::move(r));
            }
        }
        return out;
    }

    HausdorffResult emptyResult(const CallOptions& options) const {
        HausdorffResult res;
        res.backend = ws.ctx.backend();
        res.device = ws.ctx.deviceName();
        res.directedOnly = options.directedOnly;
        return res;
    }

    // Runs `work` with its timings in `timings`, and turns what it throws
    // into the error codes of the API (the accel structures are dropped, so
    // the next call starts clean).
    template <class Work>
    std::optional<Error> guarded(Timings& into, Work&& work) {
        ws.timings = &into;
        ws.mutant = core::searchMutant().load();
        handedBack = 0;
        std::optional<Error> err;
        try {
            work();
        } catch (const InputRejected& e) {
            err = e.error;
        } catch (const CallCancelled&) {
            err = Error{ErrorCode::kCancelled, "the call was cancelled (CallOptions::cancel)"};
        } catch (const gpu::VulkanError& e) {
            err = e.outOfMemory() ? Error{ErrorCode::kOutOfMemory,
                                          std::string("the inputs do not fit the device: ") + e.what()}
                                  : Error{ErrorCode::kInternal, e.what()};
            err->vkResult = int(e.result());
        } catch (const gpu::LimitError& e) {
            err =
                Error{ErrorCode::kOutOfMemory, std::string("the inputs do not fit the device: ") + e.what()};
        } catch (const std::exception& e) {
            err = Error{ErrorCode::kInternal, e.what()};
        }
        ws.timings = nullptr;
        ws.imports.clear();  // never past the call: the caller may free its arrays
        if (err) {
            ws.accel.release();
            ws.tlasBound = false;
        }
        return err;
    }
};

GpuHausdorff::GpuHausdorff(std::unique_ptr<State> state) : m_state(std::move(state)) {}
GpuHausdorff::~GpuHausdorff() = default;

void GpuHausdorff::setCullCellTests(uint32_t tests) { m_state->ws.cullCellTests = tests; }

void GpuHausdorff::setLeafGroupLeaves(uint32_t leaves) {
    m_state->ws.leafGroupLeaves = std::max<uint32_t>(1, leaves);
}

void GpuHausdorff::setUploadChunks(size_t past, size_t chunk) {
    m_state->ws.chunkedUploadPoints = past;
    m_state->ws.uploadChunkPoints = std::max<size_t>(1, chunk);
}

void GpuHausdorff::setSpaceOrderMinPoints(size_t points) { m_state->ws.spaceOrderMinPoints = points; }

void GpuHausdorff::setAdoptMinBytes(uint64_t bytes) { m_state->ws.adoptMinBytes = bytes; }
uint64_t GpuHausdorff::adoptedBuffers() const { return m_state->ws.adopted; }
size_t GpuHausdorff::spareBuffers() const { return m_state->ws.spare.size(); }

void GpuHausdorff::setMaxPairCapacity(uint64_t pairs) {
    m_state->ws.maxPairCapacity = std::max<uint64_t>(1, pairs);
}

void GpuHausdorff::setAboveFloorCapacity(uint32_t queries) {
    m_state->ws.aboveFloorCapacity = std::max<uint32_t>(1, queries);
}

void GpuHausdorff::recyclePerPoint(PerPoint&& a, PerPoint&& b) {
    m_state->spare = std::move(a);
    m_state->spareB = std::move(b);
}

void GpuHausdorff::releaseScratch() {
    Workspace& ws = m_state->ws;
    ws.accel.release();
    ws.tlasBound = false;
    ws.scratch = Scratch{};
    ws.oneShot = {};
    ws.spare.clear();
    m_state->surface.release();
    m_state->spare = m_state->spareB = PerPoint{};
    m_state->handedBack = 0;
}

uint32_t GpuHausdorff::handedBack() const { return m_state->handedBack; }

Result<std::unique_ptr<GpuHausdorff>> GpuHausdorff::create(gpu::Context& ctx, const std::string& cacheDir,
                                                           int threads, const Tuning& tuning) {
    try {
        return std::unique_ptr<GpuHausdorff>(
            new GpuHausdorff(std::make_unique<State>(ctx, cacheDir, threads, tuning)));
    } catch (const gpu::VulkanError& e) {
        return Error{ErrorCode::kInternal, std::string("pipeline creation failed: ") + e.what()};
    }
}

Result<HausdorffResult> GpuHausdorff::compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                              double scale, const CallOptions& options) {
    return scansWhole(a.size(), b.size(), options) ? scanWhole(a, b, scale, options)
                                                   : computeIndexed(a, b, scale, options);
}

Result<HausdorffResult> GpuHausdorff::scanWhole(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                double scale, const CallOptions& options) {
    State& st = *m_state;
    const std::pair<PointView, PointView> inputs{PointView(a), PointView(b)};
    return std::move(st.scanPairs(std::span(&inputs, 1), options, [&](const HausdorffResult& blank) {
        return st.smallPairs.runHostArrays(a, b, scale, options, blank);
    })[0]);
}

Result<HausdorffResult> GpuHausdorff::computeIndexed(std::span<const glm::vec3> a,
                                                     std::span<const glm::vec3> b, double scale,
                                                     const CallOptions& options,
                                                     const core::PerPointFloor& floor) {
    State& st = *m_state;
    HausdorffResult res = st.emptyResult(options);
    // Squared distances are float on the device: coordinates so large (or so
    // small) that they overflow (or underflow) are scaled by a power of two,
    // which is exact; values and witnesses are recomputed from the inputs.
    // Each set is indexed once with its own grid: as targets for the other
    // direction, and as cell-ordered (Morton) queries for its own.
    auto err = st.guarded(res.timings, [&] { st.hostPair(a, b, scale, options, res, floor); });
    if (err) return *err;
    return res;
}

Result<HausdorffResult> GpuHausdorff::computePacked(
    std::span<const glm::vec3> a, std::span<const glm::vec3> b, const CallOptions& options,
    const std::function<bool(const core::Bounds&, const core::Bounds&)>& leave) {
    State& st = *m_state;
    HausdorffResult res = st.emptyResult(options);
    auto err = st.guarded(res.timings, [&] {
        DeviceSet da, db;
        const State::Ingested ingested = st.ingestPair(da, db, a, b, options, leave);
        if (ingested == State::Ingested::kLeft) return;
        if (ingested == State::Ingested::kHostPath) {
            // Coordinates past 2^40 or below 2^-40: the host path scales them.
            const double magnitude = std::max(largestMagnitude(da.ix.bounds), largestMagnitude(db.ix.bounds));
            st.hostPair(a, b, exactScale(magnitude), options, res);
            return;
        }
        reportProgress(options, "index", 0.1);
        st.runPair(da, db, options, res, 0.1);
    });
    if (err) return *err;
    return res;
}

uint64_t GpuHausdorff::ingestPoints() { return kFusedBuildPoints; }

Result<HausdorffResult> GpuHausdorff::compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                              const CallOptions& options) {
    return compute(a, b, exactScale(std::max(largestMagnitude(a), largestMagnitude(b))), options);
}

Result<std::shared_ptr<DeviceSet>> GpuHausdorff::prepare(std::span<const glm::vec3> points, double scale,
                                                         int bits, const std::string& name,
                                                         Timings& timings) {
    auto set = std::make_shared<DeviceSet>();
    auto err = m_state->guarded(timings, [&] {
        m_state->stageSet(*set, points, scale, bits, name, m_state->ws.scratch.builds[0], nullptr);
        m_state->index.buildIndexes(std::array{&set->ix});
        set->own.releaseUnused(set->ix);  // a prepared set keeps what its index uses
    });
    if (err) return *err;
    return set;
}

Result<HausdorffResult> GpuHausdorff::compute(DeviceSet& a, DeviceSet& b, const CallOptions& options) {
    HausdorffResult res = m_state->emptyResult(options);
    auto err = m_state->guarded(res.timings, [&] {
        throwIfCancelled(options);
        m_state->runPair(a, b, options, res, 0.0);
    });
    if (err) return *err;
    return res;
}

const core::ScanLimits& GpuHausdorff::scanLimits() const { return m_state->smallPairs.limits(); }

bool GpuHausdorff::scansWhole(size_t aPoints, size_t bPoints, const CallOptions& options) const {
    return options.bits == 0 && scanLimits().takesPair(aPoints, bPoints);
}

std::vector<Result<HausdorffResult>> GpuHausdorff::computeSmallPairs(
    std::span<const std::pair<const DeviceSet*, const DeviceSet*>> pairs, const CallOptions& options) {
    std::vector<SmallPair> scans;
    std::vector<std::pair<PointView, PointView>> inputs;
    for (const auto& [a, b] : pairs) {
        const double pairScale = std::min(a->scale, b->scale);  // of the larger magnitude
        scans.push_back({scanSetOf(*a, pairScale / a->scale), scanSetOf(*b, pairScale / b->scale)});
        inputs.emplace_back(PointView(a->input), PointView(b->input));
    }
    return m_state->scanPairs(inputs, options, [&](const HausdorffResult& blank) {
        return m_state->smallPairs.run(scans, options, blank);
    });
}

Result<HausdorffResult> GpuHausdorff::computeDevice(const DeviceInput& a, const DeviceInput& b,
                                                    const CallOptions& options) {
    State& st = *m_state;
    HausdorffResult res = st.emptyResult(options);
    auto err = st.guarded(res.timings, [&] {
        throwIfCancelled(options);
        DeviceSet da, db;
        res.origin = st.devicePair(da, db, a, b, options);
        reportProgress(options, "index", 0.1);
        st.runPair(da, db, options, res, 0.1);
    });
    if (err) return *err;
    return res;
}

Result<GpuHausdorff::PreparedDevice> GpuHausdorff::prepareDevice(const DeviceInput& view,
                                                                 const std::optional<glm::dvec3>& origin,
                                                                 int bits, const std::string& name,
                                                                 Timings& timings) {
    PreparedDevice out;
    out.set = std::make_shared<DeviceSet>();
    auto err = m_state->guarded(timings, [&] { m_state->deviceSet(out, view, origin, bits, name); });
    if (err) return *err;
    return out;
}

uint64_t GpuHausdorff::deviceBytes(const DeviceSet& set) { return set.own.bytes() + set.inputCopy.size(); }

int GpuHausdorff::bits(const DeviceSet& set) { return set.ix.grid.bits; }

const std::string& GpuHausdorff::pipelineCachePath() const { return m_state->ws.pipelineCache.path(); }
const std::string& GpuHausdorff::pipelineCacheStatus() const {
    return m_state->ws.pipelineCache.loadStatus();
}

Result<SurfaceCandidates> GpuHausdorff::nearestTriangles(const core::FramedQueries& queries,
                                                         std::span<const glm::vec3> corners,
                                                         const std::atomic<bool>* cancel,
                                                         uint64_t cornersVersion) {
    Timings timings;
    SurfaceCandidates out;
    // The BLAS of triangles stays: a point search's first radius builds its own in its storage.
    auto err = m_state->guarded(
        timings, [&] { out = m_state->surface.run(queries, corners, cancel, cornersVersion); });
    if (err) return *err;
    return out;
}

}  // namespace rthdist::gpu_algo
