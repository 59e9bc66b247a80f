#pragma once
// A VkBuffer and its memory. Device-local buffers are filled through a staging copy.

#include <cstddef>
#include <cstdint>

#include "vk/VulkanContext.h"

namespace terralux::vk {

class Buffer {
public:
    Buffer() = default;
    Buffer(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
           VkMemoryPropertyFlags properties);
    ~Buffer();
    Buffer(Buffer&& o) noexcept { *this = std::move(o); }
    Buffer& operator=(Buffer&& o) noexcept;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    // A device-local buffer holding `bytes`, uploaded through a host-visible staging buffer.
    static Buffer deviceLocal(const VulkanContext& ctx, const void* bytes, VkDeviceSize size,
                              VkBufferUsageFlags usage);
    // A host-visible, coherent buffer (uniforms, readback).
    static Buffer hostVisible(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage);

    VkBuffer handle() const { return buffer_; }
    VkDeviceSize size() const { return size_; }
    void* map();   // host-visible only; stays mapped until destruction
    void write(const void* bytes, VkDeviceSize size, VkDeviceSize offset = 0);

private:
    void release();
    VkDevice device_ = VK_NULL_HANDLE;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    VkDeviceSize size_ = 0;
    void* mapped_ = nullptr;
};

}  // namespace terralux::vk
