#pragma once
// The descriptor pool and the one set the terrain pass binds: frame uniforms, probe SH,
// occupancy and the volume table. Both passes lay their sets out the same way: binding 0 the
// uniform block, bindings 1.. storage buffers, one set per pool.

#include <span>

#include "vk/Buffer.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

// A pool for one set of one uniform block and `storageBuffers` storage buffers, and that set.
VkDescriptorSet allocateSingleSet(VkDevice device, VkDescriptorSetLayout layout,
                                  uint32_t storageBuffers, VkDescriptorPool* pool);
// Points binding i of `set` at buffers[i] (binding 0 a uniform block, the rest storage).
void writeBufferSet(VkDevice device, VkDescriptorSet set, std::span<const Buffer* const> buffers);

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
