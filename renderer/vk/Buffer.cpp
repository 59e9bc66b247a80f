#include "vk/Buffer.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace terralux::vk {

Buffer::Buffer(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage,
               VkMemoryPropertyFlags properties)
    : size_(size) {
    VkDevice device = ctx.device();
    VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    bci.size = size > 0 ? size : 16;
    bci.usage = usage;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    VkBuffer buffer = VK_NULL_HANDLE;
    check(vkCreateBuffer(device, &bci, nullptr, &buffer), "vkCreateBuffer");
    buffer_ = UniqueBuffer(device, buffer);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer, &req);
    memory_ = ctx.allocateMemory(req, properties, "buffer");
    check(vkBindBufferMemory(device, buffer, memory_.get(), 0), "vkBindBufferMemory");
}

void* Buffer::map() {
    if (!mapped_)
        check(vkMapMemory(memory_.device(), memory_.get(), 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    return mapped_;
}

void Buffer::write(const void* bytes, VkDeviceSize size, VkDeviceSize offset) {
    std::memcpy(static_cast<char*>(map()) + offset, bytes, size_t(size));
}

Buffer Buffer::sharedDeviceLocal(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage) {
    // Where the device shares the host's memory, its local memory is host-visible too.
    const VkPhysicalDeviceType type = ctx.deviceType();
    if (type != VK_PHYSICAL_DEVICE_TYPE_CPU && type != VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU) return {};
    try {
        return Buffer(ctx, size, usage,
                      VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                          VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    } catch (const VulkanError&) {
        return {};  // no such memory type: through a staging copy, as on a discrete GPU
    }
}

Buffer Buffer::hostVisible(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage) {
    return Buffer(ctx, size, usage,
                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
}

Buffer Buffer::hostReadable(const VulkanContext& ctx, VkDeviceSize size, VkBufferUsageFlags usage) {
    try {
        return Buffer(ctx, size, usage,
                      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
                          VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    } catch (const VulkanError&) {
        return hostVisible(ctx, size, usage);  // no cached, coherent type: the plain one
    }
}

Buffer Buffer::deviceLocal(const VulkanContext& ctx, const void* bytes, VkDeviceSize size,
                           VkBufferUsageFlags usage, VkDeviceSize capacity) {
    // Written in place where it can be: a copy on the queue would wait behind every frame already
    // queued there.
    if (Buffer b = sharedDeviceLocal(ctx, std::max(size, capacity), usage)) {
        if (size > 0) b.write(bytes, size);
        return b;
    }
    Buffer staging = hostVisible(ctx, size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    if (size > 0) staging.write(bytes, size);
    Buffer b(ctx, std::max(size, capacity), usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (size > 0)
        ctx.submitAndWait([&](VkCommandBuffer cb) {
            VkBufferCopy copy{0, 0, size};
            vkCmdCopyBuffer(cb, staging.handle(), b.handle(), 1, &copy);
        });
    return b;
}

}  // namespace terralux::vk
