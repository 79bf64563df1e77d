// surface-cgal: CGAL 5.5's answers to rthdist's surface questions, for the
// side-by-side benchmark (tools/bench/surface_peers.py, issue 34). Not part of
// the library; built only when CGAL is found (tools/CMakeLists.txt).
//
//   surface-cgal points A.ply B.ply [--threads N] [--repeat R]
//     h(A's vertices, B's triangles), directed: every vertex of A queries an
//     AABB_tree over B's triangles (closest_point_and_primitive, with the
//     tree's default KD-tree hint), on N threads (0: every hardware thread),
//     and the largest distance is kept with its witness.
//   surface-cgal surfaces A.ply B.ply --tolerance T [--directed] [--repeat R]
//     CGAL::Polygon_mesh_processing::bounded_error_symmetric_Hausdorff_distance
//     (or bounded_error_Hausdorff_distance with --directed) at error bound T
//     (absolute). CGAL 5.5 runs it on one thread whatever the tag: its header
//     says "the parallel version is not implemented and the sequential version
//     is always used", and Parallel_tag is a compile error without METIS. The
//     value CGAL returns is its lower bound (its upper is at most T above).
//
// Input: the benchmark's prepared PLY files only (binary little endian, float
// x y z vertices, optionally a face list of uchar count and int indices,
// triangles), as surface_peers.py writes them. Output: one JSON object on
// stdout with the value, the witness, and each repeat's milliseconds (file
// reading and mesh assembly excluded; the tree build included).
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

struct PlyMesh {
    std::vector<std::array<float, 3>> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
};

// The prepared files' one layout (see the header comment); anything else is an error.
PlyMesh readPreparedPly(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::string line;
    uint64_t vertexCount = 0, faceCount = 0;
    std::vector<std::string> header;
    while (std::getline(in, line)) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        header.push_back(line);
        if (line == "end_header") break;
    }
    if (header.empty() || header.front() != "ply" || header.back() != "end_header")
        throw std::runtime_error(path + ": not a PLY file");
    std::string element;
    int vertexProperties = 0;
    for (const std::string& h : header) {
        std::istringstream words(h);
        std::string key;
        words >> key;
        if (key == "format") {
            std::string format;
            words >> format;
            if (format != "binary_little_endian")
                throw std::runtime_error(path + ": expected binary_little_endian");
        } else if (key == "element") {
            uint64_t count = 0;
            words >> element >> count;
            if (element == "vertex")
                vertexCount = count;
            else if (element == "face")
                faceCount = count;
            else
                throw std::runtime_error(path + ": unexpected element " + element);
        } else if (key == "property") {
            std::string type;
            words >> type;
            if (element == "vertex") {
                if (type != "float")
                    throw std::runtime_error(path + ": vertex properties must be float x y z");
                ++vertexProperties;
            } else if (type != "list" || h.find("uchar int") == std::string::npos) {
                throw std::runtime_error(path + ": faces must be 'list uchar int'");
            }
        }
    }
    if (vertexProperties != 3) throw std::runtime_error(path + ": vertex properties must be float x y z");
    PlyMesh mesh;
    mesh.vertices.resize(vertexCount);
    in.read(reinterpret_cast<char*>(mesh.vertices.data()), std::streamsize(vertexCount * 12));
    mesh.triangles.resize(faceCount);
    for (auto& t : mesh.triangles) {
        unsigned char n = 0;
        int32_t index[3];
        in.read(reinterpret_cast<char*>(&n), 1);
        if (n != 3) throw std::runtime_error(path + ": a face that is not a triangle");
        in.read(reinterpret_cast<char*>(index), 12);
        for (int k = 0; k < 3; ++k) {
            if (index[k] < 0 || uint64_t(index[k]) >= vertexCount)
                throw std::runtime_error(path + ": index out of range");
            t[k] = uint32_t(index[k]);
        }
    }
    if (!in) throw std::runtime_error(path + ": file ends early");
    return mesh;
}

double millisecondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

std::string jsonList(const std::vector<double>& values) {
    std::string s = "[";
    char buffer[64];
    for (size_t i = 0; i < values.size(); ++i) {
        std::snprintf(buffer, sizeof buffer, "%s%.6f", i ? ", " : "", values[i]);
        s += buffer;
    }
    return s + "]";
}

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// ---- points: A's vertices to B's triangles --------------------------------

using PointKernel = CGAL::Simple_cartesian<double>;
using Triangles = std::vector<PointKernel::Triangle_3>;
using TrianglePrimitive = CGAL::AABB_triangle_primitive<PointKernel, Triangles::const_iterator>;
using TriangleTree = CGAL::AABB_tree<CGAL::AABB_traits<PointKernel, TrianglePrimitive>>;

struct DirectedWitness {
    double distance = -1.0;
    uint64_t query = 0;
    uint64_t triangle = 0;
    PointKernel::Point_3 closest;
};

int runPoints(const PlyMesh& a, const PlyMesh& b, int threads, int repeat) {
    if (b.triangles.empty()) throw std::runtime_error("B has no triangles");
    Triangles triangles;
    triangles.reserve(b.triangles.size());
    auto point = [](const std::array<float, 3>& v) { return PointKernel::Point_3(v[0], v[1], v[2]); };
    for (const auto& t : b.triangles)
        triangles.emplace_back(point(b.vertices[t[0]]), point(b.vertices[t[1]]), point(b.vertices[t[2]]));
    std::vector<PointKernel::Point_3> queries;
    queries.reserve(a.vertices.size());
    for (const auto& v : a.vertices) queries.push_back(point(v));
    if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));

    std::vector<double> buildMs, queryMs, totalMs;
    DirectedWitness best;
    for (int r = 0; r < repeat; ++r) {
        const auto start = std::chrono::steady_clock::now();
        TriangleTree tree(triangles.begin(), triangles.end());
        tree.build();
        tree.accelerate_distance_queries();  // the KD-tree of hints, built now (not by the first query)
        const double built = millisecondsSince(start);
        const auto queryStart = std::chrono::steady_clock::now();
        constexpr uint64_t kChunk = 4096;
        std::atomic<uint64_t> next{0};
        std::vector<DirectedWitness> perThread(static_cast<size_t>(threads));
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t) {
            pool.emplace_back([&, t] {
                DirectedWitness local;
                for (;;) {
                    const uint64_t first = next.fetch_add(kChunk);
                    if (first >= queries.size()) break;
                    const uint64_t last = std::min<uint64_t>(first + kChunk, queries.size());
                    for (uint64_t i = first; i < last; ++i) {
                        const auto found = tree.closest_point_and_primitive(queries[i]);
                        const double d = std::sqrt(CGAL::squared_distance(queries[i], found.first));
                        if (d > local.distance || (d == local.distance && i < local.query))
                            local = {d, i, uint64_t(found.second - triangles.begin()), found.first};
                    }
                }
                perThread[size_t(t)] = local;
            });
        }
        for (auto& worker : pool) worker.join();
        best = DirectedWitness{};
        for (const auto& w : perThread)
            if (w.distance > best.distance || (w.distance == best.distance && w.query < best.query)) best = w;
        queryMs.push_back(millisecondsSince(queryStart));
        buildMs.push_back(built);
        totalMs.push_back(built + queryMs.back());
    }
    std::printf(
        "{\"tool\": \"cgal\", \"cgal_version\": \"%s\", \"mode\": \"points\", \"threads\": %d, \"points\": "
        "%zu, "
        "\"triangles\": %zu,\n \"h\": %.17g, \"query_index\": %llu, \"triangle\": %llu, \"closest\": [%.17g, "
        "%.17g, "
        "%.17g],\n \"build_ms\": %s, \"query_ms\": %s, \"total_ms\": %s, \"median_ms\": %.6f}\n",
        CGAL_VERSION_STR, threads, queries.size(), triangles.size(), best.distance,
        (unsigned long long)best.query, (unsigned long long)best.triangle, best.closest.x(), best.closest.y(),
        best.closest.z(), jsonList(buildMs).c_str(), jsonList(queryMs).c_str(), jsonList(totalMs).c_str(),
        median(totalMs));
    return 0;
}

// ---- surfaces: bounded-error Hausdorff between two triangle meshes --------

using SurfaceKernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<SurfaceKernel::Point_3>;
namespace PMP = CGAL::Polygon_mesh_processing;

// A Surface_mesh with every input triangle: orient_polygon_soup duplicates the
// vertices where the soup is not a manifold, so no face is dropped (checked).
SurfaceMesh toSurfaceMesh(const PlyMesh& in, const char* name) {
    std::vector<SurfaceKernel::Point_3> points;
    points.reserve(in.vertices.size());
    for (const auto& v : in.vertices) points.emplace_back(v[0], v[1], v[2]);
    std::vector<std::vector<std::size_t>> polygons;
    polygons.reserve(in.triangles.size());
    for (const auto& t : in.triangles) polygons.push_back({t[0], t[1], t[2]});
    PMP::orient_polygon_soup(points, polygons);
    SurfaceMesh mesh;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
    if (mesh.number_of_faces() != in.triangles.size()) {
        std::fprintf(stderr, "surface-cgal: %s: %zu of %zu triangles in the Surface_mesh\n", name,
                     size_t(mesh.number_of_faces()), in.triangles.size());
        throw std::runtime_error("a mesh lost triangles on conversion");
    }
    return mesh;
}

int runSurfaces(const PlyMesh& a, const PlyMesh& b, double tolerance, bool directed, int repeat) {
    if (!(tolerance > 0.0)) throw std::runtime_error("surfaces needs --tolerance T > 0");
    const SurfaceMesh meshA = toSurfaceMesh(a, "A"), meshB = toSurfaceMesh(b, "B");
    std::vector<double> totalMs;
    double value = 0.0;
    for (int r = 0; r < repeat; ++r) {
        const auto start = std::chrono::steady_clock::now();
        value = directed
                    ? PMP::bounded_error_Hausdorff_distance<CGAL::Sequential_tag>(meshA, meshB, tolerance)
                    : PMP::bounded_error_symmetric_Hausdorff_distance<CGAL::Sequential_tag>(meshA, meshB,
                                                                                            tolerance);
        totalMs.push_back(millisecondsSince(start));
    }
    std::printf(
        "{\"tool\": \"cgal\", \"cgal_version\": \"%s\", \"mode\": \"surfaces\", \"directed\": %s, "
        "\"threads\": 1, "
        "\"triangles_a\": %zu, \"triangles_b\": %zu,\n \"tolerance\": %.17g, \"h\": %.17g, \"lower\": %.17g, "
        "\"upper\": %.17g,\n \"total_ms\": %s, \"median_ms\": %.6f}\n",
        CGAL_VERSION_STR, directed ? "true" : "false", a.triangles.size(), b.triangles.size(), tolerance,
        value, value, value + tolerance, jsonList(totalMs).c_str(), median(totalMs));
    return 0;
}

int usage() {
    std::fprintf(stderr,
                 "usage: surface-cgal points A.ply B.ply [--threads N] [--repeat R]\n"
                 "       surface-cgal surfaces A.ply B.ply --tolerance T [--directed] [--repeat R]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 4) return usage();
    const std::string mode = argv[1];
    int threads = 0, repeat = 1;
    double tolerance = 0.0;
    bool directed = false;
    for (int i = 4; i < argc; ++i) {
        const std::string option = argv[i];
        const bool hasValue = i + 1 < argc;
        if (option == "--threads" && hasValue)
            threads = std::atoi(argv[++i]);
        else if (option == "--repeat" && hasValue)
            repeat = std::max(1, std::atoi(argv[++i]));
        else if (option == "--tolerance" && hasValue)
            tolerance = std::atof(argv[++i]);
        else if (option == "--directed")
            directed = true;
        else
            return usage();
    }
    try {
        const PlyMesh a = readPreparedPly(argv[2]);
        const PlyMesh b = readPreparedPly(argv[3]);
        if (mode == "points") return runPoints(a, b, threads, repeat);
        if (mode == "surfaces") return runSurfaces(a, b, tolerance, directed, repeat);
        return usage();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "surface-cgal: %s\n", e.what());
        return 1;
    }
}
