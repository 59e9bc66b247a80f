#include "render/features/Probes.h"

#include <algorithm>
#include <cmath>

#include "ShaderBinaries.h"
#include "vk/ComputePipeline.h"

namespace terralux::features {

using namespace frame;

namespace {

// The probe pass's light at `vertexCount` vertices of `vertices` (position and normal): the
// light buffer it writes (per vertex two vec4, read as a vertex attribute), its block and its
// set, over the volumes p holds.
void lightAt(vk::VulkanContext& ctx, const ProbeResources& p, uint32_t vertexCount, const char* verticesName,
             const vk::Buffer& vertices, const char* lightName, vk::Buffer& blockBuffer, vk::Buffer& light,
             vk::DescriptorSet& set) {
    light = vk::Buffer(ctx, std::max<size_t>(vertexCount, 1) * 32,
                       VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                       VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    blocks::ProbesBlock block;
    block.volumeCount = p.volumeCount;
    block.vertexCount = int32_t(vertexCount);
    block.anyErrorMap = p.anyErrorMap ? 1 : 0;
    blockBuffer = vk::Buffer::hostVisible(ctx, sizeof block, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    blockBuffer.write(&block, sizeof block);
    constexpr VkShaderStageFlags compute = VK_SHADER_STAGE_COMPUTE_BIT;
    set = vk::DescriptorSetBuilder()
              .uniform(blocks::ProbesBlock::kBinding, "probes", blockBuffer, compute)
              .storage(1, kProbeCoefficients, p.coeffs, compute)
              .storage(2, kProbeCells, p.cells, compute)
              .storage(3, kProbeVolumes, p.volumes, compute)
              .storage(4, kProbeErrorMaps, p.errors, compute)
              .storage(5, verticesName, vertices, compute)
              .storage(6, lightName, light, compute)
              .build(ctx);
}

}  // namespace

std::unique_ptr<ProbeResources> buildProbes(vk::VulkanContext& ctx, RendererGpu& g, uint32_t vertexCount,
                                            const std::vector<GpuProbeVolume>& volumes) {
    auto p = std::make_unique<ProbeResources>();
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
            p->anyErrorMap = true;
        }
        for (size_t i = 0; i < v.coeffs.size(); ++i) {
            const float moved = i < d.moved.size() && d.moved[i] ? 1.0f : 0.0f;
            coeffs.push_back(glm::vec4(v.coeffs[i][0], moved));
            for (size_t k = 1; k < 9; ++k) coeffs.push_back(glm::vec4(v.coeffs[i][k], 0.0f));
        }
        cells.insert(cells.end(), v.occupancy.begin(), v.occupancy.end());
        records.push_back(rec);
    }
    p->volumeCount = int(records.size());
    p->bytes = coeffs.size() * sizeof(glm::vec4) + cells.size() * 4;
    // Storage buffers may not be empty: a placeholder element where there is nothing to hold.
    if (errors.empty()) errors.push_back(-1.0f);
    if (coeffs.empty()) coeffs.push_back(glm::vec4(0.0f));
    if (cells.empty()) cells.push_back(-1);

    constexpr VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    p->coeffs = vk::Buffer::deviceLocal(ctx, coeffs.data(), coeffs.size() * sizeof(glm::vec4), storage);
    p->cells = vk::Buffer::deviceLocal(ctx, cells.data(), cells.size() * 4, storage);
    p->volumes = vk::Buffer::deviceLocal(ctx, records.data(), records.size() * sizeof(records[0]), storage);
    p->errors = vk::Buffer::deviceLocal(ctx, errors.data(), errors.size() * 4, storage);
    lightAt(ctx, *p, vertexCount, kVertices, g.vertices, kProbeLight, p->block, p->light, p->set);
    g.graph.importBuffer(kProbeCoefficients, p->coeffs.handle(), true);
    g.graph.importBuffer(kProbeCells, p->cells.handle(), true);
    g.graph.importBuffer(kProbeVolumes, p->volumes.handle(), true);
    g.graph.importBuffer(kProbeErrorMaps, p->errors.handle(), true);
    g.graph.importBuffer(kProbeLight, p->light.handle());
    return p;
}

std::unique_ptr<ProbeResources::Detail> buildDetailLight(vk::VulkanContext& ctx, RendererGpu& g, const ProbeResources& p) {
    auto d = std::make_unique<ProbeResources::Detail>();
    d->serial = g.detailSerial;
    d->vertexCount = g.detailVertexCount;
    lightAt(ctx, p, d->vertexCount, kDetailVertices, g.detailVertices, kDetailLight, d->block, d->light, d->set);
    g.graph.importBuffer(kDetailLight, d->light.handle());
    return d;
}

PipelineSet::Build probePassBuild(const vk::VulkanContext& ctx, RendererGpu& g, const ProbeResources& p) {
    if (!g.probeLayout.handle()) {
        const VkDescriptorSetLayout sets[] = {g.emptySet.get(), g.emptySet.get(), p.set.layout()};
        g.probeLayout = vk::PipelineLayout(ctx, sets);
    }
    return [&ctx, layout = g.probeLayout.handle()] {
        return vk::createComputePipeline(ctx, layout, shaders::probeVerticesComp());
    };
}

void addProbePass(Frame& f) {
    ProbeResources* probes = f.probes;
    if (!probes) return;
    ProbeResources::Detail* detail = probes->detail && probes->detail->vertexCount > 0 &&
                                             (probes->lightStale || probes->detail->stale)
                                         ? probes->detail.get()
                                         : nullptr;
    if (!probes->lightStale && !detail) return;
    RendererGpu& g = f.g;
    const VkPipeline pipeline = g.probePass.get(0, [&] { return probePassBuild(f.ctx, g, *probes); });
    PassInfo info{"probe-vertices",
                  {{kProbeCoefficients, Access::ComputeStorageRead},
                   {kProbeCells, Access::ComputeStorageRead},
                   {kProbeVolumes, Access::ComputeStorageRead},
                   {kProbeErrorMaps, Access::ComputeStorageRead},
                   {kVertices, Access::ComputeStorageRead},
                   {kProbeLight, Access::ComputeStorageWrite}},
                  probes->set.bindingNames()};
    const uint32_t n = probes->lightStale ? f.vertexCount : 0, nd = detail ? detail->vertexCount : 0;
    if (n == 0) {
        info.uses.erase(std::remove_if(info.uses.begin(), info.uses.end(),
                                       [](const ResourceUse& u) { return u.resource == kVertices || u.resource == kProbeLight; }),
                        info.uses.end());
        info.bindings = {};
    }
    if (detail) {
        info.uses.push_back({kDetailVertices, Access::ComputeStorageRead});
        info.uses.push_back({kDetailLight, Access::ComputeStorageWrite});
        info.bindings = concat(info.bindings, detail->set.bindingNames());
    }
    const VkDescriptorSet sets[2] = {probes->set.handle(), detail ? detail->set.handle() : VK_NULL_HANDLE};
    g.graph.addPass(std::move(info), [&g, pipeline, sets, n, nd](VkCommandBuffer c) {
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        for (int k = 0; k < 2; ++k) {
            const uint32_t count = k == 0 ? n : nd;
            if (count == 0) continue;
            vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, g.probeLayout.handle(), TLX_SET_SUBSYSTEM, 1,
                                    &sets[k], 0, nullptr);
            vkCmdDispatch(c, (count + 63) / 64, 1, 1);
        }
    });
}

}  // namespace terralux::features
