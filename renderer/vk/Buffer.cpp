#include "vk/Buffer.h"

#include <cstring>
#include <utility>

namespace terralux::vk {

Buffer::Buffer(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
               VkMemoryPropertyFlags properties)
    : device_(ctx.device()), size_(size) {
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size > 0 ? size : 16;
    bci.usage = usage;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(device_, &bci, nullptr, &buffer_), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    ai.allocationSize = req.size;
    ai.memoryTypeIndex = ctx.memoryType(req.memoryTypeBits, properties);
    check(vkAllocateMemory(device_, &ai, nullptr, &memory_), "vkAllocateMemory (buffer)");
    check(vkBindBufferMemory(device_, buffer_, memory_, 0), "vkBindBufferMemory");
}

Buffer::~Buffer() { release(); }

void Buffer::release() {
    if (!device_) return;
    if (mapped_) vkUnmapMemory(device_, memory_);
    if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
    if (memory_) vkFreeMemory(device_, memory_, nullptr);
    device_ = VK_NULL_HANDLE;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
    mapped_ = nullptr;
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
    if (this != &o) {
        release();
        device_ = std::exchange(o.device_, VK_NULL_HANDLE);
        buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
        size_ = std::exchange(o.size_, 0);
        mapped_ = std::exchange(o.mapped_, nullptr);
    }
    return *this;
}

void* Buffer::map() {
    if (!mapped_) check(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    return mapped_;
}

void Buffer::write(const void* bytes, VkDeviceSize size, VkDeviceSize offset) {
    std::memcpy(static_cast<char*>(map()) + offset, bytes, size_t(size));
}

Buffer Buffer::hostVisible(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage) {
    return Buffer(ctx, size, usage,
                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
}

Buffer Buffer::deviceLocal(const VulkanContext& ctx, const void* bytes, VkDeviceSize size,
                           VkBufferUsageFlags usage) {
    Buffer staging = hostVisible(ctx, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    if (size > 0) staging.write(bytes, size);
    Buffer b(ctx, size, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (size > 0)
        ctx.submitAndWait([&](VkCommandBuffer cb) {
            VkBufferCopy copy{0, 0, size};
            vkCmdCopyBuffer(cb, staging.handle(), b.handle(), 1, &copy);
        });
    return b;
}

}  // namespace terralux::vk
