#include <chrono>
#include <cstdio>
#include <random>
#include <vector>
#include "api/spatial_pieces.hpp"
using namespace rthdist;
int main(int argc, char** argv) {
    size_t n = argc > 1 ? std::stoul(argv[1]) : 20000000;
    int order = argc > 2 ? std::atoi(argv[2]) : 1;
    std::vector<glm::vec3> a(n), b(n);
    std::mt19937 g(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (auto& p : a) p = {u(g), u(g), u(g)};
    for (auto& p : b) p = {u(g), u(g), u(g)};
    for (int rep = 0; rep < 7; ++rep) {
        auto t0 = std::chrono::steady_clock::now();
        auto pieces =
            api::SpatialPieces::partition(a, b, 1.0, api::PieceLimits{n / 4, n / 4}, 0,
                                          order ? api::PieceOrder::kBlocks : api::PieceOrder::kInput);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("total %.1f scatter %.1f keys %.1f pieces %zu\n", ms, pieces.passTimes().scatter,
                    pieces.passTimes().keys, pieces.count());
    }
}
