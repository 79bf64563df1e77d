// The GPU form of RT-HDIST (Kim, Lee, Kim 2025) on Vulkan, with the exactness
// fixes of DESIGN.md §3-4:
//   1. index space (compute): cell keys, counting sort over a dense key table,
//      run-length encode into occupied cells with tight boxes;
//   2. neighbourhood pass (compute): exact NN inside the 3x3x3 cell block,
//      early break against the running maximum -> most queries die here;
//   3. candidate search (ray query or rt pipeline): boxes grown by radius R,
//      every reported cell within R (and beyond the scanned radius rLo)
//      becomes a (query, cell) pair unless its representative kills the query;
//   4. refinement (compute): exact scan of the pairs' cells, early break;
//      resolve: best <= R -> exact NN; best < threshold -> dead; else R grows.
#pragma once

#include <memory>
#include <span>

#include "rthdist/rthdist.hpp"

namespace rthdist::gpu {
class Context;
}

namespace rthdist::algo {

class GpuHausdorff {
public:
    [[nodiscard]] static Result<std::unique_ptr<GpuHausdorff>> create(gpu::Context& ctx);
    ~GpuHausdorff();
    [[nodiscard]] Result<HausdorffResult> compute(std::span<const glm::vec3> a, std::span<const glm::vec3> b,
                                                  const Options& options);
    // Caps the candidate-pair buffer (default 2^26 pairs); tests shrink it
    // so that queries must retry until their pairs fit.
    void setMaxPairCapacity(uint64_t pairs);

    struct State;

private:
    explicit GpuHausdorff(std::unique_ptr<State> state);
    std::unique_ptr<State> m_state;
};

}  // namespace rthdist::algo
