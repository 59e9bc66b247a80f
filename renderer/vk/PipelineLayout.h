#pragma once
// A pipeline layout: its descriptor-set layouts by set number (an empty layout where a pipeline
// binds nothing at that number) and an optional push-constant range.

#include <cstdint>
#include <span>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class PipelineLayout {
public:
    PipelineLayout() = default;
    PipelineLayout(const VulkanContext& ctx, std::span<const VkDescriptorSetLayout> sets,
                   uint32_t pushConstantBytes = 0, VkShaderStageFlags pushStages = 0);
    VkPipelineLayout handle() const { return layout_.get(); }

private:
    UniquePipelineLayout layout_;
};

}  // namespace terralux::vk
