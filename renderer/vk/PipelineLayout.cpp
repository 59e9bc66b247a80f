#include "vk/PipelineLayout.h"

namespace terralux::vk {

PipelineLayout::PipelineLayout(const VulkanContext& ctx, std::span<const VkDescriptorSetLayout> sets,
                               uint32_t pushConstantBytes, VkShaderStageFlags pushStages) {
    VkPushConstantRange pc{pushStages, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pli.setLayoutCount = uint32_t(sets.size());
    pli.pSetLayouts = sets.data();
    pli.pushConstantRangeCount = pushConstantBytes > 0 ? 1 : 0;
    pli.pPushConstantRanges = &pc;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    check(vkCreatePipelineLayout(ctx.device(), &pli, nullptr, &layout), "vkCreatePipelineLayout");
    layout_ = UniquePipelineLayout(ctx.device(), layout);
}

}  // namespace terralux::vk
