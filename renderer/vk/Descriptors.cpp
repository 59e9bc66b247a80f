#include "vk/Descriptors.h"

namespace terralux::vk {

TerrainDescriptors::TerrainDescriptors(const VulkanContext& ctx, VkDescriptorSetLayout layout)
    : device_(ctx.device()) {
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3}};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = 2;
    pci.pPoolSizes = sizes;
    check(vkCreateDescriptorPool(device_, &pci, nullptr, &pool_), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool_;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &layout;
    check(vkAllocateDescriptorSets(device_, &ai, &set_), "vkAllocateDescriptorSets");
}

TerrainDescriptors::~TerrainDescriptors() { vkDestroyDescriptorPool(device_, pool_, nullptr); }

void TerrainDescriptors::update(const Buffer& uniforms, const Buffer& probes,
                                const Buffer& occupancy, const Buffer& volumes) {
    const Buffer* buffers[4] = {&uniforms, &probes, &occupancy, &volumes};
    VkDescriptorBufferInfo info[4];
    VkWriteDescriptorSet w[4]{};
    for (uint32_t i = 0; i < 4; ++i) {
        info[i] = {buffers[i]->handle(), 0, VK_WHOLE_SIZE};
        w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[i].dstSet = set_;
        w[i].dstBinding = i;
        w[i].descriptorCount = 1;
        w[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[i].pBufferInfo = &info[i];
    }
    vkUpdateDescriptorSets(device_, 4, w, 0, nullptr);
}

}  // namespace terralux::vk
