#include "vk/Readback.h"

#include "scene/ImageCodes.h"

#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace terralux::vk {

namespace {
// IEEE 754 half to float (the readback format); no library in the dependency set provides it.
float halfToFloat(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000) << 16;
    uint32_t exp = (h >> 10) & 0x1F, mant = h & 0x3FF;
    uint32_t bits;
    if (exp == 0) {
        if (mant == 0) {
            bits = sign;
        } else {
            exp = 127 - 15 + 1;
            while (!(mant & 0x400)) {
                mant <<= 1;
                --exp;
            }
            bits = sign | (exp << 23) | ((mant & 0x3FF) << 13);
        }
    } else if (exp == 31) {
        bits = sign | 0x7F800000 | (mant << 13);
    } else {
        bits = sign | ((exp - 15 + 127) << 23) | (mant << 13);
    }
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

// Every half's float, once (256 KiB): a frame's pixels then convert with one load each.
const std::vector<float>& halfTable() {
    static const std::vector<float> table = [] {
        std::vector<float> t(65536);
        for (uint32_t h = 0; h < 65536; ++h) t[h] = halfToFloat(uint16_t(h));
        return t;
    }();
    return table;
}

// Every half's 8-bit code (64 KiB), by the rule of the floats it stands for.
const std::vector<uint8_t>& byteTable() {
    static const std::vector<uint8_t> table = [] {
        std::vector<uint8_t> t(65536);
        for (uint32_t h = 0; h < 65536; ++h) t[h] = unitToByte(halfTable()[h]);
        return t;
    }();
    return table;
}

// Each half float of the mapped frame looked up in a table of what it becomes.
template <typename T>
std::vector<T> lookUp(const uint16_t* half, size_t count, const T* table) {
    std::vector<T> out(count);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1 << 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) out[i] = table[half[i]];
    });
    return out;
}

}  // namespace

Readback::Readback(const VulkanContext& ctx, uint32_t width, uint32_t height)
    : width_(width), height_(height),
      buffer_(Buffer::hostReadable(ctx, VkDeviceSize(width) * height * 8, VK_BUFFER_USAGE_TRANSFER_DST_BIT)) {}

void Readback::recordCopy(VkCommandBuffer cb, VkImage image) const {
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {width_, height_, 1};
    vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer_.handle(), 1, &copy);
}

std::vector<float> Readback::pixels() {
    return lookUp(static_cast<const uint16_t*>(buffer_.map()), size_t(width_) * height_ * 4, halfTable().data());
}

std::vector<uint8_t> Readback::bytes() {
    return lookUp(static_cast<const uint16_t*>(buffer_.map()), size_t(width_) * height_ * 4, byteTable().data());
}

}  // namespace terralux::vk
