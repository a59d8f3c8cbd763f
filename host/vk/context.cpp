#include "host/vk/context.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <thread>

#include "host/vk/check.h"
#include "host/vk/kernel.h"

namespace mcd::vk {
namespace {

constexpr const char *kValidationLayer = "VK_LAYER_KHRONOS_validation";

void InitVolk() {
    static const VkResult result = volkInitialize();
    if (result != VK_SUCCESS)
        throw Error(
            "no Vulkan loader found (libvulkan.so.1): install libvulkan1 and a driver, "
            "e.g. mesa-vulkan-drivers for the lavapipe CPU device",
            ErrorKind::Device);
}

bool HasLayer(const char *name) {
    uint32_t count = 0;
    MCD_VK(vkEnumerateInstanceLayerProperties(&count, nullptr));
    std::vector<VkLayerProperties> layers(count);
    MCD_VK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
    for (const VkLayerProperties &layer : layers)
        if (std::strcmp(layer.layerName, name) == 0) return true;
    return false;
}

bool HasInstanceExtension(const char *name) {
    uint32_t count = 0;
    MCD_VK(vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr));
    std::vector<VkExtensionProperties> extensions(count);
    MCD_VK(vkEnumerateInstanceExtensionProperties(nullptr, &count, extensions.data()));
    for (const VkExtensionProperties &e : extensions)
        if (std::strcmp(e.extensionName, name) == 0) return true;
    return false;
}

bool HasDeviceExtension(VkPhysicalDevice physicalDevice, const char *name) {
    uint32_t count = 0;
    MCD_VK(vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &count, nullptr));
    std::vector<VkExtensionProperties> extensions(count);
    MCD_VK(vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &count,
                                                extensions.data()));
    for (const VkExtensionProperties &e : extensions)
        if (std::strcmp(e.extensionName, name) == 0) return true;
    return false;
}

int ComputeQueueFamily(VkPhysicalDevice physicalDevice, bool *timestamps) {
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &count, families.data());
    // Prefer a compute-only family (async compute on GPUs), else any with compute.
    int best = -1;
    for (uint32_t i = 0; i < count; ++i) {
        if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
        bool computeOnly = !(families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT);
        if (best < 0 || computeOnly) best = int(i);
    }
    if (best >= 0 && timestamps) *timestamps = families[best].timestampValidBits > 0;
    return best;
}

DeviceInfo DescribeDevice(VkPhysicalDevice physicalDevice, int index) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physicalDevice, &props);
    DeviceInfo info;
    info.index = index;
    info.name = props.deviceName;
    info.type = props.deviceType;
    info.apiVersion = props.apiVersion;
    info.driverVersion = props.driverVersion;
    info.limits = props.limits;
    bool queueTimestamps = false;
    info.hasCompute = ComputeQueueFamily(physicalDevice, &queueTimestamps) >= 0;
    info.timestamps = queueTimestamps && props.limits.timestampPeriod > 0;
    info.pushDescriptors =
        HasDeviceExtension(physicalDevice, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(physicalDevice, &memory);
    for (uint32_t i = 0; i < memory.memoryHeapCount; ++i)
        if (memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            info.deviceLocalBytes += memory.memoryHeaps[i].size;
    return info;
}

int TypeRank(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 4;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 3;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 1;
        default:
            return 0;
    }
}

std::string Lower(std::string s) {
    for (char &c : s) c = char(std::tolower((unsigned char)c));
    return s;
}

// Pick a device per the selector (index or name substring), else the best ranked one.
int SelectDevice(const std::vector<DeviceInfo> &devices, std::string selector) {
    auto listing = [&] {
        std::string s;
        for (const DeviceInfo &d : devices)
            s += fmt::format("\n  {}: {} ({})", d.index, d.name, DeviceTypeName(d.type));
        return s;
    };
    if (devices.empty())
        throw Error(
            "no Vulkan device found (is a driver such as mesa-vulkan-drivers installed?)",
            ErrorKind::Device);
    if (!selector.empty()) {
        bool numeric = std::all_of(selector.begin(), selector.end(),
                                   [](char c) { return std::isdigit((unsigned char)c); });
        if (numeric) {
            int index = selector.size() > 6 ? -1 : std::atoi(selector.c_str());
            if (index < 0 || index >= int(devices.size()))
                throw Error(
                    fmt::format("device index {} out of range; devices:{}", index, listing()),
                    ErrorKind::InvalidArgument);
            if (!devices[index].hasCompute)
                throw Error(fmt::format("device {} has no compute queue", index),
                            ErrorKind::Device);
            return index;
        }
        for (const DeviceInfo &d : devices)
            if (d.hasCompute && Lower(d.name).find(Lower(selector)) != std::string::npos)
                return d.index;
        throw Error(fmt::format("no device matches '{}'; devices:{}", selector, listing()),
                    ErrorKind::InvalidArgument);
    }
    int best = -1;
    for (const DeviceInfo &d : devices)
        if (d.hasCompute && (best < 0 || TypeRank(d.type) > TypeRank(devices[best].type)))
            best = d.index;
    if (best < 0) throw Error("no Vulkan device with a compute queue", ErrorKind::Device);
    return best;
}

VkInstance CreateInstance(bool validation, bool debugUtils) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "mcdenoise";
    app.apiVersion = VK_API_VERSION_1_1;
    std::vector<const char *> layers, extensions;
    if (validation) layers.push_back(kValidationLayer);
    if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();
    VkInstance instance = VK_NULL_HANDLE;
    MCD_VK(vkCreateInstance(&ci, nullptr, &instance));
    // Load every entry point once per process, through vkGetInstanceProcAddr: those are the
    // loader's trampolines, which dispatch on the handle and so stay valid for every
    // instance and device (validated or not). Reloading per context (or volkLoadDevice's
    // direct device pointers) would retarget the calls of contexts that already exist.
    static std::once_flag loaded;
    std::call_once(loaded, [instance] { volkLoadInstance(instance); });
    return instance;
}

std::vector<VkPhysicalDevice> PhysicalDevices(VkInstance instance) {
    uint32_t count = 0;
    MCD_VK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    MCD_VK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
    return devices;
}

VKAPI_ATTR VkBool32 VKAPI_CALL OnValidationMessage(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
    const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    auto *context = static_cast<Context *>(user);
    const char *level =
        (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
    context->AddValidationMessage(
        fmt::format("validation {}: {}", level, data->pMessage ? data->pMessage : "?"));
    return VK_FALSE;
}

}  // namespace

const char *DeviceTypeName(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual GPU";
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "CPU";
        default:
            return "other";
    }
}

std::vector<DeviceInfo> ListDevices() {
    InitVolk();
    VkInstance instance = CreateInstance(false, false);
    std::vector<DeviceInfo> infos;
    std::vector<VkPhysicalDevice> devices = PhysicalDevices(instance);
    for (size_t i = 0; i < devices.size(); ++i)
        infos.push_back(DescribeDevice(devices[i], int(i)));
    vkDestroyInstance(instance, nullptr);
    return infos;
}

namespace {

// The first `most` bytes of the file at `path` (all by default), or none where it is absent
// or no regular file. Never throws: the context's destructor reads it too.
std::vector<char> ReadCacheFile(const std::string &path, size_t most = SIZE_MAX) {
    std::error_code ec;
    if (path.empty() || !std::filesystem::is_regular_file(path, ec)) return {};
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) return {};
    std::vector<char> data(size_t(std::min<uintmax_t>(size, most)));
    std::ifstream in(path, std::ios::binary);
    in.read(data.data(), std::streamsize(data.size()));
    data.resize(size_t(std::max<std::streamsize>(in.gcount(), 0)));
    return data;
}

// The 32-bit word of a pipeline cache's header at byte `at`.
uint32_t CacheWord(const std::vector<char> &data, size_t at) {
    uint32_t v;
    std::memcpy(&v, data.data() + at, 4);
    return v;
}

// Whether `data` opens with a pipeline cache's header (Vulkan spec, "Pipeline Cache Header").
bool IsPipelineCache(const std::vector<char> &data) {
    return data.size() >= 16 + VK_UUID_SIZE && CacheWord(data, 0) >= 16 + VK_UUID_SIZE &&
           CacheWord(data, 4) == VK_PIPELINE_CACHE_HEADER_VERSION_ONE;
}

// The build threads: one per core, at most 8, unless the options say how many.
int BuildThreads(int asked) {
    if (asked > 0) return asked;
    return std::clamp(int(std::thread::hardware_concurrency()), 1, 8);
}

}  // namespace

Context::Context(const ContextOptions &options)
    : builds(BuildThreads(options.pipelineThreads)) {
    InitVolk();
    if (options.validation && !HasLayer(kValidationLayer))
        throw Error(fmt::format("the Vulkan validation layer {} is not installed "
                                "(Debian package vulkan-validationlayers)",
                                kValidationLayer),
                    ErrorKind::Device);
    bool debugUtils =
        options.validation && HasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    instance = CreateInstance(options.validation, debugUtils);
    try {
        if (debugUtils) {
            VkDebugUtilsMessengerCreateInfoEXT mi{
                VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
            mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                 VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
            mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                             VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
            mi.pfnUserCallback = OnValidationMessage;
            mi.pUserData = this;
            // Instance-extension entry points belong to this instance: fetch them here.
            auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
            destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
                vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
            if (!create || !destroyMessenger)
                throw Error("VK_EXT_debug_utils is advertised but its functions are missing",
                            ErrorKind::Device);
            MCD_VK(create(instance, &mi, nullptr, &messenger));
        }

        std::vector<VkPhysicalDevice> devices = PhysicalDevices(instance);
        std::vector<DeviceInfo> infos;
        for (size_t i = 0; i < devices.size(); ++i)
            infos.push_back(DescribeDevice(devices[i], int(i)));
        std::string selector = options.device;
        if (selector.empty())
            if (const char *env = std::getenv("MCD_DEVICE")) selector = env;
        int chosen = SelectDevice(infos, selector);
        physicalDevice = devices[chosen];
        info = infos[chosen];
        // Exercise the descriptor-pool path on devices that do have push descriptors.
        if (const char *off = std::getenv("MCD_NO_PUSH_DESCRIPTORS"); off && *off == '1')
            info.pushDescriptors = false;
        vkGetPhysicalDeviceMemoryProperties(physicalDevice, &memoryProperties);
        queueFamily = uint32_t(ComputeQueueFamily(physicalDevice, nullptr));

        float priority = 1.f;
        VkDeviceQueueCreateInfo qi{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        qi.queueFamilyIndex = queueFamily;
        qi.queueCount = 1;
        qi.pQueuePriorities = &priority;
        std::vector<const char *> extensions;
        if (info.pushDescriptors) extensions.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
        VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        di.queueCreateInfoCount = 1;
        di.pQueueCreateInfos = &qi;
        di.enabledExtensionCount = uint32_t(extensions.size());
        di.ppEnabledExtensionNames = extensions.data();
        MCD_VK(vkCreateDevice(physicalDevice, &di, nullptr, &device));
        vkGetDeviceQueue(device, queueFamily, 0, &queue);
        pool.SetDevice(device);
        pool.SetKeep(options.keepFreedBuffers);
        const char *poison = std::getenv("MCD_POISON_BUFFERS");
        poisonBuffers = options.poisonBuffers || (poison && *poison == '1');
        stageTransfers = options.stageTransfers;

        VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
        pi.queueFamilyIndex = queueFamily;
        MCD_VK(vkCreateCommandPool(device, &pi, nullptr, &commandPool));
        VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        MCD_VK(vkCreateFence(device, &fi, nullptr, &fence));
        pipelineCachePath = options.pipelineCache;
        LoadPipelineCache();
    } catch (...) {
        Destroy();
        throw;
    }
}

Context::~Context() {
    Destroy();
}

void Context::Destroy() {
    if (device) {
        vkDeviceWaitIdle(device);
        pool.Trim();
        stagingUp.Release(*this);
        stagingDown.Release(*this);
        kernels.clear();
        SavePipelineCache();
        if (pipelineCache) vkDestroyPipelineCache(device, pipelineCache, nullptr);
        pipelineCache = VK_NULL_HANDLE;
        if (fence) vkDestroyFence(device, fence, nullptr);
        if (commandPool) vkDestroyCommandPool(device, commandPool, nullptr);
        vkDestroyDevice(device, nullptr);
        device = VK_NULL_HANDLE;
    }
    if (messenger) {
        destroyMessenger(instance, messenger, nullptr);
        messenger = VK_NULL_HANDLE;
    }
    if (instance) {
        vkDestroyInstance(instance, nullptr);
        instance = VK_NULL_HANDLE;
    }
}

void Context::LoadPipelineCache() {
    // A path that is there but no regular file (a directory) is the caller's mistake.
    std::error_code ec;
    if (!pipelineCachePath.empty() && std::filesystem::exists(pipelineCachePath, ec) &&
        !std::filesystem::is_regular_file(pipelineCachePath, ec))
        throw Error(fmt::format("pipeline cache '{}' is not a regular file", pipelineCachePath),
                    ErrorKind::InvalidArgument);
    std::vector<char> data = ReadCacheFile(pipelineCachePath);
    // The header: a file from another device or driver version is left unread rather than
    // handed to the driver.
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physicalDevice, &props);
    bool isCache = IsPipelineCache(data);
    bool fits = isCache && CacheWord(data, 8) == props.vendorID &&
                CacheWord(data, 12) == props.deviceID &&
                std::memcmp(data.data() + 16, props.pipelineCacheUUID, VK_UUID_SIZE) == 0;
    // Only a pipeline cache (any device's) or no file is replaced at the end: a path given
    // by mistake (a frame) is left as it was.
    pipelineCacheWritable = !pipelineCachePath.empty() &&
                            (isCache || !std::filesystem::exists(pipelineCachePath, ec));
    if (!fits) data.clear();
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    ci.initialDataSize = data.size();
    ci.pInitialData = data.empty() ? nullptr : data.data();
    if (vkCreatePipelineCache(device, &ci, nullptr, &pipelineCache) != VK_SUCCESS) {
        // A cache the driver refuses is no reason to fail: start an empty one.
        ci.initialDataSize = 0;
        ci.pInitialData = nullptr;
        data.clear();
        MCD_VK(vkCreatePipelineCache(device, &ci, nullptr, &pipelineCache));
    }
    pipelineStats.loadedBytes = data.size();
}

void Context::SavePipelineCache() {
    if (!pipelineCacheWritable || !pipelineCache || pipelineStats.built == 0) return;
    size_t size = 0;
    if (vkGetPipelineCacheData(device, pipelineCache, &size, nullptr) != VK_SUCCESS || !size)
        return;
    std::vector<char> data(size);
    if (vkGetPipelineCacheData(device, pipelineCache, &size, data.data()) != VK_SUCCESS) return;
    // Atomic: another process reading the cache sees the old file or the new one. A cache
    // that cannot be written costs time next run, never this run's result.
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path path(pipelineCachePath);
    // A file that appeared there during the run (an output given the cache's name) stays.
    if (fs::exists(path, ec) &&
        (!fs::is_regular_file(path, ec) ||
         !IsPipelineCache(ReadCacheFile(pipelineCachePath, 16 + VK_UUID_SIZE))))
        return;
    if (path.has_parent_path()) fs::create_directories(path.parent_path(), ec);
    std::string temp = fmt::format("{}.{}.tmp", pipelineCachePath, ::getpid());
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        out.write(data.data(), std::streamsize(size));
        if (!out) {
            out.close();
            fs::remove(temp, ec);
            return;
        }
    }
    fs::rename(temp, path, ec);
    if (ec) fs::remove(temp, ec);
}

uint32_t Context::FindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                                 VkMemoryPropertyFlags preferred,
                                 VkMemoryPropertyFlags avoided) const {
    int fallback = -1, partial = -1;
    for (uint32_t i = 0; i < memoryProperties.memoryTypeCount; ++i) {
        if (!(typeBits & (1u << i))) continue;
        VkMemoryPropertyFlags flags = memoryProperties.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        bool preferredOk = (flags & preferred) == preferred;
        if (preferredOk && !(flags & avoided)) return i;
        if (preferredOk && partial < 0) partial = int(i);
        if (fallback < 0) fallback = int(i);
    }
    if (partial >= 0) return uint32_t(partial);
    if (fallback < 0) throw Error("no Vulkan memory type fits the request", ErrorKind::Device);
    return uint32_t(fallback);
}

VkCommandBuffer Context::AllocateCommandBuffer() {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = commandPool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer commandBuffer = VK_NULL_HANDLE;
    MCD_VK(vkAllocateCommandBuffers(device, &ai, &commandBuffer));
    return commandBuffer;
}

void Context::FreeCommandBuffer(VkCommandBuffer commandBuffer) {
    vkFreeCommandBuffers(device, commandPool, 1, &commandBuffer);
}

void Context::SubmitAndWait(VkCommandBuffer commandBuffer) {
    if (cancel && cancel()) throw Error("the run was cancelled", ErrorKind::Cancelled);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &commandBuffer;
    MCD_VK(vkResetFences(device, 1, &fence));
    MCD_VK(vkQueueSubmit(queue, 1, &si, fence));
    MCD_VK(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX));
}

void Context::SubmitAndWait(const std::function<void(VkCommandBuffer)> &record) {
    VkCommandBuffer commandBuffer = AllocateCommandBuffer();
    try {
        VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        MCD_VK(vkBeginCommandBuffer(commandBuffer, &bi));
        record(commandBuffer);
        MCD_VK(vkEndCommandBuffer(commandBuffer));
        SubmitAndWait(commandBuffer);
    } catch (...) {
        FreeCommandBuffer(commandBuffer);
        throw;
    }
    FreeCommandBuffer(commandBuffer);
}

const Kernel &Context::GetKernel(const KernelDesc &desc) {
    std::string key = KernelKey(desc);
    auto it = kernels.find(key);
    if (it != kernels.end()) {
        if (it->second->Ahead()) {
            it->second->Hasten();
            std::lock_guard<std::mutex> lock(statsMutex);
            ++pipelineStats.preparedUsed;
        }
        return *it->second;
    }
    auto kernel = std::make_unique<Kernel>(*this, desc);
    const Kernel &ref = *kernel;
    kernels.emplace(std::move(key), std::move(kernel));
    return ref;
}

void Context::PrepareKernel(const KernelDesc &desc) {
    if (!builds.HasWorkers()) return;
    std::string key = KernelKey(desc);
    if (kernels.count(key)) return;
    kernels.emplace(std::move(key), std::make_unique<Kernel>(*this, desc, true));
    std::lock_guard<std::mutex> lock(statsMutex);
    ++pipelineStats.prepared;
}

std::vector<std::string> Context::TakeValidationMessages() {
    std::lock_guard<std::mutex> lock(messageMutex);
    std::vector<std::string> messages;
    messages.swap(validationMessages);
    return messages;
}

void Context::AddValidationMessage(std::string message) {
    std::lock_guard<std::mutex> lock(messageMutex);
    validationMessages.push_back(std::move(message));
}

}  // namespace mcd::vk
