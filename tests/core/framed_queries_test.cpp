// A float search's queries (core/framed_queries.hpp): the span form writes
// each query as x y z 0, and a writer's queries are the ones asked for,
// whatever the ranges (the GPU surface search asks a block at a time).
#include <gtest/gtest.h>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <vector>

#include "core/framed_queries.hpp"

namespace rthdist {
namespace {

TEST(FramedQueries, TheSpanAndAWriterGiveTheSameFloats) {
    std::vector<glm::vec3> framed;
    for (int i = 0; i < 1000; ++i)
        framed.emplace_back(0.001f * float(i), -0.5f + 0.002f * float(i), 1.0f / float(i + 1));
    const core::FramedQueries given = core::FramedQueries::of(framed);
    core::FramedQueries written;
    written.count = framed.size();
    written.write = [&framed](size_t begin, size_t end, glm::vec4* out) {
        for (size_t i = begin; i < end; ++i) out[i - begin] = glm::vec4(framed[i], 0.0f);
    };
    ASSERT_EQ(given.count, framed.size());
    for (const size_t block : {size_t(1), size_t(7), size_t(256), size_t(1000)}) {
        std::vector<glm::vec4> a(framed.size(), glm::vec4(-1.0f)), b(framed.size(), glm::vec4(-2.0f));
        for (size_t begin = 0; begin < framed.size(); begin += block) {
            const size_t end = std::min(framed.size(), begin + block);
            given.writeTo(begin, end, &a[begin]);
            written.writeTo(begin, end, &b[begin]);
        }
        for (size_t i = 0; i < framed.size(); ++i) {
            EXPECT_EQ(a[i], glm::vec4(framed[i], 0.0f)) << "query " << i << " block " << block;
            EXPECT_EQ(b[i], a[i]) << "query " << i << " block " << block;
        }
    }
}

}  // namespace
}  // namespace rthdist
