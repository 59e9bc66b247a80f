#include "render/TerrainRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>

#include <glm/gtc/packing.hpp>
#include <glm/packing.hpp>
#include <glm/mat4x4.hpp>
#include <tbb/parallel_for.h>

#include "ShaderBinaries.h"
#include "ShaderMath.h"
#include "bake/DiffuseBake.h"
#include "bake/ReflectionBake.h"
#include "bake/SphereSampling.h"
#include "lpv/Lpv.h"
#include "render/Frame.h"
#include "render/features/Atmosphere.h"
#include "render/features/Lpv.h"
#include "render/features/Overlays.h"
#include "render/features/Probes.h"
#include "render/features/Reflections.h"
#include "render/features/Shadows.h"
#include "render/features/Terrain.h"
#include "render/features/Water.h"
#include "scene/DebugViews.h"
#include "render/UniformBlocks.h"
#include "terrain/SurfaceAlbedo.h"
#include "terrain/SurfaceMaps.h"
#include "vk/Buffer.h"
#include "vk/ComputePipeline.h"
#include "vk/Descriptors.h"
#include "vk/Image.h"
#include "vk/Pipeline.h"
#include "vk/PipelineLayout.h"
#include "vk/Readback.h"
#include "vk/RenderPass.h"
#include "vk/Sampler.h"

namespace terralux {

using namespace frame;

namespace {

// Vertices along the longer side of the water mesh, at most: the waves longer than two of its
// cells move it, the shorter ones live in the normal (water.glsl).
constexpr int kWaterMeshSide = 512;

// Shadow rays per vertex of the sun-visibility view, stratified over the sun's disc.
constexpr int kSunVisibilitySamples = 16;

// Smallest octree leaf the leaf overlay draws, in pixels on screen.
constexpr float kSmallestLeafPixels = 6.0f;

constexpr VkShaderStageFlags kVertexFragment = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

}  // namespace

struct TerrainRenderer::Output {
    bool readback = true;
    VkImage swapchainImage = VK_NULL_HANDLE;
    VkExtent2D extent{0, 0};
};

namespace {

// The lights set of a variant: sun and sky and the atmosphere; with kShadowedLights the
// cascades' block and their maps (compared, and raw for the PCSS blocker search); with
// kReflectedLights the reflection grid of frame slot `slot`, the probe records and their cubes.
// Null `maps` and `r`: the layout alone.
template <class Gpu>
vk::DescriptorSetBuilder lightsBuilder(int variant, const FrameSlot& f, const Gpu& g, VkImageView maps,
                                       const ReflectionResources* r, uint32_t slot) {
    constexpr VkShaderStageFlags frag = VK_SHADER_STAGE_FRAGMENT_BIT;
    vk::DescriptorSetBuilder b;
    b.uniform(blocks::SunSkyBlock::kBinding, "sun-sky", f.sunSky, frag)
        .uniform(blocks::AtmosphereBlock::kBinding, "atmosphere", f.atmosphere, frag);
    if (variant & kShadowedLights)
        b.uniform(blocks::ShadowBlock::kBinding, "shadow", f.shadow, frag)
            .image(TLX_SHADOW_MAP_COMPARE_BINDING, std::string(kShadowMaps) + "(compare)", maps,
                   g.compareSampler.handle(), frag)
            .image(TLX_SHADOW_MAP_DEPTH_BINDING, std::string(kShadowMaps) + "(depth)", maps,
                   g.depthSampler.handle(), frag);
    if (variant & kReflectedLights) {
        static const vk::Buffer none;
        b.uniform(blocks::ReflectionBlock::kBinding, kReflectionGrid, r ? r->blocks[slot] : none, frag)
            .storage(TLX_REFLECTION_PROBES_BINDING, kReflectionRecords, r ? r->records : none, frag)
            .image(TLX_REFLECTION_CUBES_BINDING, kReflectionCubes, r ? r->cubes.view() : VK_NULL_HANDLE,
                   g.trilinear.handle(), frag);
    }
    return b;
}

// The view set: camera, surface block and the surface maps. `t` null: the layout alone. The
// surface block reaches the vertex stage too: the water mesh finds its field by the footprint.
vk::DescriptorSetBuilder viewSetBuilder(const FrameSlot& f, const vk::Buffer& camera, const SurfaceTextures* t,
                                        VkSampler sampler) {
    constexpr VkShaderStageFlags frag = VK_SHADER_STAGE_FRAGMENT_BIT;
    return vk::DescriptorSetBuilder()
        .uniform(blocks::CameraBlock::kBinding, "camera", camera, kVertexFragment)
        .uniform(blocks::SurfaceBlock::kBinding, "surface", f.surface, kVertexFragment)
        .image(TLX_SURFACE_NORMAL_AO_BINDING, kSurfaceNormalAo, t ? t->normalAo.view() : VK_NULL_HANDLE, sampler, frag)
        .image(TLX_SURFACE_ALBEDO_BINDING, kSurfaceAlbedo, t ? t->albedo.view() : VK_NULL_HANDLE, sampler, frag)
        .image(TLX_SURFACE_FILLED_BINDING, kSurfaceFilled, t ? t->filled.view() : VK_NULL_HANDLE, sampler, frag);
}

// The water set: its block, the reflection, the frame under the water and the field (read by the
// mesh too). Null views: the layout alone.
vk::DescriptorSetBuilder waterSetBuilder(const vk::Buffer& block, VkImageView reflection, VkImageView scene,
                                         VkImageView field, VkSampler sampler) {
    constexpr VkShaderStageFlags frag = VK_SHADER_STAGE_FRAGMENT_BIT;
    return vk::DescriptorSetBuilder()
        .uniform(blocks::WaterBlock::kBinding, "water", block, kVertexFragment)
        .image(TLX_WATER_REFLECTION_BINDING, kWaterReflection, reflection, sampler, frag)
        .image(TLX_WATER_SCENE_BINDING, kWaterScene, scene, sampler, frag)
        .image(TLX_WATER_FIELD_BINDING, kWaterField, field, sampler, kVertexFragment);
}

// The terrain pass's LPV set: the block, the volumes (or the placeholder) and the lights. Null
// buffers: the layout alone.
vk::DescriptorSetBuilder lpvSetBuilder(const vk::Buffer& block, const vk::Buffer& light, const vk::Buffer& geometry,
                                       const vk::Buffer& lights, VkShaderStageFlags stages = VK_SHADER_STAGE_FRAGMENT_BIT) {
    return vk::DescriptorSetBuilder()
        .uniform(blocks::LpvBlock::kBinding, "lpv", block, stages)
        .storage(TLX_LPV_LIGHT_BINDING, kLpvLight, light, stages)
        .storage(TLX_LPV_GEOMETRY_BINDING, kLpvGeometry, geometry, stages)
        .storage(TLX_LOCAL_LIGHTS_BINDING, "local-lights", lights, stages);
}

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

// Texel bytes of a level: RGBA16F normal-AO, RGBA8 sRGB albedo, R8 filled share.
vk::MipLevel halfLevel(int w, int h, const std::vector<glm::vec4>& texels) {
    vk::MipLevel l{uint32_t(w), uint32_t(h), std::vector<uint8_t>(texels.size() * 8)};
    for (size_t i = 0; i < texels.size(); ++i) {
        const uint64_t packed = glm::packHalf4x16(texels[i]);
        std::memcpy(l.bytes.data() + 8 * i, &packed, 8);
    }
    return l;
}

}  // namespace

TerrainRenderer::TerrainRenderer(vk::VulkanContext& ctx, const Heightfield& hf, size_t vertexBudget)
    : ctx_(ctx), hf_(hf), gpu_(std::make_unique<RendererGpu>()) {
    const size_t w = size_t(hf.width()), d = size_t(hf.depth());
    while (((w - 1) / size_t(stride_) + 2) * ((d - 1) / size_t(stride_) + 2) > vertexBudget &&
           stride_ < int(std::max(w, d)))
        ++stride_;
    std::vector<int> cols, rows;
    for (size_t c = 0; c < w; c += size_t(stride_)) cols.push_back(int(c));
    if (cols.back() != int(w) - 1) cols.push_back(int(w) - 1);
    for (size_t r = 0; r < d; r += size_t(stride_)) rows.push_back(int(r));
    if (rows.back() != int(d) - 1) rows.push_back(int(d) - 1);

    std::vector<float> vertices;
    vertices.reserve(cols.size() * rows.size() * 6);
    for (int r : rows)
        for (int c : cols) {
            const glm::vec3 p = hf.vertex(c, r), n = hf.vertexNormal(c, r);
            vertices.insert(vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
        }
    std::vector<uint32_t> indices;
    const uint32_t nc = uint32_t(cols.size());
    for (uint32_t r = 0; r + 1 < rows.size(); ++r)
        for (uint32_t c = 0; c + 1 < nc; ++c) {
            const uint32_t v00 = r * nc + c, v10 = v00 + 1, v01 = v00 + nc, v11 = v01 + 1;
            // The bake's fixed diagonal (c, r)-(c+1, r+1), counter-clockwise from above.
            indices.insert(indices.end(), {v00, v01, v11, v00, v11, v10});
        }
    vertexCount_ = vertices.size() / 6;
    indexCount_ = indices.size();
    meshVertices_ = vertices;

    RendererGpu& g = *gpu_;
    g.vertices = vk::Buffer::deviceLocal(ctx_, vertices.data(), vertices.size() * 4,
                                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    g.indices = vk::Buffer::deviceLocal(ctx_, indices.data(), std::max<size_t>(indices.size(), 1) * 4,
                                        VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    g.graph.importBuffer(kVertices, g.vertices.handle(), true);
    g.graph.importBuffer(kIndices, g.indices.handle(), true);

    for (uint32_t i = 0; i < vk::kFramesInFlight; ++i) {
        FrameSlot f;
        auto ubo = [&](size_t bytes) {
            return vk::Buffer::hostVisible(ctx_, bytes, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
        };
        f.camera = ubo(sizeof(blocks::CameraBlock));
        f.reflectionCamera = ubo(sizeof(blocks::CameraBlock));
        f.surface = ubo(sizeof(blocks::SurfaceBlock));
        f.sunSky = ubo(sizeof(blocks::SunSkyBlock));
        f.atmosphere = ubo(sizeof(blocks::AtmosphereBlock));
        f.shadow = ubo(sizeof(blocks::ShadowBlock));
        f.overlay = ubo(sizeof(blocks::OverlayBlock));
        f.lpvBlock = ubo(sizeof(blocks::LpvBlock));
        f.lights = lightsBuilder(0, f, g, VK_NULL_HANDLE, nullptr, 0).build(ctx_);
        f.overlays = vk::DescriptorSetBuilder()
                         .uniform(blocks::OverlayBlock::kBinding, "overlay", f.overlay, VK_SHADER_STAGE_VERTEX_BIT)
                         .build(ctx_);
        if (ctx_.timestampPeriod() > 0.0) {
            VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
            qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
            qci.queryCount = kFrameTimestamps;
            VkQueryPool pool = VK_NULL_HANDLE;
            vk::check(vkCreateQueryPool(ctx_.device(), &qci, nullptr, &pool), "vkCreateQueryPool");
            f.timestamps = vk::UniqueQueryPool(ctx_.device(), pool);
        }
        g.slots.push_back(std::move(f));
    }
    g.trilinear = vk::Sampler::trilinearClamp(ctx_);
    g.viewLayout = viewSetBuilder(g.slots[0], g.slots[0].camera, nullptr, g.trilinear.handle()).buildLayout(ctx_);
    uploadSurfaceMaps({});
    setAlbedoMap(0, 0, {});
    g.emptySet = vk::DescriptorSetBuilder().buildLayout(ctx_);
    static_assert(TLX_SET_VIEW == 0 && TLX_SET_LIGHTS == 1 && TLX_SET_SUBSYSTEM == 2);
    const VkDescriptorSetLayout overlaySets[] = {g.viewLayout.get(), g.emptySet.get(),
                                                 g.slots[0].overlays.layout()};
    g.overlayLayout = vk::PipelineLayout(ctx_, overlaySets);

    const VkFormat colorFormats[] = {vk::kColorFormat};
    g.clearPass = vk::RenderPass(ctx_, {colorFormats, vk::kDepthFormat, true, true});
    g.drawPass = vk::RenderPass(ctx_, {colorFormats, vk::kDepthFormat, false, true});
    g.shadowPass = vk::RenderPass(ctx_, {{}, vk::kDepthFormat, true, true});
    g.compareSampler = vk::Sampler::depthCompare(ctx_);
    g.depthSampler = vk::Sampler::nearestClamp(ctx_);
    g.shadowDepthLayout = vk::PipelineLayout(ctx_, {}, sizeof(glm::mat4), VK_SHADER_STAGE_VERTEX_BIT);
    g.linear = vk::Sampler::linearClamp(ctx_);
    static const vk::Buffer noBuffer;
    g.waterLayout = waterSetBuilder(noBuffer, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, g.linear.handle())
                        .buildLayout(ctx_);
    const glm::vec4 zero(0.0f);
    g.lpvDummy = vk::Buffer::deviceLocal(ctx_, &zero, sizeof zero, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    g.lpvLayout = lpvSetBuilder(noBuffer, noBuffer, noBuffer, noBuffer).buildLayout(ctx_);
    for (int variant = 0; variant < 4; ++variant) {
        g.lightsLayouts[size_t(variant)] = lightsBuilder(variant, g.slots[0], g, VK_NULL_HANDLE, nullptr, 0).buildLayout(ctx_);
        const VkDescriptorSetLayout lpvSets[] = {g.viewLayout.get(), g.lightsLayouts[size_t(variant)].get(),
                                                 g.lpvLayout.get()};
        g.terrainLpvLayouts[size_t(variant)] = vk::PipelineLayout(ctx_, lpvSets);
        const VkDescriptorSetLayout terrainSets[] = {g.viewLayout.get(), g.lightsLayouts[size_t(variant)].get()};
        g.terrainLayouts[size_t(variant)] = vk::PipelineLayout(ctx_, terrainSets);
        const VkDescriptorSetLayout waterSets[] = {g.viewLayout.get(), g.lightsLayouts[size_t(variant)].get(),
                                                   g.waterLayout.get()};
        g.waterLayouts[size_t(variant)] = vk::PipelineLayout(ctx_, waterSets);
    }
}

bool TerrainRenderer::hasWaterResources() const { return gpu_->water != nullptr; }

glm::ivec2 TerrainRenderer::waterFieldSize() const { return gpu_->water ? gpu_->water->fieldSize : glm::ivec2(0); }

void TerrainRenderer::setWater(std::optional<float> level, float margin) {
    RendererGpu& g = *gpu_;
    if (level && g.water && g.water->level == *level && g.water->margin == margin) return;
    ctx_.waitIdle();  // frames in flight may still read the old resources
    for (const char* name : {kWaterReflection, kWaterReflectionDepth, kWaterScene, kWaterVertices, kWaterIndices})
        g.graph.forget(name);
    g.water.reset();
    if (!level) return;
    auto w = std::make_unique<WaterResources>();
    w->level = *level;
    w->margin = margin;

    // The field over the footprint, texel centres corner to corner like the surface maps: depth
    // below the level and distance to shore, from the DEM grid (bilinear where it is coarser).
    const std::vector<float> shore = water::shoreDistance(hf_, double(*level));
    const int hw = hf_.width(), hd = hf_.depth();
    const int fw = std::min(hw, 2048), fd = std::min(hd, 2048);
    vk::MipLevel texels{uint32_t(fw), uint32_t(fd), std::vector<uint8_t>(size_t(fw) * size_t(fd) * 4)};
    tbb::parallel_for(0, fd, [&](int j) {
        const double row = fd > 1 ? double(j) * double(hd - 1) / double(fd - 1) : 0.0;
        for (int i = 0; i < fw; ++i) {
            const double col = fw > 1 ? double(i) * double(hw - 1) / double(fw - 1) : 0.0;
            const float depth = *level - gridSample(hf_.heights(), hw, hd, col, row);
            const float distance = gridSample(shore, hw, hd, col, row);
            // Half floats hold ±65504: deeper water and farther shores than that look the same.
            const glm::vec2 v(std::clamp(depth, -6.0e4f, 6.0e4f), std::isfinite(distance) ? std::min(distance, 6.0e4f) : 6.0e4f);
            const uint32_t packed = glm::packHalf2x16(v);
            std::memcpy(texels.bytes.data() + 4 * (size_t(j) * size_t(fw) + size_t(i)), &packed, 4);
        }
    });
    w->fieldSize = {fw, fd};
    w->field = vk::Image::texture(ctx_, VK_FORMAT_R16G16_SFLOAT, {texels});

    // The mesh: a grid at rest on the plane over the footprint, keeping the cells whose bed lies
    // below the highest crest somewhere.
    const float spanX = hf_.maxX() - hf_.minX(), spanZ = hf_.maxZ() - hf_.minZ();
    const float longer = std::max({spanX, spanZ, 1e-3f});
    const float step = longer / float(kWaterMeshSide - 1);
    const int nx = std::max(int(std::ceil(spanX / step)) + 1, 2), nz = std::max(int(std::ceil(spanZ / step)) + 1, 2);
    w->spacing = std::max(spanX / float(nx - 1), spanZ / float(nz - 1));
    std::vector<glm::vec2> rest(size_t(nx) * size_t(nz));
    std::vector<uint8_t> wet(rest.size());
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) {
            const glm::vec2 p(hf_.minX() + spanX * float(i) / float(nx - 1), hf_.minZ() + spanZ * float(j) / float(nz - 1));
            rest[size_t(j) * size_t(nx) + size_t(i)] = p;
            wet[size_t(j) * size_t(nx) + size_t(i)] = hf_.surfaceHeight(p.x, p.y) < *level + margin ? 1 : 0;
        }
    std::vector<uint32_t> indices;
    for (int j = 0; j + 1 < nz; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const uint32_t v00 = uint32_t(j * nx + i), v10 = v00 + 1, v01 = v00 + uint32_t(nx), v11 = v01 + 1;
            if (wet[v00] || wet[v10] || wet[v01] || wet[v11]) indices.insert(indices.end(), {v00, v01, v11, v00, v11, v10});
        }
    w->indexCount = uint32_t(indices.size());
    if (indices.empty()) indices.push_back(0);
    w->vertices = vk::Buffer::deviceLocal(ctx_, rest.data(), rest.size() * sizeof(glm::vec2), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    w->indices = vk::Buffer::deviceLocal(ctx_, indices.data(), indices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    g.graph.importBuffer(kWaterVertices, w->vertices.handle(), true);
    g.graph.importBuffer(kWaterIndices, w->indices.handle(), true);
    for (uint32_t i = 0; i < vk::kFramesInFlight; ++i)
        w->blocks.push_back(vk::Buffer::hostVisible(ctx_, sizeof(blocks::WaterBlock), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
    g.water = std::move(w);
}

void TerrainRenderer::ensureWaterTargets(uint32_t width, uint32_t height, float reflectionScale) {
    RendererGpu& g = *gpu_;
    WaterResources& w = *g.water;
    const uint32_t rw = std::max(uint32_t(std::lround(float(width) * reflectionScale)), 1u);
    const uint32_t rh = std::max(uint32_t(std::lround(float(height) * reflectionScale)), 1u);
    if (w.width == width && w.height == height && w.reflectionWidth == rw && w.reflectionHeight == rh) return;
    ctx_.waitIdle();  // frames in flight may still read the old targets
    for (const char* name : {kWaterReflection, kWaterReflectionDepth, kWaterScene}) g.graph.forget(name);
    w.sets.clear();
    w.reflection = vk::Image::colorTarget(ctx_, rw, rh);
    w.reflectionDepth = vk::Image::depthTarget(ctx_, rw, rh);
    const VkImageView views[] = {w.reflection.view(), w.reflectionDepth.view()};
    w.reflectionFramebuffer = vk::Framebuffer(ctx_, g.clearPass, views, rw, rh);
    vk::ImageDesc copy;
    copy.width = width;
    copy.height = height;
    copy.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    w.scene = vk::Image(ctx_, copy);
    g.graph.importImage(kWaterReflection, w.reflection.handle(), w.reflection.aspect());
    g.graph.importImage(kWaterReflectionDepth, w.reflectionDepth.handle(), w.reflectionDepth.aspect());
    g.graph.importImage(kWaterScene, w.scene.handle(), w.scene.aspect());
    for (uint32_t i = 0; i < vk::kFramesInFlight; ++i)
        w.sets.push_back(waterSetBuilder(w.blocks[i], w.reflection.view(), w.scene.view(), w.field.view(),
                                         g.linear.handle())
                             .build(ctx_));
    w.width = width;
    w.height = height;
    w.reflectionWidth = rw;
    w.reflectionHeight = rh;
}

bool TerrainRenderer::hasShadowResources() const { return gpu_->shadows != nullptr; }

void TerrainRenderer::redrawShadowMaps() {
    if (gpu_->shadows) gpu_->shadows->drawn.clear();
}

void TerrainRenderer::uploadSurfaceMaps(const std::vector<float>& ao) {
    RendererGpu& g = *gpu_;
    const SurfaceMaps maps = buildSurfaceMaps(hf_, ao);
    std::vector<vk::MipLevel> levels;
    int w = maps.width, h = maps.height;
    for (const auto& level : maps.normalAo) {
        levels.push_back(halfLevel(w, h, level));
        w = std::max(w / 2, 1);
        h = std::max(h / 2, 1);
    }
    SurfaceTextures next;
    next.normalAo = vk::Image::texture(ctx_, VK_FORMAT_R16G16B16A16_SFLOAT, levels);
    next.filled = vk::Image::texture(ctx_, VK_FORMAT_R8_UNORM,
                                     {vk::MipLevel{uint32_t(maps.width), uint32_t(maps.height), maps.filled}});
    ctx_.waitIdle();  // no frame may still read the old maps
    g.surface.normalAo = std::move(next.normalAo);
    g.surface.filled = std::move(next.filled);
    surfaceMapSize_ = {maps.width, maps.height};
    hasAo_ = !ao.empty();
    if (g.surface.albedo.handle() != VK_NULL_HANDLE) buildViewSets();
}

void TerrainRenderer::setAmbientOcclusion(const std::vector<float>& perVertex) {
    if (!perVertex.empty() && perVertex.size() != hf_.heights().size())
        throw std::invalid_argument("ambient occlusion needs one value per DEM vertex");
    uploadSurfaceMaps(perVertex);
}

void TerrainRenderer::setAlbedoMap(int width, int height, const std::vector<uint8_t>& srgb) {
    RendererGpu& g = *gpu_;
    const bool map = width > 0 && height > 0 && srgb.size() == size_t(width) * size_t(height) * 3;
    // A full mip chain of box means in linear light, stored sRGB-encoded (the hardware decodes);
    // level 0 holds the field's own codes.
    std::vector<vk::MipLevel> levels;
    std::vector<glm::vec3> level(map ? srgb.size() / 3 : 1, glm::vec3(1.0f));
    if (map)
        for (size_t i = 0; i < level.size(); ++i)
            level[i] = {linearOfSrgb8(srgb[3 * i]), linearOfSrgb8(srgb[3 * i + 1]), linearOfSrgb8(srgb[3 * i + 2])};
    int w = map ? width : 1, h = map ? height : 1;
    while (true) {
        vk::MipLevel l{uint32_t(w), uint32_t(h), std::vector<uint8_t>(level.size() * 4)};
        for (size_t i = 0; i < level.size(); ++i)
            for (int c = 0; c < 3; ++c) l.bytes[4 * i + size_t(c)] = srgb8(level[i][c]);
        for (size_t i = 0; i < level.size(); ++i) l.bytes[4 * i + 3] = 255;
        levels.push_back(std::move(l));
        if (w == 1 && h == 1) break;
        const int nw = std::max(w / 2, 1), nh = std::max(h / 2, 1);
        std::vector<glm::vec3> next(size_t(nw) * size_t(nh));
        for (int j = 0; j < nh; ++j)
            for (int i = 0; i < nw; ++i) {
                const int x0 = i * w / nw, x1 = (i + 1) * w / nw, y0 = j * h / nh, y1 = (j + 1) * h / nh;
                glm::vec3 sum(0.0f);
                for (int y = y0; y < y1; ++y)
                    for (int x = x0; x < x1; ++x) sum += level[size_t(y) * size_t(w) + size_t(x)];
                next[size_t(j) * size_t(nw) + size_t(i)] = sum / float((x1 - x0) * (y1 - y0));
            }
        level = std::move(next);
        w = nw;
        h = nh;
    }
    vk::Image image = vk::Image::texture(ctx_, VK_FORMAT_R8G8B8A8_SRGB, levels);
    ctx_.waitIdle();  // no frame may still read the old map
    g.surface.albedo = std::move(image);
    hasAlbedoMap_ = map;
    albedoMapSize_ = map ? glm::ivec2(width, height) : glm::ivec2(1, 1);
    buildViewSets();
}

void TerrainRenderer::buildViewSets() {
    RendererGpu& g = *gpu_;
    for (FrameSlot& f : g.slots) {
        f.view = viewSetBuilder(f, f.camera, &g.surface, g.trilinear.handle()).build(ctx_);
        f.reflectionView = viewSetBuilder(f, f.reflectionCamera, &g.surface, g.trilinear.handle()).build(ctx_);
    }
}

void TerrainRenderer::ensureShadowMaps(int resolution, int cascades) {
    RendererGpu& g = *gpu_;
    if (g.shadows ? g.shadows->resolution == resolution && g.shadows->cascades == cascades : resolution <= 0)
        return;
    ctx_.waitIdle();  // frames in flight may still read the old maps
    g.graph.forget(kShadowMaps);
    for (FrameSlot& f : g.slots) f.shadowedLights = vk::DescriptorSet();
    g.shadows.reset();
    if (resolution <= 0) return buildReflectionSets();
    auto sh = std::make_unique<ShadowResources>();
    sh->resolution = resolution;
    sh->cascades = cascades;
    sh->maps = vk::Image::depthLayers(ctx_, uint32_t(resolution), uint32_t(resolution), uint32_t(cascades));
    for (uint32_t i = 0; i < uint32_t(cascades); ++i) {
        const VkImageView view = sh->maps.layerView(i);
        sh->framebuffers.emplace_back(ctx_, g.shadowPass, std::span<const VkImageView>(&view, 1),
                                      uint32_t(resolution), uint32_t(resolution));
    }
    for (FrameSlot& f : g.slots)
        f.shadowedLights = lightsBuilder(kShadowedLights, f, g, sh->maps.view(), nullptr, 0).build(ctx_);
    g.graph.importImage(kShadowMaps, sh->maps.handle(), sh->maps.aspect(), uint32_t(cascades));
    g.shadows = std::move(sh);
    buildReflectionSets();
}

void TerrainRenderer::buildReflectionSets() {
    RendererGpu& g = *gpu_;
    ReflectionResources* r = g.reflections.get();
    if (!r) return;
    r->lights.clear();
    r->shadowedLights.clear();
    for (uint32_t i = 0; i < uint32_t(g.slots.size()); ++i) {
        r->lights.push_back(lightsBuilder(kReflectedLights, g.slots[i], g, VK_NULL_HANDLE, r, i).build(ctx_));
        if (g.shadows)
            r->shadowedLights.push_back(
                lightsBuilder(kShadowedLights | kReflectedLights, g.slots[i], g, g.shadows->maps.view(), r, i).build(ctx_));
    }
}

bool TerrainRenderer::hasReflectionResources() const { return gpu_->reflections != nullptr; }

bool TerrainRenderer::hasLpvResources() const { return gpu_->lpv != nullptr; }

std::optional<double> TerrainRenderer::lpvViewRange() const {
    if (!gpu_->lpv || !(gpu_->lpv->viewRange > 0.0)) return std::nullopt;
    return gpu_->lpv->viewRange;
}

bool TerrainRenderer::propagatesLpv() const { return ctx_.deviceType() != VK_PHYSICAL_DEVICE_TYPE_CPU; }

const std::shared_ptr<const lpv::Volumes>& TerrainRenderer::lpv() const {
    static const std::shared_ptr<const lpv::Volumes> none;
    return gpu_->lpv ? gpu_->lpv->volumes : none;
}

namespace {

// One global memory dependency: what `srcStages` wrote through `srcAccess` is visible to
// `dstAccess` in `dstStages`.
void memoryBarrier(VkCommandBuffer cb, VkPipelineStageFlags srcStages, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStages, VkAccessFlags dstAccess) {
    VkMemoryBarrier b{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    b.srcAccessMask = srcAccess;
    b.dstAccessMask = dstAccess;
    vkCmdPipelineBarrier(cb, srcStages, dstStages, 0, 1, &b, 0, nullptr, 0, nullptr);
}

// The propagation pass's set: its block, the work regions, the send scales, the geometry and the
// light it accumulates into.
vk::DescriptorSetBuilder lpvPropagationSetBuilder(const LpvResources& r) {
    constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
    vk::DescriptorSetBuilder b;
    b.uniform(blocks::LpvPropagationBlock::kBinding, "lpv-propagation", r.propagationBlock, compute)
        .storage(TLX_LPV_WORK_BINDING, kLpvWork, r.work, compute)
        .storage(TLX_LPV_SCALES_BINDING, kLpvScales, r.scales, compute)
        .storage(TLX_LPV_PROPAGATE_GEOMETRY_BINDING, kLpvGeometry, r.geometry, compute)
        .storage(TLX_LPV_ACCUMULATED_BINDING, kLpvLight, r.light, compute);
    return b;
}

blocks::LpvPropagationBlock propagationBlock(float stepWeight, int cascades) {
    blocks::LpvPropagationBlock b;
    const auto& table = lpv::propagationNeighbours();
    for (size_t n = 0; n < table.size(); ++n) {
        b.neighbours[n] = glm::vec4(glm::vec3(table[n].offset), float(table[n].axis));
        for (size_t f = 0; f < table[n].faces.size(); ++f) {
            const lpv::PropagationFace& face = table[n].faces[f];
            b.faceDirs[5 * n + f] = glm::vec4(face.dir, face.solidAngle);
            b.faceLobes[5 * n + f] = glm::vec4(face.lobe[0], face.lobe[1], face.lobe[2], face.lobe[3]);
        }
    }
    b.stepWeight = stepWeight;
    b.cascadeCount = cascades;
    return b;
}

}  // namespace

void TerrainRenderer::setLpv(std::shared_ptr<const lpv::Volumes> volumes) {
    RendererGpu& g = *gpu_;
    if (g.lpv ? g.lpv->volumes == volumes : !volumes) return;
    std::unique_ptr<LpvResources> r;
    if (volumes && !volumes->cascades().empty()) {
        r = std::make_unique<LpvResources>();
        const auto& cascades = volumes->cascades();
        const size_t n = std::min<size_t>(cascades.size(), 4);
        const LpvSettings& ls = volumes->settings();
        // Propagated here unless the volumes already are, or have no step to take.
        const bool propagate = !volumes->propagated() && ls.propagationIterations > 0;
        std::vector<float> light, geometry;
        light.reserve(n * cascades[0].injected.size());
        geometry.reserve(n * cascades[0].geometry.size());
        r->block.cascadeCount = int(n);
        r->block.quality = ls.quality;
        r->block.coneSamples = ls.coneTraceSamples;
        r->viewRange = lpv::lightRange(cascades[0].injected, cascades[0].layout.cellSize, ls.indirectIntensity);
        r->block.indirectIntensity = float(ls.indirectIntensity);
        r->block.fadeRange = float(ls.fadeRange);
        r->block.viewExposure = r->viewRange > 0.0 ? float(1.0 / r->viewRange) : 0.0f;
        for (size_t c = 0; c < n; ++c) {
            const lpv::LightVolume& v = volumes->propagated() ? cascades[c].accumulated : cascades[c].injected;
            light.insert(light.end(), v.begin(), v.end());
            geometry.insert(geometry.end(), cascades[c].geometry.begin(), cascades[c].geometry.end());
            r->block.cascades[c].minCorner = glm::vec3(cascades[c].layout.origin());
            r->block.cascades[c].cellSize = float(cascades[c].layout.cellSize);
        }
        constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
        const VkDeviceSize lightBytes = VkDeviceSize(n) * cascades[0].injected.size() * 4;
        r->geometry = vk::Buffer::deviceLocal(ctx_, geometry.data(), geometry.size() * 4, storage);
        // The injected light until the pass has run, should a frame read it before.
        r->light = vk::Buffer::deviceLocal(ctx_, light.data(), lightBytes, storage);
        if (propagate) {
            // Region 0 the injected light; regions 1 and 2 the steps' outputs, written before read.
            r->work = vk::Buffer::deviceLocal(ctx_, light.data(), lightBytes, storage, 3 * lightBytes);
            r->cells = uint32_t(n) * uint32_t(lpv::kCells);
            r->scales = vk::Buffer(ctx_, VkDeviceSize(2 * 3) * r->cells * 4, storage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
            const blocks::LpvPropagationBlock block =
                propagationBlock(lpv::propagationStepWeight(ls.propagationWeight), int(n));
            r->propagationBlock = vk::Buffer::hostVisible(ctx_, sizeof block, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
            r->propagationBlock.write(&block, sizeof block);
            r->propagationSet = lpvPropagationSetBuilder(*r).build(ctx_);
            r->steps = ls.propagationIterations;
            if (!g.lpvPropagate) {
                constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
                const VkDescriptorSetLayout sets[] = {g.emptySet.get(), g.emptySet.get(), r->propagationSet.layout()};
                g.lpvPropagateLayout = vk::PipelineLayout(ctx_, sets, sizeof(glm::ivec4), compute);
                g.lpvPropagate = vk::createComputePipeline(ctx_, g.lpvPropagateLayout.handle(), shaders::lpvPropagateComp());
            }
            if (!g.lpvQueries && ctx_.timestampPeriod() > 0.0) {
                VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
                qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
                qci.queryCount = 2;
                VkQueryPool pool = VK_NULL_HANDLE;
                vk::check(vkCreateQueryPool(ctx_.device(), &qci, nullptr, &pool), "vkCreateQueryPool");
                g.lpvQueries = vk::UniqueQueryPool(ctx_.device(), pool);
            }
        }
        r->volumes = std::move(volumes);
    }
    ctx_.waitIdle();  // no frame may still read the old volumes
    for (const char* name : {kLpvLight, kLpvGeometry, kLpvWork, kLpvScales}) g.graph.forget(name);
    g.lpv = std::move(r);
    ++g.lpvGeneration;
    g.lpvTimed = false;  // the last pass's time was the old volumes'
    if (!g.lpv) return;
    g.graph.importBuffer(kLpvLight, g.lpv->light.handle(), true);
    g.graph.importBuffer(kLpvGeometry, g.lpv->geometry.handle(), true);
    if (g.lpv->steps == 0) return;
    g.graph.importBuffer(kLpvWork, g.lpv->work.handle(), true);
    g.graph.importBuffer(kLpvScales, g.lpv->scales.handle());
}

void TerrainRenderer::recordLpvPropagation(VkCommandBuffer cb) {
    RendererGpu& g = *gpu_;
    LpvResources& r = *g.lpv;
    if (g.lpvQueries) {
        // The first once everything before has finished, so an earlier pass's tail is not counted.
        vkCmdResetQueryPool(cb, g.lpvQueries.get(), 0, 2);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, g.lpvQueries.get(), 0);
    }
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.lpvPropagate.get());
    const VkDescriptorSet set = r.propagationSet.handle();
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.lpvPropagateLayout.handle(), TLX_SET_SUBSYSTEM, 1,
                            &set, 0, nullptr);
    const uint32_t groups = (r.cells + 255) / 256;
    const auto dispatch = [&](const glm::ivec4& push) {
        vkCmdPushConstants(cb, g.lpvPropagateLayout.handle(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        vkCmdDispatch(cb, groups, 1, 1);
    };
    dispatch(glm::ivec4(0, 0, 0, 0));  // the injected light's send scales
    for (int step = 0; step < r.steps; ++step) {
        // Each dispatch reads what the one before it wrote.
        memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        // Step 0 reads the injected light (region 0); then the regions 1 and 2 alternate.
        const int source = step == 0 ? 0 : 1 + (step - 1) % 2, destination = 1 + step % 2;
        dispatch(glm::ivec4(1, source, destination, step + 1 < r.steps ? 1 : 0));
    }
    if (g.lpvQueries) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, g.lpvQueries.get(), 1);
    g.lpvTimed = bool(g.lpvQueries);
    r.steps = 0;
}

void TerrainRenderer::propagateLpvNow() {
    RendererGpu& g = *gpu_;
    if (!g.lpv || g.lpv->steps == 0) return;
    ctx_.waitIdle();
    ctx_.submitAndWait([&](VkCommandBuffer cb) {
        // The injected light and the geometry were filled by transfers.
        memoryBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        recordLpvPropagation(cb);
        // Whatever reads the light later, in this submission's successors, sees it written.
        memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
    });
}

std::optional<double> TerrainRenderer::lpvPropagationMilliseconds() {
    RendererGpu& g = *gpu_;
    if (!g.lpvTimed) return std::nullopt;
    ctx_.waitIdle();
    uint64_t ticks[2] = {0, 0};
    if (vkGetQueryPoolResults(ctx_.device(), g.lpvQueries.get(), 0, 2, sizeof ticks, ticks, sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT) != VK_SUCCESS)
        return std::nullopt;
    const uint32_t bits = ctx_.timestampBits();
    const uint64_t mask = bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
    return double(((ticks[1] & mask) - (ticks[0] & mask)) & mask) * ctx_.timestampPeriod() * 1e-6;
}

std::vector<float> TerrainRenderer::readLpvLight() {
    RendererGpu& g = *gpu_;
    if (!g.lpv) return {};
    propagateLpvNow();
    vk::Buffer host = vk::Buffer::hostVisible(ctx_, g.lpv->light.size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    ctx_.waitIdle();
    ctx_.submitAndWait([&](VkCommandBuffer cb) {
        memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT);
        const VkBufferCopy region{0, 0, g.lpv->light.size()};
        vkCmdCopyBuffer(cb, g.lpv->light.handle(), host.handle(), 1, &region);
        memoryBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                      VK_ACCESS_HOST_READ_BIT);
    });
    const auto* values = static_cast<const float*>(host.map());
    return std::vector<float>(values, values + g.lpv->light.size() / 4);
}

std::vector<TerrainRenderer::LpvSample> TerrainRenderer::sampleLpv(
    const std::vector<std::array<glm::vec3, 3>>& queries, int lastCascade) {
    RendererGpu& g = *gpu_;
    if (!g.lpv || queries.empty()) return {};
    const int cascades = g.lpv->block.cascadeCount;
    const int last = lastCascade < 0 ? cascades - 1 : std::min(lastCascade, cascades - 1);
    std::vector<glm::vec4> packed;
    for (const auto& q : queries)
        for (const glm::vec3& v : q) packed.emplace_back(v, 0.0f);
    constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
    const vk::Buffer input = vk::Buffer::deviceLocal(ctx_, packed.data(), packed.size() * sizeof(glm::vec4),
                                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer results = vk::Buffer::hostVisible(ctx_, queries.size() * 2 * sizeof(glm::vec4),
                                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    vk::Buffer block = vk::Buffer::hostVisible(ctx_, sizeof(blocks::LpvBlock), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    block.write(&g.lpv->block, sizeof(blocks::LpvBlock));
    const vk::DescriptorSet set = lpvSetBuilder(block, g.lpv->light, g.lpv->geometry, g.lpvDummy, compute)
                                      .storage(4, "lpv-queries", input, compute)
                                      .storage(5, "lpv-results", results, compute)
                                      .build(ctx_);
    if (!g.lpvSample) {
        const VkDescriptorSetLayout sets[] = {g.emptySet.get(), g.emptySet.get(), set.layout()};
        g.lpvSampleLayout = vk::PipelineLayout(ctx_, sets, sizeof(glm::ivec4), compute);
        g.lpvSample = vk::createComputePipeline(ctx_, g.lpvSampleLayout.handle(), shaders::lpvSampleComp());
    }
    const glm::ivec4 push(int(queries.size()), last, 0, 0);
    propagateLpvNow();
    ctx_.waitIdle();
    ctx_.submitAndWait([&](VkCommandBuffer cb) {
        // The volumes and the queries were filled by transfers (the light perhaps by the
        // propagation pass).
        memoryBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.lpvSample.get());
        const VkDescriptorSet handle = set.handle();
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.lpvSampleLayout.handle(), TLX_SET_SUBSYSTEM, 1,
                                &handle, 0, nullptr);
        vkCmdPushConstants(cb, g.lpvSampleLayout.handle(), compute, 0, sizeof push, &push);
        vkCmdDispatch(cb, uint32_t(queries.size() + 63) / 64, 1, 1);
        memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                      VK_ACCESS_HOST_READ_BIT);
    });
    const auto* values = static_cast<const glm::vec4*>(results.map());
    std::vector<LpvSample> out(queries.size());
    for (size_t i = 0; i < queries.size(); ++i) {
        out[i].irradiance = glm::vec3(values[2 * i]);
        out[i].specular = glm::vec3(values[2 * i + 1]);
        out[i].ao = values[2 * i].w;
    }
    return out;
}

void TerrainRenderer::setReflectionProbes(std::shared_ptr<const ReflectionProbeSet> set) {
    RendererGpu& g = *gpu_;
    ctx_.waitIdle();  // no frame may still read the old probes
    for (const char* name : {kReflectionRecords, kReflectionMarkers}) g.graph.forget(name);
    g.reflections.reset();
    reflectionBytes_ = 0;
    if (!set || set->probes.empty()) return;
    const ReflectionProbeSet& s = *set;
    const size_t n = s.probes.size();
    if (s.dims[0] < 1 || s.dims[1] < 1 || size_t(s.dims[0]) * size_t(s.dims[1]) != n)
        throw std::invalid_argument("reflection probes: a grid of " + std::to_string(s.dims[0]) + " x " +
                                    std::to_string(s.dims[1]) + " holds " + std::to_string(n) + " probes");
    const bool cubemap = s.encoding == ReflectionEncoding::Cubemap;
    if (cubemap) {
        if (s.faceSize < 1 || (s.faceSize & (s.faceSize - 1)) != 0 || s.mipCount != cubeMipCount(s.faceSize))
            throw std::invalid_argument("reflection probes: cube faces of " + std::to_string(s.faceSize) +
                                        " texels with " + std::to_string(s.mipCount) + " mip levels");
        for (const ReflectionProbe& p : s.probes)
            if (p.texels.size() != s.texelsPerProbe())
                throw std::invalid_argument("reflection probe " + std::to_string(p.id) + " holds " +
                                            std::to_string(p.texels.size()) + " texels, not " +
                                            std::to_string(s.texelsPerProbe()));
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(ctx_.physicalDevice(), &props);
        if (6 * n > props.limits.maxImageArrayLayers)
            throw std::invalid_argument("reflection probes: " + std::to_string(n) + " cubes need " +
                                        std::to_string(6 * n) + " image layers, the device holds " +
                                        std::to_string(props.limits.maxImageArrayLayers));
    }

    auto r = std::make_unique<ReflectionResources>();
    std::vector<blocks::ReflectionProbeRecord> records(n);
    std::vector<glm::vec4> markers(n);
    for (size_t i = 0; i < n; ++i) {
        const ReflectionProbe& p = s.probes[i];
        records[i].position = p.position;
        records[i].halfExtent = p.halfExtent;
        for (int f = 0; f < 6; ++f) records[i].faces[f] = glm::vec4(p.faces[size_t(f)], 0.0f);
        markers[i] = glm::vec4(p.position, 3.0f);  // markers.vert: a reflection probe
    }
    // Level m holds every probe's six faces, layer 6·probe + face, as the probe's chain holds them
    // (rows top to bottom, x fastest: the bake's faces are Vulkan's), in half floats.
    std::vector<vk::MipLevel> levels;
    if (cubemap) {
        for (int m = 0; m < s.mipCount; ++m) {
            const uint32_t side = uint32_t(cubeMipSize(s.faceSize, m));
            const size_t faceTexels = size_t(side) * side;
            vk::MipLevel level{side, side, std::vector<uint8_t>(n * 6 * faceTexels * 8)};
            tbb::parallel_for(size_t(0), n, [&](size_t i) {
                const glm::vec3* texels = s.probes[i].texels.data();
                for (int f = 0; f < 6; ++f) {
                    const glm::vec3* face = texels + s.texelOffset(m, f);
                    uint8_t* out = level.bytes.data() + (i * 6 + size_t(f)) * faceTexels * 8;
                    for (size_t t = 0; t < faceTexels; ++t) {
                        const uint64_t packed = glm::packHalf4x16(glm::vec4(face[t], 1.0f));
                        std::memcpy(out + 8 * t, &packed, 8);
                    }
                }
            });
            reflectionBytes_ += level.bytes.size();
            levels.push_back(std::move(level));
        }
    } else {
        levels.push_back(vk::MipLevel{1, 1, std::vector<uint8_t>(6 * 8, 0)});  // nothing reads it
    }
    reflectionBytes_ += records.size() * sizeof(records[0]);
    r->cubes = vk::Image::cubeArrayTexture(ctx_, VK_FORMAT_R16G16B16A16_SFLOAT, cubemap ? uint32_t(n) : 1u, levels);
    r->records = vk::Buffer::deviceLocal(ctx_, records.data(), records.size() * sizeof(records[0]),
                                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    r->markers = vk::Buffer::deviceLocal(ctx_, markers.data(), markers.size() * sizeof(glm::vec4),
                                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    r->markerCount = uint32_t(n);
    r->grid.nx = s.dims[0];
    r->grid.nz = s.dims[1];
    r->grid.encoding = cubemap ? 1 : 0;
    r->grid.mipLevels = cubemap ? s.mipCount : 1;
    r->grid.origin = s.origin;
    r->grid.spacing = s.spacing;
    r->grid.cellSize = s.cellSize;
    r->grid.blendDistance = s.blendDistance;
    for (uint32_t i = 0; i < vk::kFramesInFlight; ++i)
        r->blocks.push_back(vk::Buffer::hostVisible(ctx_, sizeof(blocks::ReflectionBlock), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
    g.graph.importBuffer(kReflectionRecords, r->records.handle(), true);
    g.graph.importBuffer(kReflectionMarkers, r->markers.handle(), true);
    g.reflections = std::move(r);
    buildReflectionSets();
}

void TerrainRenderer::updateSunVisibility(const SunLight& sun, bool skirt) {
    RendererGpu& g = *gpu_;
    const glm::vec4 key(sun.direction, sun.angularRadius);
    if (g.sunVisibility.handle() != VK_NULL_HANDLE && key == g.sunVisibilityKey && g.sunVisibilitySkirt == int(skirt))
        return;
    if (!g.tracer || g.tracerSkirt != skirt) {
        HeightfieldTracer::Options opt;
        opt.skirt = skirt;
        g.tracer = std::make_unique<HeightfieldTracer>(hf_, opt);
        g.tracerSkirt = skirt;
    }
    // The bake's own sun term (sunVisibility) at every mesh vertex, on the vertex's normal;
    // deterministic per vertex. Stride 32 like the probe light: x visibility.
    std::vector<glm::vec4> values(std::max<size_t>(vertexCount_, 1) * 2, glm::vec4(0.0f));
    const HeightfieldTracer& tracer = *g.tracer;
    tbb::parallel_for(size_t(0), vertexCount_, [&](size_t i) {
        const float* v = &meshVertices_[6 * i];
        Rng rng(0x5eed0000ull + i);
        const float vis = sunVisibility(tracer, sun, glm::vec3(v[0], v[1], v[2]),
                                        glm::vec3(v[3], v[4], v[5]), kSunVisibilitySamples, rng);
        values[2 * i] = glm::vec4(vis, 0.0f, 0.0f, 0.0f);
    });
    ctx_.waitIdle();  // no frame may still read the old buffer
    g.graph.forget(kSunVisibility);
    g.sunVisibility = vk::Buffer::deviceLocal(ctx_, values.data(), values.size() * sizeof(glm::vec4),
                                              VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    g.graph.importBuffer(kSunVisibility, g.sunVisibility.handle(), true);
    g.sunVisibilityKey = key;
    g.sunVisibilitySkirt = int(skirt);
    ++sunTraces_;
}

TerrainRenderer::~TerrainRenderer() {
    // Frames in flight may still read what is about to be destroyed.
    if (gpu_) ctx_.waitIdle();
}

bool TerrainRenderer::hasProbeResources() const { return gpu_->probes != nullptr; }

const std::vector<PassInfo>& TerrainRenderer::lastFramePasses() const { return gpu_->graph.lastFrame(); }

void TerrainRenderer::setProbeVolumes(const std::vector<GpuProbeVolume>& volumes) {
    RendererGpu& g = *gpu_;
    ctx_.waitIdle();  // no frame may still read the old buffers
    for (const char* name : {kProbeCoefficients, kProbeCells, kProbeVolumes, kProbeErrorMaps, kProbeLight})
        g.graph.forget(name);
    g.probes.reset();
    volumeCount_ = 0;
    anyErrorMap_ = false;
    probeBytes_ = 0;
    finestProbeSpacing_ = 0.0f;
    if (volumes.empty()) return;
    for (const auto& v : volumes)
        finestProbeSpacing_ = finestProbeSpacing_ > 0.0f ? std::min(finestProbeSpacing_, v.spacing) : v.spacing;

    std::vector<glm::vec4> coeffs;
    std::vector<int32_t> cells;
    std::vector<blocks::ProbeVolumeRecord> records;
    std::vector<float> errors;
    for (const auto& v : volumes) {
        blocks::ProbeVolumeRecord rec{};
        rec.origin = v.origin;
        rec.spacing = v.spacing;
        rec.dims = glm::ivec3(v.dims);
        rec.firstProbe = int32_t(coeffs.size() / 9);
        rec.firstCell = int32_t(cells.size());
        rec.preConvolved = v.irradianceEncoded ? 1 : 0;
        rec.fallbackBlend = v.fallbackBlendDistance;
        rec.shScale = v.scale;
        static const ProbeDiagnostics none;
        const ProbeDiagnostics& d = v.diagnostics ? *v.diagnostics : none;
        const ErrorMap& m = d.errorMap;
        // A map that does not hold nx·nz values (or has no step) is no map.
        if (m.error.size() == size_t(m.nx) * m.nz && m.step > 0.0f && !m.error.empty()) {
            rec.firstError = int32_t(errors.size());
            rec.errorNx = int32_t(m.nx);
            rec.errorNz = int32_t(m.nz);
            rec.errorX0 = m.x0;
            rec.errorZ0 = m.z0;
            rec.errorStep = m.step;
            for (float e : m.error) errors.push_back(std::isfinite(e) ? e : -1.0f);
            anyErrorMap_ = true;
        }
        for (size_t i = 0; i < v.coeffs.size(); ++i) {
            const float moved = i < d.moved.size() && d.moved[i] ? 1.0f : 0.0f;
            coeffs.push_back(glm::vec4(v.coeffs[i][0], moved));
            for (size_t k = 1; k < 9; ++k) coeffs.push_back(glm::vec4(v.coeffs[i][k], 0.0f));
        }
        cells.insert(cells.end(), v.occupancy.begin(), v.occupancy.end());
        records.push_back(rec);
    }
    volumeCount_ = int(records.size());
    probeBytes_ = coeffs.size() * sizeof(glm::vec4) + cells.size() * 4;
    // Storage buffers may not be empty: a placeholder element where there is nothing to hold.
    if (errors.empty()) errors.push_back(-1.0f);
    if (coeffs.empty()) coeffs.push_back(glm::vec4(0.0f));
    if (cells.empty()) cells.push_back(-1);

    auto p = std::make_unique<ProbeResources>();
    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    p->coeffs = vk::Buffer::deviceLocal(ctx_, coeffs.data(), coeffs.size() * sizeof(glm::vec4), storage);
    p->cells = vk::Buffer::deviceLocal(ctx_, cells.data(), cells.size() * 4, storage);
    p->volumes = vk::Buffer::deviceLocal(ctx_, records.data(), records.size() * sizeof(records[0]), storage);
    p->errors = vk::Buffer::deviceLocal(ctx_, errors.data(), errors.size() * 4, storage);
    p->light = vk::Buffer(ctx_, std::max<size_t>(vertexCount_, 1) * 32,
                          VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | storage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    blocks::ProbesBlock block;
    block.volumeCount = volumeCount_;
    block.vertexCount = int32_t(vertexCount_);
    block.anyErrorMap = anyErrorMap_ ? 1 : 0;
    p->block = vk::Buffer::hostVisible(ctx_, sizeof block, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    p->block.write(&block, sizeof block);
    constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
    p->set = vk::DescriptorSetBuilder()
                 .uniform(blocks::ProbesBlock::kBinding, "probes", p->block, compute)
                 .storage(1, kProbeCoefficients, p->coeffs, compute)
                 .storage(2, kProbeCells, p->cells, compute)
                 .storage(3, kProbeVolumes, p->volumes, compute)
                 .storage(4, kProbeErrorMaps, p->errors, compute)
                 .storage(5, kVertices, g.vertices, compute)
                 .storage(6, kProbeLight, p->light, compute)
                 .build(ctx_);
    g.graph.importBuffer(kProbeCoefficients, p->coeffs.handle(), true);
    g.graph.importBuffer(kProbeCells, p->cells.handle(), true);
    g.graph.importBuffer(kProbeVolumes, p->volumes.handle(), true);
    g.graph.importBuffer(kProbeErrorMaps, p->errors.handle(), true);
    g.graph.importBuffer(kProbeLight, p->light.handle());
    g.probes = std::move(p);
}

void TerrainRenderer::setProbePositions(const std::vector<glm::vec4>& positions) {
    ctx_.waitIdle();  // no frame may still read the old buffer
    gpu_->graph.forget(kMarkers);
    markerCount_ = uint32_t(positions.size());
    gpu_->markers = vk::Buffer();
    if (positions.empty()) return;
    gpu_->markers = vk::Buffer::deviceLocal(ctx_, positions.data(), positions.size() * sizeof(glm::vec4),
                                            VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    gpu_->graph.importBuffer(kMarkers, gpu_->markers.handle(), true);
}

void TerrainRenderer::setProbeLeaves(const std::vector<glm::vec4>& leaves) {
    ctx_.waitIdle();  // no frame may still read the old buffer
    gpu_->graph.forget(kLeaves);
    leafCount_ = uint32_t(leaves.size());
    smallestLeaf_ = 1.0f;
    gpu_->leaves = vk::Buffer();
    if (leaves.empty()) return;
    smallestLeaf_ = leaves.front().w;
    for (const auto& l : leaves) smallestLeaf_ = std::min(smallestLeaf_, l.w);
    gpu_->leaves = vk::Buffer::deviceLocal(ctx_, leaves.data(), leaves.size() * sizeof(glm::vec4),
                                           VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    gpu_->graph.importBuffer(kLeaves, gpu_->leaves.handle(), true);
}

void TerrainRenderer::ensureTarget(uint32_t width, uint32_t height) {
    RendererGpu& g = *gpu_;
    if (g.target && g.target->color.width() == width && g.target->color.height() == height) return;
    ctx_.waitIdle();  // frames in flight may still draw into the old target
    for (const char* name : {kColor, kDepth, kReadback}) g.graph.forget(name);
    g.target.reset();
    auto t = std::make_unique<RenderTarget>(RenderTarget{
        vk::Image::colorTarget(ctx_, width, height), vk::Image::depthTarget(ctx_, width, height), {},
        vk::Readback(ctx_, width, height)});
    const VkImageView views[] = {t->color.view(), t->depth.view()};
    t->framebuffer = vk::Framebuffer(ctx_, g.clearPass, views, width, height);
    g.graph.importImage(kColor, t->color.handle(), t->color.aspect());
    g.graph.importImage(kDepth, t->depth.handle(), t->depth.aspect());
    g.graph.importBuffer(kReadback, t->readback.buffer());
    g.target = std::move(t);
}

RenderedImage TerrainRenderer::render(const RenderSettings& s) {
    const auto start = std::chrono::steady_clock::now();
    ensureTarget(s.width, s.height);
    // The synchronous path: whatever the viewport queued finishes first, then slot 0 is free.
    ctx_.waitIdle();
    ctx_.submitAndWait([&](VkCommandBuffer cb) { recordFrame(cb, 0, s, Output{}); });
    readFrameTimings(0);
    RenderedImage img;
    img.width = s.width;
    img.height = s.height;
    const auto readback = std::chrono::steady_clock::now();
    img.rgba = gpu_->target->readback.pixels();
    const auto end = std::chrono::steady_clock::now();
    timings_.readbackMilliseconds = std::chrono::duration<double, std::milli>(end - readback).count();
    img.milliseconds = std::chrono::duration<double, std::milli>(end - start).count();
    return img;
}

void TerrainRenderer::readFrameTimings(uint32_t slotIndex) {
    FrameSlot& slot = gpu_->slots[slotIndex];
    timings_ = FrameTimings{};
    timings_.recordMilliseconds = slot.recordMilliseconds;
    const uint32_t n = slot.timestampsWritten;
    slot.timestampsWritten = 0;
    if (n < 2) return;
    std::vector<uint64_t> ticks(n);
    // The slot's fence has passed: no wait, and results not yet available are left out.
    if (vkGetQueryPoolResults(ctx_.device(), slot.timestamps.get(), 0, n, n * sizeof(uint64_t), ticks.data(),
                              sizeof(uint64_t), VK_QUERY_RESULT_64_BIT) != VK_SUCCESS)
        return;
    const uint32_t bits = ctx_.timestampBits();
    const uint64_t mask = bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
    const double msPerTick = ctx_.timestampPeriod() * 1e-6;
    auto span = [&](uint32_t a, uint32_t b) {
        return double(((ticks[b] & mask) - (ticks[a] & mask)) & mask) * msPerTick;
    };
    for (uint32_t k = 0; k + 1 < n && k < slot.timedPasses.size(); ++k)
        timings_.passes.push_back({slot.timedPasses[k], span(k, k + 1)});
    timings_.gpuMilliseconds = span(0, n - 1);
}

bool TerrainRenderer::present(const RenderSettings& s, vk::Swapchain& swapchain) {
    ensureTarget(s.width, s.height);
    const std::optional<vk::SwapchainFrame> frame = swapchain.begin();
    if (!frame) return false;
    Output out;
    out.readback = false;
    out.swapchainImage = frame->image;
    out.extent = frame->extent;
    // begin() waited for this slot's fence: the frame drawn in it before is done.
    readFrameTimings(frame->slot);
    recordFrame(frame->cb, frame->slot, s, out);
    swapchain.submitAndPresent(*frame);
    return true;
}

// This slot's uniform blocks (the GPU finished the slot's previous frame), each from its
// feature's packing, and the frame's background.
void TerrainRenderer::writeBlocks(Frame& f) {
    RendererGpu& g = *gpu_;
    const RenderSettings& s = f.s;
    FrameSlot& slot = f.slot;
    const float extent = std::max({hf_.maxX() - hf_.minX(), hf_.maxZ() - hf_.minZ(),
                                   hf_.maxHeight() - hf_.minHeight(), 1.0f});
    const float aspect = float(s.width) / float(s.height);
    const blocks::CameraBlock camera = features::packCamera(s, extent, f.view);
    slot.camera.write(&camera, sizeof camera);
    const float spanX = hf_.maxX() - hf_.minX(), spanZ = hf_.maxZ() - hf_.minZ();
    // The normal-AO mip level whose texels are as large as the finest probe spacing: the AO at
    // that scale is what the probes already hold.
    float probeLevel = 0.0f;
    if (f.probes && hasAo_ && finestProbeSpacing_ > 0.0f) {
        const float texel = std::max(spanX / float(std::max(surfaceMapSize_.x - 1, 1)),
                                     spanZ / float(std::max(surfaceMapSize_.y - 1, 1)));
        if (texel > 0.0f) probeLevel = std::max(std::log2(finestProbeSpacing_ / texel), 0.0f);
    }
    features::SurfaceInputs surfaceIn;
    surfaceIn.footprintMin = glm::vec2(hf_.minX(), hf_.minZ());
    surfaceIn.footprintSpan = glm::vec2(spanX, spanZ);
    surfaceIn.normalAoMapSize = glm::vec2(surfaceMapSize_);
    surfaceIn.albedoMapSize = glm::vec2(albedoMapSize_);
    surfaceIn.albedoMap = hasAlbedoMap_;
    surfaceIn.ao = hasAo_;
    surfaceIn.probeAoLevel = probeLevel;
    const blocks::SurfaceBlock surface = features::packSurface(s, surfaceIn);
    slot.surface.write(&surface, sizeof surface);
    const blocks::SunSkyBlock sunSky = features::packSunSky(s);
    slot.sunSky.write(&sunSky, sizeof sunSky);
    const blocks::AtmosphereBlock atmosphere = features::packAtmosphere(s.fog);
    slot.atmosphere.write(&atmosphere, sizeof atmosphere);
    const glm::vec3 boundsMin(hf_.minX(), hf_.minHeight(), hf_.minZ()), boundsMax(hf_.maxX(), hf_.maxHeight(), hf_.maxZ());
        if (f.shadows) {
        const CascadeRange range = cascadeRange(s.shadows, s.camera, aspect, boundsMin, boundsMax);
        cascades_ = fitCascades(range, s.camera, aspect, s.sun.direction, f.shadows->resolution, boundsMin, boundsMax);
        for (const Cascade& c : cascades_) f.lightMatrices.push_back(c.lightViewProj);
        const blocks::ShadowBlock block = features::packShadows(s, cascades_, range, f.shadows->resolution);
        slot.shadow.write(&block, sizeof block);
    } else if (!s.shadows.enabled) {
        cascades_.clear();
    }
    if (f.water) {
        features::WaterInputs in;
        in.level = f.water->level;
        in.shoreFadeDistance = float(water::shoreFadeDistance(s.water, hf_));
        in.fieldSize = glm::vec2(f.water->fieldSize);
        in.meshSpacing = f.water->spacing;
        const blocks::WaterBlock block = features::packWater(s, in);
        f.water->blocks[f.slotIndex].write(&block, sizeof block);
    }
    if (f.planarReflection) {
        // The camera mirrored in the plane, drawing scene-linear beauty into the reflection.
        const blocks::CameraBlock mirrored =
            features::packMirroredCamera(s, camera, extent, f.water->level, float(f.water->reflectionWidth),
                                         float(f.water->reflectionHeight));
        slot.reflectionCamera.write(&mirrored, sizeof mirrored);
    }
    if (f.reflections) {
        const blocks::ReflectionBlock block = features::packReflections(*f.reflections, s);
        f.reflections->blocks[f.slotIndex].write(&block, sizeof block);
    }
    if (f.lpvSet) {
        const size_t wanted = std::max<size_t>(f.localLights ? s.lights.size() : 0, 1);
        if (slot.localLightCapacity < wanted) {
            slot.localLights = vk::Buffer::hostVisible(ctx_, wanted * sizeof(blocks::LocalLightRecord),
                                                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
            slot.localLightCapacity = wanted;
            slot.lpvSetKey = 0;
        }
        const std::vector<blocks::LocalLightRecord> records = features::packLocalLights(s.lights, f.localLights);
        slot.localLights.write(records.data(), records.size() * sizeof(records[0]));
        const blocks::LpvBlock block = features::packLpv(f);
        slot.lpvBlock.write(&block, sizeof block);
        const uint64_t key = f.lpvVolumes ? g.lpvGeneration : 1;
        if (slot.lpvSetKey != key) {
            slot.lpvSet = lpvSetBuilder(slot.lpvBlock, f.lpvVolumes ? f.lpvVolumes->light : g.lpvDummy,
                                        f.lpvVolumes ? f.lpvVolumes->geometry : g.lpvDummy, slot.localLights)
                              .build(ctx_);
            slot.lpvSetKey = key;
        }
    }
    if (f.drawMarkers || f.drawReflectionMarkers || f.drawLeaves) {
        const blocks::OverlayBlock overlay = features::packOverlay(s, smallestLeaf_, kSmallestLeafPixels);
        slot.overlay.write(&overlay, sizeof overlay);
    }

    // Background where no pass draws the sky: black, or the sky toward the horizon in the view's
    // encoding (the sky pass draws over it per pixel).
    glm::vec3& bg = f.background;
    if (f.view.background != ViewBackground::Black) {
        bg = glm::max(sh::evalRadiance(s.skySh, glm::normalize(glm::vec3(0.0f, 0.2f, -1.0f))), glm::vec3(0.0f));
        if (!s.linearOutput && f.view.background == ViewBackground::Sky) {
            // tonemap.glsl's display(), for the one colour the shader does not draw.
            for (int i = 0; i < 3; ++i) bg[i] = glsl::srgbEncode(glsl::acesFit(bg[i] * s.exposure));
        } else if (!s.linearOutput) {
            bg = glm::clamp(bg, glm::vec3(0.0f), glm::vec3(1.0f));
        }
    }
}

void TerrainRenderer::recordFrame(VkCommandBuffer cb, uint32_t slotIndex, const RenderSettings& s,
                                  const Output& out) {
    const auto recordStart = std::chrono::steady_clock::now();
    RendererGpu& g = *gpu_;
    Frame f{ctx_, g, g.slots[slotIndex], slotIndex, s,
            findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty))};
    const DebugView& view = f.view;
    // Who takes part. Probes: volumes bound, probes on and the view reads their light. Reflection
    // probes: a set bound, probes on and the view reads the environment's specular (the strength
    // does not decide it: it is a live uniform, and a weight of 0 leaves the sky's specular as it
    // is). The LPV: volumes bound and either the view lights with them and lighting.indirect asks
    // for them, or the view shows them; the local lights in the lit views whenever the scene has
    // some; either binds the terrain's LPV set.
    f.probes = g.probes && s.probes && (view.needs.probeLight || view.needs.probeDiagnostics) ? g.probes.get() : nullptr;
    f.reflections = g.reflections && s.probes && view.needs.reflectionProbes ? g.reflections.get() : nullptr;
    f.lpvVolumes = g.lpv && ((s.lpvLight && view.needs.sceneLights) || view.needs.lpvVolumes) ? g.lpv.get() : nullptr;
    f.localLights = !s.lights.empty() && view.needs.sceneLights;
    f.lpvSet = f.lpvVolumes || f.localLights;
    f.drawMarkers = (s.showProbePositions || view.needs.probeMarkers) && markerCount_ > 0;
    f.drawReflectionMarkers = s.showProbePositions && g.reflections && g.reflections->markerCount > 0;
    f.drawLeaves = s.showLeaves && leafCount_ > 0;
    f.fog = s.fog.enabled;
    f.sunVisibility = view.needs.sunVisibility;
    f.sky = view.needs.sky;
    if (f.sunVisibility) updateSunVisibility(s.sun, s.skirt);
    // Shadows: the scene has them on, the sun is up and the view draws them. A scene without
    // shadows holds no maps.
    const bool shadowed = s.shadows.enabled && view.needs.shadows && s.sun.direction.y > -0.05f;
    if (!s.shadows.enabled) ensureShadowMaps(0, 0);
    if (shadowed) ensureShadowMaps(s.shadows.mapResolution, std::clamp(s.shadows.cascades, 1, 4));
    f.shadows = shadowed ? g.shadows.get() : nullptr;
    // Water: the scene has it and the view draws it; the reflection and the copy of the frame
    // under it only where the view shades it, the reflection only when planar.
    f.water = s.water.enabled && view.needs.water ? g.water.get() : nullptr;
    f.waterShading = f.water && view.needs.waterShading;
    f.planarReflection = f.waterShading && s.water.reflection == WaterReflection::Planar;
    if (f.water) ensureWaterTargets(s.width, s.height, float(s.water.reflectionScale));
    f.vertexCount = uint32_t(vertexCount_);
    f.indexCount = uint32_t(indexCount_);
    f.markerCount = markerCount_;
    f.leafCount = leafCount_;
    f.width = s.width;
    f.height = s.height;
    f.framebuffer = g.target->framebuffer.handle();
    writeBlocks(f);

    // The passes, in order; a feature that does not take part adds none.
    g.graph.beginFrame();
    features::addProbePass(f);
    features::addLpvPropagationPass(f, [this](VkCommandBuffer c) { recordLpvPropagation(c); });
    features::addShadowPass(f);
    features::addTerrainPass(f);
    features::addSkyPass(f);
    features::addWaterPasses(f);
    features::addOverlayPass(f);
    if (out.readback) {
        RenderTarget& t = *g.target;
        g.graph.addPass({"readback", {{kColor, Access::TransferRead}, {kReadback, Access::TransferWrite}}, {}},
                        [&t](VkCommandBuffer c) { t.readback.recordCopy(c, t.color.handle()); });
        g.graph.addFinalUse({kReadback, Access::HostRead});
    } else {
        g.graph.importImage(kSwapchain, out.swapchainImage, VK_IMAGE_ASPECT_COLOR_BIT, 1,
                            VK_PIPELINE_STAGE_TRANSFER_BIT);
        const VkImage source = g.target->color.handle(), dest = out.swapchainImage;
        const VkExtent2D dstExtent = out.extent;
        const uint32_t w = s.width, h = s.height;
        g.graph.addPass({"present", {{kColor, Access::TransferRead}, {kSwapchain, Access::TransferWrite}}, {}},
                        [source, dest, w, h, dstExtent](VkCommandBuffer c) {
                            VkImageBlit blit{};
                            blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                            blit.srcOffsets[1] = {int32_t(w), int32_t(h), 1};
                            blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                            blit.dstOffsets[1] = {int32_t(dstExtent.width), int32_t(dstExtent.height), 1};
                            vkCmdBlitImage(c, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dest,
                                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
                        });
        g.graph.addFinalUse({kSwapchain, Access::Present});
    }
    FrameSlot& slot = f.slot;
    slot.timestampsWritten = g.graph.execute(cb, slot.timestamps.get(), slot.timestamps ? kFrameTimestamps : 0);
    slot.timedPasses.clear();
    for (const PassInfo& p : g.graph.lastFrame()) slot.timedPasses.push_back(p.name);
    if (f.probes) f.probes->lightStale = false;
    slot.recordMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - recordStart).count();
}

}  // namespace terralux
