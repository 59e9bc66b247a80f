#include "render/TerrainRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>

#include <glm/gtc/packing.hpp>
#include <glm/mat4x4.hpp>
#include <tbb/parallel_for.h>

#include "ShaderBinaries.h"
#include "bake/DiffuseBake.h"
#include "bake/SphereSampling.h"
#include "render/DebugViews.h"
#include "render/UniformBlocks.h"
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

namespace {

// Frame-graph resource names.
const char* const kColor = "color";
const char* const kDepth = "depth";
const char* const kReadback = "readback";
const char* const kSwapchain = "swapchain";
const char* const kVertices = "terrain-vertices";
const char* const kIndices = "terrain-indices";
const char* const kMarkers = "markers";
const char* const kLeaves = "leaves";
const char* const kProbeCoefficients = "probe-coefficients";
const char* const kProbeCells = "probe-cells";
const char* const kProbeVolumes = "probe-volumes";
const char* const kProbeErrorMaps = "probe-error-maps";
const char* const kProbeLight = "probe-light";
const char* const kShadowMaps = "shadow-maps";
const char* const kSunVisibility = "sun-visibility";

// Shadow rays per vertex of the sun-visibility view, stratified over the sun's disc.
constexpr int kSunVisibilitySamples = 16;

// Smallest octree leaf the leaf overlay draws, in pixels on screen.
constexpr float kSmallestLeafPixels = 6.0f;

constexpr VkShaderStageFlags kVertexFragment = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

const char* const kSurfaceNormalAo = "surface-normal-ao";
const char* const kSurfaceAlbedo = "surface-albedo";
const char* const kSurfaceFilled = "surface-filled";

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

}  // namespace

// The probe subsystem: present only while volumes are bound.
struct ProbeResources {
    vk::Buffer block, coeffs, cells, volumes, errors, light;
    vk::DescriptorSet set;
    bool lightStale = true;  // the probe pass has not run since the volumes changed
};

// What one frame in flight writes from the host: its uniform blocks and the sets that bind them.
// `shadowedLights` adds the cascades to `lights`; it exists while the shadow maps do.
struct FrameSlot {
    vk::Buffer camera, surface, sunSky, atmosphere, shadow, overlay;
    vk::DescriptorSet view, lights, shadowedLights, overlays;
};

// The shadow subsystem: the cascades' depth maps (one layer each) and a framebuffer per layer.
struct ShadowResources {
    vk::Image maps;
    std::vector<vk::Framebuffer> framebuffers;
    int resolution = 0, cascades = 0;
    std::vector<glm::mat4> drawn;  // the light projections the maps hold now (empty: none yet)
};

struct RenderTarget {
    vk::Image color, depth;
    vk::Framebuffer framebuffer;
    vk::Readback readback;
};

// The surface maps the view set binds (SurfaceMaps.h), always present: a terrain without AO or
// an albedo map binds neutral ones.
struct SurfaceTextures {
    vk::Image normalAo, albedo, filled;
};

struct TerrainRenderer::Gpu {
    vk::Buffer vertices, indices, markers, leaves;
    SurfaceTextures surface;
    vk::Sampler trilinear;
    vk::UniqueSetLayout viewLayout;
    std::unique_ptr<ProbeResources> probes;
    std::unique_ptr<ShadowResources> shadows;
    // The sun-visibility view's per-vertex attribute (stride 32, like the probe light), and the
    // sun and surface it was traced for.
    vk::Buffer sunVisibility;
    glm::vec4 sunVisibilityKey{0.0f};
    int sunVisibilitySkirt = -1;
    std::unique_ptr<HeightfieldTracer> tracer;
    bool tracerSkirt = true;
    std::vector<FrameSlot> slots;
    std::unique_ptr<RenderTarget> target;
    vk::RenderPass clearPass, drawPass, shadowPass;
    vk::Sampler compareSampler, depthSampler;
    vk::UniqueSetLayout emptySet, shadowedLightsLayout;
    vk::PipelineLayout terrainLayout, shadowedTerrainLayout, overlayLayout, probeLayout, shadowDepthLayout;
    // Built on first use: lavapipe compiles a pipeline when it is created. Terrain pipelines by
    // variant: kProbeLightVariant | kShadowVariant | kFogVariant.
    std::map<int, vk::UniquePipeline> terrain;
    vk::UniquePipeline skyPlain, skyFog, shadowDepth, markerPipeline, leafPipeline, probePass;
    FrameGraph graph;
};

struct TerrainRenderer::Output {
    bool readback = true;
    VkImage swapchainImage = VK_NULL_HANDLE;
    VkExtent2D extent{0, 0};
};

namespace {

constexpr int kProbeLightVariant = 1, kShadowVariant = 2, kFogVariant = 4;

// The lights set with the shadow cascades: sun and sky, atmosphere, the cascades' block and their
// maps (compared, and raw for the PCSS blocker search). `maps` null: the layout alone.
template <class Gpu>
vk::DescriptorSetBuilder shadowedLightsBuilder(const FrameSlot& f, VkImageView maps, const Gpu& g) {
    constexpr VkShaderStageFlags frag = VK_SHADER_STAGE_FRAGMENT_BIT;
    return vk::DescriptorSetBuilder()
        .uniform(blocks::SunSkyBlock::kBinding, "sun-sky", f.sunSky, frag)
        .uniform(blocks::AtmosphereBlock::kBinding, "atmosphere", f.atmosphere, frag)
        .uniform(blocks::ShadowBlock::kBinding, "shadow", f.shadow, frag)
        .image(TLX_SHADOW_MAP_COMPARE_BINDING, std::string(kShadowMaps) + "(compare)", maps,
               g.compareSampler.handle(), frag)
        .image(TLX_SHADOW_MAP_DEPTH_BINDING, std::string(kShadowMaps) + "(depth)", maps,
               g.depthSampler.handle(), frag);
}

// The view set: camera, surface block and the surface maps. `t` null: the layout alone.
vk::DescriptorSetBuilder viewSetBuilder(const FrameSlot& f, const SurfaceTextures* t, VkSampler sampler) {
    constexpr VkShaderStageFlags frag = VK_SHADER_STAGE_FRAGMENT_BIT;
    return vk::DescriptorSetBuilder()
        .uniform(blocks::CameraBlock::kBinding, "camera", f.camera, kVertexFragment)
        .uniform(blocks::SurfaceBlock::kBinding, "surface", f.surface, frag)
        .image(TLX_SURFACE_NORMAL_AO_BINDING, kSurfaceNormalAo, t ? t->normalAo.view() : VK_NULL_HANDLE, sampler, frag)
        .image(TLX_SURFACE_ALBEDO_BINDING, kSurfaceAlbedo, t ? t->albedo.view() : VK_NULL_HANDLE, sampler, frag)
        .image(TLX_SURFACE_FILLED_BINDING, kSurfaceFilled, t ? t->filled.view() : VK_NULL_HANDLE, sampler, frag);
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

uint8_t srgbByte(float linear) {
    const float c = std::clamp(linear, 0.0f, 1.0f);
    const float e = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    return uint8_t(std::lround(e * 255.0f));
}

}  // namespace

TerrainRenderer::TerrainRenderer(vk::VulkanContext& ctx, const Heightfield& hf, size_t vertexBudget)
    : ctx_(ctx), hf_(hf), gpu_(std::make_unique<Gpu>()) {
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

    Gpu& g = *gpu_;
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
        f.surface = ubo(sizeof(blocks::SurfaceBlock));
        f.sunSky = ubo(sizeof(blocks::SunSkyBlock));
        f.atmosphere = ubo(sizeof(blocks::AtmosphereBlock));
        f.shadow = ubo(sizeof(blocks::ShadowBlock));
        f.overlay = ubo(sizeof(blocks::OverlayBlock));
        f.lights = vk::DescriptorSetBuilder()
                       .uniform(blocks::SunSkyBlock::kBinding, "sun-sky", f.sunSky, VK_SHADER_STAGE_FRAGMENT_BIT)
                       .uniform(blocks::AtmosphereBlock::kBinding, "atmosphere", f.atmosphere,
                                VK_SHADER_STAGE_FRAGMENT_BIT)
                       .build(ctx_);
        f.overlays = vk::DescriptorSetBuilder()
                         .uniform(blocks::OverlayBlock::kBinding, "overlay", f.overlay, VK_SHADER_STAGE_VERTEX_BIT)
                         .build(ctx_);
        g.slots.push_back(std::move(f));
    }
    g.trilinear = vk::Sampler::trilinearClamp(ctx_);
    g.viewLayout = viewSetBuilder(g.slots[0], nullptr, g.trilinear.handle()).buildLayout(ctx_);
    uploadSurfaceMaps({});
    setAlbedoMap(0, 0, {});
    g.emptySet = vk::DescriptorSetBuilder().buildLayout(ctx_);
    static_assert(TLX_SET_VIEW == 0 && TLX_SET_LIGHTS == 1 && TLX_SET_SUBSYSTEM == 2);
    const VkDescriptorSetLayout terrainSets[] = {g.viewLayout.get(), g.slots[0].lights.layout()};
    g.terrainLayout = vk::PipelineLayout(ctx_, terrainSets);
    const VkDescriptorSetLayout overlaySets[] = {g.viewLayout.get(), g.emptySet.get(),
                                                 g.slots[0].overlays.layout()};
    g.overlayLayout = vk::PipelineLayout(ctx_, overlaySets);

    const VkFormat colorFormats[] = {vk::kColorFormat};
    g.clearPass = vk::RenderPass(ctx_, {colorFormats, vk::kDepthFormat, true, true});
    g.drawPass = vk::RenderPass(ctx_, {colorFormats, vk::kDepthFormat, false, true});
    g.shadowPass = vk::RenderPass(ctx_, {{}, vk::kDepthFormat, true, true});
    g.compareSampler = vk::Sampler::depthCompare(ctx_);
    g.depthSampler = vk::Sampler::nearestClamp(ctx_);
    g.shadowedLightsLayout = shadowedLightsBuilder(g.slots[0], VK_NULL_HANDLE, g).buildLayout(ctx_);
    const VkDescriptorSetLayout shadowedSets[] = {g.viewLayout.get(), g.shadowedLightsLayout.get()};
    g.shadowedTerrainLayout = vk::PipelineLayout(ctx_, shadowedSets);
    g.shadowDepthLayout = vk::PipelineLayout(ctx_, {}, sizeof(glm::mat4), VK_SHADER_STAGE_VERTEX_BIT);
}

bool TerrainRenderer::hasShadowResources() const { return gpu_->shadows != nullptr; }

void TerrainRenderer::uploadSurfaceMaps(const std::vector<float>& ao) {
    Gpu& g = *gpu_;
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

void TerrainRenderer::setAlbedoMap(int width, int height, const std::vector<glm::vec3>& linear) {
    Gpu& g = *gpu_;
    const bool map = width > 0 && height > 0 && linear.size() == size_t(width) * size_t(height);
    // A full mip chain of box means in linear light, stored sRGB-encoded (the hardware decodes).
    std::vector<vk::MipLevel> levels;
    std::vector<glm::vec3> level = map ? linear : std::vector<glm::vec3>{glm::vec3(1.0f)};
    int w = map ? width : 1, h = map ? height : 1;
    while (true) {
        vk::MipLevel l{uint32_t(w), uint32_t(h), std::vector<uint8_t>(level.size() * 4)};
        for (size_t i = 0; i < level.size(); ++i)
            for (int c = 0; c < 3; ++c) l.bytes[4 * i + size_t(c)] = srgbByte(level[i][c]);
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
    Gpu& g = *gpu_;
    for (FrameSlot& f : g.slots) f.view = viewSetBuilder(f, &g.surface, g.trilinear.handle()).build(ctx_);
}

void TerrainRenderer::ensureShadowMaps(int resolution, int cascades) {
    Gpu& g = *gpu_;
    if (g.shadows ? g.shadows->resolution == resolution && g.shadows->cascades == cascades : resolution <= 0)
        return;
    ctx_.waitIdle();  // frames in flight may still read the old maps
    g.graph.forget(kShadowMaps);
    for (FrameSlot& f : g.slots) f.shadowedLights = vk::DescriptorSet();
    g.shadows.reset();
    if (resolution <= 0) return;
    auto sh = std::make_unique<ShadowResources>();
    sh->resolution = resolution;
    sh->cascades = cascades;
    sh->maps = vk::Image::depthLayers(ctx_, uint32_t(resolution), uint32_t(resolution), uint32_t(cascades));
    for (uint32_t i = 0; i < uint32_t(cascades); ++i) {
        const VkImageView view = sh->maps.layerView(i);
        sh->framebuffers.emplace_back(ctx_, g.shadowPass, std::span<const VkImageView>(&view, 1),
                                      uint32_t(resolution), uint32_t(resolution));
    }
    for (FrameSlot& f : g.slots) f.shadowedLights = shadowedLightsBuilder(f, sh->maps.view(), g).build(ctx_);
    g.graph.importImage(kShadowMaps, sh->maps.handle(), sh->maps.aspect(), uint32_t(cascades));
    g.shadows = std::move(sh);
}

void TerrainRenderer::updateSunVisibility(const SunLight& sun, bool skirt) {
    Gpu& g = *gpu_;
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
    Gpu& g = *gpu_;
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
        rec.originSpacing = glm::vec4(v.origin, v.spacing);
        rec.dimsProbe = glm::ivec4(glm::ivec3(v.dims), int32_t(coeffs.size() / 9));
        rec.occupancy = glm::ivec4(int32_t(cells.size()), v.irradianceEncoded ? 1 : 0, 0, 0);
        rec.blend = glm::vec4(v.fallbackBlendDistance, v.scale, 0.0f, 0.0f);
        static const ProbeDiagnostics none;
        const ProbeDiagnostics& d = v.diagnostics ? *v.diagnostics : none;
        const ErrorMap& m = d.errorMap;
        // A map that does not hold nx·nz values (or has no step) is no map.
        if (m.error.size() == size_t(m.nx) * m.nz && m.step > 0.0f && !m.error.empty()) {
            rec.errorMap = glm::ivec4(int32_t(errors.size()), int32_t(m.nx), int32_t(m.nz), 0);
            rec.errorGrid = glm::vec4(m.x0, m.z0, m.step, 0.0f);
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
    block.counts = glm::ivec4(volumeCount_, int32_t(vertexCount_), 0, 0);
    block.flags = glm::ivec4(anyErrorMap_ ? 1 : 0, 0, 0, 0);
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
    Gpu& g = *gpu_;
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
    RenderedImage img;
    img.width = s.width;
    img.height = s.height;
    img.rgba = gpu_->target->readback.pixels();
    img.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return img;
}

bool TerrainRenderer::present(const RenderSettings& s, vk::Swapchain& swapchain) {
    ensureTarget(s.width, s.height);
    const std::optional<vk::SwapchainFrame> frame = swapchain.begin();
    if (!frame) return false;
    Output out;
    out.readback = false;
    out.swapchainImage = frame->image;
    out.extent = frame->extent;
    recordFrame(frame->cb, frame->slot, s, out);
    swapchain.submitAndPresent(*frame);
    return true;
}

void TerrainRenderer::recordFrame(VkCommandBuffer cb, uint32_t slotIndex, const RenderSettings& s,
                                  const Output& out) {
    Gpu& g = *gpu_;
    FrameSlot& slot = g.slots[slotIndex];
    const DebugView view = findDebugView(s.debugView).value_or(*findDebugView(kViewBeauty));
    // The probe subsystem takes part only when volumes are bound, probes are on and the view
    // reads their light.
    ProbeResources* probes =
        g.probes && s.probes && (view.needs.probeLight || view.needs.probeDiagnostics) ? g.probes.get() : nullptr;
    const bool drawMarkers = (s.showProbePositions || view.needs.probeMarkers) && markerCount_ > 0;
    const bool drawLeaves = s.showLeaves && leafCount_ > 0;
    // Shadows: the scene has them on, the sun is up and the view draws them.
    const bool shadowed = s.shadows.enabled && view.needs.shadows && s.sun.direction.y > -0.05f;
    const bool fog = s.fog.enabled;
    const bool sunVisibility = view.needs.sunVisibility;
    const bool sky = view.needs.sky;
    if (sunVisibility) updateSunVisibility(s.sun, s.skirt);
    if (!s.shadows.enabled) ensureShadowMaps(0, 0);  // a scene without shadows holds no maps
    if (shadowed) ensureShadowMaps(s.shadows.mapResolution, std::clamp(s.shadows.cascades, 1, 4));
    ShadowResources* shadows = shadowed ? g.shadows.get() : nullptr;

    // Pipelines, built on first use.
    if (probes && !g.probePass) {
        const VkDescriptorSetLayout sets[] = {g.emptySet.get(), g.emptySet.get(), probes->set.layout()};
        g.probeLayout = vk::PipelineLayout(ctx_, sets);
        g.probePass = vk::createComputePipeline(ctx_, g.probeLayout.handle(), shaders::probeVerticesComp());
    }
    const VkVertexInputBindingDescription meshBinding{0, 24, VK_VERTEX_INPUT_RATE_VERTEX};
    const VkVertexInputAttributeDescription position{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
        normal{1, 0, VK_FORMAT_R32G32B32_SFLOAT, 12};
    // The per-vertex attribute: probe light (or diagnostics) from the probe pass, or the traced
    // sun visibility; one of two vec4 per vertex (stride 32; bound at offset 16 for the diagnostics).
    const bool vertexAttribute = probes || sunVisibility;
    const int variant = (vertexAttribute ? kProbeLightVariant : 0) | (shadows ? kShadowVariant : 0) |
                        (fog ? kFogVariant : 0);
    vk::UniquePipeline& terrainPipeline = g.terrain[variant];
    if (!terrainPipeline) {
        vk::GraphicsPipelineDesc d;
        d.vert = vertexAttribute ? shaders::terrainProbeLightVert() : shaders::terrainVert();
        d.frag = shadows ? shaders::terrainShadowFrag() : shaders::terrainFrag();
        d.fragConstants = {fog ? 1u : 0u};
        d.bindings = {meshBinding};
        d.attributes = {position, normal};
        if (vertexAttribute) {
            d.bindings.push_back({1, 32, VK_VERTEX_INPUT_RATE_VERTEX});
            d.attributes.push_back({2, 1, VK_FORMAT_R32G32B32A32_SFLOAT, 0});
        }
        terrainPipeline = vk::createGraphicsPipeline(
            ctx_, g.clearPass.handle(), (shadows ? g.shadowedTerrainLayout : g.terrainLayout).handle(), d);
    }
    vk::UniquePipeline& skyPipeline = fog ? g.skyFog : g.skyPlain;
    if (sky && !skyPipeline) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::fullscreenVert();
        d.frag = shaders::skyBackgroundFrag();
        d.fragConstants = {fog ? 1u : 0u};
        d.depthWrite = false;
        skyPipeline = vk::createGraphicsPipeline(ctx_, g.drawPass.handle(), g.terrainLayout.handle(), d);
    }
    if (shadows && !g.shadowDepth) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::shadowDepthVert();
        d.bindings = {meshBinding};
        d.attributes = {position};
        d.colorAttachments = 0;
        g.shadowDepth = vk::createGraphicsPipeline(ctx_, g.shadowPass.handle(), g.shadowDepthLayout.handle(), d);
    }
    const VkVertexInputBindingDescription instance{0, 16, VK_VERTEX_INPUT_RATE_INSTANCE};
    const VkVertexInputAttributeDescription record{0, 0, VK_FORMAT_R32G32B32A32_SFLOAT, 0};
    if (drawMarkers && !g.markerPipeline) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::markersVert();
        d.frag = shaders::markersFrag();
        d.bindings = {instance};
        d.attributes = {record};
        d.depthWrite = false;
        g.markerPipeline = vk::createGraphicsPipeline(ctx_, g.drawPass.handle(), g.overlayLayout.handle(), d);
    }
    if (drawLeaves && !g.leafPipeline) {
        // The 12 edges of each leaf box as a line list.
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::leavesVert();
        d.frag = shaders::markersFrag();
        d.bindings = {instance};
        d.attributes = {record};
        d.topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
        d.depthWrite = false;
        g.leafPipeline = vk::createGraphicsPipeline(ctx_, g.drawPass.handle(), g.overlayLayout.handle(), d);
    }

    // This slot's uniform blocks (the GPU finished the slot's previous frame).
    const float extent = std::max({hf_.maxX() - hf_.minX(), hf_.maxZ() - hf_.minZ(),
                                   hf_.maxHeight() - hf_.minHeight(), 1.0f});
    const float aspect = float(s.width) / float(s.height);
    blocks::CameraBlock camera;
    camera.viewProj = s.camera.viewProjection(aspect, extent);
    camera.invViewProj = glm::inverse(camera.viewProj);
    camera.position = glm::vec4(s.camera.position(), s.camera.planes(extent).farPlane);
    camera.viewport = glm::vec4(float(s.width), float(s.height), 1.0f / float(s.width), 1.0f / float(s.height));
    camera.view = glm::ivec4(s.debugView, s.linearOutput ? 1 : 0,
                             sunVisibility ? 2 : view.needs.probeDiagnostics ? 1 : 0, 0);
    slot.camera.write(&camera, sizeof camera);
    blocks::SurfaceBlock surface;
    const SurfaceLook& look = s.surface;
    surface.albedo = glm::vec4(s.albedo, hasAlbedoMap_ ? 1.0f : 0.0f);
    surface.material = glm::vec4(look.roughness, s.exposure, look.specularAA ? 1.0f : 0.0f, look.roughnessFloor);
    const float spanX = hf_.maxX() - hf_.minX(), spanZ = hf_.maxZ() - hf_.minZ();
    surface.footprint = glm::vec4(hf_.minX(), hf_.minZ(), spanX > 0.0f ? 1.0f / spanX : 0.0f,
                                  spanZ > 0.0f ? 1.0f / spanZ : 0.0f);
    surface.mapSizes = glm::vec4(glm::vec2(surfaceMapSize_), glm::vec2(albedoMapSize_));
    // The normal-AO mip level whose texels are as large as the finest probe spacing: the AO at
    // that scale is what the probes already hold.
    float probeLevel = 0.0f;
    if (probes && hasAo_ && finestProbeSpacing_ > 0.0f) {
        const float texel = std::max(spanX / float(std::max(surfaceMapSize_.x - 1, 1)),
                                     spanZ / float(std::max(surfaceMapSize_.y - 1, 1)));
        if (texel > 0.0f) probeLevel = std::max(std::log2(finestProbeSpacing_ / texel), 0.0f);
    }
    surface.ao = glm::vec4(look.ao && hasAo_ ? 1.0f : 0.0f, look.ao ? look.aoStrength : 0.0f, probeLevel, 0.0f);
    const DetailSettings& d = look.detail;
    surface.detail = d.enabled ? glm::vec4(float(d.normalStrength), float(d.scale), float(d.fadeDistance),
                                           float(d.albedoVariation))
                               : glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);
    slot.surface.write(&surface, sizeof surface);
    blocks::SunSkyBlock sunSky;
    sunSky.sunDirection = glm::vec4(s.sun.direction, s.sun.angularRadius);
    sunSky.sunIlluminance = glm::vec4(s.sun.illuminance, 0.0f);
    for (int k = 0; k < 9; ++k) sunSky.skySh[k] = glm::vec4(s.skySh.c[size_t(k)], 0.0f);
    slot.sunSky.write(&sunSky, sizeof sunSky);
    blocks::AtmosphereBlock atmosphere;
    atmosphere.fog = glm::vec4(float(s.fog.density), float(s.fog.heightFalloff), float(s.fog.baseHeight.value_or(0.0)),
                               float(s.fog.anisotropy));
    atmosphere.fogColor = glm::vec4(s.fog.color.value_or(glm::vec3(0.0f)), float(s.fog.inscatter));
    slot.atmosphere.write(&atmosphere, sizeof atmosphere);
    const glm::vec3 boundsMin(hf_.minX(), hf_.minHeight(), hf_.minZ()), boundsMax(hf_.maxX(), hf_.maxHeight(), hf_.maxZ());
    std::vector<glm::mat4> lightMatrices;
    if (shadows) {
        const CascadeRange range = cascadeRange(s.shadows, s.camera, aspect, boundsMin, boundsMax);
        cascades_ = fitCascades(range, s.camera, aspect, s.sun.direction, shadows->resolution, boundsMin, boundsMax);
        blocks::ShadowBlock block;
        for (size_t i = 0; i < cascades_.size(); ++i) {
            block.lightViewProj[i] = cascades_[i].lightViewProj;
            block.ends[int(i)] = float(cascades_[i].farDistance);
            block.texel[int(i)] = cascades_[i].texelSize;
            block.depthRange[int(i)] = cascades_[i].depthRange;
            lightMatrices.push_back(cascades_[i].lightViewProj);
        }
        block.forward = glm::vec4(glm::normalize(s.camera.target - s.camera.position()), float(range.nearDistance));
        block.bias = glm::vec4(float(s.shadows.depthBias), float(s.shadows.normalBias),
                               std::tan(s.sun.angularRadius), float(shadows->resolution));
        block.mode = glm::ivec4(int(cascades_.size()), int(s.shadows.filter), 0, 0);
        slot.shadow.write(&block, sizeof block);
    } else if (!s.shadows.enabled) {
        cascades_.clear();
    }
    if (drawMarkers || drawLeaves) {
        blocks::OverlayBlock overlay;
        overlay.leaves = glm::vec4(smallestLeaf_, kSmallestLeafPixels, 0.0f, 0.0f);
        overlay.markers = glm::ivec4(s.showProbePositions ? 1 : 0, 1, 0, 0);
        slot.overlay.write(&overlay, sizeof overlay);
    }

    // Background where no pass draws the sky: black, or the sky toward the horizon in the view's
    // encoding (the sky pass draws over it per pixel).
    glm::vec3 bg(0.0f);
    if (view.background != ViewBackground::Black) {
        bg = glm::max(sh::evalRadiance(s.skySh, glm::normalize(glm::vec3(0.0f, 0.2f, -1.0f))), glm::vec3(0.0f));
        if (!s.linearOutput && view.background == ViewBackground::Sky) {
            // tonemap.glsl's display(), for the one colour the shader does not draw.
            auto aces = [](float x) { return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f); };
            auto srgb = [](float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; };
            for (int i = 0; i < 3; ++i) bg[i] = srgb(aces(bg[i] * s.exposure));
        } else if (!s.linearOutput) {
            bg = glm::clamp(bg, glm::vec3(0.0f), glm::vec3(1.0f));
        }
    }

    FrameGraph& graph = g.graph;
    graph.beginFrame();
    const uint32_t w = s.width, h = s.height;
    auto setViewport = [](VkCommandBuffer c, uint32_t vw, uint32_t vh) {
        VkViewport vp{0, 0, float(vw), float(vh), 0.0f, 1.0f};
        VkRect2D sc{{0, 0}, {vw, vh}};
        vkCmdSetViewport(c, 0, 1, &vp);
        vkCmdSetScissor(c, 0, 1, &sc);
    };
    VkFramebuffer framebuffer = g.target->framebuffer.handle();
    // A pass that draws on top of what the frame holds (sky, overlays).
    const auto beginDrawing = [&g, framebuffer, w, h, setViewport](VkCommandBuffer c) {
        VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
        rbi.renderPass = g.drawPass.handle();
        rbi.framebuffer = framebuffer;
        rbi.renderArea = {{0, 0}, {w, h}};
        vkCmdBeginRenderPass(c, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        setViewport(c, w, h);
    };

    if (probes && probes->lightStale) {
        PassInfo info{"probe-vertices",
                      {{kProbeCoefficients, Access::ComputeStorageRead},
                       {kProbeCells, Access::ComputeStorageRead},
                       {kProbeVolumes, Access::ComputeStorageRead},
                       {kProbeErrorMaps, Access::ComputeStorageRead},
                       {kVertices, Access::ComputeStorageRead},
                       {kProbeLight, Access::ComputeStorageWrite}},
                      probes->set.bindingNames()};
        const uint32_t n = uint32_t(vertexCount_);
        graph.addPass(std::move(info), [&g, probes, n](VkCommandBuffer c) {
            vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, g.probePass.get());
            VkDescriptorSet set = probes->set.handle();
            vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, g.probeLayout.handle(),
                                    TLX_SET_SUBSYSTEM, 1, &set, 0, nullptr);
            vkCmdDispatch(c, (n + 63) / 64, 1, 1);
        });
    }

    // The cascades, drawn again only when their light projections moved (the camera, the sun or
    // a shadow setting changed).
    if (shadows && shadows->drawn != lightMatrices) {
        PassInfo info{"shadow",
                      {{kShadowMaps, Access::DepthAttachmentClear},
                       {kVertices, Access::VertexAttributeRead},
                       {kIndices, Access::IndexRead}},
                      {std::string("vertex:") + kVertices, std::string("index:") + kIndices}};
        const uint32_t indexCount = uint32_t(indexCount_), res = uint32_t(shadows->resolution);
        graph.addPass(std::move(info), [&g, shadows, lightMatrices, indexCount, res, setViewport](VkCommandBuffer c) {
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
                if (indexCount > 0) {
                    setViewport(c, res, res);
                    vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, g.shadowDepth.get());
                    vkCmdPushConstants(c, g.shadowDepthLayout.handle(), VK_SHADER_STAGE_VERTEX_BIT, 0,
                                       sizeof(glm::mat4), &lightMatrices[i]);
                    const VkBuffer vb = g.vertices.handle();
                    const VkDeviceSize offset = 0;
                    vkCmdBindVertexBuffers(c, 0, 1, &vb, &offset);
                    vkCmdBindIndexBuffer(c, g.indices.handle(), 0, VK_INDEX_TYPE_UINT32);
                    vkCmdDrawIndexed(c, indexCount, 1, 0, 0, 0);
                }
                vkCmdEndRenderPass(c);
            }
        });
        shadows->drawn = lightMatrices;
    }

    {
        vk::DescriptorSet& lights = shadows ? slot.shadowedLights : slot.lights;
        PassInfo info{"terrain",
                      {{kColor, Access::ColorAttachmentClear},
                       {kDepth, Access::DepthAttachmentClear},
                       {kVertices, Access::VertexAttributeRead},
                       {kIndices, Access::IndexRead}},
                      concat(concat(slot.view.bindingNames(), lights.bindingNames()),
                             {std::string("vertex:") + kVertices, std::string("index:") + kIndices})};
        if (shadows) info.uses.push_back({kShadowMaps, Access::FragmentSampledRead});
        VkBuffer attribute = VK_NULL_HANDLE;
        if (probes) {
            info.uses.push_back({kProbeLight, Access::VertexAttributeRead});
            info.bindings.push_back(std::string("vertex:") + kProbeLight);
            attribute = probes->light.handle();
        } else if (sunVisibility) {
            info.uses.push_back({kSunVisibility, Access::VertexAttributeRead});
            info.bindings.push_back(std::string("vertex:") + kSunVisibility);
            attribute = g.sunVisibility.handle();
        }
        if (fog) info.bindings.push_back("fog");
        // The diagnostics views read the probe pass's second vec4 in place of the first: one
        // attribute and one varying either way, so no view pays for the other.
        const VkDeviceSize attributeOffset = probes && view.needs.probeDiagnostics ? 16 : 0;
        const uint32_t indexCount = uint32_t(indexCount_);
        const VkPipeline pipeline = terrainPipeline.get();
        const VkPipelineLayout layout = (shadows ? g.shadowedTerrainLayout : g.terrainLayout).handle();
        const VkDescriptorSet sets[] = {slot.view.handle(), lights.handle()};
        graph.addPass(std::move(info), [&g, pipeline, layout, sets, attribute, attributeOffset, indexCount, bg,
                                        w, h, framebuffer, setViewport](VkCommandBuffer c) {
            VkClearValue clear[2];
            clear[0].color = {{bg.x, bg.y, bg.z, 1.0f}};
            clear[1].depthStencil = {1.0f, 0};
            VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
            rbi.renderPass = g.clearPass.handle();
            rbi.framebuffer = framebuffer;
            rbi.renderArea = {{0, 0}, {w, h}};
            rbi.clearValueCount = 2;
            rbi.pClearValues = clear;
            vkCmdBeginRenderPass(c, &rbi, VK_SUBPASS_CONTENTS_INLINE);
            if (indexCount > 0) {
                setViewport(c, w, h);
                vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
                vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, layout, TLX_SET_VIEW, 2, sets, 0, nullptr);
                const VkBuffer vb[2] = {g.vertices.handle(), attribute};
                const VkDeviceSize offsets[2] = {0, attributeOffset};
                vkCmdBindVertexBuffers(c, 0, attribute ? 2 : 1, vb, offsets);
                vkCmdBindIndexBuffer(c, g.indices.handle(), 0, VK_INDEX_TYPE_UINT32);
                vkCmdDrawIndexed(c, indexCount, 1, 0, 0, 0);
            }
            vkCmdEndRenderPass(c);
        });
    }

    if (sky) {
        PassInfo info{"sky",
                      {{kColor, Access::ColorAttachmentDraw}, {kDepth, Access::DepthAttachmentDraw}},
                      concat(slot.view.bindingNames(), slot.lights.bindingNames())};
        if (fog) info.bindings.push_back("fog");
        const VkPipeline pipeline = skyPipeline.get();
        const VkDescriptorSet sets[] = {slot.view.handle(), slot.lights.handle()};
        graph.addPass(std::move(info), [&g, pipeline, sets, beginDrawing](VkCommandBuffer c) {
            beginDrawing(c);
            vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
            vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, g.terrainLayout.handle(), TLX_SET_VIEW, 2,
                                    sets, 0, nullptr);
            vkCmdDraw(c, 3, 1, 0, 0);
            vkCmdEndRenderPass(c);
        });
    }

    if (drawMarkers || drawLeaves) {
        PassInfo info{"overlays",
                      {{kColor, Access::ColorAttachmentDraw}, {kDepth, Access::DepthAttachmentDraw}},
                      concat(slot.view.bindingNames(), slot.overlays.bindingNames())};
        if (drawLeaves) {
            info.uses.push_back({kLeaves, Access::VertexAttributeRead});
            info.bindings.push_back(std::string("vertex:") + kLeaves);
        }
        if (drawMarkers) {
            info.uses.push_back({kMarkers, Access::VertexAttributeRead});
            info.bindings.push_back(std::string("vertex:") + kMarkers);
        }
        const uint32_t leafCount = drawLeaves ? leafCount_ : 0, markerCount = drawMarkers ? markerCount_ : 0;
        graph.addPass(std::move(info), [&g, &slot, leafCount, markerCount, beginDrawing](VkCommandBuffer c) {
            beginDrawing(c);
            const VkDescriptorSet view = slot.view.handle(), overlay = slot.overlays.handle();
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
            if (leafCount > 0) draw(g.leafPipeline.get(), g.leaves, 24, leafCount);
            if (markerCount > 0) draw(g.markerPipeline.get(), g.markers, 6, markerCount);
            vkCmdEndRenderPass(c);
        });
    }

    if (out.readback) {
        RenderTarget& t = *g.target;
        graph.addPass({"readback", {{kColor, Access::TransferRead}, {kReadback, Access::TransferWrite}}, {}},
                      [&t](VkCommandBuffer c) { t.readback.recordCopy(c, t.color.handle()); });
        graph.addFinalUse({kReadback, Access::HostRead});
    } else {
        graph.importImage(kSwapchain, out.swapchainImage, VK_IMAGE_ASPECT_COLOR_BIT, 1,
                          VK_PIPELINE_STAGE_TRANSFER_BIT);
        const VkImage source = g.target->color.handle(), dest = out.swapchainImage;
        const VkExtent2D dstExtent = out.extent;
        graph.addPass({"present", {{kColor, Access::TransferRead}, {kSwapchain, Access::TransferWrite}}, {}},
                      [source, dest, w, h, dstExtent](VkCommandBuffer c) {
                          VkImageBlit blit{};
                          blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                          blit.srcOffsets[1] = {int32_t(w), int32_t(h), 1};
                          blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                          blit.dstOffsets[1] = {int32_t(dstExtent.width), int32_t(dstExtent.height), 1};
                          vkCmdBlitImage(c, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dest,
                                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
                      });
        graph.addFinalUse({kSwapchain, Access::Present});
    }
    graph.execute(cb);
    if (probes) probes->lightStale = false;
}

}  // namespace terralux
