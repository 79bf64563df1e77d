// PointCloud: a loaded set in its file's precision, seen as a PointView;
// TriangleMesh: its vertices and triangles, seen as a MeshView.
#include <span>

#include "rthdist/io.hpp"

namespace rthdist::io {

size_t PointCloud::size() const { return scalar == Scalar::kFloat64 ? doubles.size() : floats.size(); }

PointView PointCloud::view() const {
    if (scalar == Scalar::kFloat64) return PointView(std::span<const glm::dvec3>(doubles));
    return PointView(std::span<const glm::vec3>(floats));
}

MeshView TriangleMesh::view() const { return MeshView{vertices.view(), indices}; }

}  // namespace rthdist::io
