#pragma once
// Render passes and framebuffers. A pass keeps each attachment in its attachment layout before
// and after: the frame graph makes every layout change with its own barriers, so passes carry no
// external dependencies. Passes of the same formats are compatible, so one pipeline and one
// framebuffer serve both the clearing pass and the one that draws on top.

#include <cstdint>
#include <span>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

struct RenderPassDesc {
    std::span<const VkFormat> colors;
    VkFormat depth = VK_FORMAT_UNDEFINED;  // none
    bool clear = true;                     // false: load what is there
    bool storeDepth = false;               // true when a later pass reads or draws on the depth
    uint32_t samples = 1;                  // of every attachment
};

class RenderPass {
public:
    RenderPass() = default;
    RenderPass(const VulkanContext& ctx, const RenderPassDesc& desc);
    VkRenderPass handle() const { return pass_.get(); }

private:
    UniqueRenderPass pass_;
};

class Framebuffer {
public:
    Framebuffer() = default;
    // `attachments`: colour views then the depth view, as the pass declares them.
    Framebuffer(const VulkanContext& ctx, const RenderPass& pass,
                std::span<const VkImageView> attachments, uint32_t width, uint32_t height);
    VkFramebuffer handle() const { return framebuffer_.get(); }
    uint32_t width() const { return width_; }
    uint32_t height() const { return height_; }

private:
    UniqueFramebuffer framebuffer_;
    uint32_t width_ = 0, height_ = 0;
};

}  // namespace terralux::vk
