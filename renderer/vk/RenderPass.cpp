#include "vk/RenderPass.h"

#include <algorithm>
#include <vector>

namespace terralux::vk {

RenderPass::RenderPass(const VulkanContext& ctx, const RenderPassDesc& desc) {
    std::vector<VkAttachmentDescription> att;
    std::vector<VkAttachmentReference> colorRefs;
    for (VkFormat f : desc.colors) {
        VkAttachmentDescription a{};
        a.format = f;
        a.samples = VkSampleCountFlagBits(std::max(desc.samples, 1u));
        a.loadOp = desc.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        a.initialLayout = a.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        colorRefs.push_back({uint32_t(att.size()), VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
        att.push_back(a);
    }
    VkAttachmentReference depthRef{};
    if (desc.depth != VK_FORMAT_UNDEFINED) {
        VkAttachmentDescription a{};
        a.format = desc.depth;
        a.samples = VkSampleCountFlagBits(std::max(desc.samples, 1u));
        a.loadOp = desc.clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        a.storeOp = desc.storeDepth ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
        a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        a.initialLayout = a.finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        depthRef = {uint32_t(att.size()), VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
        att.push_back(a);
    }
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = uint32_t(colorRefs.size());
    sub.pColorAttachments = colorRefs.data();
    sub.pDepthStencilAttachment = desc.depth != VK_FORMAT_UNDEFINED ? &depthRef : nullptr;
    VkRenderPassCreateInfo rpi{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rpi.attachmentCount = uint32_t(att.size());
    rpi.pAttachments = att.data();
    rpi.subpassCount = 1;
    rpi.pSubpasses = &sub;
    VkRenderPass pass = VK_NULL_HANDLE;
    check(vkCreateRenderPass(ctx.device(), &rpi, nullptr, &pass), "vkCreateRenderPass");
    pass_ = UniqueRenderPass(ctx.device(), pass);
}

Framebuffer::Framebuffer(const VulkanContext& ctx, const RenderPass& pass,
                         std::span<const VkImageView> attachments, uint32_t width, uint32_t height)
    : width_(width), height_(height) {
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = pass.handle();
    fci.attachmentCount = uint32_t(attachments.size());
    fci.pAttachments = attachments.data();
    fci.width = width;
    fci.height = height;
    fci.layers = 1;
    VkFramebuffer fb = VK_NULL_HANDLE;
    check(vkCreateFramebuffer(ctx.device(), &fci, nullptr, &fb), "vkCreateFramebuffer");
    framebuffer_ = UniqueFramebuffer(ctx.device(), fb);
}

}  // namespace terralux::vk
