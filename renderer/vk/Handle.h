#pragma once
// One owner per Vulkan handle: a move-only wrapper that destroys its handle with the device that
// made it. Members of this type make set-up exception-safe: whatever was created before a throw
// is destroyed by the members' destructors. The destroy calls live in Handle.cpp, so this header
// also compiles where vulkan.h comes without prototypes (Qt's QVulkanInstance).

#include <utility>

#include <vulkan/vulkan.h>

namespace terralux::vk {

void destroyHandle(VkDevice device, VkBuffer h);
void destroyHandle(VkDevice device, VkDeviceMemory h);
void destroyHandle(VkDevice device, VkImage h);
void destroyHandle(VkDevice device, VkImageView h);
void destroyHandle(VkDevice device, VkSampler h);
void destroyHandle(VkDevice device, VkRenderPass h);
void destroyHandle(VkDevice device, VkFramebuffer h);
void destroyHandle(VkDevice device, VkShaderModule h);
void destroyHandle(VkDevice device, VkPipeline h);
void destroyHandle(VkDevice device, VkPipelineLayout h);
void destroyHandle(VkDevice device, VkDescriptorSetLayout h);
void destroyHandle(VkDevice device, VkDescriptorPool h);
void destroyHandle(VkDevice device, VkFence h);
void destroyHandle(VkDevice device, VkSemaphore h);
void destroyHandle(VkDevice device, VkSwapchainKHR h);
void destroyHandle(VkDevice device, VkQueryPool h);
void freeCommandBuffer(VkDevice device, VkCommandPool pool, VkCommandBuffer cb);

template <typename T>
class DeviceHandle {
public:
    DeviceHandle() = default;
    DeviceHandle(VkDevice device, T handle) : device_(device), handle_(handle) {}
    ~DeviceHandle() { reset(); }
    DeviceHandle(DeviceHandle&& o) noexcept
        : device_(std::exchange(o.device_, VK_NULL_HANDLE)),
          handle_(std::exchange(o.handle_, VK_NULL_HANDLE)) {}
    DeviceHandle& operator=(DeviceHandle&& o) noexcept {
        if (this != &o) {
            reset();
            device_ = std::exchange(o.device_, VK_NULL_HANDLE);
            handle_ = std::exchange(o.handle_, VK_NULL_HANDLE);
        }
        return *this;
    }
    DeviceHandle(const DeviceHandle&) = delete;
    DeviceHandle& operator=(const DeviceHandle&) = delete;

    T get() const { return handle_; }
    operator T() const { return handle_; }
    explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
    VkDevice device() const { return device_; }
    void reset() {
        if (handle_ != VK_NULL_HANDLE) destroyHandle(device_, handle_);
        handle_ = VK_NULL_HANDLE;
    }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    T handle_ = VK_NULL_HANDLE;
};

using UniqueBuffer = DeviceHandle<VkBuffer>;
using UniqueMemory = DeviceHandle<VkDeviceMemory>;
using UniqueImage = DeviceHandle<VkImage>;
using UniqueImageView = DeviceHandle<VkImageView>;
using UniqueSampler = DeviceHandle<VkSampler>;
using UniqueRenderPass = DeviceHandle<VkRenderPass>;
using UniqueFramebuffer = DeviceHandle<VkFramebuffer>;
using UniqueShaderModule = DeviceHandle<VkShaderModule>;
using UniquePipeline = DeviceHandle<VkPipeline>;
using UniquePipelineLayout = DeviceHandle<VkPipelineLayout>;
using UniqueSetLayout = DeviceHandle<VkDescriptorSetLayout>;
using UniqueDescriptorPool = DeviceHandle<VkDescriptorPool>;
using UniqueFence = DeviceHandle<VkFence>;
using UniqueSemaphore = DeviceHandle<VkSemaphore>;
using UniqueSwapchain = DeviceHandle<VkSwapchainKHR>;
using UniqueQueryPool = DeviceHandle<VkQueryPool>;

// Command buffers go back to the pool they came from.
class UniqueCommandBuffer {
public:
    UniqueCommandBuffer() = default;
    UniqueCommandBuffer(VkDevice device, VkCommandPool pool, VkCommandBuffer cb)
        : device_(device), pool_(pool), cb_(cb) {}
    ~UniqueCommandBuffer() { reset(); }
    UniqueCommandBuffer(UniqueCommandBuffer&& o) noexcept
        : device_(o.device_), pool_(o.pool_), cb_(std::exchange(o.cb_, VK_NULL_HANDLE)) {}
    UniqueCommandBuffer& operator=(UniqueCommandBuffer&& o) noexcept {
        if (this != &o) {
            reset();
            device_ = o.device_;
            pool_ = o.pool_;
            cb_ = std::exchange(o.cb_, VK_NULL_HANDLE);
        }
        return *this;
    }
    UniqueCommandBuffer(const UniqueCommandBuffer&) = delete;
    UniqueCommandBuffer& operator=(const UniqueCommandBuffer&) = delete;

    VkCommandBuffer get() const { return cb_; }
    operator VkCommandBuffer() const { return cb_; }
    void reset() {
        if (cb_ != VK_NULL_HANDLE) freeCommandBuffer(device_, pool_, cb_);
        cb_ = VK_NULL_HANDLE;
    }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer cb_ = VK_NULL_HANDLE;
};

}  // namespace terralux::vk
