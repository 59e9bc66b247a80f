#include "render/TerrainRenderer.h"

#include "scene/ImageCodes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numbers>

#include <glm/gtc/packing.hpp>
#include <glm/packing.hpp>
#include <glm/mat4x4.hpp>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "ShaderBinaries.h"
#include "ShaderMath.h"
#include "bake/DiffuseBake.h"
#include "bake/ReflectionBake.h"
#include "bake/SphereSampling.h"
#include "lpv/Lpv.h"
#include "render/Frame.h"
#include "render/TargetSet.h"
#include "render/features/Antialiasing.h"
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
#include "system/BackgroundPriority.h"
#include "terrain/HorizonAO.h"
#include "terrain/MeshLod.h"
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


// Shadow rays per vertex of the sun-visibility view, stratified over the sun's disc.
constexpr int kSunVisibilitySamples = 16;

// Smallest octree leaf the leaf overlay draws, in pixels on screen.
constexpr float kSmallestLeafPixels = 6.0f;


}  // namespace

struct TerrainRenderer::Output {
    bool readback = true;
    features::AntialiasingPlan antialiasing;
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
            .image(TLX_SHADOW_MAP_DEPTH_BINDING, std::string(kShadowMaps) + "(depth)", maps,
                   g.depthSampler.handle(), frag)
            .storage(TLX_SUN_HORIZON_BINDING, "sun-horizon", f.sunHorizon, frag);
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
        .image(TLX_SURFACE_FILLED_BINDING, kSurfaceFilled, t ? t->filled.view() : VK_NULL_HANDLE, sampler, frag)
        .image(TLX_SKY_IMAGE_BINDING, kSkyImage, t ? t->sky.view() : VK_NULL_HANDLE, sampler, frag);
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


// Texel bytes of a level: RGBA16F normal-AO, RGBA8 sRGB albedo, R8 filled share.
vk::MipLevel halfLevel(int w, int h, const std::vector<glm::vec4>& texels) {
    vk::MipLevel l{uint32_t(w), uint32_t(h), std::vector<uint8_t>(texels.size() * 8)};
    for (size_t i = 0; i < texels.size(); ++i) {
        const uint64_t packed = glm::packHalf4x16(texels[i]);
        std::memcpy(l.bytes.data() + 8 * i, &packed, 8);
    }
    return l;
}

// The full mip chain of `level` (w x h texels), each texel of a level the box mean of the texels
// it covers in the one before, down to 1 x 1; each level encoded by encode(w, h, texels).
template <class Texel, class Encode>
std::vector<vk::MipLevel> boxMipChain(std::vector<Texel> level, int w, int h, Encode encode) {
    std::vector<vk::MipLevel> levels;
    while (true) {
        levels.push_back(encode(w, h, level));
        if (w == 1 && h == 1) return levels;
        const int nw = std::max(w / 2, 1), nh = std::max(h / 2, 1);
        std::vector<Texel> next(size_t(nw) * size_t(nh));
        for (int j = 0; j < nh; ++j)
            for (int i = 0; i < nw; ++i) {
                const int x0 = i * w / nw, x1 = (i + 1) * w / nw, y0 = j * h / nh, y1 = (j + 1) * h / nh;
                Texel sum(0.0f);
                for (int y = y0; y < y1; ++y)
                    for (int x = x0; x < x1; ++x) sum += level[size_t(y) * size_t(w) + size_t(x)];
                next[size_t(j) * size_t(nw) + size_t(i)] = sum / float((x1 - x0) * (y1 - y0));
            }
        level = std::move(next);
        w = nw;
        h = nh;
    }
}

// The skirt (terrain.skirt: beyond the footprint the ground keeps its border's height) as the
// shadow maps draw it, so the preview's sun is shadowed by the world the bake traces: each border
// edge of the drawn mesh extruded outward, and a level square at the corner height in each corner
// quadrant. It reaches 100 footprints out: a border ridge's shadow from further falls on the
// footprint only below a sun of about atan(relief / 100 footprints), well under a degree. Every
// border vertex of the drawn grid has its pushed-out twin, appended after the terrain's vertices
// (which only the shadow pass draws), so the skirt follows whichever border vertices the frame's
// level of detail keeps.
lod::SkirtVertices appendSkirtVertices(std::vector<float>& vertices, uint32_t nc, uint32_t nr) {
    auto at = [&](uint32_t c, uint32_t r) {
        const size_t i = (size_t(r) * nc + c) * 6;
        return glm::vec3(vertices[i], vertices[i + 1], vertices[i + 2]);
    };
    const glm::vec3 lo = at(0, 0), hi = at(nc - 1, nr - 1);
    const float reach = 100.0f * std::max({hi.x - lo.x, hi.z - lo.z, 1.0f});
    auto add = [&](glm::vec3 p) {
        vertices.insert(vertices.end(), {p.x, p.y, p.z, 0.0f, 1.0f, 0.0f});
        return uint32_t(vertices.size() / 6 - 1);
    };
    lod::SkirtVertices k;
    k.nc = nc;
    k.nr = nr;
    const glm::vec3 west(-1, 0, 0), east(1, 0, 0), north(0, 0, -1), south(0, 0, 1);
    for (uint32_t c = 0; c < nc; ++c) {
        k.north.push_back(add(at(c, 0) + north * reach));
        k.south.push_back(add(at(c, nr - 1) + south * reach));
    }
    for (uint32_t r = 0; r < nr; ++r) {
        k.west.push_back(add(at(0, r) + west * reach));
        k.east.push_back(add(at(nc - 1, r) + east * reach));
    }
    auto corner = [&](uint32_t c, uint32_t r, glm::vec3 a, glm::vec3 b) {
        const glm::vec3 p = at(c, r);
        const uint32_t ip = r * nc + c, ia = add(p + a * reach), iab = add(p + (a + b) * reach), ib = add(p + b * reach);
        k.corners.insert(k.corners.end(), {ip, ia, iab, ip, iab, ib});
    };
    corner(0, 0, west, north);
    corner(nc - 1, 0, east, north);
    corner(0, nr - 1, west, south);
    corner(nc - 1, nr - 1, east, south);
    return k;
}

}  // namespace

TerrainRenderer::TerrainRenderer(vk::VulkanContext& ctx, const Heightfield& hf, size_t vertexBudget)
    : ctx_(ctx), hf_(hf), gpu_(std::make_unique<RendererGpu>()) {
    const size_t w = size_t(hf.width()), d = size_t(hf.depth());
    while (((w - 1) / size_t(stride_) + 2) * ((d - 1) / size_t(stride_) + 2) > vertexBudget &&
           stride_ < int(std::max(w, d)))
        ++stride_;
    const std::vector<uint32_t> cols = lod::kept(uint32_t(w), uint32_t(stride_)), rows = lod::kept(uint32_t(d), uint32_t(stride_));

    std::vector<float> vertices;
    vertices.reserve(cols.size() * rows.size() * 6);
    for (uint32_t r : rows)
        for (uint32_t c : cols) {
            const glm::vec3 p = hf.vertex(int(c), int(r)), n = hf.vertexNormal(int(c), int(r));
            vertices.insert(vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
        }
    vertexCount_ = vertices.size() / 6;
    meshVertices_ = vertices;
    // The level of detail's patches (MeshLod.h); their levels' errors are against the drawn grid.
    const uint32_t nc = uint32_t(cols.size()), nr = uint32_t(rows.size());
    std::vector<float> drawnHeights(vertexCount_), colX(nc), rowZ(nr);
    for (size_t i = 0; i < vertexCount_; ++i) drawnHeights[i] = vertices[6 * i + 1];
    for (uint32_t c = 0; c < nc; ++c) colX[c] = vertices[6 * c];
    for (uint32_t r = 0; r < nr; ++r) rowZ[r] = vertices[6 * size_t(r) * nc + 2];
    patches_ = lod::buildPatches(drawnHeights, nc, nr, colX, rowZ, kLodPatchCells);
    // What the drawn grid leaves out of the source DEM, per patch: the levels keep what they
    // leave out of the drawn grid within the pixel, and the error reported adds this.
    decimation_.assign(patches_.count(), 0.0);
    if (stride_ > 1)
        for (uint32_t k = 0; k < patches_.count(); ++k) {
            const uint32_t i = k % patches_.patchesX(), j = k / patches_.patchesX();
            const std::vector<uint32_t> pc(cols.begin() + patches_.cols[i], cols.begin() + patches_.cols[i + 1] + 1);
            const std::vector<uint32_t> pr(rows.begin() + patches_.rows[j], rows.begin() + patches_.rows[j + 1] + 1);
            decimation_[k] = lod::gridError(hf.heights(), uint32_t(w), pc, pr);
            // The DEM's samples there lie within that of the drawn surface: the patch's bounds
            // (its distance from the camera) hold them.
            patches_.lo[k].y -= float(decimation_[k]);
            patches_.hi[k].y += float(decimation_[k]);
        }
    if (stride_ > 1) {
        source_.nc = uint32_t(w);
        source_.nr = uint32_t(d);
        source_.col = cols;
        source_.row = rows;
        for (int c = 0; c < hf.width(); ++c) source_.x.push_back(hf.vertex(c, 0).x);
        for (int r = 0; r < hf.depth(); ++r) source_.z.push_back(hf.vertex(0, r).z);
        while (lod::stepOf(detailLevels_) < uint32_t(stride_)) ++detailLevels_;
        detailLevelErrors_.resize(patches_.count());
    }
    skirt_ = appendSkirtVertices(vertices, nc, nr);
    indexCount_ = size_t(nc - 1) * (nr - 1) * 6;
    {
        double sum = 0.0;
        size_t n = 0;
        for (int r = 0; r < hf.depth(); ++r)
            for (int c = 0; c < hf.width(); ++c)
                if (r == 0 || r == hf.depth() - 1 || c == 0 || c == hf.width() - 1) sum += hf.vertex(c, r).y, ++n;
        borderHeight_ = float(sum / double(std::max<size_t>(n, 1)));
    }

    horizonMap_ = horizonMapOf(hf.width(), hf.depth(), hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(), kMaxSurfaceTexels);

    RendererGpu& g = *gpu_;
    g.vertices = vk::Buffer::deviceLocal(ctx_, vertices.data(), vertices.size() * 4,
                                         VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    g.graph.importBuffer(kVertices, g.vertices.handle(), true);

    for (uint32_t i = 0; i < kRenderSlots; ++i) {
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
        // One byte a vertex of the horizon map, written by the host when the slot's frame begins
        // (its previous frame done), as the uniform blocks are.
        f.sunHorizon = vk::Buffer::hostVisible(
            ctx_, std::max<VkDeviceSize>(4, (VkDeviceSize(horizonMap_.width) * VkDeviceSize(horizonMap_.height) + 3) / 4 * 4),
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
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
            f.timestampResults = vk::Buffer::hostVisible(ctx_, kFrameTimestamps * sizeof(uint64_t),
                                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT);
        }
        g.slots.push_back(std::move(f));
    }
    g.trilinear = vk::Sampler::trilinearClamp(ctx_);
    g.viewLayout = viewSetBuilder(g.slots[0], g.slots[0].camera, nullptr, g.trilinear.handle()).buildLayout(ctx_);
    uploadSurfaceMaps({});
    setSkyImage(0, 0, {});
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
    g.depthSampler = vk::Sampler::depthBorder(ctx_);
    g.shadowDepthLayout = vk::PipelineLayout(ctx_, {}, sizeof(glm::mat4), VK_SHADER_STAGE_VERTEX_BIT);
    g.linear = vk::Sampler::linearClamp(ctx_);
    static const vk::Buffer noBuffer;
    g.waterLayout = features::waterSetBuilder(noBuffer, VK_NULL_HANDLE, VK_NULL_HANDLE, VK_NULL_HANDLE, g.linear.handle())
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
    if (level ? g.water && g.water->level == *level && g.water->margin == margin : !g.water) return;
    for (const char* name : {kWaterReflection, kWaterReflectionDepth, kWaterScene, kWaterVertices, kWaterIndices})
        g.graph.forget(name);
    if (g.water) retire(std::move(g.water));
    if (!level) return;
    g.water = features::buildWater(ctx_, hf_, *level, margin);
    g.graph.importBuffer(kWaterVertices, g.water->vertices.handle(), true);
    g.graph.importBuffer(kWaterIndices, g.water->indices.handle(), true);
}

void TerrainRenderer::ensureWaterTargets(uint32_t width, uint32_t height, float reflectionScale) {
    RendererGpu& g = *gpu_;
    WaterResources& w = *g.water;
    if (features::waterTargetsServe(w.targets.get(), width, height, reflectionScale)) return;
    constexpr const char* kNames[] = {kWaterReflection, kWaterReflectionDepth, kWaterScene};
    auto importTargets = [&g](const WaterTargets& t) {
        g.graph.importImage(kWaterReflection, t.reflection.handle(), t.reflection.aspect());
        g.graph.importImage(kWaterReflectionDepth, t.reflectionDepth.handle(), t.reflectionDepth.aspect());
        g.graph.importImage(kWaterScene, t.scene.handle(), t.scene.aspect());
    };
    const auto serves = [&](const WaterTargets* t) { return features::waterTargetsServe(t, width, height, reflectionScale); };
    for (const char* name : kNames) g.graph.park(name);
    if (takeSpare(w.targets, w.spareTargets, serves)) {
        // As ensureTarget: back to a size drawn lately, each image resumed where it was left.
        importTargets(*w.targets);
        return;
    }
    ctx_.waitIdle();  // frames in flight may still read the targets
    for (const char* name : kNames) g.graph.forget(name);
    replaceTarget(w.targets, w.spareTargets, features::buildWaterTargets(ctx_, g, w, width, height, reflectionScale));
    for (const auto& spare : w.spareTargets) {
        importTargets(*spare);
        for (const char* name : kNames) g.graph.park(name);
    }
    importTargets(*w.targets);
}

bool TerrainRenderer::hasShadowResources() const { return gpu_->shadows != nullptr; }

size_t TerrainRenderer::targetAllocations() const { return gpu_->targetAllocations; }

void TerrainRenderer::redrawShadowMaps() {
    if (gpu_->shadows) gpu_->shadows->drawn.clear();
}

TerrainRenderer::SurfaceMapTextures TerrainRenderer::prepareSurfaceMaps(const vk::VulkanContext& ctx,
                                                                         const Heightfield& hf,
                                                                         const std::vector<float>& ao) {
    if (!ao.empty() && ao.size() != hf.heights().size())
        throw std::invalid_argument("ambient occlusion needs one value per DEM vertex");
    const SurfaceMaps maps = buildSurfaceMaps(hf, ao);
    std::vector<vk::MipLevel> levels;
    int w = maps.width, h = maps.height;
    for (const auto& level : maps.normalAo) {
        levels.push_back(halfLevel(w, h, level));
        w = std::max(w / 2, 1);
        h = std::max(h / 2, 1);
    }
    SurfaceMapTextures t;
    t.normalAo = vk::Image::texture(ctx, VK_FORMAT_R16G16B16A16_SFLOAT, levels);
    t.filled = vk::Image::texture(ctx, VK_FORMAT_R8_UNORM,
                                  {vk::MipLevel{uint32_t(maps.width), uint32_t(maps.height), maps.filled}});
    t.size = {maps.width, maps.height};
    t.terrain = hf.serial();
    t.ao = !ao.empty();
    return t;
}

void TerrainRenderer::setSurfaceMaps(SurfaceMapTextures maps) {
    if (maps.terrain != hf_.serial())
        throw std::invalid_argument("surface maps made for another terrain");
    RendererGpu& g = *gpu_;
    // Frames in flight may still read the old maps, and the view sets that name them: retired,
    // not waited for.
    retire(std::move(g.surface.normalAo));
    retire(std::move(g.surface.filled));
    g.surface.normalAo = std::move(maps.normalAo);
    g.surface.filled = std::move(maps.filled);
    surfaceMapSize_ = maps.size;
    hasAo_ = maps.ao;
    if (g.surface.albedo.handle() != VK_NULL_HANDLE) {
        for (FrameSlot& f : g.slots) {
            retire(std::move(f.view));
            retire(std::move(f.reflectionView));
        }
        buildViewSets();
    }
}

void TerrainRenderer::uploadSurfaceMaps(const std::vector<float>& ao) { setSurfaceMaps(prepareSurfaceMaps(ctx_, hf_, ao)); }

void TerrainRenderer::setSkyImage(int width, int height, const std::vector<glm::vec3>& radiance) {
    RendererGpu& g = *gpu_;
    const bool image = width > 0 && height > 0 && radiance.size() == size_t(width) * size_t(height);
    // A full mip chain of box means, so that a sky image many times the pixels it covers is drawn
    // from the level a pixel spans (no sparkle); half floats, clamped to their largest value.
    std::vector<glm::vec4> level(image ? radiance.size() : 1, glm::vec4(0.0f));
    if (image)
        for (size_t i = 0; i < level.size(); ++i) level[i] = glm::vec4(glm::min(radiance[i], glm::vec3(65000.0f)), 1.0f);
    const std::vector<vk::MipLevel> levels = boxMipChain(std::move(level), image ? width : 1, image ? height : 1, halfLevel);
    replaceTexture(g.surface.sky, vk::Image::stagedTexture(ctx_, VK_FORMAT_R16G16B16A16_SFLOAT, levels));
    skyImageHeight_ = image ? height : 0;
    if (g.surface.albedo.handle() != VK_NULL_HANDLE) buildViewSets();
}

void TerrainRenderer::replaceTexture(vk::Image& held, vk::StagedTexture staged) {
    RendererGpu& g = *gpu_;
    // Frames in flight may still read the old image and the view sets that name it: retired, not
    // waited for. The new one's levels are copied in by the next frame, before its passes: a
    // submission of their own would wait behind every frame queued (0.1-0.3 s a sky edit on
    // lavapipe while the water's waves kept frames coming).
    std::erase_if(pendingTextures_, [&](const vk::StagedTexture& t) { return t.target == held.handle(); });
    retire(std::move(held));
    held = std::move(staged.image);
    pendingTextures_.push_back(std::move(staged));
    for (FrameSlot& f : g.slots) {
        retire(std::move(f.view));
        retire(std::move(f.reflectionView));
    }
}

void TerrainRenderer::setAmbientOcclusion(const std::vector<float>& perVertex) { uploadSurfaceMaps(perVertex); }

void TerrainRenderer::setAlbedoMap(int width, int height, const std::vector<uint8_t>& srgb) {
    RendererGpu& g = *gpu_;
    const bool map = width > 0 && height > 0 && srgb.size() == size_t(width) * size_t(height) * 3;
    // A full mip chain of box means in linear light, stored sRGB-encoded (the hardware decodes);
    // level 0 holds the field's own codes.
    std::vector<glm::vec3> level(map ? srgb.size() / 3 : 1, glm::vec3(1.0f));
    if (map)
        for (size_t i = 0; i < level.size(); ++i)
            level[i] = {linearOfSrgb8(srgb[3 * i]), linearOfSrgb8(srgb[3 * i + 1]), linearOfSrgb8(srgb[3 * i + 2])};
    const std::vector<vk::MipLevel> levels =
        boxMipChain(std::move(level), map ? width : 1, map ? height : 1, [](int w, int h, const std::vector<glm::vec3>& texels) {
            vk::MipLevel l{uint32_t(w), uint32_t(h), std::vector<uint8_t>(texels.size() * 4)};
            for (size_t i = 0; i < texels.size(); ++i) {
                for (int c = 0; c < 3; ++c) l.bytes[4 * i + size_t(c)] = srgb8(texels[i][c]);
                l.bytes[4 * i + 3] = 255;
            }
            return l;
        });
    replaceTexture(g.surface.albedo, vk::Image::stagedTexture(ctx_, VK_FORMAT_R8G8B8A8_SRGB, levels));
    hasAlbedoMap_ = map;
    if (map) {
        // The ring of border texels, the albedo the skirt takes (it is clamped to the footprint).
        glm::dvec3 sum(0.0);
        size_t n = 0;
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x)
                if (y == 0 || y == height - 1 || x == 0 || x == width - 1) {
                    const size_t i = 3 * (size_t(y) * size_t(width) + size_t(x));
                    sum += glm::dvec3(linearOfSrgb8(srgb[i]), linearOfSrgb8(srgb[i + 1]), linearOfSrgb8(srgb[i + 2]));
                    ++n;
                }
        borderAlbedo_ = glm::vec3(sum / double(n));
    }
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
    auto sh = features::buildShadowMaps(ctx_, g, resolution, cascades);
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


}  // namespace

void TerrainRenderer::setLpv(std::shared_ptr<const lpv::Volumes> volumes) {
    RendererGpu& g = *gpu_;
    if (g.lpv ? g.lpv->volumes == volumes : !volumes) return;
    std::unique_ptr<LpvResources> r = features::buildLpv(ctx_, g, std::move(volumes));
    // Frames in flight may still read the old volumes: they go once those are done, and a slot's
    // LPV set names the new ones from its next frame on (lpvGeneration). Waiting for the device
    // here held the UI thread 0.3-0.8 s at each update while the viewport panned on lavapipe.
    for (const char* name : {kLpvLight, kLpvGeometry, kLpvWork, kLpvScales}) g.graph.forget(name);
    if (g.lpv) retire(std::move(g.lpv));
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


void TerrainRenderer::propagateLpvNow() {
    RendererGpu& g = *gpu_;
    if (!g.lpv || g.lpv->steps == 0) return;
    ctx_.waitIdle();
    ctx_.submitAndWait([&](VkCommandBuffer cb) {
        // The injected light and the geometry were filled by transfers.
        frame::memoryBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
        features::recordLpvPropagation(g, cb);
        // Whatever reads the light later, in this submission's successors, sees it written.
        frame::memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
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
        frame::memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                      VK_ACCESS_TRANSFER_READ_BIT);
        const VkBufferCopy region{0, 0, g.lpv->light.size()};
        vkCmdCopyBuffer(cb, g.lpv->light.handle(), host.handle(), 1, &region);
        frame::memoryBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
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
        frame::memoryBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT);
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.lpvSample.get());
        const VkDescriptorSet handle = set.handle();
        vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, g.lpvSampleLayout.handle(), TLX_SET_SUBSYSTEM, 1,
                                &handle, 0, nullptr);
        vkCmdPushConstants(cb, g.lpvSampleLayout.handle(), compute, 0, sizeof push, &push);
        vkCmdDispatch(cb, uint32_t(queries.size() + 63) / 64, 1, 1);
        frame::memoryBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
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
    for (const char* name : {kReflectionRecords, kReflectionMarkers}) g.graph.forget(name);
    if (g.reflections) retire(std::move(g.reflections));
    reflectionBytes_ = 0;
    if (!set || set->probes.empty()) return;
    g.reflections = features::buildReflections(ctx_, g, *set);
    reflectionBytes_ = g.reflections->bytes;
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
    g.graph.forget(kSunVisibility);
    if (g.sunVisibility) retire(std::move(g.sunVisibility));
    g.sunVisibility = vk::Buffer::deviceLocal(ctx_, values.data(), values.size() * sizeof(glm::vec4),
                                              VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    g.graph.importBuffer(kSunVisibility, g.sunVisibility.handle(), true);
    g.sunVisibilityKey = key;
    g.sunVisibilitySkirt = int(skirt);
    ++sunTraces_;
}

uint64_t TerrainRenderer::horizonMapBytes() const {
    return uint64_t(horizonMap_.width) * uint64_t(horizonMap_.height) * uint64_t(kRenderSlots);
}

bool TerrainRenderer::sunHorizonSwept() const {
    return pendingHorizon_ && pendingHorizon_->perVertex.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

std::function<TerrainRenderer::SweptHorizon()> TerrainRenderer::sunHorizonSweep(const SunLight& sun, bool skirt) const {
    // Isolated: a thread waiting for its sweep's tasks may otherwise take up any task of the
    // shared pool meanwhile, such as a chunk of the preview bake's, on the UI thread.
    return [this, direction = sun.direction, radius = sun.angularRadius, skirt] {
        std::vector<float> perVertex;
        tbb::this_task_arena::isolate([&] { perVertex = sunHorizonVisibility(hf_, direction, radius, skirt); });
        return sweptHorizonOf(std::move(perVertex));
    };
}

TerrainRenderer::SweptHorizon TerrainRenderer::sweptHorizonOf(std::vector<float> perVertex) const {
    SweptHorizon s;
    const int w = horizonMap_.width, h = horizonMap_.height;
    const bool whole = w == hf_.width() && h == hf_.depth();
    if (whole) {
        s.map = std::move(perVertex);
    } else {
        // The nearest DEM vertex to each map vertex, both spanning the footprint corner to corner.
        s.map.assign(size_t(w) * size_t(h), 1.0f);
        for (int r = 0; r < h; ++r) {
            const size_t row = size_t(std::lround(double(r) * (hf_.depth() - 1) / std::max(h - 1, 1)));
            for (int c = 0; c < w; ++c) {
                const size_t col = size_t(std::lround(double(c) * (hf_.width() - 1) / std::max(w - 1, 1)));
                s.map[size_t(r) * size_t(w) + size_t(c)] = perVertex[row * size_t(hf_.width()) + col];
            }
        }
    }
    s.bytes.assign((s.map.size() + 3) / 4, 0u);
    for (size_t i = 0; i < s.map.size(); ++i) s.bytes[i / 4] |= uint32_t(unitToByte(s.map[i])) << (8 * (i % 4));
    return s;
}

void TerrainRenderer::startSunHorizonSweep(const SunLight& sun, bool skirt) {
    auto pending = std::make_unique<PendingHorizon>();
    pending->key = glm::vec4(sun.direction, sun.angularRadius);
    pending->skirt = skirt;
    pending->perVertex = std::async(std::launch::async, [sweep = sunHorizonSweep(sun, skirt)] {
        const BackgroundThread background;
        return sweep();
    });
    pendingHorizon_ = std::move(pending);
}

bool TerrainRenderer::sunHorizonReady(const RenderSettings& s) {
    const Parts p = partsOf(s, findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty)));
    if (!p.shadowed || !s.shadows.heightfield || sunHorizonSerial_ > 0) return true;
    if (!pendingHorizon_) startSunHorizonSweep(s.sun, s.skirt);
    return sunHorizonSwept();
}

bool TerrainRenderer::sunHorizonAwaited() const {
    return sunHorizonSerial_ == 0 && pendingHorizon_ && !sunHorizonSwept();
}

void TerrainRenderer::updateSunHorizon(const SunLight& sun, bool skirt, bool wait) {
    const glm::vec4 key(sun.direction, sun.angularRadius);
    auto held = [&] { return sunHorizonSerial_ > 0 && key == sunHorizonKey_ && sunHorizonSkirt_ == int(skirt); };
    // A finished sweep lands first, unless the map held is the one asked for (the sun went back):
    // its sun is newer than the held one's. Then the one asked for starts if it is another.
    if (pendingHorizon_ && (wait || sunHorizonSwept())) {
        std::unique_ptr<PendingHorizon> done = std::move(pendingHorizon_);
        SweptHorizon swept = done->perVertex.get();
        if (!held()) installSunHorizon(std::move(swept), done->key, done->skirt);
    }
    if (held()) return;
    if (pendingHorizon_) return;  // one at a time: the frames draw the map held until it lands
    // Every map of a frame that waits, and the first of any other that was not put off for it
    // (sunHorizonReady), is swept here; the viewport's frames sweep on a worker (a 12 M-vertex
    // map takes 275 ms) and draw the map held meanwhile.
    if (wait || sunHorizonSerial_ == 0) {
        installSunHorizon(sunHorizonSweep(sun, skirt)(), key, skirt);
        return;
    }
    startSunHorizonSweep(sun, skirt);
}

void TerrainRenderer::dropSweptHorizon() {
    // A frame that reads no horizon map lets a finished sweep go: the next one that reads it
    // sweeps its own sun, and the viewport stops waiting for the sweep.
    if (sunHorizonSwept()) pendingHorizon_.reset();
}

void TerrainRenderer::installSunHorizon(SweptHorizon swept, const glm::vec4& key, bool skirt) {
    sunHorizonMap_ = std::move(swept.map);
    sunHorizonBytes_ = std::move(swept.bytes);
    sunHorizonKey_ = key;
    sunHorizonSkirt_ = int(skirt);
    ++sunHorizonSerial_;
    ++sunHorizonSweeps_;
}

void TerrainRenderer::updateLod(const RenderSettings& s, double rows, bool picture, bool sourceDetail, bool shadowed,
                                const LodInputs& inputs) {
    double worst = 0.0;
    // The data views are measured against the bake vertex by vertex: they draw every vertex.
    double maxPixels = picture ? std::max(inputs.pixelError, 0.0) : 0.0;
    lodPicture_ = picture;
    lodInputs_ = inputs;
    // A caster's height error moves the edge of its shadow 1 / tan(sun elevation) times as far
    // across the ground: with shadows, the levels keep that within the pixel (5x finer at a 11°
    // sun, 1.4x at 35°).
    if (shadowed) {
        const double up = std::clamp(double(s.sun.direction.y), 1e-3, 1.0);
        maxPixels *= std::min(1.0, up / std::sqrt(std::max(1.0 - up * up, 0.0)));
    }
    // At 0 pixels a patch still draws a coarser level whose error is 0: it loses nothing.
    const glm::vec3 eye = s.camera.position();
    const double fovY = glm::radians(double(s.camera.fovDeg));
    std::vector<uint8_t> levels = lod::chooseLevels(patches_, eye, fovY, rows, maxPixels);
    // Where the drawn grid is decimated and its patches may come from the DEM's samples, a level
    // is held to the pixel against the DEM: its error against the drawn grid plus what the grid
    // leaves out (a bound: each of the grid's triangles lies within one of the level's), finer
    // until it is; at level 0 the detail patches below take over.
    const bool detailAllowed = sourceDetail && inputs.sourceDetail && detailLevels_ > 0 && maxPixels > 0.0;
    if (detailAllowed)
        for (uint32_t k = 0; k < patches_.count(); ++k) {
            const double distance = lod::distanceToBox(eye, patches_.lo[k], patches_.hi[k]);
            while (levels[k] > 0 &&
                   lod::screenPixels(patches_.error[size_t(k) * patches_.levels + levels[k]] + decimation_[k], distance,
                                     fovY, rows) > maxPixels)
                --levels[k];
        }
    // Where the water meets the land, a height error moves the shore by the error over the
    // ground's slope, many pixels on a flat shore: patches the water's surface can cross (its
    // level, give or take the crests) draw every vertex.
    if (inputs.water)
        for (uint32_t k = 0; k < patches_.count(); ++k)
            if (patches_.lo[k].y <= inputs.waterLevel + inputs.waterMargin &&
                patches_.hi[k].y >= inputs.waterLevel - inputs.waterMargin)
                levels[k] = 0;
    // A ring zipped to a coarser neighbour can stray further than either level: such neighbours
    // come finer until every patch's drawn surface is within the pixel, and the figure reported
    // is what each patch's surface leaves out of the drawn grid (plus what the grid leaves out of
    // the DEM), seen from its nearest point.
    std::vector<double> surface, error(patches_.count());
    std::vector<int8_t> detail(patches_.count(), -1);
    // Per patch: the coarsest detail level a detail neighbour's ring asks of it (-1: none asked).
    std::vector<int8_t> finestDetail(patches_.count(), -1);
    std::vector<double> asked(patches_.count(), 0.0);
    for (;;) {
        surface = lod::settleRings(patches_, levels, std::span<const float>(meshVertices_).subspan(1), 6, eye, fovY,
                                   rows, maxPixels, &lodSurfaceCache_);
        // Source resolution: the patches at level 0 whose drawn grid still leaves more than the
        // pixel out of the DEM are drawn from the DEM's vertices, within the detail budget.
        detail.assign(patches_.count(), -1);
        if (detailAllowed)
            chooseDetail(detail, levels, surface, finestDetail, asked, eye, fovY, rows, maxPixels,
                         detailBudgetFor(inputs.detailBudget, rows, s.height > 0 ? double(s.width) / s.height : 1.0));
        // A detail patch's surface, its zipped ring included, against the DEM: measured once per
        // state of the patch and its four sides.
        const uint32_t px = patches_.patchesX(), pz = patches_.patchesZ();
        auto inside = [&](int64_t a, int64_t b) { return a >= 0 && b >= 0 && a < int64_t(px) && b < int64_t(pz); };
        std::vector<uint32_t> measure;
        for (uint32_t k = 0; k < patches_.count(); ++k) {
            error[k] = surface[k] + decimation_[k];
            if (detail[k] < 0) continue;
            const uint32_t i = k % px, j = k / px;
            auto side = [&](int64_t a, int64_t b) -> uint64_t {
                if (!inside(a, b)) return 0xFF;
                const size_t n = size_t(b) * px + size_t(a);
                return detail[n] >= 0 ? 0x80u | uint64_t(detail[n]) : levels[n];
            };
            const uint64_t key = side(i, j) | side(int64_t(i) - 1, j) << 8 | side(i + 1, j) << 16 |
                                 side(i, int64_t(j) - 1) << 24 | side(i, j + 1) << 32;
            auto& cached = detailSurfaceCache_[k];
            if (cached.first != key || std::isnan(cached.second)) {
                cached = {key, std::numeric_limits<double>::quiet_NaN()};
                measure.push_back(k);
            }
        }
        std::vector<double> measured(measure.size());
        tbb::parallel_for(size_t(0), measure.size(), [&](size_t m) {
            measured[m] = lod::detailSurfaceError(patches_, source_, levels, detail, measure[m], hf_.heights());
        });
        for (size_t m = 0; m < measure.size(); ++m) detailSurfaceCache_[measure[m]].second = measured[m];
        // A detail patch's ring zipped to a coarser drawn side can stray past the pixel, as a
        // drawn patch's can: that side comes a level finer (settleRings' rule), and the choice
        // is made again.
        bool finer = false;
        // And a drawn patch whose surface, rings included, with what the grid leaves out, is past
        // the pixel comes finer itself, or where its ring strays, its coarser sides do.
        if (detailAllowed)
            for (uint32_t k = 0; k < patches_.count(); ++k) {
                if (detail[k] >= 0 || levels[k] == 0) continue;
                const double distance = lod::distanceToBox(eye, patches_.lo[k], patches_.hi[k]);
                if (lod::screenPixels(surface[k] + decimation_[k], distance, fovY, rows) <= maxPixels) continue;
                bool sides = false;
                if (surface[k] > patches_.error[size_t(k) * patches_.levels + levels[k]]) {
                    const uint32_t i = k % px, j = k / px;
                    for (const auto& [a, b] :
                         {std::pair<int64_t, int64_t>{int64_t(i) - 1, j}, {i + 1, j}, {i, int64_t(j) - 1}, {i, j + 1}}) {
                        if (!inside(a, b)) continue;
                        const size_t n = size_t(b) * px + size_t(a);
                        if (detail[n] < 0 && levels[n] > levels[k]) --levels[n], sides = true;
                    }
                }
                if (!sides) --levels[k];
                finer = true;
            }
        for (uint32_t k = 0; k < patches_.count(); ++k) {
            if (detail[k] < 0) continue;
            error[k] = detailSurfaceCache_.at(k).second;
            const double pixels = lod::screenPixels(error[k], lod::distanceToBox(eye, patches_.lo[k], patches_.hi[k]), fovY, rows);
            if (error[k] <= detailLevelError(k, uint8_t(detail[k])) || pixels <= maxPixels) continue;
            const uint32_t i = k % px, j = k / px;
            for (const auto& [a, b] : {std::pair<int64_t, int64_t>{int64_t(i) - 1, j}, {i + 1, j}, {i, int64_t(j) - 1}, {i, j + 1}}) {
                if (!inside(a, b)) continue;
                const size_t n = size_t(b) * px + size_t(a);
                // A drawn side comes a level finer; at level 0 it is drawn from the DEM; a coarser
                // detail side comes a detail level finer.
                const int8_t cap = detail[n] < 0 ? int8_t(detailLevels_ - 1) : int8_t(detail[n] - 1);
                if (detail[n] < 0 && levels[n] > 0) {
                    --levels[n], finer = true;
                } else if (detail[n] < 0 || detail[n] > detail[k]) {
                    asked[n] = std::max(asked[n], pixels);
                    if (finestDetail[n] < 0 || finestDetail[n] > cap) finestDetail[n] = cap, finer = true;
                }
            }
        }
        if (!finer) break;
    }
    for (uint32_t k = 0; k < patches_.count(); ++k) {
        worst = std::max(worst, lod::screenPixels(error[k], lod::distanceToBox(eye, patches_.lo[k], patches_.hi[k]), fovY, rows));
    }
    lastLod_.screenErrorPixels = worst;
    if (levels == lastLod_.levels && detail == lastLod_.detail && lodSerial_ > 0) return;
    lastLod_.levels = std::move(levels);
    lastLod_.detail = std::move(detail);
    lodIndices_.clear();
    std::vector<uint32_t> border;
    lod::appendPatchTriangles(lodIndices_, patches_, lastLod_.levels, &border, lastLod_.detail);
    lodMeshIndices_ = lodIndices_.size();
    lod::appendSkirt(lodIndices_, skirt_, border);
    lodSkirtEnd_ = lodIndices_.size();
    // The detail buffer holds what this frame draws; while it does, it stays as it is.
    bool resident = true;
    for (uint32_t k = 0; k < patches_.count(); ++k)
        if (lastLod_.detail[k] >= 0 && (!detailHeld_.count(k) || detailHeld_.at(k) != lastLod_.detail[k])) resident = false;
    if (!resident) {
        std::map<uint32_t, std::vector<float>> kept;
        std::vector<uint32_t> added;
        for (uint32_t k = 0; k < patches_.count(); ++k) {
            if (lastLod_.detail[k] < 0) continue;
            auto old = detailVertices_.find(k);
            if (old != detailVertices_.end() && detailHeld_.at(k) == lastLod_.detail[k]) kept[k] = std::move(old->second);
            else kept[k], added.push_back(k);
        }
        // The DEM's own positions and normals, as the drawn grid's vertices are made, so the
        // vertices the two share are the same.
        // Then, on the DEM's border, the skirt's twins of its border vertices (appendSkirtVertices'
        // reach).
        const float reach = 100.0f * std::max({hf_.maxX() - hf_.minX(), hf_.maxZ() - hf_.minZ(), 1.0f});
        tbb::parallel_for(size_t(0), added.size(), [&](size_t a) {
            const uint32_t k = added[a];
            const uint8_t d = uint8_t(lastLod_.detail[k]);
            const lod::SourceSpan sp = lod::sourceSpan(patches_, source_, k);
            const std::vector<uint32_t> held = lod::detailVertices(patches_, source_, k, d);
            const std::vector<lod::DetailTwin> twins = lod::detailSkirtTwins(patches_, source_, k, d);
            std::vector<float>& v = kept.at(k);
            v.reserve((held.size() + twins.size()) * 6);
            for (uint32_t h : held) {
                const int c = int(sp.c0 + h % sp.nc()), r = int(sp.r0 + h / sp.nc());
                const glm::vec3 p = hf_.vertex(c, r), n = hf_.vertexNormal(c, r);
                v.insert(v.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
            }
            for (const lod::DetailTwin& t : twins) {
                const glm::vec3 p = hf_.vertex(int(t.c), int(t.r)) + glm::vec3(float(t.dx), 0.0f, float(t.dz)) * reach;
                v.insert(v.end(), {p.x, p.y, p.z, 0.0f, 1.0f, 0.0f});
            }
        });
        detailVertices_ = std::move(kept);
        detailHeld_.clear();
        for (const auto& [k, v] : detailVertices_) detailHeld_[k] = lastLod_.detail[k];
        detailBase_.clear();
        uint32_t base = 0;
        for (const auto& [k, v] : detailVertices_) detailBase_[k] = base, base += uint32_t(v.size() / 6);
    }
    lastLod_.detailVertices = 0;
    for (const auto& [k, v] : detailVertices_)
        if (lastLod_.detail[k] >= 0) lastLod_.detailVertices += v.size() / 6;
    {
        // Each detail patch's triangles and skirt, patch by patch in parallel.
        std::vector<uint32_t> drawn;
        for (uint32_t k = 0; k < patches_.count(); ++k)
            if (lastLod_.detail[k] >= 0) drawn.push_back(k);
        std::vector<std::vector<uint32_t>> tris(drawn.size()), skirts(drawn.size());
        tbb::parallel_for(size_t(0), drawn.size(), [&](size_t m) {
            const uint32_t k = drawn[m];
            lod::appendDetailPatch(tris[m], patches_, source_, lastLod_.levels, lastLod_.detail, k, detailBase_.at(k));
            lod::appendDetailSkirt(skirts[m], patches_, source_, lastLod_.detail, k, detailBase_.at(k));
        });
        for (const auto& t : tris) lodIndices_.insert(lodIndices_.end(), t.begin(), t.end());
        lodDetailEnd_ = lodIndices_.size();
        for (const auto& t : skirts) lodIndices_.insert(lodIndices_.end(), t.begin(), t.end());
    }
    lastLod_.triangles = (lodMeshIndices_ + lodDetailEnd_ - lodSkirtEnd_) / 3;
    try {
        buildLodBuffers(!resident);
    } catch (...) {
        // Nothing half made is drawn: the next choice, even of the same levels, builds it all again.
        lastLod_.levels.clear();
        lastLod_.detail.clear();
        detailHeld_.clear();
        throw;
    }
    if (!resident) ++detailSerial_;
    ++lodSerial_;
}

void TerrainRenderer::buildLodBuffers(bool detailChanged) {
    lodIndexCount_ = lodIndices_.size();
    const VkDeviceSize indexBytes = std::max<VkDeviceSize>(lodIndices_.size(), 1) * sizeof(uint32_t);
    lodIndexBuffer_ = vk::Buffer::hostVisible(ctx_, indexBytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    if (!lodIndices_.empty()) lodIndexBuffer_.write(lodIndices_.data(), lodIndices_.size() * sizeof(uint32_t));
    lodIndices_ = {};  // the buffer holds them (16 384²: 150 MB)
    if (!detailChanged) return;
    detailBuffer_ = {};
    detailUpload_.clear();
    size_t floats = 0;
    for (const auto& [k, v] : detailVertices_) floats += v.size();
    if (floats == 0) return;
    // Written here where the device shares the host's memory, so the frame only binds it;
    // elsewhere the copy needs the queue, which is the frame's.
    detailBuffer_ = vk::Buffer::sharedDeviceLocal(
        ctx_, floats * sizeof(float), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (detailBuffer_) {
        VkDeviceSize offset = 0;
        for (const auto& [k, v] : detailVertices_) {
            detailBuffer_.write(v.data(), v.size() * sizeof(float), offset);
            offset += v.size() * sizeof(float);
        }
        return;
    }
    detailUpload_.reserve(floats);
    for (const auto& [k, v] : detailVertices_) detailUpload_.insert(detailUpload_.end(), v.begin(), v.end());
}

void TerrainRenderer::chooseDetail(std::vector<int8_t>& detail, std::span<const uint8_t> levels,
                                   std::span<const double> surface, std::span<const int8_t> finest,
                                   std::span<const double> asked, const glm::vec3& eye, double fovY, double rows,
                                   double maxPixels, size_t budget) {
    // The candidates: patches at level 0 whose drawn grid still leaves more than the pixel out of
    // the DEM, or whose detail neighbour's ring asks a detail level of them (`finest`, with that
    // neighbour's error on screen, `asked`).
    std::vector<uint32_t> wanted;
    std::vector<double> distance;
    for (uint32_t k = 0; k < patches_.count(); ++k) {
        if (levels[k] != 0) continue;
        const double d = lod::distanceToBox(eye, patches_.lo[k], patches_.hi[k]);
        if (finest[k] >= 0 || lod::screenPixels(surface[k] + decimation_[k], d, fovY, rows) > maxPixels)
            wanted.push_back(k), distance.push_back(d);
    }
    if (wanted.empty()) return;
    // Every level's error of every candidate, measured once per patch, in parallel.
    tbb::parallel_for(size_t(0), wanted.size(), [&](size_t m) {
        for (uint8_t dl = 1; dl < detailLevels_; ++dl) detailLevelError(wanted[m], dl);
    });
    // A candidate's states: drawn, then detail levels from the coarsest to 0.
    std::vector<lod::DetailCandidate> candidates(wanted.size());
    tbb::parallel_for(size_t(0), wanted.size(), [&](size_t m) {
        const uint32_t k = wanted[m];
        lod::DetailCandidate& c = candidates[m];
        for (int s = -1; s < int(detailLevels_); ++s) {
            const int8_t d = s < 0 ? int8_t(-1) : int8_t(detailLevels_ - 1 - s);
            double px = lod::screenPixels(d < 0 ? surface[k] + decimation_[k] : detailLevelError(k, uint8_t(d)),
                                          distance[m], fovY, rows);
            if (finest[k] >= 0 && (d < 0 || d > finest[k])) px = std::max(px, asked[k]);
            c.pixels.push_back(px);
            c.vertices.push_back(d < 0 ? 0
                                       : lod::detailVertexCount(patches_, source_, k, uint8_t(d)) +
                                             lod::detailSkirtTwins(patches_, source_, k, uint8_t(d)).size());
        }
        // The coarsest detail level with every finer one within the pixel (chooseLevels' rule),
        // no coarser than a neighbour's ring asks.
        int8_t target = 0;
        for (uint8_t dl = 1; dl < detailLevels_; ++dl) {
            if (lod::screenPixels(detailLevelError(k, dl), distance[m], fovY, rows) > maxPixels) break;
            target = int8_t(dl);
        }
        if (finest[k] >= 0) target = std::min(target, finest[k]);
        c.target = size_t(detailLevels_ - target);
    });
    const std::vector<size_t> state = lod::allocateDetail(candidates, budget, maxPixels);
    for (size_t m = 0; m < wanted.size(); ++m)
        detail[wanted[m]] = state[m] == 0 ? int8_t(-1) : int8_t(detailLevels_ - state[m]);
}

size_t TerrainRenderer::detailBudgetFor(size_t budget, double rows, double aspect) {
    const double scale = std::clamp(rows * rows * aspect / kDetailBudgetPixels, 1.0, kDetailBudgetMaxScale);
    return size_t(double(budget) * scale);
}

TerrainRenderer::LodInputs TerrainRenderer::lodInputsOf(const WaterResources* water) const {
    LodInputs in;
    in.pixelError = lodPixelError_;
    in.detailBudget = detailVertexBudget_;
    in.sourceDetail = sourceDetail_;
    in.water = water != nullptr;
    if (water) in.waterLevel = water->level, in.waterMargin = water->margin;
    return in;
}

void TerrainRenderer::publishLod() {
    DrawnLod& d = drawnLod_;
    d.choice = lastLod_;
    d.picture = lodPicture_;
    d.inputs = lodInputs_;
    if (d.serial != lodSerial_) {
        d.indexBuffer = std::move(lodIndexBuffer_);
        d.indexCount = lodIndexCount_;
        d.meshIndices = lodMeshIndices_;
        d.skirtEnd = lodSkirtEnd_;
        d.detailEnd = lodDetailEnd_;
        d.serial = lodSerial_;
    }
    if (d.detailSerial != detailSerial_) {
        d.detailBuffer = std::move(detailBuffer_);
        d.detailVertices = std::move(detailUpload_);
        detailUpload_.clear();
        d.detailVertexCount = 0;
        for (const auto& [k, v] : detailVertices_) d.detailVertexCount += uint32_t(v.size() / 6);
        d.detailSerial = detailSerial_;
    }
}

void TerrainRenderer::startLevelOfDetail(const RenderSettings& s, const LodKey& key) {
    lodAsked_ = key;
    // Isolated: its parallel loops must not take up the UI thread's tasks, nor it theirs.
    pendingLod_ = std::async(std::launch::async, [this, settings = s, key] {
        const BackgroundThread background;
        tbb::this_task_arena::isolate([&] {
            updateLod(settings, key.rows, key.picture, key.sourceDetail, key.shadowed, key.inputs);
        });
    });
}

bool TerrainRenderer::levelOfDetailReady(const RenderSettings& s) {
    if (s.waitForLevelOfDetail || drawnLod_.serial > 0) return true;
    const Parts p = partsOf(s, findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty)));
    if (!p.sky || p.sunVisibility) return true;  // recordFrame chooses such a frame's levels itself
    if (!pendingLod_.valid()) {
        // The key recordFrame's first frame asks for: no shadow map is drawn yet, so it chooses
        // for its own output rows unless it keeps the window's, and with the shadow casters when
        // it has shadows. Where the frame asks for another key it draws this set and starts its own.
        const uint32_t outputRows = s.height / std::max<uint32_t>(uint32_t(antialiasingOf(s).scale), 1u);
        const bool ownRows = s.levelOfDetailRows == 0 || s.levelOfDetailYields;
        const double rows = double(ownRows ? outputRows : s.levelOfDetailRows);
        startLevelOfDetail(s, LodKey{s.camera.position(), double(s.camera.fovDeg), rows, double(s.sun.direction.y),
                                     true, true, p.shadowed, lodInputsOf(p.water ? gpu_->water.get() : nullptr)});
    }
    return levelOfDetailBuilt();
}

bool TerrainRenderer::levelOfDetailAwaited() const {
    return drawnLod_.serial == 0 && pendingLod_.valid() && !levelOfDetailBuilt();
}

bool TerrainRenderer::levelOfDetailBuilt() const {
    return pendingLod_.valid() && pendingLod_.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
}

double TerrainRenderer::detailLevelError(uint32_t k, uint8_t d) {
    std::vector<double>& e = detailLevelErrors_[k];
    if (e.empty()) {
        e.assign(detailLevels_, std::numeric_limits<double>::quiet_NaN());
        e[0] = 0.0;
    }
    if (std::isnan(e[d])) e[d] = lod::detailLevelError(patches_, source_, k, d, hf_.heights());
    return e[d];
}

void TerrainRenderer::releaseRetired(bool idle) {
    // An offscreen frame still drawing may read what was retired after it was recorded.
    if (!idle && offscreen_ && !offscreen_->read && !offscreen_->submission.done()) return;
    std::erase_if(retired_, [&](const Retired& r) { return idle || r.releaseAt <= framesBegun_; });
}

TerrainRenderer::~TerrainRenderer() {
    // A sweep or a choice of levels under way reads the heightfield.
    if (pendingHorizon_) pendingHorizon_->perVertex.wait();
    if (pendingLod_.valid()) pendingLod_.wait();
    // Frames in flight may still read what is about to be destroyed.
    if (gpu_) ctx_.waitIdle();
}

bool TerrainRenderer::hasProbeResources() const { return gpu_->probes != nullptr; }

const std::vector<PassInfo>& TerrainRenderer::lastFramePasses() const { return gpu_->graph.lastFrame(); }

void TerrainRenderer::setProbeVolumes(const std::vector<GpuProbeVolume>& volumes) {
    RendererGpu& g = *gpu_;
    for (const char* name : {kProbeCoefficients, kProbeCells, kProbeVolumes, kProbeErrorMaps, kProbeLight, kDetailLight})
        g.graph.forget(name);
    if (g.probes) retire(std::move(g.probes));
    volumeCount_ = 0;
    anyErrorMap_ = false;
    probeBytes_ = 0;
    finestProbeSpacing_ = 0.0f;
    if (volumes.empty()) return;
    for (const auto& v : volumes)
        finestProbeSpacing_ = finestProbeSpacing_ > 0.0f ? std::min(finestProbeSpacing_, v.spacing) : v.spacing;

    g.probes = features::buildProbes(ctx_, g, uint32_t(vertexCount_), volumes);
    volumeCount_ = g.probes->volumeCount;
    anyErrorMap_ = g.probes->anyErrorMap;
    probeBytes_ = g.probes->bytes;
}

void TerrainRenderer::setProbePositions(const std::vector<glm::vec4>& positions) {
    gpu_->graph.forget(kMarkers);
    markerCount_ = uint32_t(positions.size());
    if (gpu_->markers) retire(std::move(gpu_->markers));
    if (positions.empty()) return;
    gpu_->markers = vk::Buffer::deviceLocal(ctx_, positions.data(), positions.size() * sizeof(glm::vec4),
                                            VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    gpu_->graph.importBuffer(kMarkers, gpu_->markers.handle(), true);
}

void TerrainRenderer::setProbeLeaves(const std::vector<glm::vec4>& leaves) {
    gpu_->graph.forget(kLeaves);
    leafCount_ = uint32_t(leaves.size());
    smallestLeaf_ = 1.0f;
    if (gpu_->leaves) retire(std::move(gpu_->leaves));
    if (leaves.empty()) return;
    smallestLeaf_ = leaves.front().w;
    for (const auto& l : leaves) smallestLeaf_ = std::min(smallestLeaf_, l.w);
    gpu_->leaves = vk::Buffer::deviceLocal(ctx_, leaves.data(), leaves.size() * sizeof(glm::vec4),
                                           VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    gpu_->graph.importBuffer(kLeaves, gpu_->leaves.handle(), true);
}

namespace {

// Whether `t` serves a frame of that size and plan. A view without the pass keeps the output image
// it does not use: switching between a picture and a data view allocates nothing, except with
// msaa, whose multisampled target a data view (one sample) cannot draw in; it takes a
// single-sampled one, kept as a spare beside it.
bool serves(const RenderTarget* t, uint32_t width, uint32_t height, const features::AntialiasingPlan& plan) {
    return t && t->width == width && t->height == height && t->scale == plan.scale && t->samples == plan.samples &&
           (t->source || !plan.pass) && (t->output.handle() || !plan.resolve);
}

void importTarget(FrameGraph& graph, const RenderTarget& t) {
    graph.importImage(kColor, t.color.handle(), t.color.aspect());
    graph.importImage(kDepth, t.depth.handle(), t.depth.aspect());
    graph.importBuffer(kReadback, t.readback.buffer());
    if (t.output.handle()) graph.importImage(kOutput, t.output.handle(), t.output.aspect());
}

}  // namespace

void TerrainRenderer::ensureMultisampledPasses(uint32_t samples) {
    RendererGpu& g = *gpu_;
    if (samples <= 1 || g.multisampledPasses.count(samples)) return;
    const VkFormat colorFormats[] = {vk::kColorFormat};
    vk::RenderPassDesc clear{colorFormats, vk::kDepthFormat, true, true};
    clear.samples = samples;
    vk::RenderPassDesc draw = clear;
    draw.clear = false;
    g.multisampledPasses.emplace(samples, std::make_pair(vk::RenderPass(ctx_, clear), vk::RenderPass(ctx_, draw)));
}

void TerrainRenderer::ensureTarget(uint32_t width, uint32_t height, const features::AntialiasingPlan& plan) {
    RendererGpu& g = *gpu_;
    if (serves(g.target.get(), width, height, plan)) return;
    constexpr const char* kTargetNames[] = {kColor, kDepth, kReadback, kOutput};
    for (const char* name : kTargetNames) g.graph.park(name);
    if (takeSpare(g.target, g.spareTargets, [&](const RenderTarget* t) { return serves(t, width, height, plan); })) {
        // Back to a target drawn lately: the graph resumes each image where it was left, so the
        // barriers still order this frame after the frames in flight that used it.
        importTarget(g.graph, *g.target);
        return;
    }
    // A size not drawn lately. Only when the spares are full does a target go, and frames in
    // flight may still draw into it: then wait. A new one beside them waits for nothing: the
    // graph has parked the current target's state and starts the new images afresh.
    const bool evicts = g.spareTargets.size() + (g.target ? 1 : 0) > kSpareTargets;
    if (evicts) {
        ctx_.waitIdle();
        readOffscreen();  // before its target may go
        for (const char* name : kTargetNames) g.graph.forget(name);
    }
    ++g.targetAllocations;
    const uint32_t drawnWidth = width * plan.scale, drawnHeight = height * plan.scale;
    const uint32_t samples = plan.samples;
    ensureMultisampledPasses(samples);
    auto t = std::make_unique<RenderTarget>(RenderTarget{
        samples > 1 ? vk::Image::multisampledTarget(ctx_, drawnWidth, drawnHeight, samples, vk::kColorFormat)
                    : vk::Image::colorTarget(ctx_, drawnWidth, drawnHeight),
        samples > 1 ? vk::Image::multisampledTarget(ctx_, drawnWidth, drawnHeight, samples, vk::kDepthFormat)
                    : vk::Image::depthTarget(ctx_, drawnWidth, drawnHeight),
        {}, vk::Readback(ctx_, width, height)});
    t->width = width;
    t->height = height;
    t->scale = plan.scale;
    t->samples = samples;
    const VkImageView views[] = {t->color.view(), t->depth.view()};
    t->framebuffer = vk::Framebuffer(ctx_, g.clearPassFor(samples), views, drawnWidth, drawnHeight);
    if (plan.pass) features::buildAntialiasingTarget(ctx_, g, *t);
    if (plan.resolve) features::buildResolveTarget(ctx_, *t);
    replaceTarget(g.target, g.spareTargets, std::move(t));
    // After a wait the spares' handles start afresh too (the graph forgot them; nothing is in
    // flight now).
    if (evicts)
        for (const auto& spare : g.spareTargets) {
            importTarget(g.graph, *spare);
            for (const char* name : kTargetNames) g.graph.park(name);
        }
    importTarget(g.graph, *g.target);
}

features::AntialiasingPlan TerrainRenderer::antialiasingOf(const RenderSettings& s) const {
    return features::antialiasingPlan(s.antialiasing,
                                      findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty)),
                                      ctx_.framebufferSampleCounts());
}

// The settings the passes draw with: the output's size times the anti-aliasing's samples a side.
const RenderSettings& TerrainRenderer::drawnSettings(const RenderSettings& s, const features::AntialiasingPlan& plan,
                                                     RenderSettings& scaled) {
    if (plan.scale == 1) return s;
    scaled = s;
    // The level of detail keeps to the output's pixels.
    if (scaled.levelOfDetailRows == 0) scaled.levelOfDetailRows = s.height;
    scaled.width *= plan.scale;
    scaled.height *= plan.scale;
    return scaled;
}

RenderedImage TerrainRenderer::render(const RenderSettings& s) {
    const auto start = std::chrono::steady_clock::now();
    Output out;
    out.antialiasing = antialiasingOf(s);
    drawnAntialiasing_ = out.antialiasing.mode;
    ensureTarget(s.width, s.height, out.antialiasing);
    RenderSettings scaled;
    const RenderSettings& drawn = drawnSettings(s, out.antialiasing, scaled);
    // The synchronous path: whatever the viewport queued finishes first, then slot 0 is free
    // (and an offscreen frame's read-back is read before this frame may overwrite it).
    ctx_.waitIdle();
    readOffscreen();
    releaseRetired(true);
    ctx_.submitAndWait([&](VkCommandBuffer cb) { recordFrame(cb, 0, drawn, out); });
    gpu_->slots[0].width = s.width;
    gpu_->slots[0].height = s.height;
    readFrameTimings(0);
    RenderedImage img;
    img.width = s.width;
    img.height = s.height;
    const auto readback = std::chrono::steady_clock::now();
    if (s.readbackBytes)
        img.bytes = gpu_->target->readback.bytes();
    else
        img.rgba = gpu_->target->readback.pixels();
    const auto end = std::chrono::steady_clock::now();
    timings_.readbackMilliseconds = std::chrono::duration<double, std::milli>(end - readback).count();
    img.milliseconds = std::chrono::duration<double, std::milli>(end - start).count();
    return img;
}

bool TerrainRenderer::beginOffscreen(const RenderSettings& s) {
    if (offscreen_) return false;
    Offscreen o;
    o.start = std::chrono::steady_clock::now();
    Output out;
    out.antialiasing = antialiasingOf(s);
    ensureTarget(s.width, s.height, out.antialiasing);
    RenderSettings scaled;
    const RenderSettings& drawn = drawnSettings(s, out.antialiasing, scaled);
    o.target = gpu_->target.get();
    o.image.width = s.width;
    o.image.height = s.height;
    // Its slot's last frame was read (takeOffscreen) before this one could begin: it is free.
    o.submission = ctx_.submit([&](VkCommandBuffer cb) { recordFrame(cb, kOffscreenSlot, drawn, out); });
    gpu_->slots[kOffscreenSlot].width = s.width;
    gpu_->slots[kOffscreenSlot].height = s.height;
    offscreen_ = std::move(o);
    return true;
}

void TerrainRenderer::readOffscreen() {
    if (!offscreen_ || offscreen_->read || !offscreen_->submission.done()) return;
    offscreen_->image.rgba = offscreen_->target->readback.pixels();
    offscreen_->image.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - offscreen_->start).count();
    offscreen_->read = true;
    offscreen_->submission = vk::Submission();
}

std::optional<RenderedImage> TerrainRenderer::takeOffscreen() {
    readOffscreen();
    if (!offscreen_ || !offscreen_->read) return std::nullopt;
    RenderedImage image = std::move(offscreen_->image);
    offscreen_.reset();
    return image;
}

void TerrainRenderer::readFrameTimings(uint32_t slotIndex) {
    FrameSlot& slot = gpu_->slots[slotIndex];
    timings_ = FrameTimings{};
    timings_.recordMilliseconds = slot.recordMilliseconds;
    timings_.width = slot.width;
    timings_.height = slot.height;
    const uint32_t n = slot.timestampsWritten;
    slot.timestampsWritten = 0;
    if (n < 2) return;
    // The slot's fence has passed: the frame's copy of its timestamps is there.
    std::vector<uint64_t> ticks(n);
    std::memcpy(ticks.data(), slot.timestampResults.map(), n * sizeof(uint64_t));
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
    Output out;
    out.antialiasing = antialiasingOf(s);
    drawnAntialiasing_ = out.antialiasing.mode;
    ensureTarget(s.width, s.height, out.antialiasing);
    const std::optional<vk::SwapchainFrame> frame = swapchain.begin();
    if (!frame) return false;
    ++framesBegun_;
    releaseRetired(false);
    out.readback = false;
    out.swapchainImage = frame->image;
    out.extent = frame->extent;
    // begin() waited for this slot's fence: the frame drawn in it before is done.
    readFrameTimings(frame->slot);
    RenderSettings scaled;
    recordFrame(frame->cb, frame->slot, drawnSettings(s, out.antialiasing, scaled), out);
    gpu_->slots[frame->slot].width = s.width;
    gpu_->slots[frame->slot].height = s.height;
    swapchain.submit(*frame);
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
    surfaceIn.borderHeight = borderHeight_;
    if (skyImageHeight_ > 0) {
        // The level whose texels span what a pixel spans: π / height radians a texel against
        // the vertical field of view over the pixels drawn.
        const double pixel = glm::radians(double(s.camera.fovDeg)) / (double(std::max(1u, f.height)) * g.target->scale);
        surfaceIn.skyImageLod = float(std::max(0.0, std::log2(pixel / (std::numbers::pi / skyImageHeight_))));
        surfaceIn.skyImage = true;
    }
    if (hasAlbedoMap_) surfaceIn.borderAlbedo = borderAlbedo_;
    const blocks::SurfaceBlock surface = features::packSurface(s, surfaceIn);
    slot.surface.write(&surface, sizeof surface);
    const blocks::SunSkyBlock sunSky = features::packSunSky(s);
    slot.sunSky.write(&sunSky, sizeof sunSky);
    const blocks::AtmosphereBlock atmosphere = features::packAtmosphere(s.fog);
    slot.atmosphere.write(&atmosphere, sizeof atmosphere);
    if (f.shadows) {
        const bool horizon = f.horizonFrom < int(cascades_.size());
        const blocks::ShadowBlock block = features::packShadows(s, cascades_, f.cascadeRange, f.shadows->resolution,
                                                                f.horizonFrom, horizon ? horizonMap_ : HorizonMapInfo{});
        slot.shadow.write(&block, sizeof block);
        if (horizon && slot.sunHorizonSerial != sunHorizonSerial_) {
            slot.sunHorizon.write(sunHorizonBytes_.data(), sunHorizonBytes_.size() * sizeof(uint32_t));
            slot.sunHorizonSerial = sunHorizonSerial_;
        }
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
            features::packMirroredCamera(s, camera, extent, f.water->level, float(f.water->targets->reflectionWidth),
                                         float(f.water->targets->reflectionHeight));
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
    if (f.drawGizmos) {
        if (slot.gizmoCapacity < s.gizmos.size()) {
            slot.gizmos = vk::Buffer::hostVisible(ctx_, s.gizmos.size() * sizeof(features::GizmoInstance),
                                                  VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
            slot.gizmoCapacity = s.gizmos.size();
        }
        const std::vector<features::GizmoInstance> lines = features::packGizmos(s.gizmos);
        slot.gizmos.write(lines.data(), lines.size() * sizeof(lines[0]));
    }
    if (f.drawMarkers || f.drawReflectionMarkers || f.drawLeaves) {
        const blocks::OverlayBlock overlay =
            features::packOverlay(s, smallestLeaf_, kSmallestLeafPixels, float(g.target->scale));
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

TerrainRenderer::Parts TerrainRenderer::partsOf(const RenderSettings& s, const DebugView& view) const {
    const RendererGpu& g = *gpu_;
    Parts p;
    // Probes: volumes bound, probes on and the view reads their light. Reflection probes: a set
    // bound, probes on and the view reads the environment's specular (the strength does not decide
    // it: it is a live uniform, and a weight of 0 leaves the sky's specular as it is). The LPV:
    // volumes bound and either the view lights with them and lighting.indirect asks for them, or
    // the view shows them; the local lights in the lit views whenever the scene has some; either
    // binds the terrain's LPV set.
    p.probes = g.probes && s.probes && (view.needs.probeLight || view.needs.probeDiagnostics);
    p.reflections = g.reflections && s.probes && view.needs.reflectionProbes;
    p.lpvVolumes = g.lpv && ((s.lpvLight && view.needs.sceneLights) || view.needs.lpvVolumes);
    p.localLights = !s.lights.empty() && view.needs.sceneLights;
    p.sunVisibility = view.needs.sunVisibility;
    p.sky = view.needs.sky;
    // Shadows: the scene has them on, the sun is up and the view draws them: a lit view only for a
    // sun that gives light (an image sky without a glow, a sun at 0 lx), the shadow views for any.
    const bool sunLights = std::max({s.sun.illuminance.x, s.sun.illuminance.y, s.sun.illuminance.z}) > 0.0f;
    p.shadowed = s.shadows.enabled && view.needs.shadows && s.sun.direction.y > -0.05f &&
                 (sunLights || view.needs.showsShadows);
    // Water: the scene has it and the view draws it; the reflection and the copy of the frame
    // under it only where the view shades it, the reflection only when planar.
    p.water = s.water.enabled && view.needs.water && g.water;
    p.waterShading = p.water && view.needs.waterShading;
    p.planarReflection = p.waterShading && s.water.reflection == WaterReflection::Planar;
    return p;
}

bool TerrainRenderer::pipelinesReady(const RenderSettings& s) {
    RendererGpu& g = *gpu_;
    const Parts p = partsOf(s, findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty)));
    const uint32_t samples = antialiasingOf(s).samples;
    ensureMultisampledPasses(samples);
    const int terrain = features::terrainVariant(p.probes || p.sunVisibility, p.shadowed, s.fog.enabled,
                                                 p.reflections, p.lpvVolumes, p.localLights);
    // Each missing one starts now, beside the others.
    auto terrainAt = [&](uint32_t n) {
        return g.terrain.ready(terrain | kSamplesKey(n),
                               [&] { return features::terrainPipelineBuild(ctx_, g, terrain, n); });
    };
    bool ready = terrainAt(samples);
    if (p.planarReflection) ready = terrainAt(1) && ready;
    // The sky behind the frame and in the water's reflection.
    const int sky = features::skyVariant(s.fog.enabled);
    auto skyAt = [&](uint32_t n) {
        return g.sky.ready(sky | kSamplesKey(n), [&] { return features::skyPipelineBuild(ctx_, g, sky, n); });
    };
    if (p.sky) ready = skyAt(samples) && ready;
    if (p.planarReflection) ready = skyAt(1) && ready;
    if (p.probes) ready = g.probePass.ready(0, [&] { return features::probePassBuild(ctx_, g, *g.probes); }) && ready;
    if (p.water) {
        const int water = features::waterVariant(p.shadowed, s.fog.enabled, p.reflections);
        ready = g.waterPipelines.ready(water | kSamplesKey(samples),
                                       [&] { return features::waterPipelineBuild(ctx_, g, water, samples); }) &&
                ready;
    }
    return ready;
}

bool TerrainRenderer::workersFinished() const {
    return !pipelinesBuilding() && (!sunHorizonSweeping() || sunHorizonSwept()) &&
           (!levelOfDetailBuilding() || levelOfDetailBuilt());
}

bool TerrainRenderer::pipelinesBuilding() const {
    return gpu_->terrain.building() || gpu_->waterPipelines.building() || gpu_->sky.building() ||
           gpu_->probePass.building();
}

size_t TerrainRenderer::pipelinesBuiltInline() const {
    return gpu_->terrain.builtHere() + gpu_->waterPipelines.builtHere() + gpu_->sky.builtHere() +
           gpu_->probePass.builtHere();
}

size_t TerrainRenderer::pipelinesBuiltOnWorkers() const {
    return gpu_->terrain.builtOnWorkers() + gpu_->waterPipelines.builtOnWorkers() + gpu_->sky.builtOnWorkers() +
           gpu_->probePass.builtOnWorkers();
}

void TerrainRenderer::recordFrame(VkCommandBuffer cb, uint32_t slotIndex, const RenderSettings& s,
                                  const Output& out) {
    const auto recordStart = std::chrono::steady_clock::now();
    RendererGpu& g = *gpu_;
    Frame f{ctx_, g, g.slots[slotIndex], slotIndex, s,
            findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty))};
    const DebugView& view = f.view;
    // Who takes part (partsOf).
    const Parts parts = partsOf(s, view);
    f.probes = parts.probes ? g.probes.get() : nullptr;
    f.reflections = parts.reflections ? g.reflections.get() : nullptr;
    f.lpvVolumes = parts.lpvVolumes ? g.lpv.get() : nullptr;
    f.localLights = parts.localLights;
    f.lpvSet = f.lpvVolumes || f.localLights;
    f.drawMarkers = (s.showProbePositions || view.needs.probeMarkers) && markerCount_ > 0;
    f.drawReflectionMarkers = s.showProbePositions && g.reflections && g.reflections->markerCount > 0;
    f.drawLeaves = s.showLeaves && leafCount_ > 0;
    f.drawGizmos = !s.gizmos.empty();
    f.gizmoCount = uint32_t(s.gizmos.size());
    f.fog = s.fog.enabled;
    f.sunVisibility = parts.sunVisibility;
    f.sky = parts.sky;
    if (f.sunVisibility) updateSunVisibility(s.sun, s.skirt);
    // A scene without shadows holds no maps.
    const bool shadowed = parts.shadowed;
    if (!s.shadows.enabled) ensureShadowMaps(0, 0);
    if (shadowed) ensureShadowMaps(s.shadows.mapResolution, std::clamp(s.shadows.cascades, 1, 4));
    f.shadows = shadowed ? g.shadows.get() : nullptr;
    if (shadowed && s.shadows.heightfield) updateSunHorizon(s.sun, s.skirt, s.waitForHorizon);
    else dropSweptHorizon();
    f.water = parts.water ? g.water.get() : nullptr;
    f.waterShading = parts.waterShading;
    f.planarReflection = parts.planarReflection;
    if (f.water) ensureWaterTargets(s.width, s.height, float(s.water.reflectionScale));
    f.vertexCount = uint32_t(vertexCount_);
    // The cascades, fitted to this frame's view. The ones the horizon map stands in for are read
    // by the water alone: without it the shadow pass leaves them undrawn, and where it draws none
    // no caster's height error moves a shadow.
    if (f.shadows) {
        const float aspect = float(s.width) / float(s.height);
        const glm::vec3 boundsMin(hf_.minX(), hf_.minHeight(), hf_.minZ()), boundsMax(hf_.maxX(), hf_.maxHeight(), hf_.maxZ());
        f.cascadeRange = cascadeRange(s.shadows, s.camera, aspect, boundsMin, boundsMax);
        cascades_ = fitCascades(f.cascadeRange, s.camera, aspect, s.sun.direction, f.shadows->resolution, boundsMin, boundsMax);
        f.horizonFrom = s.shadows.heightfield ? horizonFirstCascade(cascades_, s.sun.direction.y, horizonMap_)
                                              : int(cascades_.size());
        const int drawn = f.waterShading ? int(cascades_.size()) : f.horizonFrom;
        for (int i = 0; i < drawn; ++i) f.lightMatrices.push_back(cascades_[size_t(i)].lightViewProj);
    }
    // The level of detail's triangles, in this slot's index buffer (its last frame is done).
    // A viewport frame below full resolution (RenderSettings::levelOfDetailYields) draws the levels
    // the shadow maps hold while its cascades stand, and its own where they moved or where it
    // draws no maps (nothing to keep).
    const bool redrawsShadows =
        !f.lightMatrices.empty() && (f.shadows->drawn != f.lightMatrices || f.shadows->drawnSkirt != s.skirt);
    const bool yields = s.levelOfDetailYields && s.levelOfDetailRows > 0;
    const LodInputs lodInputs = lodInputsOf(f.water);
    const bool keepLevels = yields && view.needs.sky && drawnLod_.picture && drawnLod_.inputs == lodInputs &&
                            !f.lightMatrices.empty() && !redrawsShadows && drawnLod_.serial > 0 &&
                            f.shadows->drawnLod == drawnLod_.serial;
    // The output's rows, not the supersampled target's.
    const uint32_t outputRows = s.height / std::max<uint32_t>(uint32_t(out.antialiasing.scale), 1u);
    const bool ownRows = s.levelOfDetailRows == 0 || (yields && (redrawsShadows || f.lightMatrices.empty()));
    const double rows = double(ownRows ? outputRows : s.levelOfDetailRows);
    // Detail patches where the per-vertex attribute is none or the probe light (the probe pass
    // lights their vertices too), not the traced sun visibility.
    const bool sourceDetail = !f.sunVisibility;
    const bool anyDetail =
        std::any_of(drawnLod_.choice.detail.begin(), drawnLod_.choice.detail.end(), [](int8_t d) { return d >= 0; });
    if (!keepLevels || (!sourceDetail && anyDetail)) {
        const bool picture = view.needs.sky, shadowed = !f.lightMatrices.empty();
        const LodKey key{s.camera.position(), double(s.camera.fovDeg), rows, double(s.sun.direction.y),
                         picture, sourceDetail, shadowed, lodInputs};
        // A viewport picture chooses its levels on a worker once a set is held (the first close
        // view of a 16 384² DEM takes 0.6 s to choose and build) and draws the held set until the
        // new one lands; every other frame waits for one under way and chooses its own here.
        // A frame that holds none takes the first set started for it (levelOfDetailReady),
        // waiting for it if it has not landed.
        const bool onWorker =
            !s.waitForLevelOfDetail && picture && sourceDetail && (drawnLod_.serial > 0 || pendingLod_.valid());
        if (pendingLod_.valid() && (!onWorker || drawnLod_.serial == 0 || levelOfDetailBuilt())) {
            try {
                pendingLod_.get();
            } catch (...) {
                lodAsked_.reset();  // the same camera asks again
                throw;
            }
            publishLod();
        }
        if (!onWorker) {
            updateLod(s, rows, picture, sourceDetail, shadowed, lodInputs);
            publishLod();
            lodAsked_ = key;
        } else if (!pendingLod_.valid() && lodAsked_ != key) {
            startLevelOfDetail(s, key);
        }
    }
    if (g.detailSerial != drawnLod_.detailSerial) {
        g.graph.forget(kDetailVertices);
        if (g.detailVertices) retire(std::move(g.detailVertices));
        g.detailVertices = {};
        g.detailVertexCount = drawnLod_.detailVertexCount;
        if (drawnLod_.detailBuffer)
            g.detailVertices = std::move(drawnLod_.detailBuffer);
        else if (!drawnLod_.detailVertices.empty())
            g.detailVertices = vk::Buffer::deviceLocal(ctx_, drawnLod_.detailVertices.data(),
                                                       drawnLod_.detailVertices.size() * sizeof(float),
                                                       VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
        if (g.detailVertices) g.graph.importBuffer(kDetailVertices, g.detailVertices.handle(), true);
        drawnLod_.detailVertices = {};
        g.detailSerial = drawnLod_.detailSerial;
    }
    if (g.probes && g.detailVertexCount > 0 && (!g.probes->detail || g.probes->detail->serial != g.detailSerial)) {
        g.graph.forget(kDetailLight);
        if (g.probes->detail) retire(std::move(g.probes->detail));
        g.probes->detail = features::buildDetailLight(ctx_, g, *g.probes);
    }
    if (g.terrainIndicesSerial != drawnLod_.serial) {
        g.graph.forget(kIndices);
        if (g.terrainIndices) retire(std::move(g.terrainIndices));
        g.terrainIndices = std::move(drawnLod_.indexBuffer);
        g.terrainIndicesSerial = drawnLod_.serial;
    }
    g.graph.park(kIndices);
    g.graph.importBuffer(kIndices, g.terrainIndices.handle());
    f.indexBuffer = g.terrainIndices.handle();
    f.lodSerial = drawnLod_.serial;
    f.indexCount = uint32_t(drawnLod_.meshIndices);
    f.skirtIndexCount = s.skirt ? uint32_t(drawnLod_.skirtEnd - drawnLod_.meshIndices) : 0;
    f.detailFirstIndex = uint32_t(drawnLod_.skirtEnd);
    f.detailIndexCount = uint32_t(drawnLod_.detailEnd - drawnLod_.skirtEnd);
    f.detailSkirtIndexCount = s.skirt ? uint32_t(drawnLod_.indexCount - drawnLod_.detailEnd) : 0;
    f.markerCount = markerCount_;
    f.leafCount = leafCount_;
    f.width = s.width;
    f.height = s.height;
    f.framebuffer = g.target->framebuffer.handle();
    f.samples = g.target->samples;
    writeBlocks(f);

    // The passes, in order; a feature that does not take part adds none.
    g.graph.beginFrame();
    features::addProbePass(f);
    features::addLpvPropagationPass(f);
    features::addShadowPass(f);
    features::addTerrainPass(f);
    features::addSkyPass(f);
    features::addWaterPasses(f);
    features::addOverlayPass(f);
    features::addAntialiasPass(f, out.antialiasing);
    features::addResolvePass(f, out.antialiasing);
    // What leaves the frame: the anti-aliased output where a pass or a resolve wrote it, else the colour.
    RenderTarget& t = *g.target;
    const bool toOutput = out.antialiasing.pass || out.antialiasing.resolve;
    const char* final = toOutput ? kOutput : kColor;
    const VkImage source = toOutput ? t.output.handle() : t.color.handle();
    if (out.readback) {
        g.graph.addPass({"readback", {{final, Access::TransferRead}, {kReadback, Access::TransferWrite}}, {}},
                        [&t, source](VkCommandBuffer c) { t.readback.recordCopy(c, source); });
        g.graph.addFinalUse({kReadback, Access::HostRead});
    } else {
        g.graph.importImage(kSwapchain, out.swapchainImage, VK_IMAGE_ASPECT_COLOR_BIT, 1,
                            VK_PIPELINE_STAGE_TRANSFER_BIT);
        const VkImage dest = out.swapchainImage;
        const VkExtent2D dstExtent = out.extent;
        const uint32_t w = t.width, h = t.height;
        g.graph.addPass({"present", {{final, Access::TransferRead}, {kSwapchain, Access::TransferWrite}}, {}},
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
    // Textures set since the last frame: their levels go in before anything reads them.
    for (vk::StagedTexture& t : pendingTextures_) {
        t.record(cb);
        retire(std::move(t.staging));
    }
    pendingTextures_.clear();
    FrameSlot& slot = f.slot;
    slot.timestampsWritten = g.graph.execute(cb, slot.timestamps.get(), slot.timestamps ? kFrameTimestamps : 0);
    if (slot.timestampsWritten > 0) {
        // The frame copies its own timestamps into memory the host reads once the slot's fence
        // has passed: asking the query pool instead waits, on some drivers (lavapipe), for every
        // frame submitted since, the meter's included.
        vkCmdCopyQueryPoolResults(cb, slot.timestamps.get(), 0, slot.timestampsWritten, slot.timestampResults.handle(), 0,
                                  sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
        VkBufferMemoryBarrier toHost{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
        toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        toHost.srcQueueFamilyIndex = toHost.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        toHost.buffer = slot.timestampResults.handle();
        toHost.size = VK_WHOLE_SIZE;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1, &toHost, 0,
                             nullptr);
    }
    slot.timedPasses.clear();
    for (const PassInfo& p : g.graph.lastFrame()) slot.timedPasses.push_back(p.name);
    if (f.probes) {
        f.probes->lightStale = false;
        if (f.probes->detail) f.probes->detail->stale = false;
    }
    slot.recordMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - recordStart).count();
}

}  // namespace terralux
