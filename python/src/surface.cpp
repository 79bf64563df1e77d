#include "surface.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "engine.hpp"
#include "errors.hpp"
#include "points.hpp"
#include "rthdist/eval.hpp"
#include "rthdist/surface.hpp"

namespace py = pybind11;

namespace rthdist::python {
namespace {

// The faces of an (F, 3) integer array as 32-bit indices, each checked
// against the vertex count (a negative or too large index is a ValueError
// naming the face, never a wrapped unsigned value).
template <class T>
std::vector<uint32_t> facesAs(const py::array& faces, size_t vertices, const char* name) {
    const auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(faces);
    const T* p = a.data();
    std::vector<uint32_t> out(size_t(a.size()));
    for (size_t i = 0; i < out.size(); ++i) {
        const auto v = static_cast<long long>(p[i]);
        if (v < 0 || static_cast<unsigned long long>(v) >= vertices) {
            throw py::value_error(std::string(name) + ": face " + std::to_string(i / 3) + ": vertex index " +
                                  std::to_string(v) + " out of range (" + std::to_string(vertices) +
                                  " vertices)");
        }
        out[i] = uint32_t(v);
    }
    return out;
}

py::tuple vec(const glm::dvec3& v) { return py::make_tuple(v.x, v.y, v.z); }

Backend surfaceBackend(const std::string& backend, int threads) {
    return engineOptions(backend, std::nullopt, threads, false).backend;
}

// A read-only NumPy array that owns `values` (moved, not copied): (n,) for
// scalars, (n, 3) for glm::dvec3 (three adjacent doubles).
template <class T, class Scalar>
py::array ownedArray(std::vector<T>&& values) {
    static_assert(sizeof(T) % sizeof(Scalar) == 0 && alignof(T) == alignof(Scalar));
    constexpr auto columns = py::ssize_t(sizeof(T) / sizeof(Scalar));
    auto* heap = new std::vector<T>(std::move(values));
    const py::capsule owner(heap, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    const auto n = py::ssize_t(heap->size());
    const auto* data = reinterpret_cast<const Scalar*>(heap->data());
    py::array_t<Scalar> out =
        columns > 1 ? py::array_t<Scalar>({n, columns}, data, owner) : py::array_t<Scalar>({n}, data, owner);
    py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return out;
}

py::dict toSurface(const py::array& points, const py::array& vertices, const py::array& faces, bool perPoint,
                   const std::string& backend, int threads) {
    SurfaceOptions options;
    options.backend = surfaceBackend(backend, threads);
    options.threads = threads;
    options.perPointDistances = perPoint;
    const PointView vp = viewOf(points, "points"), vv = viewOf(vertices, "vertices");
    const std::vector<uint32_t> f = facesOf(faces, vv.count, "faces");
    std::optional<Result<SurfaceResult>> r;
    {
        py::gil_scoped_release release;
        const PointCopy cp(vp), cv(vv);
        r.emplace(hausdorffToSurface(cp.view(), MeshView{cv.view(), f}, options));
    }
    return surfaceResultDict(valueOrRaise(std::move(*r)), perPoint);
}

py::dict directedDict(const SurfaceBoundsDirected& d) {
    py::dict out;
    out["bounds"] = py::make_tuple(d.lower, d.upper);
    out["distance"] = d.distance;
    out["from_triangle"] = d.fromTriangle;
    out["from_point"] = vec(d.fromPoint);
    out["from_barycentric"] = vec(d.fromBarycentric);
    out["triangle"] = d.toTriangle;
    out["to_point"] = vec(d.toPoint);
    out["barycentric"] = vec(d.toBarycentric);
    out["queries"] = d.counters.queries;
    return out;
}

py::dict surfaceToSurface(const py::array& va, const py::array& fa, const py::array& vb, const py::array& fb,
                          double tolerance, bool directed, const std::string& backend, int threads) {
    SurfaceBoundsOptions options;
    options.backend = surfaceBackend(backend, threads);
    options.threads = threads;
    options.tolerance = tolerance;
    options.directedOnly = directed;
    const PointView pa = viewOf(va, "vertices_a"), pb = viewOf(vb, "vertices_b");
    const std::vector<uint32_t> ia = facesOf(fa, pa.count, "faces_a"), ib = facesOf(fb, pb.count, "faces_b");
    std::optional<Result<SurfaceBoundsResult>> r;
    {
        py::gil_scoped_release release;
        const PointCopy ca(pa), cb(pb);
        r.emplace(surfaceHausdorff(MeshView{ca.view(), ia}, MeshView{cb.view(), ib}, options));
    }
    const SurfaceBoundsResult s = valueOrRaise(std::move(*r));
    py::dict out;
    out["bounds"] = py::make_tuple(s.lower, s.upper);
    out["tolerance"] = s.tolerance;
    out["slack"] = s.slack;
    out["directed"] = s.directed;
    out["backend"] = backendName(s.backend);
    out["device"] = s.device;
    out["a_to_b"] = directedDict(s.aToB);
    out["b_to_a"] = s.directed ? py::object(py::none()) : py::object(directedDict(s.bToA));
    return out;
}

py::dict distancesDict(const EvalDistances& d) {
    py::dict out;
    out["count"] = d.count;
    out["kept"] = d.kept;
    out["mean"] = d.mean;
    out["median"] = d.median;
    out["mean_squared"] = d.meanSquared;
    out["max"] = d.max;
    return out;
}

py::dict evalDict(const EvalSummary& s) {
    py::dict out, chamfer;
    out["reconstruction"] = "a";
    out["ground_truth"] = "b";
    out["cap"] = s.cap > 0.0 ? py::object(py::float_(s.cap)) : py::object(py::none());
    out["accuracy"] = distancesDict(s.accuracy);
    out["completeness"] = distancesDict(s.completeness);
    chamfer["mean_of_means"] = s.chamferMeanOfMeans;
    chamfer["sum_of_means"] = s.chamferSumOfMeans;
    chamfer["sum_of_mean_squares"] = s.chamferSumOfMeanSquares;
    out["chamfer"] = chamfer;
    py::list thresholds;
    for (const EvalThreshold& t : s.thresholds) {
        py::dict row;
        row["threshold"] = t.threshold;
        row["precision"] = t.precision;
        row["recall"] = t.recall;
        row["fscore"] = t.fscore;
        thresholds.append(row);
    }
    out["thresholds"] = thresholds;
    return out;
}

py::dict evaluate(const py::array& reconstruction, const py::array& truth, std::optional<py::array> faces,
                  const std::vector<double>& thresholds, double cap, const std::string& backend,
                  int threads) {
    EvalOptions eval;
    eval.thresholds = thresholds;
    eval.cap = cap;
    const Options engine = engineOptions(backend, std::nullopt, threads, false);
    const PointView pr = viewOf(reconstruction, "reconstruction"), pt = viewOf(truth, "ground_truth");
    std::vector<uint32_t> f;
    if (faces) f = facesOf(*faces, pt.count, "faces");
    std::optional<Result<EvalSummary>> r;
    {
        py::gil_scoped_release release;
        const PointCopy cr(pr), ct(pt);
        if (faces) {
            SurfaceOptions options;
            options.backend = engine.backend;
            options.threads = threads;
            r.emplace(evaluateToSurface(cr.view(), MeshView{ct.view(), f}, eval, options));
        } else {
            r.emplace(evaluatePoints(cr.view(), ct.view(), eval, engine));
        }
    }
    return evalDict(valueOrRaise(std::move(*r)));
}

}  // namespace

std::vector<uint32_t> facesOf(const py::array& faces, size_t vertices, const char* name) {
    if (faces.ndim() != 2 || faces.shape(1) != 3)
        throw py::value_error(std::string(name) + ": expected an (F, 3) array of faces, got shape " +
                              std::string(py::str(faces.attr("shape"))));
    if (faces.dtype().is(py::dtype::of<int32_t>())) return facesAs<int32_t>(faces, vertices, name);
    if (faces.dtype().is(py::dtype::of<int64_t>())) return facesAs<int64_t>(faces, vertices, name);
    if (faces.dtype().is(py::dtype::of<uint32_t>())) return facesAs<uint32_t>(faces, vertices, name);
    throw py::value_error(std::string(name) + ": expected int32, int64 or uint32 faces, got dtype " +
                          std::string(py::str(faces.dtype())));
}

py::dict surfaceResultDict(SurfaceResult&& r, bool perPoint) {
    const SurfaceDirected& d = r.directed;
    py::dict out;
    out["hausdorff"] = r.hausdorff;
    out["query_index"] = d.queryIndex;
    out["triangle"] = d.triangle;
    out["query_point"] = vec(d.queryPoint);
    out["surface_point"] = vec(d.surfacePoint);
    out["barycentric"] = vec(d.barycentric);
    out["backend"] = backendName(r.backend);
    if (perPoint) {  // moved into the arrays, in point order
        SurfacePerPoint& p = r.perPoint;
        out["distances"] = ownedArray<double, double>(std::move(p.distance));
        out["triangles"] = ownedArray<uint32_t, uint32_t>(std::move(p.triangle));
        out["surface_points"] = ownedArray<glm::dvec3, double>(std::move(p.closest));
        out["barycentrics"] = ownedArray<glm::dvec3, double>(std::move(p.barycentric));
        out["tolerance"] = p.tolerance;
    }
    return out;
}

void bindSurface(py::module_& m) {
    m.def("_hausdorff_to_surface", &toSurface, py::arg("points"), py::arg("vertices"), py::arg("faces"),
          py::arg("per_point"), py::arg("backend"), py::arg("threads"));
    m.def("_surface_hausdorff", &surfaceToSurface, py::arg("vertices_a"), py::arg("faces_a"),
          py::arg("vertices_b"), py::arg("faces_b"), py::arg("tolerance"), py::arg("directed"),
          py::arg("backend"), py::arg("threads"));
    m.def("_evaluate", &evaluate, py::arg("reconstruction"), py::arg("ground_truth"), py::arg("faces"),
          py::arg("thresholds"), py::arg("cap"), py::arg("backend"), py::arg("threads"));
}

}  // namespace rthdist::python
