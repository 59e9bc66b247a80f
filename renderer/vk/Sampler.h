#pragma once
// Samplers: filtered and nearest reads of colour targets, and the depth-compare sampler that
// shadow-map lookups use (hardware 2x2 PCF where the device filters depth).

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class Sampler {
public:
    Sampler() = default;
    Sampler(const VulkanContext& ctx, const VkSamplerCreateInfo& info);

    // Bilinear, clamped to the edge.
    static Sampler linearClamp(const VulkanContext& ctx);
    // Trilinear over every mip level, clamped to the edge (surface textures).
    static Sampler trilinearClamp(const VulkanContext& ctx);
    // Nearest texel, clamped to the edge (data images, debug reads).
    static Sampler nearestClamp(const VulkanContext& ctx);
    // Stored depths, nearest, clamped to a white border (depth 1): a texel outside the shadow map
    // blocks nothing. The shadows gather and compare them themselves (shaders/shadows.glsl).
    static Sampler depthBorder(const VulkanContext& ctx);

    VkSampler handle() const { return sampler_.get(); }

private:
    UniqueSampler sampler_;
};

}  // namespace terralux::vk
