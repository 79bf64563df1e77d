// evaluatePoints and evaluateToSurface (rthdist/eval.hpp): the exact
// per-point distances of both directions from the engine (point targets)
// or the point-to-surface search (accuracy to a surface), then the summary
// (cpu/eval_summary.cpp). The reconstruction is the first input.
#include <vector>

#include "rthdist/eval.hpp"
#include "rthdist/rthdist.hpp"

namespace rthdist {
namespace {

// The vertices the triangles use, each once, in the order first used.
std::vector<glm::dvec3> usedVertices(const MeshView& mesh) {
    std::vector<bool> seen(mesh.vertices.count, false);
    std::vector<glm::dvec3> out;
    for (uint32_t v : mesh.indices) {
        if (v >= mesh.vertices.count || seen[v]) continue;  // out of range: refused by the surface call
        seen[v] = true;
        out.push_back(mesh.vertices.at(v));
    }
    return out;
}

}  // namespace

Result<EvalSummary> evaluatePoints(PointView reconstruction, PointView groundTruth, const EvalOptions& eval,
                                   const Options& options) {
    Options o = options;
    o.perPointDistances = true;
    o.directedOnly = false;
    Result<HausdorffResult> r = hausdorff(reconstruction, groundTruth, o);
    if (!r) return r.error();
    return evaluationSummary(r->aNearest.distance, r->bNearest.distance, eval);
}

Result<EvalSummary> evaluateToSurface(PointView reconstruction, MeshView groundTruth, const EvalOptions& eval,
                                      const SurfaceOptions& options) {
    const std::vector<glm::dvec3> samples = usedVertices(groundTruth);
    CallOptions call;
    call.cancel = options.cancel;
    call.perPointDistances = true;
    call.directedOnly = true;
    SurfaceCallOptions surfaceCall;
    surfaceCall.cancel = options.cancel;
    surfaceCall.perPointDistances = true;
    surfaceCall.perPointDistancesOnly = true;  // the summary reads the distances alone
    if (options.backend == Backend::kRayQuery || options.backend == Backend::kRtPipeline) {
        // Both directions on one device: an Engine opens it once.
        EngineOptions engineOptions;
        engineOptions.backend = options.backend;
        engineOptions.threads = options.threads;
        engineOptions.deviceIndex = options.deviceIndex;
        engineOptions.validation = options.validation;
        Result<Engine> engine = Engine::create(engineOptions);
        if (!engine) return engine.error();
        Result<SurfaceResult> accuracy = engine->hausdorffToSurface(reconstruction, groundTruth, surfaceCall);
        if (!accuracy) return accuracy.error();
        Result<HausdorffResult> completeness = engine->compute(PointView(samples), reconstruction, call);
        if (!completeness) return completeness.error();
        return evaluationSummary(accuracy->perPoint.distance, completeness->aNearest.distance, eval);
    }
    SurfaceOptions so = options;
    static_cast<SurfaceCallOptions&>(so) = surfaceCall;
    Result<SurfaceResult> accuracy = hausdorffToSurface(reconstruction, groundTruth, so);
    if (!accuracy) return accuracy.error();
    Options o;
    static_cast<CallOptions&>(o) = call;
    o.backend = options.backend;
    o.threads = options.threads;
    Result<HausdorffResult> completeness = hausdorff(PointView(samples), reconstruction, o);
    if (!completeness) return completeness.error();
    return evaluationSummary(accuracy->perPoint.distance, completeness->aNearest.distance, eval);
}

}  // namespace rthdist
