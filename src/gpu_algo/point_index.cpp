#include "gpu_algo/point_index.hpp"

namespace rthdist::gpu_algo {

static_assert(sizeof(sh::Cell) == 32 && offsetof(sh::Cell, hi) == 16 && offsetof(sh::Cell, count) == 28);
static_assert(sizeof(sh::GridParams) == 32);
static_assert(sizeof(sh::LeafGroup) == 32 && offsetof(sh::LeafGroup, hi) == 16);

uint64_t SetBuffers::bytes() const {
    uint64_t total = 0;
    for (const Buffer* b : {&sorted, &sortedKeys, &dense, &cells, &sorted2, &sortedKeys2, &leaves0, &leaves1,
                            &groupFirst, &leafGroups})
        total += b->size();
    for (const Level& level : levels) total += level.cells.size() + level.fineFirst.size();
    return total;
}

void SetBuffers::releaseUnused(const PointIndex& ix) {
    for (Buffer* b : {&sorted, &sortedKeys, &dense, &cells, &sorted2, &sortedKeys2, &leaves0, &leaves1,
                      &groupFirst, &leafGroups}) {
        const bool used = b == ix.sorted || b == ix.dense || b == ix.cells || b == ix.sortedKeys ||
                          b == ix.groupFirst || b == ix.groups;
        if (!used) b->reset();
    }
}

sh::GridParams gridParams(const core::GridSpec& g) {
    sh::GridParams p{};
    p.originX = float(g.origin.x);
    p.originY = float(g.origin.y);
    p.originZ = float(g.origin.z);
    p.cellSize = float(g.cellSize);
    p.invCellSize = float(1.0 / g.cellSize);
    p.bits = uint32_t(g.bits);
    p.cellsPerAxis = g.cellsPerAxis;
    return p;
}

}  // namespace rthdist::gpu_algo
