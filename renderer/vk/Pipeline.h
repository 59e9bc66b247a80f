#pragma once
// The terrain graphics pipeline: SPIR-V modules, its descriptor-set layout (one uniform block
// and three storage buffers), pipeline layout and pipeline state.

#include <cstdint>
#include <span>

#include "vk/VulkanContext.h"

namespace terralux::vk {

// Graphics pipeline state shared by the terrain and the overlays: depth test, dynamic viewport
// and scissor.
VkPipeline createGraphicsPipeline(VkDevice device, VkRenderPass pass, VkPipelineLayout layout,
                                  std::span<const uint32_t> vert, std::span<const uint32_t> frag,
                                  const VkPipelineVertexInputStateCreateInfo& vertexInput,
                                  bool depthWrite,
                                  VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);

class TerrainPipeline {
public:
    // vertex input: binding 0, interleaved vec3 position + vec3 normal (24 bytes); binding 1, one
    // of the two vec4 per vertex of the probe pass (stride 32; bound at offset 16 for the
    // diagnostics).
    TerrainPipeline(const VulkanContext& ctx, VkRenderPass pass, std::span<const uint32_t> vertSpirv,
                    std::span<const uint32_t> fragSpirv, std::span<const uint32_t> markerVert,
                    std::span<const uint32_t> markerFrag, std::span<const uint32_t> leafVert);
    ~TerrainPipeline();
    TerrainPipeline(const TerrainPipeline&) = delete;
    TerrainPipeline& operator=(const TerrainPipeline&) = delete;

    VkPipeline handle() const { return pipeline_; }
    // The probe-position overlay: per-instance vec4 (position, validity), same layout and set.
    VkPipeline markers() const { return markers_; }
    // The octree-leaf overlay: per-instance vec4 (min corner, edge), drawn as 24 line vertices.
    VkPipeline leaves() const { return leaves_; }
    VkPipelineLayout layout() const { return layout_; }
    VkDescriptorSetLayout setLayout() const { return setLayout_; }

private:
    VkDevice device_;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkPipeline leaves_ = VK_NULL_HANDLE;
    VkPipeline markers_ = VK_NULL_HANDLE;
};

}  // namespace terralux::vk
