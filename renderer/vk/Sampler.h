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
    // Depth compare (reference <= stored gives 1), bilinear, clamped to a white border: a point
    // outside the shadow map is lit.
    static Sampler depthCompare(const VulkanContext& ctx);

    VkSampler handle() const { return sampler_.get(); }

private:
    UniqueSampler sampler_;
};

}  // namespace terralux::vk
