#pragma once
// Colour (RGBA16F, linear or display-encoded by the shader) + depth images, the render pass that
// clears and draws into them, and the readback of the colour image into host memory.

#include <vector>

#include "vk/Buffer.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class OffscreenTarget {
public:
    OffscreenTarget(const VulkanContext& ctx, uint32_t width, uint32_t height);
    ~OffscreenTarget();
    OffscreenTarget(const OffscreenTarget&) = delete;
    OffscreenTarget& operator=(const OffscreenTarget&) = delete;

    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }
    VkRenderPass renderPass() const { return renderPass_; }
    VkFramebuffer framebuffer() const { return framebuffer_; }
    // The colour image, in TRANSFER_SRC_OPTIMAL layout after a render (for presenting).
    VkImage colorImage() const { return color_.image; }

    // Copies the colour image (after the render pass) into the readback buffer; call inside the
    // same command buffer as the draw.
    void recordReadback(VkCommandBuffer cb);
    // RGBA float pixels, row 0 at the top, after the submitted readback finished.
    std::vector<float> pixels();

private:
    struct Image {
        VkImage image = VK_NULL_HANDLE;
        VkDeviceMemory memory = VK_NULL_HANDLE;
        VkImageView view = VK_NULL_HANDLE;
    };
    Image createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect);
    void destroyImage(Image& image);

    const VulkanContext& ctx_;
    uint32_t width_, height_;
    Image color_, depth_;
    VkRenderPass renderPass_ = VK_NULL_HANDLE;
    VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
    Buffer readback_;
};

inline constexpr VkFormat kColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

}  // namespace terralux::vk
