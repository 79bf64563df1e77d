// Surface to surface on a GPU backend (planSurfacePairRoute's kSurfaceGpu;
// design.md §12, "On a GPU backend"): the refinement of
// cpu/surface_bounds.hpp with each round's batch searched by the device's
// float search (ComputeBackend::nearestTriangles, the point-to-surface
// route's) and proven on the host (api/surface_certify.hpp):
//   - every sample's distance is the shared rule in double to its
//     candidate triangle (its exact nearest where the device left it open):
//     a real triangle's distance, so an upper bound of its exact distance,
//     which is all the patches' bounds need to hold;
//   - the batch's maximum is proven exactly (its witness and its nearest
//     triangle, the brute force's), which is all the lower bound needs.
// So the bounds are certified whatever the device found. What the device's
// rounding decides is only how far a candidate's distance can exceed the
// exact one: the float rule's error is below 2^-18 of the search frame
// (surface_certify.cpp, kSearchedReach), so a candidate is within 2^-17 of
// the nearest; a patch settles once its corners' distances are within the
// tolerance less 2 slack of the lower bound, hence the floor below (8x that
// reach).
#pragma once

#include <glm/vec3.hpp>

#include <atomic>
#include <span>

#include "api/backend.hpp"
#include "api/surface_gpu.hpp"
#include "core/uninit_vector.hpp"
#include "cpu/sample_search.hpp"
#include "rthdist/mesh.hpp"

namespace rthdist::api {

// The smallest tolerance a GPU backend takes, in the search frame's units
// (SearchFrame: |coordinate| <= 1): 2^-14 / SearchFrame::scale in the
// meshes' units, at most 2^-14 (~6.1e-5) of the diagonal of their box, so
// the default tolerance (1e-4 of it) is always above it. Below it the call
// is refused naming it (the CPU backend reaches 4 slack).
inline constexpr double kGpuPairFloor = 0x1p-14;

class DeviceSampleSearch final : public cpu::SampleSearch {
public:
    // to: the other surface in the work frame (it outlives the search);
    // frame: of both meshes' boxes in the work frame (every sample lies in
    // them); magnitude: the largest |coordinate| of both there
    // (core::closestSlack's); threads as EngineOptions::threads; cancel read
    // between the device's submissions and by the proof. The corners are
    // framed once here, for every batch.
    DeviceSampleSearch(ComputeBackend& device, const MeshView& to, const SearchFrame& frame, double magnitude,
                       int threads, const std::atomic<bool>* cancel);
    [[nodiscard]] Result<size_t> search(std::span<const glm::dvec3> points, std::span<double> distance,
                                        std::span<uint32_t> nearest) override;
    [[nodiscard]] double gpuMs() const { return m_gpuMs; }

private:
    ComputeBackend& m_device;
    const MeshView& m_to;
    SearchFrame m_frame;
    double m_magnitude = 0.0;
    int m_threads = 0;
    const std::atomic<bool>* m_cancel = nullptr;
    core::UninitVector<glm::vec3> m_corners;
    uint64_t m_cornersVersion;  // theirs for every round's search (the device keeps its tree)
    double m_gpuMs = 0.0;
};

}  // namespace rthdist::api
