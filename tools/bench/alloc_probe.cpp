// The cost of device memory itself (design.md §9): vkAllocateMemory and
// vkFreeMemory of 0.25-16 GiB on device 0, plain, dedicated
// (VkMemoryDedicatedAllocateInfo), with and without the device-address flag
// and with VK_EXT_memory_priority where the device has it; then a 16 GiB
// buffer of each kind read, filled twice and freed, and sets of buffers alive
// together. Plain Vulkan, no rthdist code: what a driver charges, measured.
// Run on a lent GPU (docs/gpu.md): rthdist-alloc-probe > probe.txt.
#include <vulkan/vulkan.h>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>
using Clock = std::chrono::steady_clock;
static double ms(Clock::time_point s) {
    return std::chrono::duration<double, std::milli>(Clock::now() - s).count();
}
#define CK(x)                                      \
    do {                                           \
        VkResult r_ = (x);                         \
        if (r_ != VK_SUCCESS) {                    \
            std::printf("FAIL %s = %d\n", #x, r_); \
            return 1;                              \
        }                                          \
    } while (0)
VkDevice dev;
VkPhysicalDevice pd;
VkPhysicalDeviceMemoryProperties mp;
bool hasPriority = false;
struct Alloc {
    VkBuffer b;
    VkDeviceMemory m;
};
bool make(VkDeviceSize size, uint32_t type, bool addr, bool dedicated, float prio, Alloc& out) {
    VkBufferCreateInfo bi{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bi.size = size;
    bi.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
               VK_BUFFER_USAGE_TRANSFER_SRC_BIT | (addr ? VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT : 0);
    if (vkCreateBuffer(dev, &bi, nullptr, &out.b) != VK_SUCCESS) return false;
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(dev, out.b, &req);
    VkMemoryAllocateFlagsInfo fl{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    fl.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryDedicatedAllocateInfo de{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
    de.buffer = out.b;
    VkMemoryPriorityAllocateInfoEXT pr{VK_STRUCTURE_TYPE_MEMORY_PRIORITY_ALLOCATE_INFO_EXT};
    pr.priority = prio;
    const void* chain = nullptr;
    if (addr) {
        fl.pNext = chain;
        chain = &fl;
    }
    if (dedicated) {
        de.pNext = chain;
        chain = &de;
    }
    if (prio >= 0 && hasPriority) {
        pr.pNext = chain;
        chain = &pr;
    }
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, chain};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = type;
    if (vkAllocateMemory(dev, &ai, nullptr, &out.m) != VK_SUCCESS) {
        std::printf("alloc failed\n");
        return false;
    }
    vkBindBufferMemory(dev, out.b, out.m, 0);
    return true;
}
void drop(Alloc& a) {
    vkDestroyBuffer(dev, a.b, nullptr);
    vkFreeMemory(dev, a.m, nullptr);
}
int main() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    VkInstance inst;
    CK(vkCreateInstance(&ici, nullptr, &inst));
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(inst, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(inst, &n, pds.data());
    pd = pds[0];
    VkPhysicalDeviceProperties pp;
    vkGetPhysicalDeviceProperties(pd, &pp);
    std::printf("device %s\n", pp.deviceName);
    vkGetPhysicalDeviceMemoryProperties(pd, &mp);
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
        std::printf("type %u flags 0x%x heap %u (%.1f GiB)\n", i, mp.memoryTypes[i].propertyFlags,
                    mp.memoryTypes[i].heapIndex,
                    mp.memoryHeaps[mp.memoryTypes[i].heapIndex].size / 1073741824.0);
    uint32_t ne = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &ne, nullptr);
    std::vector<VkExtensionProperties> ex(ne);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &ne, ex.data());
    std::vector<const char*> want;
    for (auto& e : ex) {
        if (!std::strcmp(e.extensionName, "VK_EXT_memory_priority")) {
            hasPriority = true;
            want.push_back("VK_EXT_memory_priority");
        }
        if (!std::strcmp(e.extensionName, "VK_EXT_pageable_device_local_memory"))
            std::printf("has pageable_device_local_memory\n");
    }
    float qp = 1.0f;
    VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qi.queueFamilyIndex = 0;
    qi.queueCount = 1;
    qi.pQueuePriorities = &qp;
    VkPhysicalDeviceMemoryPriorityFeaturesEXT mpf{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PRIORITY_FEATURES_EXT};
    mpf.memoryPriority = hasPriority;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.bufferDeviceAddress = VK_TRUE;
    if (hasPriority) f12.pNext = &mpf;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &f12};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qi;
    dci.enabledExtensionCount = uint32_t(want.size());
    dci.ppEnabledExtensionNames = want.data();
    auto t0 = Clock::now();
    CK(vkCreateDevice(pd, &dci, nullptr, &dev));
    std::printf("device created in %.1f ms, memory_priority %d\n", ms(t0), hasPriority);
    uint32_t dl = ~0u;
    for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
        if (mp.memoryTypes[i].propertyFlags == VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) {
            dl = i;
            break;
        }
    for (uint32_t i = 0; dl == ~0u && i < mp.memoryTypeCount; ++i)  // a unified-memory device
        if (mp.memoryTypes[i].propertyFlags & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT) dl = i;
    if (dl == ~0u) {
        std::printf("no device-local memory type\n");
        return 1;
    }
    std::printf("device-local type %u\n", dl);
    const VkDeviceSize GiB = VkDeviceSize(1) << 30;
    struct V {
        const char* name;
        bool addr, ded;
        float prio;
    };
    V vs[] = {{"addr", true, false, -1},
              {"plain", false, false, -1},
              {"addr+dedicated", true, true, -1},
              {"addr+prio0", true, false, 0.0f},
              {"addr+prio1", true, false, 1.0f}};
    for (int round = 0; round < 2; ++round)
        for (auto& v : vs) {
            for (VkDeviceSize s : {VkDeviceSize(256) << 20, GiB, 4 * GiB, 16 * GiB}) {
                Alloc a;
                t0 = Clock::now();
                if (!make(s, dl, v.addr, v.ded, v.prio, a)) return 1;
                double am = ms(t0);
                t0 = Clock::now();
                drop(a);
                double fm = ms(t0);
                std::printf(
                    "round %d %-16s %6.2f GiB: alloc %8.2f ms (%6.2f ms/GiB) free %8.2f ms (%6.2f ms/GiB)\n",
                    round, v.name, double(s) / GiB, am, am / (double(s) / GiB), fm, fm / (double(s) / GiB));
            }
        }

    {
        VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pci.queueFamilyIndex = 0;
        pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        VkCommandPool pool;
        CK(vkCreateCommandPool(dev, &pci, nullptr, &pool));
        VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        cai.commandPool = pool;
        cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cai.commandBufferCount = 1;
        VkCommandBuffer cb;
        CK(vkAllocateCommandBuffers(dev, &cai, &cb));
        VkQueue q;
        vkGetDeviceQueue(dev, 0, 0, &q);
        VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        VkFence fence;
        CK(vkCreateFence(dev, &fci, nullptr, &fence));
        // host-visible readback of the first bytes
        uint32_t hv = ~0u;
        for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
            if ((mp.memoryTypes[i].propertyFlags & 6) == 6) {
                hv = i;
                break;
            }
        Alloc rb;
        make(1 << 20, hv, false, false, -1, rb);
        void* mapped;
        vkMapMemory(dev, rb.m, 0, VK_WHOLE_SIZE, 0, &mapped);
        auto fillTime = [&](Alloc& a, VkDeviceSize size, bool copyBack) {
            VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
            vkResetCommandBuffer(cb, 0);
            vkBeginCommandBuffer(cb, &bi);
            if (copyBack) {
                VkBufferCopy c{size - (1 << 20), 0, 1 << 20};
                vkCmdCopyBuffer(cb, a.b, rb.b, 1, &c);
            } else
                vkCmdFillBuffer(cb, a.b, 0, size, 0x12345678u);
            vkEndCommandBuffer(cb);
            VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
            si.commandBufferCount = 1;
            si.pCommandBuffers = &cb;
            auto t = Clock::now();
            vkQueueSubmit(q, 1, &si, fence);
            vkWaitForFences(dev, 1, &fence, VK_TRUE, ~0ull);
            vkResetFences(dev, 1, &fence);
            return ms(t);
        };
        for (int round = 0; round < 2; ++round)
            for (bool ded : {false, true}) {
                const VkDeviceSize s = 16 * GiB;
                Alloc a;
                auto t = Clock::now();
                make(s, dl, true, ded, -1, a);
                double am = ms(t);
                double read = fillTime(a, s, true);
                const uint32_t* w = static_cast<const uint32_t*>(mapped);
                uint32_t nz = 0;
                for (int i = 0; i < (1 << 18); ++i) nz += w[i] != 0;
                double f1 = fillTime(a, s, false), f2 = fillTime(a, s, false);
                t = Clock::now();
                drop(a);
                double fm = ms(t);
                std::printf(
                    "touch round %d %s 16 GiB: alloc %.1f ms, first read of the tail %.2f ms (nonzero words "
                    "%u), fill %.1f ms, fill again %.1f ms, free %.1f ms\n",
                    round, ded ? "dedicated" : "suballoc ", am, read, nz, f1, f2, fm);
            }
        // a realistic sequence: 8 dedicated buffers 2-6 GiB alive together, filled, then freed
        std::vector<Alloc> xs(8);
        auto t = Clock::now();
        for (int i = 0; i < 8; ++i) make(VkDeviceSize(2 + i % 3 * 2) * GiB, dl, true, true, -1, xs[i]);
        double am = ms(t);
        double fills = 0;
        for (int i = 0; i < 8; ++i) fills += fillTime(xs[i], VkDeviceSize(2 + i % 3 * 2) * GiB, false);
        t = Clock::now();
        for (auto& x : xs) drop(x);
        std::printf("8 dedicated (32 GiB) live: alloc %.1f ms, fills %.1f ms, free %.1f ms\n", am, fills,
                    ms(t));
        drop(rb);
        vkDestroyFence(dev, fence, nullptr);
        vkDestroyCommandPool(dev, pool, nullptr);
    }
    // many live at once, like a call: 16 x 1 GiB then free all
    {
        std::vector<Alloc> as(16);
        t0 = Clock::now();
        for (auto& a : as) make(GiB, dl, true, false, -1, a);
        double am = ms(t0);
        t0 = Clock::now();
        for (auto& a : as) drop(a);
        std::printf("16 x 1 GiB live: alloc %.1f ms free %.1f ms\n", am, ms(t0));
        std::vector<Alloc> bs(4);
        t0 = Clock::now();
        for (auto& a : bs) make(8 * GiB, dl, true, false, -1, a);
        am = ms(t0);
        t0 = Clock::now();
        for (auto& a : bs) drop(a);
        std::printf("4 x 8 GiB live: alloc %.1f ms free %.1f ms\n", am, ms(t0));
        // free by destroying the device with 32 GiB live
        std::vector<Alloc> cs(4);
        t0 = Clock::now();
        for (auto& a : cs) make(8 * GiB, dl, true, false, -1, a);
        am = ms(t0);
        t0 = Clock::now();
        vkDestroyDevice(dev, nullptr);
        std::printf("4 x 8 GiB then destroy device: alloc %.1f ms destroy %.1f ms\n", am, ms(t0));
    }
    return 0;
}
