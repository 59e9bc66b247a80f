#include "vk/ComputePipeline.h"

#include "vk/Descriptors.h"

namespace terralux::vk {

ProbeVertexPass::ProbeVertexPass(const VulkanContext& ctx, std::span<const uint32_t> spirv)
    : device_(ctx.device()) {
    VkDescriptorSetLayoutBinding b[7]{};
    for (uint32_t i = 0; i < 7; ++i) {
        b[i].binding = i;
        b[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        b[i].descriptorCount = 1;
        b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo sli{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    sli.bindingCount = 7;
    sli.pBindings = b;
    check(vkCreateDescriptorSetLayout(device_, &sli, nullptr, &setLayout_), "vkCreateDescriptorSetLayout (compute)");
    VkPushConstantRange pc{VK_SHADER_STAGE_COMPUTE_BIT, 0, 4};
    VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pli.setLayoutCount = 1;
    pli.pSetLayouts = &setLayout_;
    pli.pushConstantRangeCount = 1;
    pli.pPushConstantRanges = &pc;
    check(vkCreatePipelineLayout(device_, &pli, nullptr, &layout_), "vkCreatePipelineLayout (compute)");

    VkShaderModuleCreateInfo mci{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    mci.codeSize = spirv.size_bytes();
    mci.pCode = spirv.data();
    VkShaderModule module;
    check(vkCreateShaderModule(device_, &mci, nullptr, &module), "vkCreateShaderModule (compute)");
    VkComputePipelineCreateInfo cpi{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cpi.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpi.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpi.stage.module = module;
    cpi.stage.pName = "main";
    cpi.layout = layout_;
    const VkResult r = vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &cpi, nullptr, &pipeline_);
    vkDestroyShaderModule(device_, module, nullptr);
    check(r, "vkCreateComputePipelines");

    set_ = allocateSingleSet(device_, setLayout_, 6, &pool_);
}

ProbeVertexPass::~ProbeVertexPass() {
    vkDestroyDescriptorPool(device_, pool_, nullptr);
    vkDestroyPipeline(device_, pipeline_, nullptr);
    vkDestroyPipelineLayout(device_, layout_, nullptr);
    vkDestroyDescriptorSetLayout(device_, setLayout_, nullptr);
}

void ProbeVertexPass::record(VkCommandBuffer cb, const Buffer& uniforms, const Buffer& probes,
                             const Buffer& cells, const Buffer& volumes, const Buffer& vertices,
                             const Buffer& out, const Buffer& errors, uint32_t vertexCount) {
    const Buffer* buffers[7] = {&uniforms, &probes, &cells, &volumes, &vertices, &out, &errors};
    writeBufferSet(device_, set_, buffers);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
    vkCmdPushConstants(cb, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &vertexCount);
    vkCmdDispatch(cb, (vertexCount + 63) / 64, 1, 1);
    VkBufferMemoryBarrier barrier{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.buffer = out.handle();
    barrier.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
                         0, 0, nullptr, 1, &barrier, 0, nullptr);
}

}  // namespace terralux::vk
