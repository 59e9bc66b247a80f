#include "render/features/Lpv.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "ShaderBinaries.h"
#include "lpv/Lpv.h"
#include "vk/ComputePipeline.h"

namespace terralux::features {

using namespace frame;

std::vector<blocks::LocalLightRecord> packLocalLights(const std::vector<LocalLight>& lights, bool used) {
    std::vector<blocks::LocalLightRecord> records(std::max<size_t>(used ? lights.size() : 0, 1));
    for (size_t i = 0; used && i < lights.size(); ++i) {
        const LocalLight& l = lights[i];
        blocks::LocalLightRecord& r = records[i];
        const bool spot = l.type == LocalLightType::Spot;
        r.position = l.position;
        r.range = float(l.range);
        r.emitted = l.emitted();
        r.spot = spot ? 1.0f : 0.0f;
        const float len = glm::length(l.direction);
        r.direction = len > 0.0f ? l.direction / len : glm::vec3(0.0f, -1.0f, 0.0f);
        const float cosOuter = std::cos(glm::radians(float(l.outerConeDeg)));
        const float cosInner = std::cos(glm::radians(float(l.innerConeDeg)));
        r.cosOuter = cosOuter;
        r.invConeWidth = 1.0f / std::max(0.001f, cosInner - cosOuter);
    }
    return records;
}

namespace {

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

std::unique_ptr<LpvResources> buildLpv(vk::VulkanContext& ctx, RendererGpu& g,
                                       std::shared_ptr<const lpv::Volumes> volumes) {
    if (!volumes || volumes->cascades().empty()) return nullptr;
    auto r = std::make_unique<LpvResources>();
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
    r->geometry = vk::Buffer::deviceLocal(ctx, geometry.data(), geometry.size() * 4, storage);
    // The injected light until the pass has run, should a frame read it before.
    r->light = vk::Buffer::deviceLocal(ctx, light.data(), lightBytes, storage);
    if (propagate) {
        // Region 0 the injected light; regions 1 and 2 the steps' outputs, written before read.
        r->work = vk::Buffer::deviceLocal(ctx, light.data(), lightBytes, storage, 3 * lightBytes);
        r->cells = uint32_t(n) * uint32_t(lpv::kCells);
        r->scales = vk::Buffer(ctx, VkDeviceSize(2 * 3) * r->cells * 4, storage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        const blocks::LpvPropagationBlock block =
            propagationBlock(lpv::propagationStepWeight(ls.propagationWeight), int(n));
        r->propagationBlock = vk::Buffer::hostVisible(ctx, sizeof block, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
        r->propagationBlock.write(&block, sizeof block);
        r->propagationSet = lpvPropagationSetBuilder(*r).build(ctx);
        r->steps = ls.propagationIterations;
        if (!g.lpvPropagate) {
            constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
            const VkDescriptorSetLayout sets[] = {g.emptySet.get(), g.emptySet.get(), r->propagationSet.layout()};
            g.lpvPropagateLayout = vk::PipelineLayout(ctx, sets, sizeof(glm::ivec4), compute);
            g.lpvPropagate = vk::createComputePipeline(ctx, g.lpvPropagateLayout.handle(), shaders::lpvPropagateComp());
        }
        if (!g.lpvQueries && ctx.timestampPeriod() > 0.0) {
            VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
            qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
            qci.queryCount = 2;
            VkQueryPool pool = VK_NULL_HANDLE;
            vk::check(vkCreateQueryPool(ctx.device(), &qci, nullptr, &pool), "vkCreateQueryPool");
            g.lpvQueries = vk::UniqueQueryPool(ctx.device(), pool);
        }
    }
    r->volumes = std::move(volumes);
    return r;
}

void recordLpvPropagation(RendererGpu& g, VkCommandBuffer cb) {
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

blocks::LpvBlock packLpv(const Frame& f) {
    blocks::LpvBlock block = f.lpvVolumes ? f.lpvVolumes->block : blocks::LpvBlock{};
    block.lightCount = f.localLights ? int(f.s.lights.size()) : 0;
    block.addsToAmbient = f.lpvVolumes && f.s.lpvLight && f.view.needs.sceneLights ? 1.0f : 0.0f;
    return block;
}

void addLpvPropagationPass(Frame& f) {
    if (!f.lpvVolumes || f.lpvVolumes->steps <= 0) return;
    PassInfo info{"lpv-propagate",
                  {{kLpvWork, Access::ComputeStorageReadWrite},
                   {kLpvScales, Access::ComputeStorageReadWrite},
                   {kLpvGeometry, Access::ComputeStorageRead},
                   {kLpvLight, Access::ComputeStorageReadWrite}},
                  f.lpvVolumes->propagationSet.bindingNames()};
    f.g.graph.addPass(std::move(info), [&g = f.g](VkCommandBuffer c) { recordLpvPropagation(g, c); });
}

}  // namespace terralux::features
