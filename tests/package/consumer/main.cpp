// H(A,B) of two tiny point sets with rthdist: one call on the CPU backend,
// then an Engine on the default backend (a ray-tracing GPU when there is one,
// else the CPU), one-shot and with prepared sets. The consumer that tools/package_test.sh builds against the
// installed package, and the README's C++ example.
#include <rthdist/rthdist.hpp>
#include <rthdist/version.hpp>

#include <cstdio>
#include <cstring>
#include <vector>

// Prints r and checks it against the known answer: h(A,B) = 1, H = 2, realized by B's point 2.
static bool report(const rthdist::Result<rthdist::HausdorffResult>& r) {
    if (!r) {
        std::fprintf(stderr, "rthdist: %s\n", r.error().message.c_str());  // ErrorCode + message
        return false;
    }
    std::printf("H = %g on %s (%s): B[%u] -> A[%u]\n", r->hausdorff, rthdist::backendName(r->backend),
                r->device.c_str(), r->bToA.queryIndex, r->bToA.targetIndex);
    return r->hausdorff == 2.0 && r->aToB.distance == 1.0 && r->bToA.queryIndex == 2;
}

int main() {
    std::vector<glm::vec3> a = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // or glm::dvec3
    // Interleaved data is read in place: here x, y, z and an intensity per
    // point, in double. B is A with its last point moved 2 up.
    const double b[] = {0, 0, 0, 0.9, 1, 0, 0, 0.8, 0, 1, 2, 0.7};
    rthdist::PointView bView = rthdist::PointView::doubles(b, 3, 4 * sizeof(double));

    rthdist::Options cpu;
    cpu.backend = rthdist::Backend::kCpu;
    if (!report(rthdist::hausdorff(a, bView, cpu))) return 1;

    // An Engine keeps its device and pipelines between calls.
    rthdist::Result<rthdist::Engine> engine = rthdist::Engine::create(rthdist::Options{});
    if (!engine) {
        std::fprintf(stderr, "rthdist: %s\n", engine.error().message.c_str());
        return 1;
    }
    if (!report(engine->compute(a, bView))) return 1;

    // Build once, query many: a prepared set is indexed once on the Engine's
    // device and reused by every later call; call options change per call.
    rthdist::Result<rthdist::PreparedSet> pa = engine->prepare(a), pb = engine->prepare(bView);
    if (!pa || !pb) return 1;
    rthdist::CallOptions directed;
    directed.directedOnly = true;  // h(A,B) only
    rthdist::Result<rthdist::HausdorffResult> h = engine->compute(*pa, *pb, directed);
    if (!h || h->hausdorff != 1.0 || !report(engine->compute(*pa, *pb))) return 1;

    // The headers and the library come from the same release.
    return std::strcmp(rthdist::versionString(), RTHDIST_VERSION_STRING) == 0 ? 0 : 1;
}
