#pragma once
// The descriptor pool and the one set the terrain pass binds: frame uniforms, probe SH,
// occupancy and the volume table.

#include "vk/Buffer.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class TerrainDescriptors {
public:
    TerrainDescriptors(const VulkanContext& ctx, VkDescriptorSetLayout layout);
    ~TerrainDescriptors();
    TerrainDescriptors(const TerrainDescriptors&) = delete;
    TerrainDescriptors& operator=(const TerrainDescriptors&) = delete;

    void update(const Buffer& uniforms, const Buffer& probes, const Buffer& occupancy,
                const Buffer& volumes);
    VkDescriptorSet set() const { return set_; }

private:
    VkDevice device_;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
};

}  // namespace terralux::vk
