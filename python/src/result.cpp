#include "result.hpp"

#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "errors.hpp"
#include "rthdist/stats.hpp"

namespace py = pybind11;

namespace rthdist::python {
namespace {

py::array_t<double> point(const glm::dvec3& p) {
    py::array_t<double> out(3);
    auto w = out.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < 3; ++i) w(i) = p[int(i)];
    return out;
}

py::dict counters(const Counters& c) {
    py::dict d;
    d["bits"] = c.bits;
    d["occupied_cells"] = c.occupiedCells;
    d["queries"] = c.queries;
    d["culled_by_neighbourhood"] = c.culledByNeighbourhood;
    d["surviving_queries"] = c.survivingQueries;
    d["iterations"] = c.iterations;
    d["rays"] = c.rays;
    d["candidate_pairs"] = c.candidatePairs;
    d["tail_scanned"] = c.tailScanned;
    d["query_chunks"] = c.queryChunks;
    d["target_tiles"] = c.targetTiles;
    d["cross_piece_queries"] = c.crossPieceQueries;
    d["narrowed_targets"] = c.narrowedTargets;
    d["per_point_mended"] = c.perPointMended;
    return d;
}

// The proof of one directed value (rthdist.hpp, Certificate): the CLI's
// certificate.a_to_b / b_to_a keys.
py::dict certificate(const Certificate& c) {
    py::dict d;
    d["confirmed"] = c.confirmed;
    d["query"] = c.query;
    d["nearest"] = c.nearest;
    d["distance"] = c.distance;
    d["band"] = c.band;
    d["recomputed"] = c.recomputed;
    return d;
}

// {"a_to_b": of(aToB), "b_to_a": of(bToA) or None when directed}.
template <class Of>
py::dict perDirection(const HausdorffResult& r, Of&& of) {
    py::dict d;
    d["a_to_b"] = of(r.aToB);
    d["b_to_a"] = r.directedOnly ? py::object(py::none()) : py::object(of(r.bToA));
    return d;
}

py::dict timings(const Timings& t) {
    py::dict d;
    d["setup"] = t.setup;
    d["upload"] = t.upload;
    d["index"] = t.index;
    d["cull"] = t.cull;
    d["search"] = t.search;
    d["refine"] = t.refine;
    d["check"] = t.check;
    d["total"] = t.total;
    d["gpu_index"] = t.gpuIndex;
    d["gpu_cull"] = t.gpuCull;
    d["gpu_search"] = t.gpuSearch;
    d["gpu_refine"] = t.gpuRefine;
    d["certificate"] = t.certificate;
    d["pieces"] = t.pieces;
    d["gpu_certificate"] = t.gpuCertificate;
    return d;
}

// A read-only array over `values`, kept alive by `owner` (the result).
template <class T>
py::object sharedArray(const std::vector<T>& values, py::handle owner) {
    py::array_t<T> out({py::ssize_t(values.size())}, {py::ssize_t(sizeof(T))}, values.data(), owner);
    py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return out;
}

// The getter of one per-point array of the result (None without per_point).
template <class T>
auto perPointArray(PerPoint HausdorffResult::*side, std::vector<T> PerPoint::*field) {
    return [side, field](py::object self) -> py::object {
        const std::vector<T>& values = (self.cast<const PyResult&>().result.*side).*field;
        if (values.empty()) return py::none();
        return sharedArray(values, self);
    };
}

void requirePerPoint(const PyResult& r) {
    if (r.result.aNearest.distance.empty()) {
        throw py::value_error("this result has no per-point distances: call with per_point=True");
    }
}

void sortOnce(PyResult& r) {
    if (r.sorted) return;
    requirePerPoint(r);
    const HausdorffResult& h = r.result;
    r.sortedA = h.aNearest.distance;
    std::sort(r.sortedA.begin(), r.sortedA.end());
    if (!h.directedOnly) {
        r.sortedB = h.bNearest.distance;
        std::sort(r.sortedB.begin(), r.sortedB.end());
        r.sortedPooled.reserve(r.sortedA.size() + r.sortedB.size());
        std::merge(r.sortedA.begin(), r.sortedA.end(), r.sortedB.begin(), r.sortedB.end(),
                   std::back_inserter(r.sortedPooled));
    }
    r.sorted = true;
}

void checkPercentile(double q) {
    if (!(q >= 0.0 && q <= 100.0)) throw py::value_error("percentile outside [0, 100]: " + std::to_string(q));
}

// stats.hpp's percentiles: "max" (symmetric) = max(P(d_A), P(d_B)), "pooled" = P(d_A ∪ d_B).
double percentile(PyResult& r, double q, const std::string& variant) {
    checkPercentile(q);
    sortOnce(r);
    if (variant == "pooled") {
        if (r.result.directedOnly) throw py::value_error("a directed result has no pooled percentile");
        return percentileNearestRank(r.sortedPooled, q);
    }
    if (variant != "max" && variant != "symmetric" && variant != "a_to_b" && variant != "b_to_a") {
        throw py::value_error("unknown percentile variant '" + variant +
                              "' (expected 'max', 'pooled', 'a_to_b' or 'b_to_a')");
    }
    if (variant == "b_to_a" && r.result.directedOnly)
        throw py::value_error("a directed result has no b_to_a");
    const double pa = percentileNearestRank(r.sortedA, q);
    if (variant == "a_to_b" || r.result.directedOnly) return pa;
    const double pb = percentileNearestRank(r.sortedB, q);
    return variant == "b_to_a" ? pb : std::max(pa, pb);
}

// The distances the symmetric mean and RMS are over: pooled, or A->B when directed.
const std::vector<double>& meanSet(PyResult& r) {
    sortOnce(r);
    return r.result.directedOnly ? r.sortedA : r.sortedPooled;
}

// A kept input as C-ordered doubles (N, >= 3): the statistics' diagonals are
// taken from the values as given (a float32 array's are exact in double).
py::array_t<double, py::array::c_style | py::array::forcecast> keptDoubles(const py::object& array) {
    py::array_t<double, py::array::c_style | py::array::forcecast> d(array);
    if (d.ndim() != 2 || d.shape(1) < 3) throw py::value_error("stats: the kept input is not (N, 3)");
    return d;
}

PointView viewOf(const py::array_t<double, py::array::c_style | py::array::forcecast>& d) {
    return PointView::doubles(d.data(), size_t(d.shape(0)), size_t(d.shape(1)) * sizeof(double));
}

py::list percentileList(const std::vector<Percentile>& list) {
    py::list out;
    for (const Percentile& p : list) out.append(py::dict(py::arg("p") = p.p, py::arg("value") = p.value));
    return out;
}

py::dict block(const DistanceStats& s) {
    py::dict d;
    d["count"] = s.count;
    d["min"] = s.min;
    d["max"] = s.max;
    d["mean"] = s.mean;
    d["rms"] = s.rms;
    d["percentiles"] = percentileList(s.percentiles);
    return d;
}

py::array_t<uint64_t> counts(const Histogram& h) {
    return py::array_t<uint64_t>(py::ssize_t(h.counts.size()), h.counts.data());
}

// hausdorffStats (the CLI's --per-point block) as a dict of the CLI JSON's keys.
py::dict stats(PyResult& r, const std::vector<double>& percentiles, int bins, py::object range) {
    requirePerPoint(r);
    StatsOptions options;
    options.percentiles = percentiles;
    options.histogramBins = bins;
    if (!range.is_none()) {
        const auto lohi = range.cast<std::pair<double, double>>();
        // As StatsOptions' fixed range (stats.hpp): finite, lo < hi; (0, 0) is
        // refused here too (the C++ API reads it as "auto", range=None here).
        if (!(std::isfinite(lohi.first) && std::isfinite(lohi.second) && lohi.second > lohi.first))
            throw py::value_error("range: expected finite (lo, hi) with lo < hi, got (" +
                                  std::string(py::str(py::float_(lohi.first))) + ", " +
                                  std::string(py::str(py::float_(lohi.second))) + ")");
        options.rangeLo = lohi.first;
        options.rangeHi = lohi.second;
    }
    if (bins < 1) throw py::value_error("bins must be >= 1");
    for (double p : percentiles) checkPercentile(p);
    const auto a = keptDoubles(r.a);
    const auto b = keptDoubles(r.b);
    const HausdorffStats s = valueOrRaise(hausdorffStats(r.result, viewOf(a), viewOf(b), options));
    const bool directed = r.result.directedOnly;
    py::dict d;
    d["diagonal"] = s.diagonal;
    d["diagonal_a"] = s.diagonalA;
    d["diagonal_b"] = s.diagonalB;
    d["a_to_b"] = block(s.aToB);
    d["b_to_a"] = directed ? py::object(py::none()) : py::object(block(s.bToA));
    d["pooled"] = directed ? py::object(py::none()) : py::object(block(s.pooled));
    py::list symmetric;
    for (size_t i = 0; i < s.symmetric.size(); ++i) {
        py::dict p;
        p["p"] = s.symmetric[i].p;
        p["max"] = s.symmetric[i].value;
        p["pooled"] =
            directed ? py::object(py::none()) : py::object(py::float_(s.pooled.percentiles[i].value));
        symmetric.append(p);
    }
    d["percentiles"] = symmetric;
    const Histogram& h = s.aToB.histogram;
    py::dict hist;
    hist["lo"] = h.lo;
    hist["hi"] = h.hi;
    hist["bins"] = h.counts.size();
    py::array_t<double> edges(py::ssize_t(h.counts.size() + 1));
    auto e = edges.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < e.shape(0); ++i)
        e(i) = h.lo + (h.hi - h.lo) * double(i) / double(h.counts.size());
    hist["edges"] = edges;
    hist["a_to_b"] = counts(s.aToB.histogram);
    hist["b_to_a"] = directed ? py::object(py::none()) : py::object(counts(s.bToA.histogram));
    hist["pooled"] = directed ? py::object(py::none()) : py::object(counts(s.pooled.histogram));
    py::dict below, above;
    below["a_to_b"] = s.aToB.histogram.below;
    above["a_to_b"] = s.aToB.histogram.above;
    if (!directed) {
        below["b_to_a"] = s.bToA.histogram.below;
        below["pooled"] = s.pooled.histogram.below;
        above["b_to_a"] = s.bToA.histogram.above;
        above["pooled"] = s.pooled.histogram.above;
    }
    hist["below"] = below;
    hist["above"] = above;
    d["histogram"] = hist;
    return d;
}

std::string directedRepr(const Directed& d) {
    return "Directed(distance=" + std::string(py::str(py::float_(d.distance))) +
           ", query_index=" + std::to_string(d.queryIndex) +
           ", target_index=" + std::to_string(d.targetIndex) + ")";
}

}  // namespace

void bindResult(py::module_& m) {
    py::class_<Directed>(m, "Directed", "One directed distance h(Q, T) with the pair that realizes it.")
        .def_readonly("distance", &Directed::distance, "h(Q, T), recomputed in double from the pair")
        .def_readonly("query_index", &Directed::queryIndex, "index of the farthest query point")
        .def_readonly("target_index", &Directed::targetIndex, "index of its nearest point in the target set")
        .def_property_readonly(
            "query_point", [](const Directed& d) { return point(d.queryPoint); }, "its coordinates (float64)")
        .def_property_readonly(
            "target_point", [](const Directed& d) { return point(d.targetPoint); },
            "its neighbour's coordinates")
        .def_property_readonly(
            "indices", [](const Directed& d) { return py::make_tuple(d.queryIndex, d.targetIndex); },
            "(query_index, target_index)")
        .def_property_readonly(
            "points",
            [](const Directed& d) { return py::make_tuple(point(d.queryPoint), point(d.targetPoint)); },
            "(query_point, target_point)")
        .def_property_readonly(
            "counters", [](const Directed& d) { return counters(d.counters); }, "what the search did (dict)")
        .def_property_readonly(
            "certificate", [](const Directed& d) { return certificate(d.certificate); },
            "the proof that distance is exact in double (dict: confirmed, query, nearest, distance, band, "
            "recomputed)")
        .def("__float__", [](const Directed& d) { return d.distance; })
        .def("__repr__", &directedRepr);

    py::class_<PyResult>(m, "HausdorffResult",
                         "H(A, B) with its witnesses, timings, counters and (per_point=True) per-point "
                         "distances and statistics.")
        .def_property_readonly(
            "distance", [](const PyResult& r) { return r.result.hausdorff; },
            "H(A, B) = max(h(A, B), h(B, A)); h(A, B) when directed")
        .def_property_readonly(
            "directed", [](const PyResult& r) { return r.result.directedOnly; }, "only h(A, B) was computed")
        .def_property_readonly(
            "a_to_b", [](const PyResult& r) { return r.result.aToB; }, "h(A, B) and its witness pair")
        .def_property_readonly(
            "b_to_a",
            [](const PyResult& r) -> py::object {
                if (r.result.directedOnly) return py::none();
                return py::cast(r.result.bToA);
            },
            "h(B, A) and its witness pair; None when directed")
        .def_property_readonly(
            "backend", [](const PyResult& r) { return std::string(backendName(r.result.backend)); },
            "the backend that ran: 'cpu', 'ray-query' or 'rt-pipeline'")
        .def_property_readonly(
            "device", [](const PyResult& r) { return r.result.device; },
            "its device's name ('cpu' for the CPU)")
        .def_property_readonly(
            "origin", [](const PyResult& r) { return point(r.result.origin); },
            "subtracted from both sets before the float32 search (0 for float32 data)")
        .def_property_readonly(
            "timings", [](const PyResult& r) { return timings(r.result.timings); },
            "milliseconds per stage (the CLI's timings_ms; 'total' is the computation without setup)")
        .def_property_readonly(
            "counters",
            [](const PyResult& r) {
                return perDirection(r.result, [](const Directed& d) { return counters(d.counters); });
            },
            "per direction: bits, occupied_cells, queries, culled_by_neighbourhood, ... (the CLI's keys)")
        .def_property_readonly(
            "certificate",
            [](const PyResult& r) {
                return perDirection(r.result, [](const Directed& d) { return certificate(d.certificate); });
            },
            "per direction: the proof that the value is exact in double (the CLI's certificate keys)")
        .def_property_readonly(
            "validation_messages", [](const PyResult& r) { return r.result.validationMessages; },
            "validation-layer messages (validation=True only)")
        .def_property_readonly("a_distances", perPointArray(&HausdorffResult::aNearest, &PerPoint::distance),
                               "every a's nearest distance to B (float64, read-only; exact for float64 "
                               "input, at most a relative "
                               "2^-21 above it for float32); None without per_point")
        .def_property_readonly("a_nearest", perPointArray(&HausdorffResult::aNearest, &PerPoint::nearest),
                               "index in B of every a's nearest point (uint32); None without per_point")
        .def_property_readonly(
            "b_distances", perPointArray(&HausdorffResult::bNearest, &PerPoint::distance),
            "every b's nearest distance to A (as a_distances); None without per_point or when directed")
        .def_property_readonly(
            "b_nearest", perPointArray(&HausdorffResult::bNearest, &PerPoint::nearest),
            "index in A of every b's nearest point; None without per_point or when directed")
        .def("percentile", &percentile, py::arg("q"), py::arg("variant") = "max",
             "Nearest-rank percentile q in [0, 100] of the per-point distances (stats.hpp): 'max' "
             "(default) = max(P_q(d_A), P_q(d_B)), 'pooled' = P_q(d_A + d_B), or one direction "
             "('a_to_b', 'b_to_a'). percentile(100) == distance. Needs per_point=True.")
        .def_property_readonly(
            "hd95", [](PyResult& r) { return percentile(r, 95.0, "max"); },
            "percentile(95): the symmetric 95th percentile (HD95). Needs per_point=True")
        .def_property_readonly(
            "mean",
            [](PyResult& r) {
                const std::vector<double>& d = meanSet(r);
                return distanceStats(d, StatsOptions{{}, 1}, 0.0, 1.0).mean;
            },
            "mean of the pooled per-point distances (A->B only when directed). Needs per_point=True")
        .def_property_readonly(
            "rms",
            [](PyResult& r) {
                const std::vector<double>& d = meanSet(r);
                return distanceStats(d, StatsOptions{{}, 1}, 0.0, 1.0).rms;
            },
            "root mean square of the pooled per-point distances. Needs per_point=True")
        .def("stats", &stats, py::arg("percentiles") = std::vector<double>{50.0, 90.0, 95.0, 99.0},
             py::arg("bins") = 20, py::arg("range") = py::none(),
             "The CLI's --per-point statistics (stats.hpp) as a dict: a_to_b / b_to_a / pooled blocks "
             "(count, min, max, mean, rms, percentiles), symmetric percentiles, diagonals and the "
             "histogram over [0, max] (or range=(lo, hi), finite, lo < hi: else ValueError). Needs "
             "per_point=True.")
        .def(
            "histogram",
            [](PyResult& r, int bins, py::object range) {
                // A dict of its own (an item accessor of the temporary stats
                // dict would outlive it).
                const py::dict all = stats(r, {}, bins, std::move(range));
                return py::dict(all["histogram"]);
            },
            py::arg("bins") = 20, py::arg("range") = py::none(),
            "stats(bins=bins, range=range)['histogram']: counts per direction and pooled, edges, "
            "below/above.")
        .def("__float__", [](const PyResult& r) { return r.result.hausdorff; })
        .def("__repr__", [](const PyResult& r) {
            std::string s =
                "HausdorffResult(distance=" + std::string(py::str(py::float_(r.result.hausdorff))) +
                ", backend='" + backendName(r.result.backend) + "', a_to_b=" + directedRepr(r.result.aToB);
            if (!r.result.directedOnly) s += ", b_to_a=" + directedRepr(r.result.bToA);
            return s + ")";
        });
}

}  // namespace rthdist::python
