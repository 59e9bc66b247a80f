#include "vk/Sampler.h"

namespace terralux::vk {

namespace {
VkSamplerCreateInfo clampInfo(VkFilter filter) {
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = filter;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.maxLod = 0.0f;
    return si;
}
}  // namespace

Sampler::Sampler(const VulkanContext& ctx, const VkSamplerCreateInfo& info) {
    VkSampler s = VK_NULL_HANDLE;
    check(vkCreateSampler(ctx.device(), &info, nullptr, &s), "vkCreateSampler");
    sampler_ = UniqueSampler(ctx.device(), s);
}

Sampler Sampler::linearClamp(const VulkanContext& ctx) { return Sampler(ctx, clampInfo(VK_FILTER_LINEAR)); }

Sampler Sampler::trilinearClamp(const VulkanContext& ctx) {
    VkSamplerCreateInfo si = clampInfo(VK_FILTER_LINEAR);
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    si.maxLod = VK_LOD_CLAMP_NONE;
    return Sampler(ctx, si);
}

Sampler Sampler::nearestClamp(const VulkanContext& ctx) { return Sampler(ctx, clampInfo(VK_FILTER_NEAREST)); }

Sampler Sampler::depthBorder(const VulkanContext& ctx) {
    VkSamplerCreateInfo si = clampInfo(VK_FILTER_NEAREST);
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
    si.borderColor = VK_BORDER_COLOR_FLOAT_OPAQUE_WHITE;
    return Sampler(ctx, si);
}

}  // namespace terralux::vk
