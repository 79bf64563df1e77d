// rthdist-device-input-bench: H of two point sets that already lie in the
// GPU's memory (rthdist/vulkan_interop.hpp), as an embedding Vulkan
// application holds them, against the same sets from host arrays, on one
// Engine borrowing this program's device (issue 11's device-resident input;
// X-HD's published figures are for points already on the GPU).
//
//   rthdist-device-input-bench A B [--translate T] [--backend B] [--runs 7] [--warmup 3]
//
// The program plays the embedder: its own VkInstance and VkDevice (created
// from vulkanDeviceSetup), both sets uploaded once into device-local
// VkBuffers (float32, packed), then --runs calls of compute(DevicePointView,
// DevicePointView) and of compute(host A, host B) after --warmup each,
// alternating. Prints one JSON object: medians of the call's wall time and
// of its device time (Timings' gpu* fields); the two H must be equal (exit 1
// otherwise).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/stopwatch.hpp"
#include "gpu/vk_struct.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"
#include "rthdist/vulkan_interop.hpp"

namespace {

using rthdist::core::Clock;
using rthdist::core::msSince;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

void check(VkResult r, const char* what) {
    if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: " + std::to_string(int(r)));
}

// The embedding application: instance, device, queue and its buffers.
class Embedder {
public:
    explicit Embedder(rthdist::Backend backend) {
        VkApplicationInfo app = rthdist::gpu::vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
        app.apiVersion = VK_API_VERSION_1_3;
        VkInstanceCreateInfo ci =
            rthdist::gpu::vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
        ci.pApplicationInfo = &app;
        check(vkCreateInstance(&ci, nullptr, &m_instance), "vkCreateInstance");
        uint32_t n = 0;
        vkEnumeratePhysicalDevices(m_instance, &n, nullptr);
        std::vector<VkPhysicalDevice> pds(n);
        vkEnumeratePhysicalDevices(m_instance, &n, pds.data());
        std::string why;
        for (VkPhysicalDevice pd : pds) {
            rthdist::Result<rthdist::VulkanDeviceSetup> setup = rthdist::vulkanDeviceSetup(pd, backend);
            if (!setup) {
                why += setup.error().message + "; ";
                continue;
            }
            createDevice(pd, *setup);
            return;
        }
        throw std::runtime_error("no device runs the backend: " + why);
    }
    ~Embedder() {
        if (m_device) {
            vkDeviceWaitIdle(m_device);
            for (auto& [buffer, memory] : m_buffers) {
                vkDestroyBuffer(m_device, buffer, nullptr);
                vkFreeMemory(m_device, memory, nullptr);
            }
            if (m_pool) vkDestroyCommandPool(m_device, m_pool, nullptr);
            vkDestroyDevice(m_device, nullptr);
        }
        if (m_instance) vkDestroyInstance(m_instance, nullptr);
    }
    Embedder(const Embedder&) = delete;
    Embedder& operator=(const Embedder&) = delete;

    [[nodiscard]] const rthdist::VulkanDevice& handles() const { return m_handles; }

    // A device-local buffer holding `points`, uploaded and waited for.
    rthdist::DevicePointView upload(const std::vector<glm::vec3>& points) {
        const VkDeviceSize size = points.size() * sizeof(glm::vec3);
        VkBuffer staging =
            makeBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        void* mapped = nullptr;
        check(vkMapMemory(m_device, m_buffers.back().second, 0, size, 0, &mapped), "vkMapMemory");
        std::memcpy(mapped, points.data(), size);
        vkUnmapMemory(m_device, m_buffers.back().second);
        VkBuffer dst = makeBuffer(size,
                                  VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        VkCommandBufferAllocateInfo ai = rthdist::gpu::vkStruct<VkCommandBufferAllocateInfo>(
            VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
        ai.commandPool = m_pool;
        ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        ai.commandBufferCount = 1;
        VkCommandBuffer cmd;
        check(vkAllocateCommandBuffers(m_device, &ai, &cmd), "vkAllocateCommandBuffers");
        VkCommandBufferBeginInfo bi =
            rthdist::gpu::vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        vkBeginCommandBuffer(cmd, &bi);
        const VkBufferCopy region{0, 0, size};
        vkCmdCopyBuffer(cmd, staging, dst, 1, &region);
        vkEndCommandBuffer(cmd);
        VkSubmitInfo si = rthdist::gpu::vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cmd;
        check(vkQueueSubmit(m_handles.queue, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
        check(vkQueueWaitIdle(m_handles.queue), "vkQueueWaitIdle");
        return rthdist::DevicePointView::floats(dst, size, points.size());
    }

private:
    void createDevice(VkPhysicalDevice pd, rthdist::VulkanDeviceSetup setup) {
        const float priority = 1.0f;
        VkDeviceQueueCreateInfo qi =
            rthdist::gpu::vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
        qi.queueFamilyIndex = setup.queueFamily;
        qi.queueCount = 1;
        qi.pQueuePriorities = &priority;
        VkDeviceCreateInfo di =
            rthdist::gpu::vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
        di.pNext = setup.chain();
        di.queueCreateInfoCount = 1;
        di.pQueueCreateInfos = &qi;
        di.enabledExtensionCount = uint32_t(setup.extensions.size());
        di.ppEnabledExtensionNames = setup.extensions.data();
        check(vkCreateDevice(pd, &di, nullptr, &m_device), "vkCreateDevice");
        m_physical = pd;
        vkGetDeviceQueue(m_device, setup.queueFamily, 0, &m_handles.queue);
        VkCommandPoolCreateInfo pi =
            rthdist::gpu::vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
        pi.queueFamilyIndex = setup.queueFamily;
        check(vkCreateCommandPool(m_device, &pi, nullptr, &m_pool), "vkCreateCommandPool");
        m_handles.instance = m_instance;
        m_handles.physicalDevice = pd;
        m_handles.device = m_device;
        m_handles.queueFamily = setup.queueFamily;
        m_handles.shaderFloat64 = setup.shaderFloat64;
    }

    VkBuffer makeBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags wanted) {
        VkBufferCreateInfo bi =
            rthdist::gpu::vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
        bi.size = size;
        bi.usage = usage;
        VkBuffer buffer;
        check(vkCreateBuffer(m_device, &bi, nullptr, &buffer), "vkCreateBuffer");
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(m_device, buffer, &req);
        VkPhysicalDeviceMemoryProperties props;
        vkGetPhysicalDeviceMemoryProperties(m_physical, &props);
        uint32_t type = 0;
        while (type < props.memoryTypeCount && (!(req.memoryTypeBits & (1u << type)) ||
                                                (props.memoryTypes[type].propertyFlags & wanted) != wanted))
            ++type;
        if (type == props.memoryTypeCount) throw std::runtime_error("no memory type for a buffer");
        VkMemoryAllocateFlagsInfo flags =
            rthdist::gpu::vkStruct<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        VkMemoryAllocateInfo ai =
            rthdist::gpu::vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
        ai.pNext = &flags;
        ai.allocationSize = req.size;
        ai.memoryTypeIndex = type;
        VkDeviceMemory memory;
        check(vkAllocateMemory(m_device, &ai, nullptr, &memory), "vkAllocateMemory");
        check(vkBindBufferMemory(m_device, buffer, memory, 0), "vkBindBufferMemory");
        m_buffers.emplace_back(buffer, memory);
        return buffer;
    }

    VkInstance m_instance = VK_NULL_HANDLE;
    VkPhysicalDevice m_physical = VK_NULL_HANDLE;
    VkDevice m_device = VK_NULL_HANDLE;
    VkCommandPool m_pool = VK_NULL_HANDLE;
    rthdist::VulkanDevice m_handles;
    std::vector<std::pair<VkBuffer, VkDeviceMemory>> m_buffers;
};

double gpuMs(const rthdist::Timings& t) {
    return t.gpuUpload + t.gpuIndex + t.gpuCull + t.gpuSearch + t.gpuRefine;
}

// Medians of `runs` timed calls of `call` after `warmup` untimed ones.
struct Medians {
    double wall = 0.0, gpu = 0.0, h = 0.0;
};
template <class Call>
Medians timeCalls(int warmup, int runs, Call&& call) {
    std::vector<double> wall, gpu;
    double h = 0.0;
    for (int i = 0; i < warmup + runs; ++i) {
        const auto t0 = Clock::now();
        rthdist::Result<rthdist::HausdorffResult> r = call();
        const double ms = msSince(t0);
        if (!r) throw std::runtime_error(r.error().message);
        h = r->hausdorff;
        if (i < warmup) continue;
        wall.push_back(ms);
        gpu.push_back(gpuMs(r->timings));
    }
    return {median(wall), median(gpu), h};
}

std::vector<glm::vec3> loadFloats(const std::string& path) {
    auto p = rthdist::io::loadPoints(path);
    if (!p) throw std::runtime_error(p.error().message);
    return std::move(p.value());
}

int run(const std::string& pathA, const std::string& pathB, double translate, const std::string& backendName,
        int runs, int warmup) {
    rthdist::Backend backend = rthdist::Backend::kAuto;
    if (!rthdist::parseBackend(backendName, backend) || backend == rthdist::Backend::kCpu)
        throw std::runtime_error("--backend expects auto, ray-query or rt-pipeline");
    std::vector<glm::vec3> a = loadFloats(pathA), b = loadFloats(pathB);
    if (translate != 0.0) {
        float lo = b.front().x, hi = lo;
        for (const glm::vec3& p : b) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
        for (glm::vec3& p : b) p.x += float(translate * double(hi - lo));
    }
    Embedder embedder(backend);
    const rthdist::DevicePointView da = embedder.upload(a), db = embedder.upload(b);
    rthdist::EngineOptions options;
    options.backend = backend;
    rthdist::Result<rthdist::Engine> engine = rthdist::Engine::create(embedder.handles(), options);
    if (!engine) throw std::runtime_error(engine.error().message);
    const Medians device = timeCalls(warmup, runs, [&] { return engine->compute(da, db); });
    const Medians host = timeCalls(
        warmup, runs, [&] { return engine->compute(rthdist::PointView(a), rthdist::PointView(b)); });
    nlohmann::ordered_json j = {{"a", pathA},
                                {"b", pathB},
                                {"translate", translate},
                                {"points", {a.size(), b.size()}},
                                {"device", engine->deviceName()},
                                {"backend", rthdist::backendName(engine->backend())},
                                {"runs", runs},
                                {"device_input_wall_ms", device.wall},
                                {"device_input_gpu_ms", device.gpu},
                                {"host_arrays_wall_ms", host.wall},
                                {"host_arrays_gpu_ms", host.gpu},
                                {"hausdorff", device.h},
                                {"agree", device.h == host.h}};
    std::cout << j.dump() << "\n";
    return device.h == host.h ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"H from device-resident point sets against host arrays (rthdist/vulkan_interop.hpp)"};
    std::string pathA, pathB, backend = "auto";
    double translate = 0.0;
    int runs = 7, warmup = 3;
    app.add_option("A", pathA)->required();
    app.add_option("B", pathB)->required();
    app.add_option("--translate", translate, "move B by this fraction of its x extent");
    app.add_option("--backend", backend);
    app.add_option("--runs", runs)->check(CLI::Range(1, 1000));
    app.add_option("--warmup", warmup)->check(CLI::Range(0, 1000));
    CLI11_PARSE(app, argc, argv);
    try {
        return run(pathA, pathB, translate, backend, runs, warmup);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rthdist-device-input-bench: %s\n", e.what());
        return 1;
    }
}
