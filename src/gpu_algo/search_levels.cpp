#include "gpu_algo/index_build.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/parallel.hpp"
#include "gpu/device_limits.hpp"
#include "gpu_algo/self_check.hpp"

namespace rthdist::gpu_algo {

const PointIndex::Level& IndexBuild::searchLevel(PointIndex& T, int level) {
    while (int(T.levels.size()) < level) {
        const int j = int(T.levels.size()) + 1;
        Buffer* finer = j == 1 ? T.cells : T.levels.back().cells;
        Buffer* finerFineFirst = j == 1 ? T.cells : T.levels.back().fineFirst;  // unused at j = 1
        const uint32_t numFiner = j == 1 ? T.numCells : T.levels.back().count;
        const std::string tag = ".level" + std::to_string(j);
        PointIndex::Level lv;
        if (T.store->levels.size() < size_t(j)) T.store->levels.resize(size_t(j));
        SetBuffers::Level& memory = T.store->levels[size_t(j - 1)];
        lv.cells = &m_ws.setBuffer(T, memory.cells, tag.c_str(), VkDeviceSize(numFiner) * sizeof(sh::Cell));
        lv.fineFirst =
            &m_ws.setBuffer(T, memory.fineFirst, (tag + ".fineFirst").c_str(), VkDeviceSize(numFiner) * 4);
        Buffer& flags = m_ws.grow(m_ws.scratch.levels.flags, VkDeviceSize(numFiner) * 4, "level.flags");
        auto t0 = Clock::now();
        VkCommandBuffer cmd = m_ws.ctx.begin();
        m_ws.ctx.cmdBeginLabel(cmd, "search level");
        sh::CoarsenPush co{finer->address(),
                           T.sortedKeys->address(),
                           flags.address(),
                           lv.cells->address(),
                           m_ws.cellsCounterAddr(),
                           finerFineFirst->address(),
                           lv.fineFirst->address(),
                           numFiner,
                           0,
                           uint32_t(3 * j)};
        m_ws.dispatch(cmd, Kernel::kCoarsen, co, numFiner);
        m_ws.barrier(cmd);
        m_ws.cmdScan(cmd, flags.address(), numFiner, m_ws.scratch.levels.scan, "level.scan");
        m_ws.barrier(cmd);
        co.mode = 1;
        m_ws.dispatch(cmd, Kernel::kCoarsen, co, numFiner);
        m_ws.ctx.cmdEndLabel(cmd);
        m_ws.ctx.submitAndWait(cmd);
        m_ws.timings->gpuIndex += m_ws.ctx.lastGpuMs();
        m_ws.timings->index += msSince(t0);
        lv.count = m_ws.counters().cells;
        T.levels.push_back(lv);
    }
    return T.levels[size_t(level - 1)];
}

PointIndex::Level IndexBuild::levelCells(PointIndex& T, int level) {
    return level > 0 ? searchLevel(T, level) : PointIndex::Level{T.cells, nullptr, T.numCells};
}

}  // namespace rthdist::gpu_algo
