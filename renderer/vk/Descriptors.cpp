#include "vk/Descriptors.h"

#include <algorithm>
#include <map>

namespace terralux::vk {

DescriptorSetBuilder& DescriptorSetBuilder::uniform(uint32_t binding, std::string name,
                                                    const Buffer& buffer, VkShaderStageFlags stages) {
    Entry e{binding, std::move(name), VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, stages};
    e.buffer = {buffer.handle(), 0, VK_WHOLE_SIZE};
    entries_.push_back(std::move(e));
    return *this;
}

DescriptorSetBuilder& DescriptorSetBuilder::storage(uint32_t binding, std::string name,
                                                    const Buffer& buffer, VkShaderStageFlags stages) {
    Entry e{binding, std::move(name), VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, stages};
    e.buffer = {buffer.handle(), 0, VK_WHOLE_SIZE};
    entries_.push_back(std::move(e));
    return *this;
}

DescriptorSetBuilder& DescriptorSetBuilder::image(uint32_t binding, std::string name, VkImageView view,
                                                  VkSampler sampler, VkShaderStageFlags stages,
                                                  VkImageLayout layout) {
    Entry e{binding, std::move(name), VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, stages};
    e.image = {sampler, view, layout};
    entries_.push_back(std::move(e));
    return *this;
}

UniqueSetLayout DescriptorSetBuilder::buildLayout(const VulkanContext& ctx) const {
    std::vector<VkDescriptorSetLayoutBinding> b;
    for (const Entry& e : entries_) b.push_back({e.binding, e.type, 1, e.stages, nullptr});
    VkDescriptorSetLayoutCreateInfo sli{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    sli.bindingCount = uint32_t(b.size());
    sli.pBindings = b.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    check(vkCreateDescriptorSetLayout(ctx.device(), &sli, nullptr, &layout), "vkCreateDescriptorSetLayout");
    return UniqueSetLayout(ctx.device(), layout);
}

DescriptorSet DescriptorSetBuilder::build(const VulkanContext& ctx) const {
    DescriptorSet s;
    s.layout_ = buildLayout(ctx);
    std::map<VkDescriptorType, uint32_t> counts;
    for (const Entry& e : entries_) ++counts[e.type];
    std::vector<VkDescriptorPoolSize> sizes;
    for (const auto& [type, n] : counts) sizes.push_back({type, n});
    VkDescriptorPoolCreateInfo pci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pci.maxSets = 1;
    pci.poolSizeCount = uint32_t(sizes.size());
    pci.pPoolSizes = sizes.data();
    VkDescriptorPool pool = VK_NULL_HANDLE;
    check(vkCreateDescriptorPool(ctx.device(), &pci, nullptr, &pool), "vkCreateDescriptorPool");
    s.pool_ = UniqueDescriptorPool(ctx.device(), pool);
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool;
    ai.descriptorSetCount = 1;
    VkDescriptorSetLayout layout = s.layout_.get();
    ai.pSetLayouts = &layout;
    check(vkAllocateDescriptorSets(ctx.device(), &ai, &s.set_), "vkAllocateDescriptorSets");

    std::vector<VkWriteDescriptorSet> w;
    for (const Entry& e : entries_) {
        VkWriteDescriptorSet write{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        write.dstSet = s.set_;
        write.dstBinding = e.binding;
        write.descriptorCount = 1;
        write.descriptorType = e.type;
        if (e.type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER) write.pImageInfo = &e.image;
        else write.pBufferInfo = &e.buffer;
        w.push_back(write);
    }
    if (!w.empty()) vkUpdateDescriptorSets(ctx.device(), uint32_t(w.size()), w.data(), 0, nullptr);

    std::vector<const Entry*> ordered;
    for (const Entry& e : entries_) ordered.push_back(&e);
    std::sort(ordered.begin(), ordered.end(), [](const Entry* a, const Entry* b) { return a->binding < b->binding; });
    for (const Entry* e : ordered) s.names_.push_back(e->name);
    return s;
}

}  // namespace terralux::vk
