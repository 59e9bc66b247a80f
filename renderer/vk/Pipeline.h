#pragma once
// Graphics pipelines: the state every pass shares (depth test, dynamic viewport and scissor, no
// culling) with each pass's shaders, vertex input, topology and colour attachments.

#include <cstdint>
#include <span>
#include <vector>

#include "vk/Handle.h"
#include "vk/VulkanContext.h"

namespace terralux::vk {

struct GraphicsPipelineDesc {
    std::span<const uint32_t> vert, frag;  // no fragment shader: a depth-only pass
    // Fragment-shader specialisation constants, by constant_id 0, 1, ... (32-bit each).
    std::vector<uint32_t> fragConstants;
    uint32_t colorAttachments = 1;  // 0 for a depth-only pass
    std::vector<VkVertexInputBindingDescription> bindings;
    std::vector<VkVertexInputAttributeDescription> attributes;
    VkPrimitiveTopology topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    bool depthWrite = true;
    // The camera's passes use reversed Z (near 1, far 0: float depth keeps its precision out to
    // the far plane, so water meets the shore without fighting); shadow maps keep 0 near.
    VkCompareOp depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    bool depthClamp = false;  // needs VulkanContext::depthClamp()
    uint32_t samples = 1;     // the render pass's
};

UniquePipeline createGraphicsPipeline(const VulkanContext& ctx, VkRenderPass pass,
                                      VkPipelineLayout layout, const GraphicsPipelineDesc& desc);

}  // namespace terralux::vk
