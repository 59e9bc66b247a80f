#include "render/features/Water.h"

#include <algorithm>

#include "ShaderBinaries.h"
#include "render/features/Atmosphere.h"
#include "render/features/Reflections.h"
#include "render/features/Terrain.h"
#include "water/Water.h"

namespace terralux::features {

using namespace frame;

blocks::WaterBlock packWater(const RenderSettings& s, const WaterInputs& in) {
    const WaterSettings& ws = s.water;
    blocks::WaterBlock block;
    block.level = in.level;
    block.time = float(s.time);
    block.shoreFade = in.shoreFadeDistance;
    block.depthAware = ws.depthAware ? 1.0f : 0.0f;
    block.scatter = ws.color;
    block.roughness = float(ws.roughness);
    block.absorption = ws.absorption;
    block.planarReflection = ws.reflection == WaterReflection::Planar ? 1.0f : 0.0f;
    const size_t waves = std::min<size_t>(ws.waves.size(), WaterSettings::kMaxWaves);
    block.fieldSize = in.fieldSize;
    block.distortion = float(ws.distortion);
    block.waveCount = float(waves);
    block.meshSpacing = in.meshSpacing;
    for (size_t i = 0; i < waves; ++i) {
        const water::WaveTerms wave = water::waveTerms(ws.waves[i]);
        blocks::WaveRecord& r = block.waves[i];
        r.direction = glm::vec2(wave.direction);
        r.k = float(wave.k);
        r.amplitude = float(wave.amplitude);
        r.omegaDeep = float(wave.omegaDeep);
        r.phase = float(wave.phase);
    }
    return block;
}

namespace {

VkPipeline waterPipeline(Frame& f) {
    const int variant = (f.shadows ? kShadowVariant : 0) | (f.fog ? kFogVariant : 0) |
                        (f.reflections ? kReflectionVariant : 0);
    vk::UniquePipeline& pipeline = f.g.waterPipelines[variant];
    if (!pipeline) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::waterVert();
        d.frag = f.reflections ? (f.shadows ? shaders::waterShadowReflectionFrag() : shaders::waterReflectionFrag())
                               : (f.shadows ? shaders::waterShadowFrag() : shaders::waterFrag());
        d.fragConstants = {f.fog ? 1u : 0u};
        d.bindings = {{0, sizeof(glm::vec2), VK_VERTEX_INPUT_RATE_VERTEX}};
        d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}};
        pipeline = vk::createGraphicsPipeline(f.ctx, f.g.drawPass.handle(),
                                              f.g.waterLayouts[size_t(f.lightsVariant())].handle(), d);
    }
    return pipeline.get();
}

// The terrain and the sky seen from the mirrored camera, scene-linear, with everything below the
// water clipped by the oblique near plane.
void addReflectionPass(Frame& f) {
    WaterResources* water = f.water;
    PassInfo info = terrainPassInfo(f, "water-reflection",
                                    {{kWaterReflection, Access::ColorAttachmentClear},
                                     {kWaterReflectionDepth, Access::DepthAttachmentClear}},
                                    f.slot.reflectionView);
    info.bindings.push_back("sky");
    const VkDescriptorSet viewSet = f.slot.reflectionView.handle(), skyLights = f.slot.lights.handle();
    const VkFramebuffer fb = water->reflectionFramebuffer.handle();
    const uint32_t rw = water->reflectionWidth, rh = water->reflectionHeight;
    const VkPipeline sky = skyPipeline(f);
    f.g.graph.addPass(std::move(info), [&f, draw = terrainDraw(f), viewSet, skyLights, fb, rw, rh,
                                        sky](VkCommandBuffer c) {
        f.beginClearing(c, fb, rw, rh, glm::vec3(0.0f));
        draw(c, viewSet);
        vkCmdEndRenderPass(c);
        VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
        rbi.renderPass = f.g.drawPass.handle();
        rbi.framebuffer = fb;
        rbi.renderArea = {{0, 0}, {rw, rh}};
        vkCmdBeginRenderPass(c, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        setViewport(c, rw, rh);
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, sky);
        const VkDescriptorSet sets[] = {viewSet, skyLights};
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, f.g.terrainLayouts[0].handle(), TLX_SET_VIEW, 2,
                                sets, 0, nullptr);
        vkCmdDraw(c, 3, 1, 0, 0);
        vkCmdEndRenderPass(c);
    });
}

// What lies under the water as the frame drew it, for the refraction.
void addSceneCopyPass(Frame& f) {
    const VkImage source = f.g.target->color.handle(), dest = f.water->scene.handle();
    const uint32_t w = f.width, h = f.height;
    f.g.graph.addPass({"water-scene", {{kColor, Access::TransferRead}, {kWaterScene, Access::TransferWrite}}, {}},
                      [source, dest, w, h](VkCommandBuffer c) {
                          VkImageCopy region{};
                          region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                          region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                          region.extent = {w, h, 1};
                          vkCmdCopyImage(c, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dest,
                                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
                      });
}

void addSurfacePass(Frame& f) {
    WaterResources* water = f.water;
    const vk::DescriptorSet& waterSet = water->sets[f.slotIndex];
    const vk::DescriptorSet& lights = f.lights();
    PassInfo info{"water",
                  {{kColor, Access::ColorAttachmentDraw},
                   {kDepth, Access::DepthAttachmentDraw},
                   {kWaterVertices, Access::VertexAttributeRead},
                   {kWaterIndices, Access::IndexRead},
                   {kWaterReflection, Access::FragmentSampledRead},
                   {kWaterScene, Access::FragmentSampledRead}},
                  concat(concat(concat(f.slot.view.bindingNames(), lights.bindingNames()), waterSet.bindingNames()),
                         {std::string("vertex:") + kWaterVertices, std::string("index:") + kWaterIndices})};
    if (f.shadows) info.uses.push_back({kShadowMaps, Access::FragmentSampledRead});
    if (f.reflections) info.uses.push_back({kReflectionRecords, Access::FragmentStorageRead});
    if (f.fog) info.bindings.push_back("fog");
    const VkPipeline pipeline = waterPipeline(f);
    const VkPipelineLayout layout = f.g.waterLayouts[size_t(f.lightsVariant())].handle();
    const VkDescriptorSet sets[] = {f.slot.view.handle(), lights.handle(), waterSet.handle()};
    const VkBuffer vb = water->vertices.handle(), ib = water->indices.handle();
    const uint32_t indices = water->indexCount;
    f.g.graph.addPass(std::move(info), [&f, pipeline, layout, sets, vb, ib, indices](VkCommandBuffer c) {
        f.beginDrawing(c);
        if (indices > 0) {
            vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
            vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, TLX_SET_VIEW, 3, sets, 0, nullptr);
            const VkDeviceSize offset = 0;
            vkCmdBindVertexBuffers(c, 0, 1, &vb, &offset);
            vkCmdBindIndexBuffer(c, ib, 0, VK_INDEX_TYPE_UINT32);
            vkCmdDrawIndexed(c, indices, 1, 0, 0, 0);
        }
        vkCmdEndRenderPass(c);
    });
}

}  // namespace

void addWaterPasses(Frame& f) {
    if (f.planarReflection) addReflectionPass(f);
    if (f.waterShading) addSceneCopyPass(f);
    if (f.water) addSurfacePass(f);
}

}  // namespace terralux::features
