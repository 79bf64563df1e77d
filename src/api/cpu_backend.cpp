// The CPU backend (src/cpu) as the Engine's backend (api/backend.hpp): one
// lane, no scan, no device ingest, no device views.
#include <memory>
#include <string>
#include <utility>

#include "api/backend.hpp"
#include "cpu/cpu_hausdorff.hpp"

namespace rthdist::api {

namespace {

class CpuPrepared final : public BackendSet {
public:
    explicit CpuPrepared(std::shared_ptr<cpu::CpuSet> set) : set(std::move(set)) {}
    [[nodiscard]] int bits() const override { return set->order.grid.bits; }
    [[nodiscard]] uint64_t deviceBytes() const override { return 0; }
    [[nodiscard]] uint64_t hostBytes() const override { return set->hostBytes(); }
    std::shared_ptr<cpu::CpuSet> set;
};

const cpu::CpuSet& cpuSet(const BackendSet& set) { return *static_cast<const CpuPrepared&>(set).set; }

class CpuBackend final : public ComputeBackend {
public:
    explicit CpuBackend(const EngineOptions& options) : m_options(options) {}

    [[nodiscard]] Backend kind() const override { return Backend::kCpu; }
    [[nodiscard]] const std::string& deviceName() const override { return m_name; }
    [[nodiscard]] BackendCaps caps() const override {
        BackendCaps caps;
        caps.noDeviceViews =
            "device views (DevicePointView) need a GPU backend: the cpu backend cannot read VkBuffers";
        return caps;
    }
    [[nodiscard]] MemoryBudget memoryBudget() const override {
        MemoryBudget budget;
        if (m_options.memoryBudget > 0) {
            budget.bytes = m_options.memoryBudget;
            budget.source = "EngineOptions::memoryBudget";
        }
        return budget;
    }

    [[nodiscard]] Result<HausdorffResult> computeFramed(int /*lane*/, std::span<const glm::vec3> a,
                                                        std::span<const glm::vec3> b, double scale,
                                                        const CallOptions& call,
                                                        const core::PerPointFloor& floor) override {
        Options options;
        static_cast<CallOptions&>(options) = call;
        static_cast<EngineOptions&>(options) = m_options;
        return cpu::cpuHausdorff(a, b, scale, options, floor);
    }

    [[nodiscard]] Result<std::shared_ptr<BackendSet>> prepare(std::span<const glm::vec3> floats, double scale,
                                                              int bits,
                                                              const std::string& /*name*/) override {
        return std::shared_ptr<BackendSet>(
            std::make_shared<CpuPrepared>(cpu::prepareCpuSet(floats, scale, bits, m_options.threads)));
    }
    [[nodiscard]] Result<HausdorffResult> computePrepared(const BackendSet& a, const BackendSet& b,
                                                          const CallOptions& call) override {
        return cpu::cpuHausdorff(cpuSet(a), cpuSet(b), call, m_options.threads);
    }

private:
    EngineOptions m_options;
    std::string m_name = "cpu";
};

}  // namespace

std::unique_ptr<ComputeBackend> makeCpuBackend(const EngineOptions& options) {
    return std::make_unique<CpuBackend>(options);
}

}  // namespace rthdist::api
