// The queries of a float search as the device takes them (x y z w = 0 floats
// a query, in the search's frame): a span of framed floats, or the caller's
// framing writing them straight into the search's upload buffer (the GPU
// surface search, gpu_algo/surface_search.cpp: no framed copy of its own
// and no pass to copy it, ~0.03 ms of a 36k-point call on the H200's
// 16 cores, docs/bench/surfaces, session 29).
//
// Contract: writeTo(begin, end, out) writes queries [begin, end) to
// out[0 .. end - begin); it is called from several threads at once on
// disjoint ranges and must not throw. The same bits either way: a writer
// gives each query what the span would hold.
#pragma once

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstddef>
#include <functional>
#include <span>

namespace rthdist::core {

struct FramedQueries {
    size_t count = 0;
    std::span<const glm::vec3> floats;                                    // where given: count of them
    std::function<void(size_t begin, size_t end, glm::vec4* out)> write;  // else

    [[nodiscard]] static FramedQueries of(std::span<const glm::vec3> framed) {
        return FramedQueries{framed.size(), framed, {}};
    }
    void writeTo(size_t begin, size_t end, glm::vec4* out) const {
        if (write) {
            write(begin, end, out);
            return;
        }
        for (size_t i = begin; i < end; ++i) out[i - begin] = glm::vec4(floats[i], 0.0f);
    }
};

}  // namespace rthdist::core
