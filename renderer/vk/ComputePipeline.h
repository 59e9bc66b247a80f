#pragma once
// Compute pipelines: one shader on a pipeline layout.

#include <cstdint>
#include <span>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

UniquePipeline createComputePipeline(const VulkanContext& ctx, VkPipelineLayout layout,
                                     std::span<const uint32_t> spirv);

}  // namespace terralux::vk
