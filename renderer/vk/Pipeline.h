#pragma once
// Graphics pipelines: the state every pass shares (depth test, dynamic viewport and scissor, no
// culling, one colour attachment) with each pass's shaders, vertex input and topology.

#include <cstdint>
#include <span>
#include <vector>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

struct GraphicsPipelineDesc {
    std::span<const uint32_t> vert, frag;
    std::vector<VkVertexInputBindingDescription> bindings;
    std::vector<VkVertexInputAttributeDescription> attributes;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    bool depthWrite = true;
};

UniquePipeline createGraphicsPipeline(const VulkanContext& ctx, VkRenderPass pass,
                                      VkPipelineLayout layout, const GraphicsPipelineDesc& desc);

}  // namespace terralux::vk
