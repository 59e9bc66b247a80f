#pragma once
// Instance, physical device choice, logical device, one graphics queue and a command pool: the
// one Vulkan device that serves offscreen rendering, tests and (later) the viewport.

#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "vk/Handle.h"

namespace terralux::vk {

// No Vulkan loader, no instance or no usable device: the CPU bake still works, rendering does not.
class VulkanUnavailable : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};
class VulkanError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Throws VulkanError naming the call and the VkResult.
void check(VkResult result, const char* what);

struct ContextOptions {
    // Device choice: "" = discrete GPU, then integrated, then virtual, then CPU (lavapipe);
    // "cpu" / "gpu" restrict the kind; anything else picks the first device whose name contains it.
    // The TERRALUX_VK_DEVICE environment variable supplies it when this is empty.
    std::string device;
    // Khronos validation layer with a messenger that counts (and records) every message;
    // TERRALUX_VK_VALIDATION=1 turns it on too.
    bool validation = false;
    // Presentation (the UI viewport): extra instance extensions (the window system's surface
    // extensions) and VK_KHR_swapchain on the device.
    std::vector<std::string> instanceExtensions;
    bool swapchain = false;
};

// Work submitted without waiting (VulkanContext::submit): its command buffer and fence.
class Submission {
public:
    Submission() = default;
    // Whether there is work (a default submission has none).
    explicit operator bool() const { return fence_.get() != VK_NULL_HANDLE; }
    // Whether the device has finished it: true when there is none.
    bool done() const;
    void wait() const;

private:
    friend class VulkanContext;
    VkDevice device_ = VK_NULL_HANDLE;
    UniqueCommandBuffer cb_;
    UniqueFence fence_;
};

class WorkerCommands;

class VulkanContext {
public:
    explicit VulkanContext(const ContextOptions& options = {});
    ~VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    uint32_t queueFamily() const { return queueFamily_; }
    VkCommandPool commandPool() const { return pool_; }
    const std::string& deviceName() const { return deviceName_; }
    // Whether the device samples cube-map arrays (imageCubeArray, enabled when present): the
    // reflection probes' cubes are one.
    bool cubeArrays() const { return cubeArrays_; }
    // Whether a pipeline may clamp depth instead of clipping at the near and far planes
    // (depthClamp, enabled when present): the shadow maps' skirt.
    bool depthClamp() const { return depthClamp_; }
    VkPhysicalDeviceType deviceType() const { return deviceType_; }
    // Nanoseconds a timestamp tick, 0 where the queue writes no timestamps; the bits a timestamp
    // holds (the rest are undefined).
    double timestampPeriod() const { return timestampPeriod_; }
    uint32_t timestampBits() const { return timestampBits_; }
    // The sample counts (VkSampleCountFlags) a framebuffer may have with both a colour and a depth
    // attachment: the multisampled anti-aliasing the device offers.
    uint32_t framebufferSampleCounts() const { return sampleCounts_; }
    bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }

    // Validation messages seen so far (warnings and errors), for tests that must see none.
    // A copy: the layers may report from a worker making buffers (TerrainRenderer's levels).
    size_t validationMessageCount() const {
        const std::lock_guard lock(messagesMutex_);
        return messages_.size();
    }
    std::vector<std::string> validationMessages() const {
        const std::lock_guard lock(messagesMutex_);
        return messages_;
    }

    uint32_t memoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const;

    // A primary command buffer from the context's pool, freed when it goes out of scope.
    UniqueCommandBuffer allocateCommandBuffer() const;
    // Memory for a buffer or image with these requirements; `what` names it in the error.
    UniqueMemory allocateMemory(const VkMemoryRequirements& requirements, VkMemoryPropertyFlags properties,
                                const char* what) const;
    // Records commands into a one-time command buffer, submits it and waits. The command buffer
    // is freed on every path, a throw from `record` included. On a thread holding WorkerCommands
    // the buffer and the fence are that thread's own.
    void submitAndWait(const std::function<void(VkCommandBuffer)>& record) const;
    // Records and submits as submitAndWait does, without waiting: the submission says when the
    // device has finished it, and must outlive the work (wait for it, or for the queue, first).
    Submission submit(const std::function<void(VkCommandBuffer)>& record) const;
    // Waits until the queue has finished everything submitted so far.
    void waitIdle() const;
    // How often the host has waited for the device here (waitIdle, submitAndWait): what a path
    // that must not wait is checked against.
    size_t hostWaits() const { return hostWaits_.load(std::memory_order_relaxed); }
    // The queue is externally synchronised (Vulkan): every submission, present and wait on it
    // holds this lock, for the moment of the call only, so a worker's uploads and the UI
    // thread's frames may reach it from two threads.
    std::unique_lock<std::mutex> lockQueue() const { return std::unique_lock(queueMutex_); }

private:
    friend class WorkerCommands;
    // Destroys whatever exists, in reverse order of creation; safe on a half-built context.
    void create(const ContextOptions& options);
    void destroy();
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    uint32_t queueFamily_ = 0;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    mutable std::atomic<size_t> hostWaits_{0};
    std::string deviceName_;
    bool cubeArrays_ = false;
    bool depthClamp_ = false;
    double timestampPeriod_ = 0.0;
    uint32_t timestampBits_ = 0;
    uint32_t sampleCounts_ = VK_SAMPLE_COUNT_1_BIT;
    VkPhysicalDeviceType deviceType_ = VK_PHYSICAL_DEVICE_TYPE_OTHER;
    VkPhysicalDeviceMemoryProperties memory_{};
    std::vector<std::string> messages_;
    mutable std::mutex messagesMutex_;
    mutable std::mutex queueMutex_;

    friend VKAPI_ATTR VkBool32 VKAPI_CALL onValidationMessage(
        VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
        const VkDebugUtilsMessengerCallbackDataEXT*, void*);
};

// A command pool and a fence of the calling thread's own, for as long as it lives: a worker
// that makes a renderer (its uploads go through submitAndWait) records beside the UI thread,
// whose frames use the context's pool (a pool, like the queue, is externally synchronised). Made
// and destroyed on the worker; every command buffer the thread allocates meanwhile comes from
// it, so none may outlive it (submit(), whose buffer does, is not for such a thread).
class WorkerCommands {
public:
    explicit WorkerCommands(const VulkanContext& ctx);
    ~WorkerCommands();
    WorkerCommands(const WorkerCommands&) = delete;
    WorkerCommands& operator=(const WorkerCommands&) = delete;

private:
    friend class VulkanContext;
    const VulkanContext& ctx_;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    WorkerCommands* outer_ = nullptr;
};

}  // namespace terralux::vk
