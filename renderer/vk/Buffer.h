#pragma once
// A VkBuffer and its memory. Device-local buffers are filled through a staging copy.

#include <cstddef>
#include <cstdint>
#include <utility>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class Buffer {
public:
    Buffer() = default;
    Buffer(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
           VkMemoryPropertyFlags properties);
    Buffer(Buffer&& o) noexcept
        : memory_(std::move(o.memory_)), buffer_(std::move(o.buffer_)),
          size_(std::exchange(o.size_, 0)), mapped_(std::exchange(o.mapped_, nullptr)) {}
    Buffer& operator=(Buffer&& o) noexcept {
        if (this != &o) {
            buffer_ = std::move(o.buffer_);  // the old buffer before the memory it is bound to
            memory_ = std::move(o.memory_);
            size_ = std::exchange(o.size_, 0);
            mapped_ = std::exchange(o.mapped_, nullptr);
        }
        return *this;
    }

    // A device-local buffer holding `bytes`, uploaded through a host-visible staging buffer (on
    // a device that shares the host's memory, written in place); `capacity` bytes long where that
    // is more (the rest undefined until written).
    static Buffer deviceLocal(const VulkanContext& ctx, const void* bytes, VkDeviceSize size,
                              VkBufferUsageFlags usage, VkDeviceSize capacity = 0);
    // A device-local buffer the host writes in place, where the device shares the host's memory
    // (a CPU device, an integrated GPU); empty elsewhere. It needs no queue, so any thread may
    // make and fill it.
    static Buffer sharedDeviceLocal(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage);
    // A host-visible, coherent buffer (uniforms, staging).
    static Buffer hostVisible(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage);
    // A host-visible, coherent buffer the host reads: host-cached memory where the device has it.
    // A discrete GPU's plain host-visible memory is write-combined, and reading it back a value
    // at a time is an order of magnitude slower than reading cached memory.
    static Buffer hostReadable(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage);

    VkBuffer handle() const { return buffer_.get(); }
    VkDeviceSize size() const { return size_; }
    explicit operator bool() const { return bool(buffer_); }
    void* map();   // host-visible only; stays mapped until destruction (freeing unmaps)
    void write(const void* bytes, VkDeviceSize size, VkDeviceSize offset = 0);

private:
    // Declared in destruction order: the buffer goes before the memory bound to it.
    UniqueMemory memory_;
    UniqueBuffer buffer_;
    VkDeviceSize size_ = 0;
    void* mapped_ = nullptr;
};

}  // namespace terralux::vk
