#include "render/features/Shadows.h"

#include <cmath>
#include <span>

#include <glm/geometric.hpp>

#include "ShaderBinaries.h"

namespace terralux::features {

using namespace frame;

blocks::ShadowBlock packShadows(const RenderSettings& s, const std::vector<Cascade>& cascades,
                                const CascadeRange& range, int resolution, int horizonFrom,
                                const HorizonMapInfo& horizon) {
    blocks::ShadowBlock block;
    for (size_t i = 0; i < cascades.size(); ++i) {
        block.lightViewProj[i] = cascades[i].lightViewProj;
        block.ends[int(i)] = float(cascades[i].farDistance);
        block.texel[int(i)] = cascades[i].texelSize;
        block.depthRange[int(i)] = cascades[i].depthRange;
    }
    block.forward = glm::normalize(s.camera.target - s.camera.position());
    block.nearDepth = float(range.nearDistance);
    block.depthBias = float(s.shadows.depthBias);
    block.normalBias = float(s.shadows.normalBias);
    block.tanSunRadius = std::tan(s.sun.angularRadius);
    block.mapResolution = float(resolution);
    block.cascadeCount = int(cascades.size());
    block.filterMode = int(s.shadows.filter);
    block.cascadeBlend = float(s.shadows.cascadeBlend);
    block.fadeOut = range.fadesOut ? 1.0f : 0.0f;
    block.horizonFrom = horizonFrom;
    block.horizonWidth = horizon.width;
    block.horizonHeight = horizon.height;
    return block;
}

std::unique_ptr<ShadowResources> buildShadowMaps(vk::VulkanContext& ctx, const RendererGpu& g, int resolution,
                                                 int cascades) {
    auto sh = std::make_unique<ShadowResources>();
    sh->resolution = resolution;
    sh->cascades = cascades;
    sh->maps = vk::Image::depthLayers(ctx, uint32_t(resolution), uint32_t(resolution), uint32_t(cascades));
    for (uint32_t i = 0; i < uint32_t(cascades); ++i) {
        const VkImageView view = sh->maps.layerView(i);
        sh->framebuffers.emplace_back(ctx, g.shadowPass, std::span<const VkImageView>(&view, 1),
                                      uint32_t(resolution), uint32_t(resolution));
    }
    return sh;
}

void addShadowPass(Frame& f) {
    ShadowResources* shadows = f.shadows;
    const bool skirt = f.skirtIndexCount > 0;
    if (!shadows || (shadows->drawn == f.lightMatrices && shadows->drawnSkirt == skirt &&
                     shadows->drawnLod == f.lodSerial))
        return;
    RendererGpu& g = f.g;
    if (!g.shadowDepth) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::shadowDepthVert();
        d.bindings = {kMeshBinding};
        d.attributes = {kMeshPosition};
        d.colorAttachments = 0;
        d.depthCompare = VK_COMPARE_OP_LESS_OR_EQUAL;
        // The skirt reaches past the map's near plane toward the sun: clamped there, it still
        // blocks (where the device clamps depth).
        d.depthClamp = f.ctx.depthClamp();
        g.shadowDepth = vk::createGraphicsPipeline(f.ctx, g.shadowPass.handle(), g.shadowDepthLayout.handle(), d);
    }
    PassInfo info{"shadow",
                  {{kShadowMaps, Access::DepthAttachmentClear},
                   {kVertices, Access::VertexAttributeRead},
                   {kIndices, Access::IndexRead}},
                  {std::string("vertex:") + kVertices, std::string("index:") + kIndices}};
    // The detail patches cast as they are drawn.
    if (f.detailIndexCount > 0) {
        info.uses.push_back({kDetailVertices, Access::VertexAttributeRead});
        info.bindings.push_back(std::string("vertex:") + kDetailVertices);
    }
    const uint32_t indexCount = f.indexCount + f.skirtIndexCount, res = uint32_t(shadows->resolution);
    const uint32_t detailCount = f.detailIndexCount + f.detailSkirtIndexCount, detailFirst = f.detailFirstIndex;
    const VkBuffer indices = f.indexBuffer, detailVertices = g.detailVertices.handle();
    g.graph.addPass(std::move(info), [&g, shadows, lightMatrices = f.lightMatrices, indexCount, indices, res,
                                      detailCount, detailFirst, detailVertices](VkCommandBuffer c) {
        for (size_t i = 0; i < lightMatrices.size(); ++i) {
            VkClearValue clear{};
            clear.depthStencil = {1.0f, 0};
            VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
            rbi.renderPass = g.shadowPass.handle();
            rbi.framebuffer = shadows->framebuffers[i].handle();
            rbi.renderArea = {{0, 0}, {res, res}};
            rbi.clearValueCount = 1;
            rbi.pClearValues = &clear;
            vkCmdBeginRenderPass(c, &rbi, VK_SUBPASS_CONTENTS_INLINE);
            if (indexCount > 0 || detailCount > 0) {
                setViewport(c, res, res);
                vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, g.shadowDepth.get());
                vkCmdPushConstants(c, g.shadowDepthLayout.handle(), VK_SHADER_STAGE_VERTEX_BIT, 0,
                                   sizeof(glm::mat4), &lightMatrices[i]);
                const VkBuffer vb = g.vertices.handle();
                const VkDeviceSize offset = 0;
                vkCmdBindVertexBuffers(c, 0, 1, &vb, &offset);
                vkCmdBindIndexBuffer(c, indices, 0, VK_INDEX_TYPE_UINT32);
                if (indexCount > 0) vkCmdDrawIndexed(c, indexCount, 1, 0, 0, 0);
                if (detailCount > 0) {
                    vkCmdBindVertexBuffers(c, 0, 1, &detailVertices, &offset);
                    vkCmdDrawIndexed(c, detailCount, 1, detailFirst, 0, 0);
                }
            }
            vkCmdEndRenderPass(c);
        }
    });
    shadows->drawn = f.lightMatrices;
    shadows->drawnSkirt = skirt;
    shadows->drawnLod = f.lodSerial;
}

}  // namespace terralux::features
