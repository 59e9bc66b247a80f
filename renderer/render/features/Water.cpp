#include "render/features/Water.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/packing.hpp>
#include <glm/packing.hpp>
#include <glm/vec2.hpp>
#include <tbb/parallel_for.h>

#include "ShaderBinaries.h"
#include "render/features/Atmosphere.h"
#include "render/features/Reflections.h"
#include "render/features/Terrain.h"
#include "vk/Swapchain.h"
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

// Vertices along the longer side of the water mesh, at most: the waves longer than two of its
// cells move it, the shorter ones live in the normal (water.glsl).
constexpr int kWaterMeshSide = 512;

// Bilinear sample of a row-major DEM-grid array at fractional (col, row).
float gridSample(const std::vector<float>& values, int width, int depth, double col, double row) {
    col = std::clamp(col, 0.0, double(width - 1));
    row = std::clamp(row, 0.0, double(depth - 1));
    const int c0 = std::min(int(col), std::max(width - 2, 0)), r0 = std::min(int(row), std::max(depth - 2, 0));
    const int c1 = std::min(c0 + 1, width - 1), r1 = std::min(r0 + 1, depth - 1);
    const double fx = col - c0, fz = row - r0;
    auto at = [&](int c, int r) { return double(values[size_t(r) * size_t(width) + size_t(c)]); };
    return float((at(c0, r0) * (1 - fx) + at(c1, r0) * fx) * (1 - fz) + (at(c0, r1) * (1 - fx) + at(c1, r1) * fx) * fz);
}

glm::uvec2 reflectionSize(uint32_t width, uint32_t height, float reflectionScale) {
    return {std::max(uint32_t(std::lround(float(width) * reflectionScale)), 1u),
            std::max(uint32_t(std::lround(float(height) * reflectionScale)), 1u)};
}

}  // namespace

vk::DescriptorSetBuilder waterSetBuilder(const vk::Buffer& block, VkImageView reflection, VkImageView scene,
                                         VkImageView field, VkSampler sampler) {
    constexpr VkShaderStageFlags frag = VK_SHADER_STAGE_FRAGMENT_BIT;
    return vk::DescriptorSetBuilder()
        .uniform(blocks::WaterBlock::kBinding, "water", block, kVertexFragment)
        .image(TLX_WATER_REFLECTION_BINDING, kWaterReflection, reflection, sampler, frag)
        .image(TLX_WATER_SCENE_BINDING, kWaterScene, scene, sampler, frag)
        .image(TLX_WATER_FIELD_BINDING, kWaterField, field, sampler, kVertexFragment);
}

std::unique_ptr<WaterResources> buildWater(vk::VulkanContext& ctx, const Heightfield& hf, float level, float margin) {
    auto w = std::make_unique<WaterResources>();
    w->level = level;
    w->margin = margin;

    // The field over the footprint, texel centres corner to corner like the surface maps: depth
    // below the level and distance to shore, from the DEM grid (bilinear where it is coarser).
    const std::vector<float> shore = water::shoreDistance(hf, double(level));
    const int hw = hf.width(), hd = hf.depth();
    const int fw = std::min(hw, 2048), fd = std::min(hd, 2048);
    vk::MipLevel texels{uint32_t(fw), uint32_t(fd), std::vector<uint8_t>(size_t(fw) * size_t(fd) * 4)};
    tbb::parallel_for(0, fd, [&](int j) {
        const double row = fd > 1 ? double(j) * double(hd - 1) / double(fd - 1) : 0.0;
        for (int i = 0; i < fw; ++i) {
            const double col = fw > 1 ? double(i) * double(hw - 1) / double(fw - 1) : 0.0;
            const float depth = level - gridSample(hf.heights(), hw, hd, col, row);
            const float distance = gridSample(shore, hw, hd, col, row);
            // Half floats hold ±65504: deeper water and farther shores than that look the same.
            const glm::vec2 v(std::clamp(depth, -6.0e4f, 6.0e4f), std::isfinite(distance) ? std::min(distance, 6.0e4f) : 6.0e4f);
            const uint32_t packed = glm::packHalf2x16(v);
            std::memcpy(texels.bytes.data() + 4 * (size_t(j) * size_t(fw) + size_t(i)), &packed, 4);
        }
    });
    w->fieldSize = {fw, fd};
    w->field = vk::Image::texture(ctx, VK_FORMAT_R16G16_SFLOAT, {texels});

    // The mesh: a grid at rest on the plane over the footprint, keeping the cells whose bed lies
    // below the highest crest somewhere.
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    const float longer = std::max({spanX, spanZ, 1e-3f});
    const float step = longer / float(kWaterMeshSide - 1);
    const int nx = std::max(int(std::ceil(spanX / step)) + 1, 2), nz = std::max(int(std::ceil(spanZ / step)) + 1, 2);
    w->spacing = std::max(spanX / float(nx - 1), spanZ / float(nz - 1));
    std::vector<glm::vec2> rest(size_t(nx) * size_t(nz));
    std::vector<uint8_t> wet(rest.size());
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const glm::vec2 p(hf.minX() + spanX * float(i) / float(nx - 1), hf.minZ() + spanZ * float(j) / float(nz - 1));
            rest[size_t(j) * size_t(nx) + size_t(i)] = p;
            wet[size_t(j) * size_t(nx) + size_t(i)] = hf.surfaceHeight(p.x, p.y) < level + margin ? 1 : 0;
        }
    std::vector<uint32_t> indices;
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const uint32_t v00 = uint32_t(j * nx + i), v10 = v00 + 1, v01 = v00 + uint32_t(nx), v11 = v01 + 1;
            if (wet[v00] || wet[v10] || wet[v01] || wet[v11]) indices.insert(indices.end(), {v00, v01, v11, v00, v11, v10});
        }
    w->indexCount = uint32_t(indices.size());
    if (indices.empty()) indices.push_back(0);
    w->vertices = vk::Buffer::deviceLocal(ctx, rest.data(), rest.size() * sizeof(glm::vec2), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    w->indices = vk::Buffer::deviceLocal(ctx, indices.data(), indices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    for (uint32_t i = 0; i < kRenderSlots; ++i)
        w->blocks.push_back(vk::Buffer::hostVisible(ctx, sizeof(blocks::WaterBlock), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
    return w;
}

bool waterTargetsServe(const WaterTargets* t, uint32_t width, uint32_t height, float reflectionScale) {
    const glm::uvec2 r = reflectionSize(width, height, reflectionScale);
    return t && t->width == width && t->height == height && t->reflectionWidth == r.x && t->reflectionHeight == r.y;
}

std::unique_ptr<WaterTargets> buildWaterTargets(vk::VulkanContext& ctx, const RendererGpu& g, const WaterResources& w,
                                                uint32_t width, uint32_t height, float reflectionScale) {
    const glm::uvec2 r = reflectionSize(width, height, reflectionScale);
    auto t = std::make_unique<WaterTargets>();
    t->reflection = vk::Image::colorTarget(ctx, r.x, r.y);
    t->reflectionDepth = vk::Image::depthTarget(ctx, r.x, r.y);
    const VkImageView views[] = {t->reflection.view(), t->reflectionDepth.view()};
    t->reflectionFramebuffer = vk::Framebuffer(ctx, g.clearPass, views, r.x, r.y);
    vk::ImageDesc copy;
    copy.width = width;
    copy.height = height;
    copy.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    t->scene = vk::Image(ctx, copy);
    for (uint32_t i = 0; i < kRenderSlots; ++i)
        t->sets.push_back(waterSetBuilder(w.blocks[i], t->reflection.view(), t->scene.view(), w.field.view(),
                                          g.linear.handle())
                              .build(ctx));
    t->width = width;
    t->height = height;
    t->reflectionWidth = r.x;
    t->reflectionHeight = r.y;
    return t;
}

int waterVariant(bool shadows, bool fog, bool reflections) {
    return (shadows ? kShadowVariant : 0) | (fog ? kFogVariant : 0) | (reflections ? kReflectionVariant : 0);
}

PipelineSet::Build waterPipelineBuild(const vk::VulkanContext& ctx, const RendererGpu& g, int variant,
                                      uint32_t samples) {
    const bool shadows = variant & kShadowVariant, reflections = variant & kReflectionVariant;
    vk::GraphicsPipelineDesc d;
    d.vert = shaders::waterVert();
    d.frag = reflections ? (shadows ? shaders::waterShadowReflectionFrag() : shaders::waterReflectionFrag())
                         : (shadows ? shaders::waterShadowFrag() : shaders::waterFrag());
    d.fragConstants = {(variant & kFogVariant) ? 1u : 0u};
    d.bindings = {{0, sizeof(glm::vec2), VK_VERTEX_INPUT_RATE_VERTEX}};
    d.attributes = {{0, 0, VK_FORMAT_R32G32_SFLOAT, 0}};
    d.samples = samples;
    const size_t lights = size_t(lightsOfVariant(variant));
    const VkRenderPass pass = g.drawPassFor(samples).handle();
    const VkPipelineLayout layout = g.waterLayouts[lights].handle();
    return [&ctx, pass, layout, d = std::move(d)] { return vk::createGraphicsPipeline(ctx, pass, layout, d); };
}

namespace {

VkPipeline waterPipeline(Frame& f) {
    const int variant = waterVariant(f.shadows, f.fog, f.reflections);
    return f.g.waterPipelines.get(variant | kSamplesKey(f.samples),
                                  [&] { return waterPipelineBuild(f.ctx, f.g, variant, f.samples); });
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
    const VkFramebuffer fb = water->targets->reflectionFramebuffer.handle();
    const uint32_t rw = water->targets->reflectionWidth, rh = water->targets->reflectionHeight;
    // The reflection target has one sample a pixel, whatever the frame's.
    const VkPipeline sky = skyPipeline(f, 1);
    f.g.graph.addPass(std::move(info), [&f, draw = terrainDraw(f, 1), viewSet, skyLights, fb, rw, rh,
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

// What lies under the water as the frame drew it, for the refraction: copied, or with msaa
// resolved (the refraction reads one value a pixel).
void addSceneCopyPass(Frame& f) {
    const VkImage source = f.g.target->color.handle(), dest = f.water->targets->scene.handle();
    const uint32_t w = f.width, h = f.height;
    const bool resolve = f.samples > 1;
    f.g.graph.addPass({"water-scene", {{kColor, Access::TransferRead}, {kWaterScene, Access::TransferWrite}}, {}},
                      [source, dest, w, h, resolve](VkCommandBuffer c) { copyColor(c, source, dest, w, h, resolve); });
}

void addSurfacePass(Frame& f) {
    WaterResources* water = f.water;
    const vk::DescriptorSet& waterSet = water->targets->sets[f.slotIndex];
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
