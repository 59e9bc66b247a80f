#pragma once
// Descriptor sets from a list of named bindings: uniform blocks, storage buffers and sampled
// images (combined image samplers). The builder makes the set layout (for pipeline layouts), or
// the layout, a pool sized for exactly those bindings and the written set.

#include <cstdint>
#include <string>
#include <vector>

#include "vk/Buffer.h"
#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class DescriptorSet {
public:
    DescriptorSet() = default;
    VkDescriptorSet handle() const { return set_; }
    VkDescriptorSetLayout layout() const { return layout_.get(); }
    // What each binding holds, by binding order: what a pass reports it binds.
    const std::vector<std::string>& bindingNames() const { return names_; }
    explicit operator bool() const { return set_ != VK_NULL_HANDLE; }

private:
    friend class DescriptorSetBuilder;
    UniqueSetLayout layout_;
    UniqueDescriptorPool pool_;  // freeing the pool frees the set
    VkDescriptorSet set_ = VK_NULL_HANDLE;
    std::vector<std::string> names_;
};

class DescriptorSetBuilder {
public:
    DescriptorSetBuilder& uniform(uint32_t binding, std::string name, const Buffer& buffer,
                                  VkShaderStageFlags stages);
    DescriptorSetBuilder& storage(uint32_t binding, std::string name, const Buffer& buffer,
                                  VkShaderStageFlags stages);
    // A combined image sampler; the image is in `layout` whenever the set is used.
    DescriptorSetBuilder& image(uint32_t binding, std::string name, VkImageView view, VkSampler sampler,
                                VkShaderStageFlags stages,
                                VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);

    // The layout alone (a pipeline layout needs it before any resource exists). No bindings
    // gives the empty layout that fills a set number a pipeline does not use.
    UniqueSetLayout buildLayout(const VulkanContext& ctx) const;
    // Layout, pool and the set, written.
    DescriptorSet build(const VulkanContext& ctx) const;

private:
    struct Entry {
        uint32_t binding;
        std::string name;
        VkDescriptorType type;
        VkShaderStageFlags stages;
        VkDescriptorBufferInfo buffer{};
        VkDescriptorImageInfo image{};
    };
    std::vector<Entry> entries_;
};

}  // namespace terralux::vk
