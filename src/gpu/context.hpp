// Device selection and the single compute queue of an Engine or of the splat
// renderer, on the process's Vulkan instance (gpu/process_instance.hpp) or an
// embedder's. Device selection is headless, takes its requirements as data
// (gpu/device_requirements.hpp) and records why every rejected device was
// rejected (vk-bootstrap's habit). Every handle it creates is owned
// (gpu/unique_handle.hpp): a failure midway releases what exists.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gpu/device_limits.hpp"
#include "gpu/device_requirements.hpp"
#include "gpu/process_instance.hpp"
#include "gpu/unique_handle.hpp"
#include "gpu/vk_check.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/vulkan_interop.hpp"

namespace rthdist::gpu {

// Device-level entry points of the ray-tracing extensions: Debian 12's loader
// (1.3.239) does not export them, so they are fetched with vkGetDeviceProcAddr.
struct RtFunctions {
    PFN_vkGetAccelerationStructureBuildSizesKHR getBuildSizes = nullptr;
    PFN_vkCreateAccelerationStructureKHR createAccel = nullptr;
    PFN_vkDestroyAccelerationStructureKHR destroyAccel = nullptr;
    PFN_vkCmdBuildAccelerationStructuresKHR cmdBuildAccel = nullptr;
    PFN_vkGetAccelerationStructureDeviceAddressKHR getAccelAddress = nullptr;
    PFN_vkCreateRayTracingPipelinesKHR createRtPipelines = nullptr;
    PFN_vkGetRayTracingShaderGroupHandlesKHR getGroupHandles = nullptr;
    PFN_vkCmdTraceRaysKHR cmdTraceRays = nullptr;
    // Where the device has rayTracingPipelineTraceRaysIndirect (optional).
    PFN_vkCmdTraceRaysIndirectKHR cmdTraceRaysIndirect = nullptr;
};

// Every Vulkan physical device with what each backend it lacks (one
// instance, no device created): the data behind rthdist::listDevices.
[[nodiscard]] Result<std::vector<DeviceInfo>> describeDevices();

class Context {
public:
    // backend: kAuto, kRayQuery or kRtPipeline (backendRequirements; kAuto:
    // ray query where the chosen device has it, else the ray-tracing
    // pipeline). deviceIndex -1 = the best usable device (discrete first).
    // `tuning`: host import, debug labels, submit trace, fence polling
    // (rthdist/tuning.hpp; default: none of them, the library's fence time).
    [[nodiscard]] static Result<std::unique_ptr<Context>> create(Backend backend, int deviceIndex,
                                                                 bool validation, const Tuning& tuning = {});
    // The device (deviceIndex, or the best usable one) that meets one of
    // `alternatives`, the first it meets on that device; backend() is that
    // alternative's. kNoDevice names `purpose` ("backend ray-query", "the
    // splat renderer") and every rejected device with what it lacks.
    [[nodiscard]] static Result<std::unique_ptr<Context>> create(
        std::span<const DeviceRequirements> alternatives, const std::string& purpose, int deviceIndex,
        bool validation, const Tuning& tuning = {});
    // Wraps an embedder's instance, device and queue (rthdist/vulkan_interop.hpp)
    // without owning them: the context creates and destroys only its own
    // children (command pool, fence, query pool, messenger). `backend`
    // (kRayQuery, kRtPipeline, kAuto: ray query where the device has it) must
    // be the one whose VulkanDeviceSetup the device was created with; the
    // physical device must meet its requirements (kNoDevice naming what it
    // lacks), and the queue family must have compute and timestamps.
    [[nodiscard]] static Result<std::unique_ptr<Context>> borrow(const VulkanDevice& handles, Backend backend,
                                                                 bool validation, const Tuning& tuning = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    // The process's instance (gpu/process_instance.hpp) or the embedder's.
    [[nodiscard]] VkInstance instance() const { return m_instanceHandle; }
    [[nodiscard]] VkDevice device() const { return m_deviceHandle; }
    [[nodiscard]] VkPhysicalDevice physicalDevice() const { return m_physical; }
    [[nodiscard]] VkQueue queue() const { return m_queue; }
    // kRayQuery or kRtPipeline; kAuto for a compute-only context (no ray tracing).
    [[nodiscard]] Backend backend() const { return m_backend; }
    [[nodiscard]] const std::string& deviceName() const { return m_name; }
    // The device is the embedder's (borrow): device input is possible.
    [[nodiscard]] bool borrowed() const { return m_borrowed; }
    // shaderFloat64 is enabled on the device (double views of device input,
    // the bit count's probe): on every device that has it.
    [[nodiscard]] bool shaderFloat64() const { return m_shaderFloat64; }
    // The device runs on the host's cores (VK_PHYSICAL_DEVICE_TYPE_CPU: lavapipe).
    [[nodiscard]] bool cpuDevice() const { return m_cpuDevice; }
    [[nodiscard]] const RtFunctions& rt() const { return m_rt; }
    [[nodiscard]] const VkPhysicalDeviceRayTracingPipelinePropertiesKHR& rtProps() const { return m_rtProps; }
    [[nodiscard]] const VkPhysicalDeviceAccelerationStructurePropertiesKHR& asProps() const {
        return m_asProps;
    }
    // Size limits of the device (design.md §9); setLimits replaces them (tests
    // shrink them to cross every split boundary with small inputs; a larger
    // value than the device's would be unsafe).
    [[nodiscard]] const DeviceLimits& limits() const { return m_limits; }
    void setLimits(const DeviceLimits& limits) { m_limits = limits; }
    // Validation messages since this Context was made: its borrowed
    // instance's messenger's, or the process instance's (which Contexts
    // alive at the same time share: gpu/process_instance.hpp).
    [[nodiscard]] uint64_t validationMessageCount() const {
        return m_validationMessages.load() +
               (m_process != nullptr ? m_process->messages.load() - m_processMessagesBefore : 0);
    }
    [[nodiscard]] uint32_t memoryTypeIndex(uint32_t typeBits, VkMemoryPropertyFlags wanted) const;
    [[nodiscard]] float timestampPeriodNs() const { return m_timestampPeriod; }
    // VK_EXT_external_memory_host is on (host arrays can be imported in
    // place, gpu/host_import.hpp), with its pointer alignment.
    [[nodiscard]] bool hostImport() const { return m_hostImport; }
    [[nodiscard]] VkDeviceSize importAlignment() const { return m_importAlignment; }
    [[nodiscard]] PFN_vkGetMemoryHostPointerPropertiesEXT getHostPointerProperties() const {
        return m_getHostPointerProperties;
    }

    // One-shot command buffers: begin() returns a recording buffer;
    // submitAndWait() submits it and blocks until the queue has executed it.
    [[nodiscard]] VkCommandBuffer begin();
    void submitAndWait(VkCommandBuffer cmd);
    // Device milliseconds between begin() and the end of the last submitted
    // command buffer (timestamp queries).
    [[nodiscard]] double lastGpuMs() const { return m_lastGpuMs; }
    // A timestamp after the commands recorded so far (at most
    // kTimestampSlots - 2 per command buffer); returns its mark, 0 being
    // begin(). After submitAndWait, gpuMsBetween(mark, later mark) times the
    // commands between them (e.g. the uploads of a submission).
    uint32_t cmdMark(VkCommandBuffer cmd);
    [[nodiscard]] double gpuMsBetween(uint32_t from, uint32_t to) const;
    // RTHDIST_SUBMIT_TRACE is set: stages may add their own stderr lines.
    [[nodiscard]] bool tracingSubmits() const { return m_traceSubmits; }
    // With RTHDIST_SUBMIT_TRACE, a mark (cmdMark) where slots remain: the
    // submission's trace line then lists the device time between its marks
    // (a stage's phases); nothing otherwise.
    void cmdTraceMark(VkCommandBuffer cmd) {
        if (m_traceSubmits && m_marks + 2 < kTimestampSlots) cmdMark(cmd);
    }
    static constexpr uint32_t kTimestampSlots = 40;

    // Debug utilities (VK_EXT_debug_utils, enabled with validation, or with
    // Tuning::debugLabels, RTHDIST_DEBUG_LABELS=1, for GPU captures). Without it
    // they do nothing, so callers never test for it.
    //
    // Gives a Vulkan object a debug name (shown in validation messages and
    // captures).
    void setDebugName(VkObjectType type, uint64_t handle, const char* name) const;
    // Opens / closes a labelled region of a command buffer: GPU captures
    // (RenderDoc, Nsight) show the commands between as one named step, and
    // validation messages name the region. Regions nest; each begin needs an
    // end in the same command buffer (ScopedLabel below pairs them).
    void cmdBeginLabel(VkCommandBuffer cmd, const char* name) const;
    void cmdEndLabel(VkCommandBuffer cmd) const;

private:
    Context() = default;
    // The steps of create(), in order.
    [[nodiscard]] std::optional<Error> createInstance(bool validation);
    // The messenger that counts validation messages on a borrowed instance.
    [[nodiscard]] std::optional<Error> createMessenger();
    // borrow(): the handles checked and adopted, the debug-utils entry points.
    [[nodiscard]] std::optional<Error> adopt(const VulkanDevice& handles, const DeviceRequirements& req,
                                             bool validation);
    void loadLabelFunctions();
    void createDevice(const DeviceRequirements& req);
    [[nodiscard]] std::optional<Error> loadRtFunctions(const DeviceRequirements& req);
    void readProperties(const DeviceRequirements& req);
    void createCommandObjects();

    // Declared in creation order: destroyed in reverse, children first.
    // The process's instance (kept for the process), or null when borrowed.
    ProcessInstance* m_process = nullptr;
    uint64_t m_processMessagesBefore = 0;
    VkInstance m_instanceHandle = VK_NULL_HANDLE;
    UniqueMessenger m_messenger;
    PFN_vkSetDebugUtilsObjectNameEXT m_setObjectName = nullptr;
    PFN_vkCmdBeginDebugUtilsLabelEXT m_cmdBeginLabel = nullptr;
    PFN_vkCmdEndDebugUtilsLabelEXT m_cmdEndLabel = nullptr;
    VkPhysicalDevice m_physical = VK_NULL_HANDLE;
    UniqueDevice m_device;  // empty when borrowed
    VkDevice m_deviceHandle = VK_NULL_HANDLE;
    bool m_borrowed = false;
    bool m_shaderFloat64 = false;
    VkQueue m_queue = VK_NULL_HANDLE;
    uint32_t m_queueFamily = 0;
    UniqueCommandPool m_pool;
    VkCommandBuffer m_cmd = VK_NULL_HANDLE;  // freed with m_pool
    UniqueFence m_fence;
    UniqueQueryPool m_timestamps;
    double m_lastGpuMs = 0.0;
    uint32_t m_marks = 1;  // timestamps written since begin()
    Tuning m_tuning;       // create's or borrow's
    // Tuning::traceSubmits: one stderr line per submission (host time
    // recording it, waiting for it, its device time; a benchmark's tool).
    bool m_traceSubmits = false;
    bool m_cpuDevice = false;
    void traceSubmit(uint32_t last);  // last: the submission's end mark
    // How long submitAndWait polls its fence before it sleeps on it
    // (Tuning::fenceSpinMicros; 0: never).
    unsigned long m_spinMicros = 2000;
    [[nodiscard]] VkResult waitBriefly(VkFence fence) const;
    std::chrono::steady_clock::time_point m_begun, m_submitted, m_lastDone;
    std::array<uint64_t, kTimestampSlots> m_stamps{};  // of the last submission
    uint32_t m_timestampBits = 64;
    Backend m_backend = Backend::kRayQuery;
    std::string m_name;
    RtFunctions m_rt;
    VkPhysicalDeviceRayTracingPipelinePropertiesKHR m_rtProps{};
    VkPhysicalDeviceAccelerationStructurePropertiesKHR m_asProps{};
    VkPhysicalDeviceMemoryProperties m_memProps{};
    DeviceLimits m_limits;
    float m_timestampPeriod = 1.0f;
    bool m_hostImport = false;
    VkDeviceSize m_importAlignment = 0;
    PFN_vkGetMemoryHostPointerPropertiesEXT m_getHostPointerProperties = nullptr;
    std::atomic<uint64_t> m_validationMessages{0};
};

// A debug-utils label over the commands recorded during its lifetime:
//
//     {
//         gpu::ScopedLabel label(ctx, cmd, "cull");
//         ... cmd* calls ...
//     }
//
// Nothing is recorded when the instance has no VK_EXT_debug_utils.
class ScopedLabel {
public:
    ScopedLabel(const Context& ctx, VkCommandBuffer cmd, const char* name) : m_ctx(ctx), m_cmd(cmd) {
        m_ctx.cmdBeginLabel(m_cmd, name);
    }
    ~ScopedLabel() { m_ctx.cmdEndLabel(m_cmd); }
    ScopedLabel(const ScopedLabel&) = delete;
    ScopedLabel& operator=(const ScopedLabel&) = delete;

private:
    const Context& m_ctx;
    VkCommandBuffer m_cmd;
};

}  // namespace rthdist::gpu
