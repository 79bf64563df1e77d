// PointCloud: a loaded set in its file's precision, seen as a PointView;
// TriangleMesh: its vertices and triangles, seen as a MeshView.
#include "rthdist/io.hpp"

namespace rthdist::io {

size_t PointCloud::size() const { return scalar == Scalar::kFloat64 ? doubles.size() : floats.size(); }

PointView PointCloud::view() const {
    if (scalar == Scalar::kFloat64) return PointView(doubles);
    return PointView(floats);
}

MeshView TriangleMesh::view() const { return MeshView{vertices.view(), indices}; }

}  // namespace rthdist::io
