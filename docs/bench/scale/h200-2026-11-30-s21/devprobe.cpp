// Times vkCreateInstance and vkCreateDevice on the first GPU: a bare device
// (one compute queue, nothing enabled), then what rthdist enables for
// rt-pipeline, each 3 times, alternated.
#include <rthdist/vulkan_interop.hpp>
#include <chrono>
#include <cstdio>
#include <vector>
using Clock = std::chrono::steady_clock;
static double ms(Clock::time_point a) { return std::chrono::duration<double, std::milli>(Clock::now() - a).count(); }
int main() {
    auto t0 = Clock::now();
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    VkInstance inst;
    if (vkCreateInstance(&ici, nullptr, &inst) != VK_SUCCESS) return 1;
    std::printf("instance %.1f ms\n", ms(t0));
    uint32_t n = 0;
    t0 = Clock::now();
    vkEnumeratePhysicalDevices(inst, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(inst, &n, pds.data());
    std::printf("enumerate %.1f ms (%u)\n", ms(t0), n);
    VkPhysicalDevice pd = pds[0];
    auto setup = rthdist::vulkanDeviceSetup(pd, rthdist::Backend::kRtPipeline);
    if (!setup) { std::printf("setup: %s\n", setup.error().message.c_str()); return 1; }
    const float prio = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = setup->queueFamily;
    q.queueCount = 1;
    q.pQueuePriorities = &prio;
    for (int r = 0; r < 3; ++r) {
        for (int full = 0; full < 2; ++full) {
            VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
            dci.queueCreateInfoCount = 1;
            dci.pQueueCreateInfos = &q;
            if (full) {
                dci.enabledExtensionCount = uint32_t(setup->extensions.size());
                dci.ppEnabledExtensionNames = setup->extensions.data();
                dci.pNext = setup->chain();
            }
            VkDevice d;
            t0 = Clock::now();
            VkResult res = vkCreateDevice(pd, &dci, nullptr, &d);
            const double c = ms(t0);
            t0 = Clock::now();
            if (res == VK_SUCCESS) vkDestroyDevice(d, nullptr);
            std::printf("%s device: create %.1f ms (rc %d), destroy %.1f ms\n", full ? "rthdist's" : "bare", c, int(res), ms(t0));
        }
    }
    vkDestroyInstance(inst, nullptr);
}
