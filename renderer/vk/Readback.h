#pragma once
// Copies a colour image into host memory: the only way pixels come back to the CPU (`--render`,
// the tests, the viewport's on-demand grab).

#include <cstdint>
#include <vector>

#include "vk/Buffer.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class Readback {
public:
    // For RGBA16F images of `width` x `height`.
    Readback(const VulkanContext& ctx, uint32_t width, uint32_t height);

    VkBuffer buffer() const { return buffer_.handle(); }
    // Records the copy of `image` (TRANSFER_SRC_OPTIMAL) into the buffer.
    void recordCopy(VkCommandBuffer cb, VkImage image) const;
    // RGBA float pixels, row 0 at the top, once the copy has finished and is visible to the host.
    std::vector<float> pixels();
    // The same as 8-bit codes (unitToByte of each float), what a PNG holds: one table lookup a
    // sample and a quarter of the memory.
    std::vector<uint8_t> bytes();

private:
    uint32_t width_, height_;
    Buffer buffer_;
};

}  // namespace terralux::vk
