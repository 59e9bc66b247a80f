#include "vk/Descriptors.h"

#include <vector>

namespace terralux::vk {

VkDescriptorSet allocateSingleSet(VkDevice device, VkDescriptorSetLayout layout,
                                  uint32_t storageBuffers, VkDescriptorPool* pool) {
    VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storageBuffers}};
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = 2;
    pci.pPoolSizes = sizes;
    check(vkCreateDescriptorPool(device, &pci, nullptr, pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = *pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    check(vkAllocateDescriptorSets(device, &ai, &set), "vkAllocateDescriptorSets");
    return set;
}

void writeBufferSet(VkDevice device, VkDescriptorSet set, std::span<const Buffer* const> buffers) {
    std::vector<VkDescriptorBufferInfo> info(buffers.size());
    std::vector<VkWriteDescriptorSet> w(buffers.size());
    for (uint32_t i = 0; i < buffers.size(); ++i) {
        info[i] = {buffers[i]->handle(), 0, VK_WHOLE_SIZE};
        w[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        w[i].dstSet = set;
        w[i].dstBinding = i;
        w[i].descriptorCount = 1;
        w[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        w[i].pBufferInfo = &info[i];
    }
    vkUpdateDescriptorSets(device, uint32_t(w.size()), w.data(), 0, nullptr);
}

TerrainDescriptors::TerrainDescriptors(const VulkanContext& ctx, VkDescriptorSetLayout layout)
    : device_(ctx.device()), set_(allocateSingleSet(device_, layout, 3, &pool_)) {}

TerrainDescriptors::~TerrainDescriptors() { vkDestroyDescriptorPool(device_, pool_, nullptr); }

void TerrainDescriptors::update(const Buffer& uniforms, const Buffer& probes,
                                const Buffer& occupancy, const Buffer& volumes) {
    const Buffer* buffers[4] = {&uniforms, &probes, &occupancy, &volumes};
    writeBufferSet(device_, set_, buffers);
}

}  // namespace terralux::vk
