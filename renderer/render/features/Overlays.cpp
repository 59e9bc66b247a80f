#include "render/features/Overlays.h"

#include <span>

#include "ShaderBinaries.h"
#include "render/features/Reflections.h"

namespace terralux::features {

using namespace frame;

blocks::OverlayBlock packOverlay(const RenderSettings& s, float smallestLeaf, float smallestLeafPixels,
                                 float pixelScale) {
    blocks::OverlayBlock overlay;
    overlay.smallestLeaf = smallestLeaf;
    overlay.smallestLeafPixels = smallestLeafPixels * pixelScale;
    overlay.markerPixels = kMarkerPixels * pixelScale;
    overlay.drawValid = s.showProbePositions ? 1 : 0;
    overlay.drawMovedRejected = 1;
    return overlay;
}

std::vector<GizmoInstance> packGizmos(const std::vector<GizmoLine>& lines) {
    std::vector<GizmoInstance> out;
    out.reserve(lines.size());
    for (const GizmoLine& l : lines) out.push_back({glm::vec4(l.a, 1.0f), glm::vec4(l.b, 1.0f), glm::vec4(l.color, 1.0f)});
    return out;
}

namespace {

// An overlay pipeline: one vec4 per instance (a marker: xyz, w its kind; a leaf: min corner,
// edge), drawn over the frame without writing depth.
vk::UniquePipeline overlayPipeline(Frame& f, std::span<const uint32_t> vert, VkPrimitiveTopology topology) {
    vk::GraphicsPipelineDesc d;
    d.vert = vert;
    d.frag = shaders::markersFrag();
    d.bindings = {{0, 16, VK_VERTEX_INPUT_RATE_INSTANCE}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0}};
    d.topology = topology;
    d.depthWrite = false;
    d.samples = f.samples;
    return vk::createGraphicsPipeline(f.ctx, f.g.drawPassFor(f.samples).handle(), f.g.overlayLayout.handle(), d);
}

void ensurePipelines(Frame& f) {
    RendererGpu& g = f.g;
    const int key = kSamplesKey(f.samples);
    vk::UniquePipeline& markers = g.markerPipelines[key];
    if ((f.drawMarkers || f.drawReflectionMarkers) && !markers)
        markers = overlayPipeline(f, shaders::markersVert(), VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST);
    // The 12 edges of each leaf box as a line list.
    vk::UniquePipeline& leaves = g.leafPipelines[key];
    if (f.drawLeaves && !leaves)
        leaves = overlayPipeline(f, shaders::leavesVert(), VK_PRIMITIVE_TOPOLOGY_LINE_LIST);
    // Gizmos: two vertices per line instance, drawn whatever the depth says, so a volume's bounds
    // and handles stay in sight behind a ridge.
    vk::UniquePipeline& gizmos = g.gizmoPipelines[key];
    if (f.drawGizmos && !gizmos) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::gizmosVert();
        d.frag = shaders::markersFrag();
        d.bindings = {{0, sizeof(GizmoInstance), VK_VERTEX_INPUT_RATE_INSTANCE}};
        d.attributes = {{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0},
                        {1, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 16},
                        {2, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 32}};
        d.topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
        d.depthWrite = false;
        d.depthCompare = VK_COMPARE_OP_ALWAYS;
        d.samples = f.samples;
        gizmos = vk::createGraphicsPipeline(f.ctx, f.g.drawPassFor(f.samples).handle(), f.g.overlayLayout.handle(), d);
    }
}

}  // namespace

void addOverlayPass(Frame& f) {
    if (!f.drawMarkers && !f.drawReflectionMarkers && !f.drawLeaves && !f.drawGizmos) return;
    ensurePipelines(f);
    RendererGpu& g = f.g;
    PassInfo info{"overlays",
                  {{kColor, Access::ColorAttachmentDraw}, {kDepth, Access::DepthAttachmentDraw}},
                  concat(f.slot.view.bindingNames(), f.slot.overlays.bindingNames())};
    if (f.drawLeaves) {
        info.uses.push_back({kLeaves, Access::VertexAttributeRead});
        info.bindings.push_back(std::string("vertex:") + kLeaves);
    }
    if (f.drawMarkers) {
        info.uses.push_back({kMarkers, Access::VertexAttributeRead});
        info.bindings.push_back(std::string("vertex:") + kMarkers);
    }
    if (f.drawReflectionMarkers) {
        info.uses.push_back({kReflectionMarkers, Access::VertexAttributeRead});
        info.bindings.push_back(std::string("vertex:") + kReflectionMarkers);
    }
    if (f.drawGizmos) info.bindings.push_back("vertex:gizmos");
    const uint32_t leafCount = f.drawLeaves ? f.leafCount : 0, markerCount = f.drawMarkers ? f.markerCount : 0;
    const uint32_t gizmoCount = f.drawGizmos ? f.gizmoCount : 0;
    const vk::Buffer* reflectionMarkers = f.drawReflectionMarkers ? &g.reflections->markers : nullptr;
    const uint32_t reflectionMarkerCount = f.drawReflectionMarkers ? g.reflections->markerCount : 0;
    const int key = kSamplesKey(f.samples);
    const VkPipeline leafPipeline = g.leafPipelines[key].get(), markerPipeline = g.markerPipelines[key].get(),
                     gizmoPipeline = g.gizmoPipelines[key].get();
    g.graph.addPass(std::move(info), [&f, leafCount, markerCount, reflectionMarkers, reflectionMarkerCount,
                                      gizmoCount, leafPipeline, markerPipeline, gizmoPipeline](VkCommandBuffer c) {
        RendererGpu& g = f.g;
        f.beginDrawing(c);
        const VkDescriptorSet view = f.slot.view.handle(), overlay = f.slot.overlays.handle();
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, g.overlayLayout.handle(),
                                TLX_SET_VIEW, 1, &view, 0, nullptr);
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, g.overlayLayout.handle(),
                                TLX_SET_SUBSYSTEM, 1, &overlay, 0, nullptr);
        auto draw = [&](VkPipeline pipeline, const vk::Buffer& instances, uint32_t vertices, uint32_t count) {
            vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
            const VkDeviceSize offset = 0;
            const VkBuffer b = instances.handle();
            vkCmdBindVertexBuffers(c, 0, 1, &b, &offset);
            vkCmdDraw(c, vertices, count, 0, 0);
        };
        if (leafCount > 0) draw(leafPipeline, g.leaves, 24, leafCount);
        if (markerCount > 0) draw(markerPipeline, g.markers, 6, markerCount);
        if (reflectionMarkerCount > 0) draw(markerPipeline, *reflectionMarkers, 6, reflectionMarkerCount);
        if (gizmoCount > 0) draw(gizmoPipeline, f.slot.gizmos, 2, gizmoCount);
        vkCmdEndRenderPass(c);
    });
}

}  // namespace terralux::features
