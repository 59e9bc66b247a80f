#include "render/TerrainRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

#include <glm/mat4x4.hpp>

#include "ShaderBinaries.h"
#include "vk/Buffer.h"
#include "vk/ComputePipeline.h"
#include "vk/Descriptors.h"
#include "vk/OffscreenTarget.h"
#include "vk/Pipeline.h"

namespace terralux {

namespace {

// std140 mirror of `Frame` in shaders/frame.glsl.
struct FrameUniforms {
    glm::mat4 viewProj;
    glm::vec4 cameraPos;
    glm::vec4 sunDirection;
    glm::vec4 sunIlluminance;
    glm::vec4 albedo;
    glm::vec4 skySh[9];
    int32_t params[4];
    glm::vec4 exposure;
    glm::vec4 overlay;
};
static_assert(sizeof(FrameUniforms) == 320);

// std430 mirror of `Volume`.
struct VolumeRecord {
    glm::vec4 originSpacing;
    int32_t dimsProbe[4];
    int32_t occupancy[4];
    glm::vec4 blend;
    int32_t errorMap[4];
    glm::vec4 errorGrid;
};
static_assert(sizeof(VolumeRecord) == 96);

}  // namespace

struct TerrainRenderer::Gpu {
    vk::Buffer vertices, indices, uniforms, probes, cells, volumes, probeLight, errors, markers, leaves;
    std::unique_ptr<vk::ProbeVertexPass> probePass;
    std::unique_ptr<vk::OffscreenTarget> target;
    std::unique_ptr<vk::TerrainPipeline> pipeline;
    std::unique_ptr<vk::TerrainDescriptors> descriptors;
};

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

    gpu_->vertices = vk::Buffer::deviceLocal(ctx_, vertices.data(), vertices.size() * 4,
                                             VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_->probeLight = vk::Buffer(ctx_, std::max<size_t>(vertexCount(), 1) * 32,
                                  VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    gpu_->probePass = std::make_unique<vk::ProbeVertexPass>(ctx_, shaders::probeVerticesComp());
    gpu_->indices = vk::Buffer::deviceLocal(ctx_, indices.data(), std::max<size_t>(indices.size(), 1) * 4,
                                            VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    gpu_->uniforms = vk::Buffer::hostVisible(ctx_, sizeof(FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    setProbeVolumes({});
}

TerrainRenderer::~TerrainRenderer() = default;

void TerrainRenderer::setProbeVolumes(const std::vector<GpuProbeVolume>& volumes) {
    std::vector<glm::vec4> coeffs;
    std::vector<int32_t> cells;
    std::vector<VolumeRecord> records;
    std::vector<float> errors;
    for (const auto& v : volumes) {
        VolumeRecord rec{};
        rec.originSpacing = glm::vec4(v.origin, v.spacing);
        rec.dimsProbe[0] = int32_t(v.dims.x);
        rec.dimsProbe[1] = int32_t(v.dims.y);
        rec.dimsProbe[2] = int32_t(v.dims.z);
        rec.dimsProbe[3] = int32_t(coeffs.size() / 9);
        rec.occupancy[0] = int32_t(cells.size());
        rec.occupancy[1] = v.irradianceEncoded ? 1 : 0;
        rec.blend = glm::vec4(v.fallbackBlendDistance, v.scale, 0.0f, 0.0f);
        static const ProbeDiagnostics none;
        const ProbeDiagnostics& d = v.diagnostics ? *v.diagnostics : none;
        const ErrorMap& m = d.errorMap;
        // A map that does not hold nx·nz values (or has no step) is no map.
        if (m.error.size() == size_t(m.nx) * m.nz && m.step > 0.0f && !m.error.empty()) {
            rec.errorMap[0] = int32_t(errors.size());
            rec.errorMap[1] = int32_t(m.nx);
            rec.errorMap[2] = int32_t(m.nz);
            rec.errorGrid = glm::vec4(m.x0, m.z0, m.step, 0.0f);
            for (float e : m.error) errors.push_back(std::isfinite(e) ? e : -1.0f);
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
    if (errors.empty()) errors.push_back(-1.0f);
    // Storage buffers may not be empty: a placeholder element when there is nothing to bind.
    if (coeffs.empty()) coeffs.push_back(glm::vec4(0.0f));
    if (cells.empty()) cells.push_back(-1);
    if (records.empty()) records.push_back(VolumeRecord{});
    ctx_.submitAndWait([](VkCommandBuffer) {});  // no draw may still read the old buffers
    gpu_->probes = vk::Buffer::deviceLocal(ctx_, coeffs.data(), coeffs.size() * sizeof(glm::vec4),
                                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_->cells = vk::Buffer::deviceLocal(ctx_, cells.data(), cells.size() * 4,
                                          VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_->volumes = vk::Buffer::deviceLocal(ctx_, records.data(), records.size() * sizeof(VolumeRecord),
                                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    gpu_->errors = vk::Buffer::deviceLocal(ctx_, errors.data(), errors.size() * 4,
                                           VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    if (gpu_->descriptors)
        gpu_->descriptors->update(gpu_->uniforms, gpu_->probes, gpu_->cells, gpu_->volumes);

    // Probe light per vertex, once per change of probes (the pass reads only the volume count
    // from the frame uniforms).
    FrameUniforms u{};
    u.params[1] = volumeCount_;
    gpu_->uniforms.write(&u, sizeof u);
    ctx_.submitAndWait([&](VkCommandBuffer cb) {
        gpu_->probePass->record(cb, gpu_->uniforms, gpu_->probes, gpu_->cells, gpu_->volumes,
                                gpu_->vertices, gpu_->probeLight, gpu_->errors, uint32_t(vertexCount_));
    });
}

VkImage TerrainRenderer::lastImage() const {
    return gpu_->target ? gpu_->target->colorImage() : VK_NULL_HANDLE;
}

void TerrainRenderer::setProbePositions(const std::vector<glm::vec4>& positions) {
    ctx_.submitAndWait([](VkCommandBuffer) {});  // no draw may still read the old buffer
    markerCount_ = uint32_t(positions.size());
    if (positions.empty()) {
        gpu_->markers = vk::Buffer();
        return;
    }
    gpu_->markers = vk::Buffer::deviceLocal(ctx_, positions.data(), positions.size() * sizeof(glm::vec4),
                                            VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
}

void TerrainRenderer::setProbeLeaves(const std::vector<glm::vec4>& leaves) {
    ctx_.submitAndWait([](VkCommandBuffer) {});  // no draw may still read the old buffer
    leafCount_ = uint32_t(leaves.size());
    smallestLeaf_ = 1.0f;
    if (leaves.empty()) {
        gpu_->leaves = vk::Buffer();
        return;
    }
    smallestLeaf_ = leaves.front().w;
    for (const auto& l : leaves) smallestLeaf_ = std::min(smallestLeaf_, l.w);
    gpu_->leaves = vk::Buffer::deviceLocal(ctx_, leaves.data(), leaves.size() * sizeof(glm::vec4),
                                           VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
}

RenderedImage TerrainRenderer::render(const RenderSettings& s) {
    const auto start = std::chrono::steady_clock::now();
    if (!gpu_->target || gpu_->target->width() != s.width || gpu_->target->height() != s.height) {
        gpu_->target.reset();
        gpu_->target = std::make_unique<vk::OffscreenTarget>(ctx_, s.width, s.height);
        // Render passes of the same formats are compatible: one pipeline serves every size.
        if (!gpu_->pipeline) {
            gpu_->pipeline = std::make_unique<vk::TerrainPipeline>(
                ctx_, gpu_->target->renderPass(), shaders::terrainVert(), shaders::terrainFrag(),
                shaders::markersVert(), shaders::markersFrag(), shaders::leavesVert());
            gpu_->descriptors = std::make_unique<vk::TerrainDescriptors>(ctx_, gpu_->pipeline->setLayout());
            gpu_->descriptors->update(gpu_->uniforms, gpu_->probes, gpu_->cells, gpu_->volumes);
        }
    }
    const float extent = std::max({hf_.maxX() - hf_.minX(), hf_.maxZ() - hf_.minZ(),
                                   hf_.maxHeight() - hf_.minHeight(), 1.0f});
    FrameUniforms u{};
    u.viewProj = s.camera.viewProjection(float(s.width) / float(s.height), extent);
    u.cameraPos = glm::vec4(s.camera.position(), 1.0f);
    u.sunDirection = glm::vec4(s.sun.direction, 0.0f);
    u.sunIlluminance = glm::vec4(s.sun.illuminance, 0.0f);
    u.albedo = glm::vec4(s.albedo, 1.0f);
    for (int k = 0; k < 9; ++k) u.skySh[k] = glm::vec4(s.skySh.c[size_t(k)], 0.0f);
    u.params[0] = s.debugView;
    u.params[1] = volumeCount_;
    u.params[2] = s.probes ? 1 : 0;
    u.params[3] = s.linearOutput ? 1 : 0;
    u.exposure = glm::vec4(s.exposure, s.roughness, float(s.width), float(s.height));
    u.overlay = glm::vec4(smallestLeaf_, s.showProbePositions ? 1.0f : 0.0f, 0.0f, 0.0f);
    gpu_->uniforms.write(&u, sizeof u);

    // Background: the sky toward the horizon, in the same encoding as the view.
    glm::vec3 bg(0.0f);
    if (s.debugView == 0 || s.debugView == 32) {
        const glm::vec3 horizon = glm::max(sh::evalRadiance(s.skySh, glm::normalize(glm::vec3(0.0f, 0.2f, -1.0f))), glm::vec3(0.0f));
        bg = horizon;
        if (!s.linearOutput && s.debugView == 0) {
            auto aces = [](float x) { return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f); };
            auto srgb = [](float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; };
            for (int i = 0; i < 3; ++i) bg[i] = srgb(aces(bg[i] * s.exposure));
        } else if (!s.linearOutput) {
            bg = glm::clamp(bg, glm::vec3(0.0f), glm::vec3(1.0f));
        }
    }

    vk::OffscreenTarget& target = *gpu_->target;
    ctx_.submitAndWait([&](VkCommandBuffer cb) {
        VkClearValue clear[2];
        clear[0].color = {{bg.x, bg.y, bg.z, 1.0f}};
        clear[1].depthStencil = {1.0f, 0};
        VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
        rbi.renderPass = target.renderPass();
        rbi.framebuffer = target.framebuffer();
        rbi.renderArea = {{0, 0}, {s.width, s.height}};
        rbi.clearValueCount = 2;
        rbi.pClearValues = clear;
        vkCmdBeginRenderPass(cb, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        if (indexCount_ > 0) {
            VkViewport vp{0, 0, float(s.width), float(s.height), 0.0f, 1.0f};
            VkRect2D sc{{0, 0}, {s.width, s.height}};
            vkCmdSetViewport(cb, 0, 1, &vp);
            vkCmdSetScissor(cb, 0, 1, &sc);
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gpu_->pipeline->handle());
            VkDescriptorSet set = gpu_->descriptors->set();
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gpu_->pipeline->layout(), 0, 1,
                                    &set, 0, nullptr);
            // Views 54 and 56 read the probe pass's second vec4 (the diagnostics) in place of the
            // first: one attribute and one varying either way, so no view pays for the other.
            const bool diagnostics = s.debugView == 54 || s.debugView == 56;
            VkDeviceSize offsets[2] = {0, diagnostics ? VkDeviceSize(16) : VkDeviceSize(0)};
            VkBuffer vb[2] = {gpu_->vertices.handle(), gpu_->probeLight.handle()};
            vkCmdBindVertexBuffers(cb, 0, 2, vb, offsets);
            vkCmdBindIndexBuffer(cb, gpu_->indices.handle(), 0, VK_INDEX_TYPE_UINT32);
            vkCmdDrawIndexed(cb, uint32_t(indexCount_), 1, 0, 0, 0);
        }
        // Overlays: per-instance vec4 records, same layout and descriptor set as the terrain.
        auto overlay = [&](VkPipeline pipeline, const vk::Buffer& instances, uint32_t vertices,
                           uint32_t count) {
            VkViewport vp{0, 0, float(s.width), float(s.height), 0.0f, 1.0f};
            VkRect2D sc{{0, 0}, {s.width, s.height}};
            vkCmdSetViewport(cb, 0, 1, &vp);
            vkCmdSetScissor(cb, 0, 1, &sc);
            vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
            VkDescriptorSet set = gpu_->descriptors->set();
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, gpu_->pipeline->layout(), 0, 1,
                                    &set, 0, nullptr);
            VkDeviceSize offset = 0;
            VkBuffer b = instances.handle();
            vkCmdBindVertexBuffers(cb, 0, 1, &b, &offset);
            vkCmdDraw(cb, vertices, count, 0, 0);
        };
        if (s.showLeaves && leafCount_ > 0) overlay(gpu_->pipeline->leaves(), gpu_->leaves, 24, leafCount_);
        // View 54 is about the probes themselves: their markers are part of it.
        if ((s.showProbePositions || s.debugView == 54) && markerCount_ > 0)
            overlay(gpu_->pipeline->markers(), gpu_->markers, 6, markerCount_);
        vkCmdEndRenderPass(cb);
        target.recordReadback(cb);
    });
    RenderedImage img;
    img.width = s.width;
    img.height = s.height;
    img.rgba = target.pixels();
    img.milliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return img;
}

}  // namespace terralux
