#include "vk/ComputePipeline.h"

#include "vk/ShaderModule.h"

namespace terralux::vk {

UniquePipeline createComputePipeline(const VulkanContext& ctx, VkPipelineLayout layout,
                                     std::span<const uint32_t> spirv) {
    const UniqueShaderModule module = createShaderModule(ctx, spirv);
    VkComputePipelineCreateInfo cpi{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpi.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpi.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpi.stage.module = module.get();
    cpi.stage.pName = "main";
    cpi.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    check(vkCreateComputePipelines(ctx.device(), VK_NULL_HANDLE, 1, &cpi, nullptr, &pipeline),
          "vkCreateComputePipelines");
    return UniquePipeline(ctx.device(), pipeline);
}

}  // namespace terralux::vk
