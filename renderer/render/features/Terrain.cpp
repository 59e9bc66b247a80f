#include "render/features/Terrain.h"

#include <glm/matrix.hpp>

#include "ShaderBinaries.h"
#include "render/features/Probes.h"
#include "render/features/Reflections.h"
#include "render/features/Lpv.h"
#include "render/features/Shadows.h"

namespace terralux::features {

using namespace frame;

blocks::CameraBlock packCamera(const RenderSettings& s, float extent, const DebugView& view) {
    const float aspect = float(s.width) / float(s.height);
    blocks::CameraBlock camera;
    camera.viewProj = s.camera.viewProjection(aspect, extent);
    camera.invViewProj = glm::inverse(camera.viewProj);
    camera.position = s.camera.position();
    camera.farPlane = s.camera.planes(extent).farPlane;
    camera.viewportSize = glm::vec2(float(s.width), float(s.height));
    camera.invViewportSize = 1.0f / camera.viewportSize;
    camera.debugView = s.debugView;
    camera.linearOutput = s.linearOutput ? 1 : 0;
    // What the per-vertex attribute holds: 2 the traced sun visibility, 1 the probe diagnostics,
    // 0 probe light.
    camera.vertexAttribute = view.needs.sunVisibility ? 2 : view.needs.probeDiagnostics ? 1 : 0;
    camera.shadowFilter = -1;
    return camera;
}

blocks::CameraBlock packMirroredCamera(const RenderSettings& s, const blocks::CameraBlock& camera, float extent,
                                       float level, float width, float height) {
    const float aspect = float(s.width) / float(s.height);
    blocks::CameraBlock mirrored = camera;
    mirrored.viewProj = s.camera.reflectedViewProjection(aspect, extent, level);
    mirrored.invViewProj = glm::inverse(mirrored.viewProj);
    mirrored.position = s.camera.reflectedPosition(level);
    mirrored.viewportSize = glm::vec2(width, height);
    mirrored.invViewportSize = 1.0f / mirrored.viewportSize;
    mirrored.debugView = kViewBeauty;
    mirrored.linearOutput = 1;
    // The waves distort the reflection by more than a penumbra: the 40 taps of PCSS would cost the
    // terrain drawn again at full price for nothing seen.
    mirrored.shadowFilter = int(ShadowFilter::Hard);
    return mirrored;
}

blocks::SurfaceBlock packSurface(const RenderSettings& s, const SurfaceInputs& in) {
    blocks::SurfaceBlock surface;
    surface.albedo = s.albedo;
    surface.albedoFromMap = in.albedoMap ? 1.0f : 0.0f;
    surface.roughness = float(s.terrain.roughness);
    surface.exposure = s.exposure;
    surface.specularAA = s.terrain.specularAA ? 1.0f : 0.0f;
    surface.roughnessFloor = float(kRoughnessFloor);
    surface.footprintMin = in.footprintMin;
    surface.invFootprintSpan = glm::vec2(in.footprintSpan.x > 0.0f ? 1.0f / in.footprintSpan.x : 0.0f,
                                         in.footprintSpan.y > 0.0f ? 1.0f / in.footprintSpan.y : 0.0f);
    surface.normalAoMapSize = in.normalAoMapSize;
    surface.albedoMapSize = in.albedoMapSize;
    surface.aoOnSky = s.ao.enabled && in.ao ? 1.0f : 0.0f;
    surface.aoOnProbes = s.ao.enabled ? float(s.ao.strength) : 0.0f;
    surface.probeAoLevel = in.probeAoLevel;
    const DetailSettings& d = s.detail;
    surface.detailStrength = d.enabled ? float(d.normalStrength) : 0.0f;
    surface.detailScale = d.enabled ? float(d.scale) : 1.0f;
    surface.detailFade = d.enabled ? float(d.fadeDistance) : 0.0f;
    surface.albedoVariation = d.enabled ? float(d.albedoVariation) : 0.0f;
    surface.groundAlbedo = in.borderAlbedo.value_or(s.albedo);
    surface.groundHeight = in.borderHeight;
    surface.ground = s.skirt ? 1.0f : 0.0f;
    surface.skyImage = in.skyImage ? 1.0f : 0.0f;
    surface.skyImageLod = in.skyImageLod;
    surface.skyImageScale = s.skyImageScale;
    surface.skyImageRotation = s.skyImageRotation;
    return surface;
}

int terrainVariant(bool vertexAttribute, bool shadows, bool fog, bool reflections, bool lpvVolumes, bool localLights) {
    return (vertexAttribute ? kProbeLightVariant : 0) | (shadows ? kShadowVariant : 0) | (fog ? kFogVariant : 0) |
           (reflections ? kReflectionVariant : 0) | (lpvVolumes ? kLpvVariant : 0) |
           (localLights ? kLocalLightsVariant : 0);
}

namespace {

// The terrain pass binds the LPV set with either the volumes or the local lights.
bool bindsLpvSet(int variant) { return (variant & (kLpvVariant | kLocalLightsVariant)) != 0; }

VkPipelineLayout terrainLayoutOf(const RendererGpu& g, int variant) {
    const size_t lights = size_t(lightsOfVariant(variant));
    return bindsLpvSet(variant) ? g.terrainLpvLayouts[lights].handle() : g.terrainLayouts[lights].handle();
}

}  // namespace

PipelineSet::Build terrainPipelineBuild(const vk::VulkanContext& ctx, const RendererGpu& g, int variant,
                                        uint32_t samples) {
    const bool vertexAttribute = variant & kProbeLightVariant, shadows = variant & kShadowVariant,
               reflections = variant & kReflectionVariant, lpvSet = bindsLpvSet(variant);
    vk::GraphicsPipelineDesc d;
    d.vert = vertexAttribute ? shaders::terrainProbeLightVert() : shaders::terrainVert();
    if (lpvSet)
        d.frag = reflections ? (shadows ? shaders::terrainShadowReflectionLpvFrag() : shaders::terrainReflectionLpvFrag())
                             : (shadows ? shaders::terrainShadowLpvFrag() : shaders::terrainLpvFrag());
    else
        d.frag = reflections ? (shadows ? shaders::terrainShadowReflectionFrag() : shaders::terrainReflectionFrag())
                             : (shadows ? shaders::terrainShadowFrag() : shaders::terrainFrag());
    d.fragConstants = {(variant & kFogVariant) ? 1u : 0u};
    if (lpvSet)
        d.fragConstants.insert(d.fragConstants.end(),
                               {(variant & kLpvVariant) ? 1u : 0u, (variant & kLocalLightsVariant) ? 1u : 0u});
    d.bindings = {kMeshBinding};
    d.attributes = {kMeshPosition, kMeshNormal};
    if (vertexAttribute) {
        d.bindings.push_back({1, 32, VK_VERTEX_INPUT_RATE_VERTEX});
        d.attributes.push_back({2, 1, VK_FORMAT_R32G32B32A32_SFLOAT, 0});
    }
    d.samples = samples;
    const VkRenderPass pass = g.clearPassFor(samples).handle();
    const VkPipelineLayout layout = terrainLayoutOf(g, variant);
    return [&ctx, pass, layout, d = std::move(d)] { return vk::createGraphicsPipeline(ctx, pass, layout, d); };
}

TerrainDraw terrainDraw(Frame& f, uint32_t samples) {
    RendererGpu& g = f.g;
    // The per-vertex attribute: probe light (or diagnostics) from the probe pass, or the traced
    // sun visibility; one of two vec4 per vertex (stride 32; bound at offset 16 for the diagnostics).
    const int variant = terrainVariant(f.probes || f.sunVisibility, f.shadows, f.fog, f.reflections, f.lpvVolumes,
                                       f.localLights);
    const VkPipelineLayout layout = terrainLayoutOf(g, variant);
    const VkPipeline handle =
        g.terrain.get(variant | kSamplesKey(samples), [&] { return terrainPipelineBuild(f.ctx, g, variant, samples); });
    VkBuffer attribute = VK_NULL_HANDLE;
    if (f.probes)
        attribute = f.probes->light.handle();
    else if (f.sunVisibility)
        attribute = g.sunVisibility.handle();
    // The diagnostics views read the probe pass's second vec4 in place of the first: one
    // attribute and one varying either way, so no view pays for the other.
    const VkDeviceSize attributeOffset = f.probes && f.view.needs.probeDiagnostics ? 16 : 0;
    const VkDescriptorSet lights = f.lights().handle();
    const VkDescriptorSet lpvSet = f.lpvSet ? f.slot.lpvSet.handle() : VK_NULL_HANDLE;
    const VkBuffer vertices = g.vertices.handle(), indices = f.indexBuffer;
    const uint32_t indexCount = f.indexCount;
    // The detail patches: the same pipeline over their own vertices and, with probes, the probe
    // light the probe pass wrote at them (a frame with detail patches has no other attribute).
    const uint32_t detailCount = f.detailIndexCount, detailFirst = f.detailFirstIndex;
    const VkBuffer detailVertices = g.detailVertices.handle();
    const VkBuffer detailAttribute = f.probes && f.probes->detail ? f.probes->detail->light.handle() : VK_NULL_HANDLE;
    return [handle, layout, lights, lpvSet, vertices, indices, attribute, attributeOffset, indexCount, detailCount,
            detailFirst, detailVertices, detailAttribute](VkCommandBuffer c, VkDescriptorSet viewSet) {
        if (indexCount == 0 && detailCount == 0) return;
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, handle);
        const VkDescriptorSet sets[] = {viewSet, lights, lpvSet};
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, TLX_SET_VIEW,
                                lpvSet != VK_NULL_HANDLE ? 3 : 2, sets, 0, nullptr);
        const VkBuffer vb[2] = {vertices, attribute};
        const VkDeviceSize offsets[2] = {0, attributeOffset};
        vkCmdBindVertexBuffers(c, 0, attribute ? 2 : 1, vb, offsets);
        vkCmdBindIndexBuffer(c, indices, 0, VK_INDEX_TYPE_UINT32);
        if (indexCount > 0) vkCmdDrawIndexed(c, indexCount, 1, 0, 0, 0);
        if (detailCount > 0) {
            const VkBuffer dvb[2] = {detailVertices, detailAttribute};
            vkCmdBindVertexBuffers(c, 0, attribute ? 2 : 1, dvb, offsets);
            vkCmdDrawIndexed(c, detailCount, 1, detailFirst, 0, 0);
        }
    };
}

PassInfo terrainPassInfo(const Frame& f, const char* name, std::vector<ResourceUse> targets,
                         const vk::DescriptorSet& viewSet) {
    PassInfo info{name, std::move(targets),
                  concat(concat(viewSet.bindingNames(), f.lights().bindingNames()),
                         {std::string("vertex:") + kVertices, std::string("index:") + kIndices})};
    info.uses.push_back({kVertices, Access::VertexAttributeRead});
    info.uses.push_back({kIndices, Access::IndexRead});
    if (f.shadows) info.uses.push_back({kShadowMaps, Access::FragmentSampledRead});
    if (f.reflections) info.uses.push_back({kReflectionRecords, Access::FragmentStorageRead});
    if (f.lpvVolumes) {
        info.uses.push_back({kLpvLight, Access::FragmentStorageRead});
        info.uses.push_back({kLpvGeometry, Access::FragmentStorageRead});
    }
    if (f.lpvSet) info.bindings = concat(info.bindings, f.slot.lpvSet.bindingNames());
    const char* attribute = f.probes ? kProbeLight : f.sunVisibility ? kSunVisibility : nullptr;
    if (attribute) {
        info.uses.push_back({attribute, Access::VertexAttributeRead});
        info.bindings.push_back(std::string("vertex:") + attribute);
    }
    if (f.detailIndexCount > 0) {
        info.uses.push_back({kDetailVertices, Access::VertexAttributeRead});
        info.bindings.push_back(std::string("vertex:") + kDetailVertices);
        if (attribute) {
            info.uses.push_back({kDetailLight, Access::VertexAttributeRead});
            info.bindings.push_back(std::string("vertex:") + kDetailLight);
        }
    }
    if (f.fog) info.bindings.push_back("fog");
    return info;
}

void addTerrainPass(Frame& f) {
    PassInfo info = terrainPassInfo(f, "terrain", {{kColor, Access::ColorAttachmentClear}, {kDepth, Access::DepthAttachmentClear}},
                                    f.slot.view);
    const VkDescriptorSet viewSet = f.slot.view.handle();
    f.g.graph.addPass(std::move(info), [&f, draw = terrainDraw(f, f.samples), viewSet](VkCommandBuffer c) {
        f.beginClearing(c, f.framebuffer, f.width, f.height, f.background, f.samples);
        draw(c, viewSet);
        vkCmdEndRenderPass(c);
    });
}

}  // namespace terralux::features
