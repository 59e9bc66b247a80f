#include "render/features/Atmosphere.h"

#include "ShaderBinaries.h"

namespace terralux::features {

using namespace frame;

blocks::SunSkyBlock packSunSky(const RenderSettings& s) {
    blocks::SunSkyBlock sunSky;
    sunSky.sunDirection = s.sun.direction;
    sunSky.sunAngularRadius = s.sun.angularRadius;
    sunSky.sunIlluminance = s.sun.illuminance;
    for (int k = 0; k < 9; ++k) sunSky.skySh[k] = glm::vec4(s.skySh.c[size_t(k)], 0.0f);
    return sunSky;
}

blocks::AtmosphereBlock packAtmosphere(const FogSettings& fog) {
    blocks::AtmosphereBlock atmosphere;
    atmosphere.fogDensity = float(fog.density);
    atmosphere.fogFalloff = float(fog.scaleHeight > 0.0 ? 1.0 / fog.scaleHeight : 0.0);
    atmosphere.fogBase = float(fog.baseHeight.value_or(0.0));
    atmosphere.fogAnisotropy = float(fog.anisotropy);
    atmosphere.fogColor = fog.ambientRadiance();
    atmosphere.sunInscatter = float(fog.inscatter);
    return atmosphere;
}

int skyVariant(bool fog) { return fog ? 1 : 0; }

PipelineSet::Build skyPipelineBuild(const vk::VulkanContext& ctx, const RendererGpu& g, int variant, uint32_t samples) {
    vk::GraphicsPipelineDesc d;
    d.vert = shaders::fullscreenVert();
    d.frag = shaders::skyBackgroundFrag();
    d.fragConstants = {uint32_t(variant & 1)};
    d.depthWrite = false;
    d.samples = samples;
    const VkRenderPass pass = g.drawPassFor(samples).handle();
    const VkPipelineLayout layout = g.terrainLayouts[0].handle();
    return [&ctx, pass, layout, d = std::move(d)] { return vk::createGraphicsPipeline(ctx, pass, layout, d); };
}

VkPipeline skyPipeline(Frame& f, uint32_t samples) {
    const int variant = skyVariant(f.fog);
    return f.g.sky.get(variant | kSamplesKey(samples), [&] { return skyPipelineBuild(f.ctx, f.g, variant, samples); });
}

void addSkyPass(Frame& f) {
    if (!f.sky) return;
    PassInfo info{"sky",
                  {{kColor, Access::ColorAttachmentDraw}, {kDepth, Access::DepthAttachmentDraw}},
                  concat(f.slot.view.bindingNames(), f.slot.lights.bindingNames())};
    if (f.fog) info.bindings.push_back("fog");
    const VkPipeline pipeline = skyPipeline(f, f.samples);
    const VkDescriptorSet sets[] = {f.slot.view.handle(), f.slot.lights.handle()};
    f.g.graph.addPass(std::move(info), [&f, pipeline, sets](VkCommandBuffer c) {
        f.beginDrawing(c);
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, f.g.terrainLayouts[0].handle(), TLX_SET_VIEW, 2,
                                sets, 0, nullptr);
        vkCmdDraw(c, 3, 1, 0, 0);
        vkCmdEndRenderPass(c);
    });
}

}  // namespace terralux::features
