// The Vulkan context: instance (with the validation layer when asked), device selection,
// one compute queue, memory-type lookup, one-shot submits and the kernel cache.
#pragma once

#include <volk.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "host/vk/buffer.h"
#include "host/vk/buffer_pool.h"
#include "host/vk/build_pool.h"

namespace mcd::vk {

class Kernel;
struct KernelDesc;

struct DeviceInfo {
    int index = -1;
    std::string name;
    VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
    uint32_t apiVersion = 0;
    uint32_t driverVersion = 0;
    bool hasCompute = false;
    bool pushDescriptors = false;
    bool timestamps = false;
    VkPhysicalDeviceLimits limits{};
    VkDeviceSize deviceLocalBytes = 0;
};

const char *DeviceTypeName(VkPhysicalDeviceType type);

// Every Vulkan device the loader sees, in enumeration order.
std::vector<DeviceInfo> ListDevices();

struct ContextOptions {
    // Device index or case-insensitive name substring; empty means $MCD_DEVICE, then the
    // best device (discrete, then integrated, then virtual, then CPU).
    std::string device;
    // Khronos validation layer; its messages are collected (see TakeValidationMessages).
    bool validation = false;
    // A VkPipelineCache file: read when the context starts (ignored when absent, damaged or
    // from another device or driver), written back atomically when it ends if pipelines
    // were built and the file was absent or a pipeline cache. Empty: no file.
    std::string pipelineCache;
    // Threads that build pipelines while a run records (host/vk/build_pool.h): 0 one per
    // core (at most 8), 1 each pipeline built when it is asked for.
    int pipelineThreads = 0;
    // Keep freed buffers for the next of the same size (host/vk/buffer_pool.h).
    bool keepFreedBuffers = true;
    // Fill every buffer handed out, fresh or reused, with NaN bits (0xff bytes) before its
    // user sees it: a check that no kernel reads what it did not write. Also set by
    // $MCD_POISON_BUFFERS=1.
    bool poisonBuffers = false;
    // Transfers go through the staging buffers even where device memory is host-visible
    // (the path of discrete GPUs, for tests on other devices).
    bool stageTransfers = false;
};

class Context {
  public:
    explicit Context(const ContextOptions &options = {});
    ~Context();
    Context(const Context &) = delete;
    Context &operator=(const Context &) = delete;

    VkInstance Instance() const { return instance; }
    VkPhysicalDevice PhysicalDevice() const { return physicalDevice; }
    VkDevice Device() const { return device; }
    VkQueue Queue() const { return queue; }
    uint32_t QueueFamily() const { return queueFamily; }
    const DeviceInfo &Info() const { return info; }
    const VkPhysicalDeviceLimits &Limits() const { return info.limits; }
    // The largest buffer a kernel can bind both as a storage buffer and as a float texel
    // view (Buffer::FloatView): what one binding of a stage written by one kernel and read
    // by the next may hold.
    VkDeviceSize BindingBytes() const {
        return std::min<VkDeviceSize>(info.limits.maxStorageBufferRange,
                                      VkDeviceSize(info.limits.maxTexelBufferElements) * 4);
    }
    bool ValidationEnabled() const { return messenger != VK_NULL_HANDLE; }

    // Index of a memory type allowed by typeBits with all `required` flags, preferring
    // one that also has `preferred` and none of `avoided`.
    uint32_t FindMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                            VkMemoryPropertyFlags preferred,
                            VkMemoryPropertyFlags avoided = 0) const;

    // Record with `record` into a fresh command buffer, submit, and wait for it.
    void SubmitAndWait(const std::function<void(VkCommandBuffer)> &record);
    VkCommandBuffer AllocateCommandBuffer();
    void FreeCommandBuffer(VkCommandBuffer commandBuffer);
    void SubmitAndWait(VkCommandBuffer commandBuffer);
    // A run's cancellation (RunOptions::cancel): polled before each submission, which
    // throws mcd::Error of kind Cancelled once it returns true. Empty: never.
    void SetCancel(std::function<bool()> poll) { cancel = std::move(poll); }

    // A kernel is built once per SPIR-V blob and specialization, then reused. Its pipeline
    // builds on the build threads (Kernel::Pipeline waits for it).
    const Kernel &GetKernel(const KernelDesc &desc);
    // The kernel made ahead of the run that will record it, its build queued behind those
    // asked for now (GetKernel then moves it up, if it has not started): a method lists the
    // kernels a run will record before it starts (FrontEnd::PrepareKernels), so that they
    // build beside earlier work. Nothing with one build thread (nothing to build beside).
    void PrepareKernel(const KernelDesc &desc);
    BuildPool &Builds() { return builds; }
    VkPipelineCache PipelineCache() const { return pipelineCache; }
    // Pipelines built so far and the seconds vkCreateComputePipelines took for them (what a
    // pipeline cache saves), and the bytes the cache file gave at the start (0: none).
    struct PipelineStats {
        int built = 0;
        double seconds = 0;
        size_t loadedBytes = 0;
        // Of the kernels made so far, those made ahead (PrepareKernel) and those of them a
        // run asked for (GetKernel) since.
        int prepared = 0, preparedUsed = 0;
        // Each build: the kernel's name and its seconds, in build order.
        std::vector<std::pair<std::string, double>> each;
    };
    // Waits for the builds under way. The seconds are each build's own, summed: with
    // several build threads, more than the wall time they took.
    const PipelineStats &Pipelines() {
        builds.Wait();
        return pipelineStats;
    }
    // Called from the build threads.
    void NotePipelineBuilt(const std::string &name, double seconds) {
        std::lock_guard<std::mutex> lock(statsMutex);
        ++pipelineStats.built;
        pipelineStats.seconds += seconds;
        pipelineStats.each.emplace_back(name, seconds);
    }
    // Keys (name, code, specialization constants; see KernelKey) of the kernels built so
    // far: which variants a run compiled.
    std::vector<std::string> KernelKeys() const {
        std::vector<std::string> keys;
        for (const auto &[key, kernel] : kernels) keys.push_back(key);
        return keys;
    }

    // Validation messages since the last call (errors and warnings).
    std::vector<std::string> TakeValidationMessages();
    void AddValidationMessage(std::string message);

    // GPU memory held in Buffers: live bytes, the peak since the last reset, and every
    // allocation since then by name, so a run can say what it allocated (--explain) and
    // tests can check what it did not.
    struct MemoryLedger {
        VkDeviceSize live = 0, peak = 0;
        std::vector<std::pair<std::string, VkDeviceSize>> allocations;
    };
    const MemoryLedger &Ledger() const { return ledger; }
    void ResetLedger() {
        ledger.peak = ledger.live;
        ledger.allocations.clear();
    }
    void NoteAllocation(const std::string &name, VkDeviceSize bytes) {
        ledger.live += bytes;
        ledger.peak = std::max(ledger.peak, ledger.live);
        ledger.allocations.push_back({name, bytes});
    }
    void NoteRelease(VkDeviceSize bytes) { ledger.live -= std::min(ledger.live, bytes); }

    // Freed buffers kept for reuse, and the options of how buffers are made.
    BufferPool &Pool() { return pool; }
    bool PoisonsBuffers() const { return poisonBuffers; }
    bool StagesTransfers() const { return stageTransfers; }
    // The staging buffer of one direction, kept for the context's life and grown as
    // transfers need (Buffer::Upload, Buffer::Download).
    Staging &StagingFor(bool download) { return download ? stagingDown : stagingUp; }

  private:
    void Destroy();
    void LoadPipelineCache();
    void SavePipelineCache();

    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    PFN_vkDestroyDebugUtilsMessengerEXT destroyMessenger = nullptr;
    VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    uint32_t queueFamily = 0;
    VkCommandPool commandPool = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkPipelineCache pipelineCache = VK_NULL_HANDLE;
    std::string pipelineCachePath;
    bool pipelineCacheWritable = false;
    PipelineStats pipelineStats;
    std::mutex statsMutex;
    DeviceInfo info;
    VkPhysicalDeviceMemoryProperties memoryProperties{};

    std::mutex messageMutex;
    std::vector<std::string> validationMessages;
    // Declared before the kernels: destroyed after them, so that a kernel's build finishes
    // before the kernel goes.
    BuildPool builds;
    std::map<std::string, std::unique_ptr<Kernel>> kernels;
    MemoryLedger ledger;
    std::function<bool()> cancel;
    // Freed with the device (Destroy), before it goes.
    BufferPool pool;
    Staging stagingUp{false}, stagingDown{true};
    bool poisonBuffers = false, stageTransfers = false;
};

}  // namespace mcd::vk
