#include "render/Frame.h"

#include "bake/HeightfieldTracer.h"
#include "render/features/Lpv.h"
#include "render/features/Probes.h"
#include "render/features/Reflections.h"
#include "render/features/Shadows.h"
#include "render/features/Water.h"

namespace terralux {

namespace frame {

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

void setViewport(VkCommandBuffer cb, uint32_t width, uint32_t height) {
    VkViewport vp{0, 0, float(width), float(height), 0.0f, 1.0f};
    VkRect2D sc{{0, 0}, {width, height}};
    vkCmdSetViewport(cb, 0, 1, &vp);
    vkCmdSetScissor(cb, 0, 1, &sc);
}

void copyColor(VkCommandBuffer cb, VkImage source, VkImage dest, uint32_t width, uint32_t height, bool resolve) {
    const VkImageSubresourceLayers layers{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    if (resolve) {
        const VkImageResolve r{layers, {}, layers, {}, {width, height, 1}};
        vkCmdResolveImage(cb, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dest, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          1, &r);
    } else {
        const VkImageCopy r{layers, {}, layers, {}, {width, height, 1}};
        vkCmdCopyImage(cb, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dest, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                       &r);
    }
}

void memoryBarrier(VkCommandBuffer cb, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStages, VkAccessFlags dstAccess) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cb, srcStages, dstStages, 0, 1, &b, 0, nullptr, 0, nullptr);
}

}  // namespace frame

RendererGpu::~RendererGpu() = default;

int Frame::lightsVariant() const {
    return frame::lightsOfVariant((shadows ? frame::kShadowVariant : 0) |
                                  (reflections ? frame::kReflectionVariant : 0));
}

const vk::DescriptorSet& Frame::lights() const {
    if (reflections) return shadows ? reflections->shadowedLights[slotIndex] : reflections->lights[slotIndex];
    return shadows ? slot.shadowedLights : slot.lights;
}

const vk::RenderPass& RendererGpu::clearPassFor(uint32_t samples) const {
    return samples > 1 ? multisampledPasses.at(samples).first : clearPass;
}

const vk::RenderPass& RendererGpu::drawPassFor(uint32_t samples) const {
    return samples > 1 ? multisampledPasses.at(samples).second : drawPass;
}

void Frame::beginDrawing(VkCommandBuffer cb) const {
    VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rbi.renderPass = g.drawPassFor(samples).handle();
    rbi.framebuffer = framebuffer;
    rbi.renderArea = {{0, 0}, {width, height}};
    vkCmdBeginRenderPass(cb, &rbi, VK_SUBPASS_CONTENTS_INLINE);
    frame::setViewport(cb, width, height);
}

void Frame::beginClearing(VkCommandBuffer cb, VkFramebuffer fb, uint32_t fw, uint32_t fh, glm::vec3 clearColor,
                          uint32_t fbSamples) const {
    VkClearValue clear[2];
    clear[0].color = {{clearColor.x, clearColor.y, clearColor.z, 1.0f}};
    clear[1].depthStencil = {0.0f, 0};  // reversed Z: the far plane
    VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rbi.renderPass = g.clearPassFor(fbSamples).handle();
    rbi.framebuffer = fb;
    rbi.renderArea = {{0, 0}, {fw, fh}};
    rbi.clearValueCount = 2;
    rbi.pClearValues = clear;
    vkCmdBeginRenderPass(cb, &rbi, VK_SUBPASS_CONTENTS_INLINE);
    frame::setViewport(cb, fw, fh);
}

}  // namespace terralux
