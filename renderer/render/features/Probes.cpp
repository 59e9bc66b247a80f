#include "render/features/Probes.h"

#include "ShaderBinaries.h"
#include "vk/ComputePipeline.h"

namespace terralux::features {

using namespace frame;

void addProbePass(Frame& f) {
    ProbeResources* probes = f.probes;
    if (!probes || !probes->lightStale) return;
    RendererGpu& g = f.g;
    if (!g.probePass) {
        const VkDescriptorSetLayout sets[] = {g.emptySet.get(), g.emptySet.get(), probes->set.layout()};
        g.probeLayout = vk::PipelineLayout(f.ctx, sets);
        g.probePass = vk::createComputePipeline(f.ctx, g.probeLayout.handle(), shaders::probeVerticesComp());
    }
    PassInfo info{"probe-vertices",
                  {{kProbeCoefficients, Access::ComputeStorageRead},
                   {kProbeCells, Access::ComputeStorageRead},
                   {kProbeVolumes, Access::ComputeStorageRead},
                   {kProbeErrorMaps, Access::ComputeStorageRead},
                   {kVertices, Access::ComputeStorageRead},
                   {kProbeLight, Access::ComputeStorageWrite}},
                  probes->set.bindingNames()};
    const uint32_t n = f.vertexCount;
    g.graph.addPass(std::move(info), [&g, probes, n](VkCommandBuffer c) {
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_COMPUTE, g.probePass.get());
        VkDescriptorSet set = probes->set.handle();
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_COMPUTE, g.probeLayout.handle(),
                                TLX_SET_SUBSYSTEM, 1, &set, 0, nullptr);
        vkCmdDispatch(c, (n + 63) / 64, 1, 1);
    });
}

}  // namespace terralux::features
