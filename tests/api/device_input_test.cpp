// Device-resident input (rthdist/vulkan_interop.hpp): the test plays the
// embedding application. It creates its own VkInstance (validation layer,
// debug utils) and VkDevice from vulkanDeviceSetup, fills VkBuffers through
// a staging copy submitted to the queue it lends the Engine (not waited for:
// the synchronisation contract says the Engine's first barrier orders it),
// and compares every device-view call with the host-array call on the same
// coordinates: the same H, directed values, witness indices and points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "common/brute_force.hpp"
#include "common/geo_cases.hpp"
#include "engine_test_support.hpp"
#include "gpu/vk_struct.hpp"
#include "rthdist/surface.hpp"
#include "rthdist/vulkan_interop.hpp"

namespace rthdist::test {
namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL countMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                            VkDebugUtilsMessageTypeFlagsEXT,
                                            const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        ++*static_cast<int*>(user);
        std::fprintf(stderr, "test embedder: validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

// The embedding application: instance, device, queue, buffers. Everything
// it made is destroyed in its destructor (after the test's Engines).
class Embedder {
public:
    // Empty (why() says why) when no device can run `backend`.
    explicit Embedder(Backend backend) {
        VkApplicationInfo app = gpu::vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
        app.apiVersion = VK_API_VERSION_1_3;
        const char* layer = "VK_LAYER_KHRONOS_validation";
        const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
        // Synchronization validation as in the other GPU suites: VK_LAYER_ENABLES=
        // VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT in the
        // environment (docs/gpu.md). Not forced here: under the asan preset the
        // layer's synchronization validation leaves allocations LeakSanitizer
        // cannot attribute to it.
        VkInstanceCreateInfo ci = gpu::vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
        ci.pApplicationInfo = &app;
        ci.enabledLayerCount = 1;
        ci.ppEnabledLayerNames = &layer;
        ci.enabledExtensionCount = 1;
        ci.ppEnabledExtensionNames = &ext;
        if (vkCreateInstance(&ci, nullptr, &m_instance) != VK_SUCCESS) {
            m_why = "vkCreateInstance with the validation layer failed";
            return;
        }
        createMessenger();
        uint32_t n = 0;
        vkEnumeratePhysicalDevices(m_instance, &n, nullptr);
        std::vector<VkPhysicalDevice> pds(n);
        vkEnumeratePhysicalDevices(m_instance, &n, pds.data());
        for (VkPhysicalDevice pd : pds) {
            Result<VulkanDeviceSetup> setup = vulkanDeviceSetup(pd, backend);
            if (!setup) {
                m_why += setup.error().message + "; ";
                continue;
            }
            createDevice(pd, *setup);
            return;
        }
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
        if (m_messenger) {
            auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(m_instance, "vkDestroyDebugUtilsMessengerEXT"));
            destroy(m_instance, m_messenger, nullptr);
        }
        if (m_instance) vkDestroyInstance(m_instance, nullptr);
    }
    Embedder(const Embedder&) = delete;
    Embedder& operator=(const Embedder&) = delete;

    [[nodiscard]] bool ok() const { return m_device != VK_NULL_HANDLE; }
    [[nodiscard]] const std::string& why() const { return m_why; }
    [[nodiscard]] const VulkanDevice& handles() const { return m_handles; }
    [[nodiscard]] int messages() const { return m_messages; }

    // A device buffer holding `bytes`, filled by a staging copy submitted to
    // the lent queue and not waited for.
    VkBuffer upload(const void* bytes, VkDeviceSize size) {
        const VkBufferUsageFlags usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        VkBuffer staging =
            makeBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                       VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        void* mapped = nullptr;
        vkMapMemory(m_device, m_buffers.back().second, 0, size, 0, &mapped);
        std::memcpy(mapped, bytes, size);
        vkUnmapMemory(m_device, m_buffers.back().second);
        VkBuffer dst = makeBuffer(size, usage, 0);
        VkCommandBufferAllocateInfo ai =
            gpu::vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
        ai.commandPool = m_pool;
        ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        ai.commandBufferCount = 1;
        VkCommandBuffer cmd;
        vkAllocateCommandBuffers(m_device, &ai, &cmd);
        VkCommandBufferBeginInfo bi =
            gpu::vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        vkBeginCommandBuffer(cmd, &bi);
        const VkBufferCopy region{0, 0, size};
        vkCmdCopyBuffer(cmd, staging, dst, 1, &region);
        vkEndCommandBuffer(cmd);
        VkSubmitInfo si = gpu::vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cmd;
        EXPECT_EQ(vkQueueSubmit(m_handles.queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
        return dst;  // the command buffer is freed with the pool
    }
    template <class T>
    VkBuffer upload(const std::vector<T>& v) {
        return upload(v.data(), VkDeviceSize(v.size() * sizeof(T)));
    }

private:
    void createMessenger() {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(m_instance, "vkCreateDebugUtilsMessengerEXT"));
        VkDebugUtilsMessengerCreateInfoEXT mi = gpu::vkStruct<VkDebugUtilsMessengerCreateInfoEXT>(
            VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
        mi.messageSeverity =
            VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        mi.pfnUserCallback = countMessage;
        mi.pUserData = &m_messages;
        if (create) create(m_instance, &mi, nullptr, &m_messenger);
    }

    void createDevice(VkPhysicalDevice pd, VulkanDeviceSetup& setup) {
        const float priority = 1.0f;
        VkDeviceQueueCreateInfo qi =
            gpu::vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
        qi.queueFamilyIndex = setup.queueFamily;
        qi.queueCount = 1;
        qi.pQueuePriorities = &priority;
        VkDeviceCreateInfo di = gpu::vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
        di.pNext = setup.chain();
        di.queueCreateInfoCount = 1;
        di.pQueueCreateInfos = &qi;
        di.enabledExtensionCount = uint32_t(setup.extensions.size());
        di.ppEnabledExtensionNames = setup.extensions.data();
        if (vkCreateDevice(pd, &di, nullptr, &m_device) != VK_SUCCESS) {
            m_why = "vkCreateDevice with the setup failed";
            m_device = VK_NULL_HANDLE;
            return;
        }
        m_physical = pd;
        m_handles = VulkanDevice{m_instance,          pd,  m_device, VK_NULL_HANDLE, setup.queueFamily,
                                 setup.shaderFloat64, true};
        vkGetDeviceQueue(m_device, setup.queueFamily, 0, &m_handles.queue);
        VkCommandPoolCreateInfo pci =
            gpu::vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
        pci.queueFamilyIndex = setup.queueFamily;
        vkCreateCommandPool(m_device, &pci, nullptr, &m_pool);
    }

    VkBuffer makeBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags wanted) {
        VkBufferCreateInfo bci = gpu::vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
        bci.size = size;
        bci.usage = usage;
        VkBuffer buffer;
        vkCreateBuffer(m_device, &bci, nullptr, &buffer);
        VkMemoryRequirements req;
        vkGetBufferMemoryRequirements(m_device, buffer, &req);
        VkPhysicalDeviceMemoryProperties props;
        vkGetPhysicalDeviceMemoryProperties(m_physical, &props);
        uint32_t type = 0;
        while (!((req.memoryTypeBits >> type) & 1u) ||
               (props.memoryTypes[type].propertyFlags & wanted) != wanted)
            ++type;
        VkMemoryAllocateFlagsInfo flags =
            gpu::vkStruct<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        VkMemoryAllocateInfo mai =
            gpu::vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
        mai.pNext = &flags;
        mai.allocationSize = req.size;
        mai.memoryTypeIndex = type;
        VkDeviceMemory memory;
        vkAllocateMemory(m_device, &mai, nullptr, &memory);
        vkBindBufferMemory(m_device, buffer, memory, 0);
        m_buffers.emplace_back(buffer, memory);
        return buffer;
    }

    VkInstance m_instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT m_messenger = VK_NULL_HANDLE;
    VkPhysicalDevice m_physical = VK_NULL_HANDLE;
    VkDevice m_device = VK_NULL_HANDLE;
    VkCommandPool m_pool = VK_NULL_HANDLE;
    VulkanDevice m_handles;
    std::vector<std::pair<VkBuffer, VkDeviceMemory>> m_buffers;
    std::string m_why;
    int m_messages = 0;
};

// The same computation, exactly: values, witnesses and (when present)
// per-point output. A directed distance of 0 has every query as a witness;
// which one a GPU names is its own pick (an NVIDIA H100 named another than
// its host-array call did), so there only the witness's distance is checked.
void expectIdentical(const HausdorffResult& got, const HausdorffResult& want) {
    EXPECT_EQ(got.hausdorff, want.hausdorff);
    EXPECT_EQ(got.origin, want.origin);
    for (auto [g, w] : {std::pair{&got.aToB, &want.aToB}, std::pair{&got.bToA, &want.bToA}}) {
        EXPECT_EQ(g->distance, w->distance);
        if (w->distance == 0.0) {
            EXPECT_EQ(g->queryPoint, g->targetPoint);
            continue;
        }
        EXPECT_EQ(g->queryIndex, w->queryIndex);
        EXPECT_EQ(g->targetIndex, w->targetIndex);
        EXPECT_EQ(g->queryPoint, w->queryPoint);
        EXPECT_EQ(g->targetPoint, w->targetPoint);
    }
    EXPECT_EQ(got.aNearest.distance, want.aNearest.distance);
    EXPECT_EQ(got.aNearest.nearest, want.aNearest.nearest);
    EXPECT_EQ(got.bNearest.distance, want.bNearest.distance);
    EXPECT_EQ(got.bNearest.nearest, want.bNearest.nearest);
    EXPECT_EQ(got.validationMessages, 0u);
}

// Points as `count` records of `stride` scalars T, xyz first, the rest NaN junk.
template <class T>
std::vector<T> interleaved(const std::vector<glm::dvec3>& p, size_t strideScalars) {
    std::vector<T> out(p.size() * strideScalars, std::numeric_limits<T>::quiet_NaN());
    for (size_t i = 0; i < p.size(); ++i)
        for (int k = 0; k < 3; ++k) out[i * strideScalars + size_t(k)] = T(p[i][k]);
    return out;
}

std::vector<glm::dvec3> randomDoubles(size_t n, uint64_t seed, glm::dvec3 offset, double extent) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, extent);
    std::vector<glm::dvec3> p(n);
    for (auto& v : p) v = glm::dvec3(u(rng), u(rng), u(rng)) + offset;
    return p;
}

// The embedder and an Engine on it (a skip, which CI fails, without a device).
#define RTHDIST_REQUIRE_EMBEDDER(emb, engine)                                                    \
    if (backendUnderTest() == Backend::kCpu) GTEST_SKIP() << "device input needs a GPU backend"; \
    Embedder emb(backendUnderTest());                                                            \
    if (!emb.ok()) GTEST_SKIP() << "no device for this backend: " << emb.why();                  \
    Result<Engine> engine = Engine::create(emb.handles(), engineUnderTest());                    \
    ASSERT_TRUE(engine) << engine.error().message

TEST(DeviceInput, FloatPackedAndStridedMatchHostArrays) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    const std::vector<glm::dvec3> a = randomDoubles(3000, 11, glm::dvec3(0.0), 1.0);
    const std::vector<glm::dvec3> b = randomDoubles(2200, 12, glm::dvec3(0.3, 0.0, 0.1), 1.0);
    const std::vector<float> fa = interleaved<float>(a, 3),
                             fb = interleaved<float>(b, 8);  // b: 32-byte stride
    const Result<HausdorffResult> host =
        engine->compute(PointView::floats(fa.data(), a.size()), PointView::floats(fb.data(), b.size(), 32));
    ASSERT_TRUE(host) << host.error().message;
    const VkBuffer ba = emb.upload(fa), bb = emb.upload(fb);
    const Result<HausdorffResult> dev =
        engine->compute(DevicePointView::floats(ba, fa.size() * 4, a.size()),
                        DevicePointView::floats(bb, fb.size() * 4, b.size(), 0, 32));
    ASSERT_TRUE(dev) << dev.error().message;
    expectIdentical(*dev, *host);
    EXPECT_GT(dev->hausdorff, 0.0);
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, DoubleStridedMatchesHostArrays) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    if (!emb.handles().shaderFloat64) GTEST_SKIP() << "the device has no shaderFloat64";
    // UTM-like coordinates: not float values, so both paths shift by the union's centre.
    const std::vector<glm::dvec3> a = randomDoubles(2500, 21, glm::dvec3(512345.25, 5401234.5, 120.0), 200.0);
    const std::vector<glm::dvec3> b = randomDoubles(1800, 22, glm::dvec3(512350.0, 5401230.0, 118.0), 200.0);
    const std::vector<double> da = interleaved<double>(a, 3),
                              db = interleaved<double>(b, 4);  // 32-byte stride
    const Result<HausdorffResult> host =
        engine->compute(PointView::doubles(da.data(), a.size()), PointView::doubles(db.data(), b.size(), 32));
    ASSERT_TRUE(host) << host.error().message;
    EXPECT_NE(host->origin, glm::dvec3(0.0));
    const VkBuffer ba = emb.upload(da), bb = emb.upload(db);
    // A starts 64 bytes into its buffer (offsets are honoured).
    std::vector<double> shifted(8, 0.0);
    shifted.insert(shifted.end(), da.begin(), da.end());
    const VkBuffer bs = emb.upload(shifted);
    const Result<HausdorffResult> dev =
        engine->compute(DevicePointView::doubles(ba, da.size() * 8, a.size()),
                        DevicePointView::doubles(bb, db.size() * 8, b.size(), 0, 32));
    ASSERT_TRUE(dev) << dev.error().message;
    expectIdentical(*dev, *host);
    // Doubles that hold float values are searched unshifted (origin 0), as on the host.
    std::vector<glm::dvec3> fv(a.size());
    for (size_t i = 0; i < a.size(); ++i)
        fv[i] = glm::dvec3(glm::vec3(a[i] - glm::dvec3(512345.0, 5401234.0, 0.0)));
    const Result<HausdorffResult> hostFv = engine->compute(fv, std::span<const glm::dvec3>(fv).first(900));
    const Result<HausdorffResult> devFv =
        engine->compute(DevicePointView::doubles(emb.upload(fv), fv.size() * 24, fv.size()),
                        DevicePointView::doubles(emb.upload(fv), fv.size() * 24, 900));
    ASSERT_TRUE(hostFv && devFv);
    EXPECT_EQ(devFv->origin, glm::dvec3(0.0));
    expectIdentical(*devFv, *hostFv);
    const Result<HausdorffResult> offset =
        engine->compute(DevicePointView::doubles(bs, shifted.size() * 8, a.size(), 64),
                        DevicePointView::doubles(bb, db.size() * 8, b.size(), 0, 32));
    ASSERT_TRUE(offset) << offset.error().message;
    expectIdentical(*offset, *host);
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, FloatBesideDoubleMatchesHostArrays) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    if (!emb.handles().shaderFloat64) GTEST_SKIP() << "the device has no shaderFloat64";
    const std::vector<glm::dvec3> a = randomDoubles(1500, 31, glm::dvec3(1000.0), 5.0);
    const std::vector<glm::dvec3> b = randomDoubles(1700, 32, glm::dvec3(1001.0), 5.0);
    const std::vector<float> fa = interleaved<float>(a, 3);
    const std::vector<double> db = interleaved<double>(b, 3);
    const Result<HausdorffResult> host =
        engine->compute(PointView::floats(fa.data(), a.size()), PointView::doubles(db.data(), b.size()));
    ASSERT_TRUE(host) << host.error().message;
    const Result<HausdorffResult> dev =
        engine->compute(DevicePointView::floats(emb.upload(fa), fa.size() * 4, a.size()),
                        DevicePointView::doubles(emb.upload(db), db.size() * 8, b.size()));
    ASSERT_TRUE(dev) << dev.error().message;
    expectIdentical(*dev, *host);
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, PerPointMatchesHostArrays) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    const std::vector<glm::dvec3> a = randomDoubles(1200, 41, glm::dvec3(0.0), 2.0);
    const std::vector<glm::dvec3> b = randomDoubles(900, 42, glm::dvec3(0.5), 2.0);
    const std::vector<float> fa = interleaved<float>(a, 4),
                             fb = interleaved<float>(b, 3);  // a: 16-byte stride
    CallOptions call;
    call.perPointDistances = true;
    const Result<HausdorffResult> host = engine->compute(PointView::floats(fa.data(), a.size(), 16),
                                                         PointView::floats(fb.data(), b.size()), call);
    ASSERT_TRUE(host) << host.error().message;
    const Result<HausdorffResult> dev =
        engine->compute(DevicePointView::floats(emb.upload(fa), fa.size() * 4, a.size(), 0, 16),
                        DevicePointView::floats(emb.upload(fb), fb.size() * 4, b.size()), call);
    ASSERT_TRUE(dev) << dev.error().message;
    ASSERT_EQ(dev->aNearest.distance.size(), a.size());
    ASSERT_EQ(dev->bNearest.distance.size(), b.size());
    expectIdentical(*dev, *host);
}

TEST(DeviceInput, PreparedFromDeviceBuffersMatchOneShot) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    const std::vector<glm::dvec3> a = randomDoubles(2000, 51, glm::dvec3(0.0), 1.0);
    const std::vector<glm::dvec3> b = randomDoubles(1600, 52, glm::dvec3(0.2), 1.0);
    const std::vector<float> fa = interleaved<float>(a, 3), fb = interleaved<float>(b, 8);
    const Result<HausdorffResult> host =
        engine->compute(PointView::floats(fa.data(), a.size()), PointView::floats(fb.data(), b.size(), 32));
    ASSERT_TRUE(host) << host.error().message;
    const VkBuffer ba = emb.upload(fa), bb = emb.upload(fb);
    Result<PreparedSet> pa = engine->prepare(DevicePointView::floats(ba, fa.size() * 4, a.size()));
    Result<PreparedSet> pb = engine->prepare(DevicePointView::floats(bb, fb.size() * 4, b.size(), 0, 32));
    ASSERT_TRUE(pa) << pa.error().message;
    ASSERT_TRUE(pb) << pb.error().message;
    EXPECT_EQ(pa->size(), a.size());
    EXPECT_GT(pb->deviceBytes(), 0u);
    for (int call = 0; call < 3; ++call) {  // reused: the views are not read after prepare
        const Result<HausdorffResult> r = engine->compute(*pa, *pb);
        ASSERT_TRUE(r) << r.error().message;
        expectIdentical(*r, *host);
    }
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, PreparedDoubleSetsShareAFrame) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    if (!emb.handles().shaderFloat64) GTEST_SKIP() << "the device has no shaderFloat64";
    const std::vector<glm::dvec3> a = randomDoubles(1500, 61, glm::dvec3(4.9e6, 1.2e5, -3.0e5), 5.0);
    const std::vector<glm::dvec3> b = randomDoubles(1300, 62, glm::dvec3(4.9e6 + 0.5, 1.2e5, -3.0e5), 5.0);
    const std::vector<double> da = interleaved<double>(a, 3), db = interleaved<double>(b, 3);
    PrepareOptions frame;
    frame.origin = glm::dvec3(4.9e6 + 2.5, 1.2e5 + 2.5, -3.0e5 + 2.5);
    Result<PreparedSet> ha = engine->prepare(PointView::doubles(da.data(), a.size()), frame);
    Result<PreparedSet> hb = engine->prepare(PointView::doubles(db.data(), b.size()), frame);
    Result<PreparedSet> pa =
        engine->prepare(DevicePointView::doubles(emb.upload(da), da.size() * 8, a.size()), frame);
    Result<PreparedSet> pb =
        engine->prepare(DevicePointView::doubles(emb.upload(db), db.size() * 8, b.size()), frame);
    ASSERT_TRUE(ha && hb && pa && pb);
    EXPECT_EQ(pa->origin(), *frame.origin);
    const Result<HausdorffResult> host = engine->compute(*ha, *hb);
    const Result<HausdorffResult> dev = engine->compute(*pa, *pb);
    ASSERT_TRUE(host) << host.error().message;
    ASSERT_TRUE(dev) << dev.error().message;
    expectIdentical(*dev, *host);
    // Without a shared frame the sets cannot be re-indexed from the host: an error, not a guess.
    Result<PreparedSet> own =
        engine->prepare(DevicePointView::doubles(emb.upload(db), db.size() * 8, b.size()));
    ASSERT_TRUE(own);
    const Result<HausdorffResult> mixed = engine->compute(*pa, *own);
    ASSERT_FALSE(mixed);
    EXPECT_EQ(mixed.error().code, ErrorCode::kInvalidArgument);
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, BadViewsAreErrors) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    std::vector<float> p = interleaved<float>(randomDoubles(100, 71, glm::dvec3(0.0), 1.0), 3);
    const VkBuffer good = emb.upload(p);
    const DevicePointView ok = DevicePointView::floats(good, p.size() * 4, 100);
    auto expectError = [&](const DevicePointView& bad, ErrorCode code, const std::string& words) {
        const Result<HausdorffResult> r = engine->compute(ok, bad);
        ASSERT_FALSE(r);
        EXPECT_EQ(r.error().code, code);
        EXPECT_NE(r.error().message.find(words), std::string::npos) << r.error().message;
    };
    expectError(DevicePointView::floats(good, p.size() * 4, 100, 0, 8), ErrorCode::kInvalidArgument,
                "strideBytes 8");
    expectError(DevicePointView::floats(good, p.size() * 4, 100, 0, 14), ErrorCode::kInvalidArgument,
                "multiple of 4");
    expectError(DevicePointView::floats(good, p.size() * 4, 101), ErrorCode::kInvalidArgument,
                "past bufferBytes");
    expectError(DevicePointView::floats(good, p.size() * 4, 100, 4), ErrorCode::kInvalidArgument,
                "past bufferBytes");
    expectError(DevicePointView::floats(good, p.size() * 4, 100, ~VkDeviceSize(0) - 3),
                ErrorCode::kInvalidArgument,
                "past bufferBytes");  // offset + size would wrap
    expectError(DevicePointView::floats(good, p.size() * 4, 99, 2), ErrorCode::kInvalidArgument, "offset 2");
    expectError(DevicePointView::floats(good, p.size() * 4, 0), ErrorCode::kInvalidArgument, "empty");
    expectError(DevicePointView::floats(VK_NULL_HANDLE, 1200, 100), ErrorCode::kInvalidArgument, "no buffer");
    p[3 * 7 + 1] = std::numeric_limits<float>::quiet_NaN();
    expectError(DevicePointView::floats(emb.upload(p), p.size() * 4, 100), ErrorCode::kInvalidArgument,
                "point set B: point 7 has a NaN");
    if (emb.handles().shaderFloat64) {
        std::vector<double> d = interleaved<double>(randomDoubles(50, 72, glm::dvec3(0.0), 1.0), 3);
        d[3 * 9] = std::numeric_limits<double>::infinity();
        expectError(DevicePointView::doubles(emb.upload(d), d.size() * 8, 50), ErrorCode::kInvalidArgument,
                    "point set B: point 9 has a NaN or infinite");
    }
    // The same checks, once, before a set is prepared from a view.
    const Result<PreparedSet> prepared = engine->prepare(DevicePointView::floats(good, p.size() * 4, 101));
    ASSERT_FALSE(prepared);
    EXPECT_EQ(prepared.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(prepared.error().message.find("device view to prepare: "), std::string::npos)
        << prepared.error().message;
    EXPECT_NE(prepared.error().message.find("past bufferBytes"), std::string::npos)
        << prepared.error().message;
    // The Engine stays usable.
    const Result<HausdorffResult> r = engine->compute(ok, ok);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->hausdorff, 0.0);
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, DoubleViewsNeedShaderFloat64) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    VulkanDevice without = emb.handles();
    without.shaderFloat64 = false;  // as for a device created without the feature
    Result<Engine> e = Engine::create(without, engineUnderTest());
    ASSERT_TRUE(e) << e.error().message;
    const std::vector<double> d = interleaved<double>(randomDoubles(40, 91, glm::dvec3(0.5), 1.0), 3);
    const std::vector<float> f = interleaved<float>(randomDoubles(40, 92, glm::dvec3(0.0), 1.0), 3);
    const DevicePointView dv = DevicePointView::doubles(emb.upload(d), d.size() * 8, 40);
    const DevicePointView fv = DevicePointView::floats(emb.upload(f), f.size() * 4, 40);
    const Result<HausdorffResult> r = e->compute(fv, dv);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kNoDevice);
    EXPECT_NE(r.error().message.find("shaderFloat64"), std::string::npos) << r.error().message;
    const Result<HausdorffResult> floats = e->compute(fv, fv);  // float views need no Float64
    ASSERT_TRUE(floats) << floats.error().message;
    EXPECT_EQ(floats->hausdorff, 0.0);
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, OwnedEnginesRefuseDeviceViews) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    RTHDIST_REQUIRE_TEST_ENGINE(owned);  // on a device of its own: it cannot read the embedder's buffers
    const std::vector<float> f = interleaved<float>(randomDoubles(10, 93, glm::dvec3(0.0), 1.0), 3);
    const DevicePointView v = DevicePointView::floats(emb.upload(f), f.size() * 4, 10);
    const Result<HausdorffResult> r = owned->compute(v, v);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("created on your VkDevice"), std::string::npos) << r.error().message;
    EXPECT_FALSE(owned->prepare(v));
    EXPECT_TRUE(engine->compute(v, v));
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInput, OracleOnRandomSets) {
    RTHDIST_REQUIRE_EMBEDDER(emb, engine);
    for (uint64_t seed : {81u, 82u, 83u}) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        std::mt19937_64 rng(seed);
        const size_t na = 200 + rng() % 2000, nb = 200 + rng() % 2000;
        const std::vector<glm::vec3> a = randomCloud(na, seed, glm::vec3(0.0f));
        const std::vector<glm::vec3> b = randomCloud(nb, seed + 100, glm::vec3(0.1f * float(seed % 3)));
        const Result<HausdorffResult> r =
            engine->compute(DevicePointView::floats(emb.upload(a), na * 12, na),
                            DevicePointView::floats(emb.upload(b), nb * 12, nb));
        ASSERT_TRUE(r) << r.error().message;
        const oracle::DirectedExact ab = oracle::bruteForceDirected(a, b),
                                    ba = oracle::bruteForceDirected(b, a);
        EXPECT_EQ(r->aToB.distance, ab.distance);
        EXPECT_EQ(r->bToA.distance, ba.distance);
        EXPECT_EQ(r->aToB.queryIndex, ab.queryIndex);
        EXPECT_EQ(r->bToA.queryIndex, ba.queryIndex);
        EXPECT_EQ(r->hausdorff, std::max(ab.distance, ba.distance));
    }
    if (emb.handles().shaderFloat64) {
        for (const GeoCase& c : makeGeoCases()) {
            const Result<HausdorffResult> r =
                engine->compute(DevicePointView::doubles(emb.upload(c.a), c.a.size() * 24, c.a.size()),
                                DevicePointView::doubles(emb.upload(c.b), c.b.size() * 24, c.b.size()));
            ASSERT_TRUE(r) << c.name << ": " << r.error().message;
            expectMatchesGeoOracle(c, *r);
        }
    }
    EXPECT_EQ(emb.messages(), 0);
}

// An auto Engine on a lent device keeps a GPU backend (an owned auto Engine
// on lavapipe takes the CPU backend), so here the surface route's auto rule
// (api::autoSurfaceOnGpu) runs end to end: a call of many queries against
// few triangles searches on the device, per-point distances and few queries
// stay on the CPU backend, and every value and witness is the CPU's (==).
TEST(DeviceInput, AnAutoEngineOnALentDeviceRoutesSurfaceCallsByShape) {
    if (backendUnderTest() == Backend::kCpu) GTEST_SKIP() << "a lent device needs a GPU backend";
    Embedder emb(
        Backend::kAuto);  // the device set up for kAuto, as the Engine's backend (vulkan_interop.hpp)
    if (!emb.ok()) GTEST_SKIP() << "no device for the auto backend: " << emb.why();
    EngineOptions autoOptions = engineUnderTest();
    autoOptions.backend = Backend::kAuto;
    Result<Engine> engine = Engine::create(emb.handles(), autoOptions);
    ASSERT_TRUE(engine) << engine.error().message;
    // A wavy 8 x 8 grid of quads (128 triangles) and points above and below it.
    std::vector<double> vertices;
    for (int j = 0; j <= 8; ++j)
        for (int i = 0; i <= 8; ++i) {
            const double x = i / 8.0, y = j / 8.0;
            vertices.insert(vertices.end(), {x, y, 0.1 * std::sin(7.0 * x + 3.0 * y)});
        }
    std::vector<uint32_t> indices;
    for (uint32_t j = 0; j < 8; ++j)
        for (uint32_t i = 0; i < 8; ++i) {
            const uint32_t v = j * 9 + i;
            indices.insert(indices.end(), {v, v + 1, v + 10, v, v + 10, v + 9});
        }
    const MeshView mesh{PointView::doubles(vertices.data(), vertices.size() / 3), indices};
    const std::vector<glm::dvec3> many =
        randomDoubles(size_t(1) << 14, 71, glm::dvec3(-0.2, -0.2, -0.5), 1.4);
    std::vector<double> flat;
    for (const glm::dvec3& p : many) flat.insert(flat.end(), {p.x, p.y, p.z});
    const PointView manyView = PointView::doubles(flat.data(), many.size());
    const PointView fewView = PointView::doubles(flat.data(), 1000);

    SurfaceOptions cpu;
    cpu.backend = Backend::kCpu;
    for (const PointView& points : {manyView, fewView}) {
        for (const bool perPoint : {false, true}) {
            SCOPED_TRACE(std::to_string(points.count) + " points, per point " + std::to_string(perPoint));
            SurfaceCallOptions call;
            call.perPointDistances = perPoint;
            const Result<SurfaceResult> r = engine->hausdorffToSurface(points, mesh, call);
            ASSERT_TRUE(r) << r.error().message;
            const bool onDevice = points.count == manyView.count && !perPoint;
            if (onDevice)
                EXPECT_NE(r->backend, Backend::kCpu);
            else
                EXPECT_EQ(r->backend, Backend::kCpu);
            SurfaceOptions want = cpu;
            want.perPointDistances = perPoint;
            const Result<SurfaceResult> w = hausdorffToSurface(points, mesh, want);
            ASSERT_TRUE(w) << w.error().message;
            EXPECT_EQ(r->hausdorff, w->hausdorff);
            EXPECT_EQ(r->directed.queryIndex, w->directed.queryIndex);
            EXPECT_EQ(r->directed.triangle, w->directed.triangle);
            EXPECT_EQ(r->directed.surfacePoint, w->directed.surfacePoint);
            if (perPoint) EXPECT_EQ(r->perPoint.distance, w->perPoint.distance);
        }
    }
    EXPECT_EQ(emb.messages(), 0);
}

TEST(DeviceInputRefused, OnTheCpuBackend) {
    // The CPU backend takes no Vulkan device and no device views.
    Options cpu;
    cpu.backend = Backend::kCpu;
    Result<Engine> engine = Engine::create(cpu);
    ASSERT_TRUE(engine);
    VkBuffer fake = reinterpret_cast<VkBuffer>(uintptr_t(0x10));
    const DevicePointView v = DevicePointView::floats(fake, 120, 10);
    const Result<HausdorffResult> r = engine->compute(v, v);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(r.error().message.find("cpu backend"), std::string::npos) << r.error().message;
    const Result<Engine> borrowed = Engine::create(VulkanDevice{}, static_cast<const EngineOptions&>(cpu));
    ASSERT_FALSE(borrowed);
    EXPECT_EQ(borrowed.error().code, ErrorCode::kInvalidArgument);
    EngineOptions gpu;
    gpu.backend = Backend::kRayQuery;
    const Result<Engine> empty = Engine::create(VulkanDevice{}, gpu);  // no handles
    ASSERT_FALSE(empty);
    EXPECT_EQ(empty.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(empty.error().message.find("must all be set"), std::string::npos) << empty.error().message;
}

}  // namespace
}  // namespace rthdist::test
