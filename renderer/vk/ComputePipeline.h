#pragma once
// The per-vertex probe-lighting compute pass: its descriptor-set layout (frame uniforms, the
// three probe buffers, vertices in, probe light out, the error maps), a push constant for the
// count, the pipeline, and its one descriptor set.

#include <cstdint>
#include <span>

#include "vk/Buffer.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

class ProbeVertexPass {
public:
    ProbeVertexPass(const VulkanContext& ctx, std::span<const uint32_t> spirv);
    ~ProbeVertexPass();
    ProbeVertexPass(const ProbeVertexPass&) = delete;
    ProbeVertexPass& operator=(const ProbeVertexPass&) = delete;

    // Binds the buffers and records the dispatch over `vertexCount` vertices, with a barrier
    // that makes the output visible to vertex input.
    void record(VkCommandBuffer cb, const Buffer& uniforms, const Buffer& probes, const Buffer& cells,
                const Buffer& volumes, const Buffer& vertices, const Buffer& out,
                const Buffer& errors, uint32_t vertexCount);

private:
    VkDevice device_;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    VkDescriptorSet set_ = VK_NULL_HANDLE;
};

}  // namespace terralux::vk
