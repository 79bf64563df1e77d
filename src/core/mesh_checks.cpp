#include "core/mesh_checks.hpp"

#include <atomic>
#include <cstdint>

#include "core/parallel.hpp"

namespace rthdist::core {

std::optional<Error> checkTriangles(const MeshView& mesh, const std::string& name, int threads) {
    if (mesh.indices.size() % 3 != 0) {
        return Error{ErrorCode::kInvalidArgument,
                     name + ": " + std::to_string(mesh.indices.size()) +
                         " indices are not a whole number of triangles (3 each)"};
    }
    if (mesh.triangleCount() == 0)
        return Error{ErrorCode::kInvalidArgument, name + " has no triangles: the distance is undefined"};
    if (mesh.triangleCount() > UINT32_MAX || mesh.vertices.count > UINT32_MAX) {
        return Error{ErrorCode::kInvalidArgument,
                     name + ": at most 2^32 - 1 triangles and vertices (32-bit indices), not " +
                         std::to_string(mesh.triangleCount()) + " triangles of " +
                         std::to_string(mesh.vertices.count) + " vertices"};
    }
    const size_t n = mesh.indices.size();
    std::atomic<size_t> first{n};
    parallelChunks(n, size_t(1) << 16, threads, [&](size_t begin, size_t end, int) {
        if (begin >= first.load(std::memory_order_relaxed)) return;
        for (size_t i = begin; i < end; ++i) {
            if (mesh.indices[i] < mesh.vertices.count) continue;
            size_t seen = first.load(std::memory_order_relaxed);
            while (i < seen && !first.compare_exchange_weak(seen, i, std::memory_order_relaxed)) {
            }
            return;
        }
    });
    const size_t at = first.load();
    if (at == n) return std::nullopt;
    return Error{ErrorCode::kInvalidArgument, name + ": triangle " + std::to_string(at / 3) +
                                                  ": vertex index " + std::to_string(mesh.indices[at]) +
                                                  " out of range (" + std::to_string(mesh.vertices.count) +
                                                  " vertices)"};
}

}  // namespace rthdist::core
