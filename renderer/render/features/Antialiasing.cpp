#include "render/features/Antialiasing.h"

#include "ShaderBinaries.h"

namespace terralux::features {

using namespace frame;

AntialiasingPlan antialiasingPlan(Antialiasing mode, const DebugView& view, uint32_t sampleCounts) {
    // The data views are measured per pixel (shadow agreement, masks, indices): one exact sample.
    if (mode == Antialiasing::Off || view.background == ViewBackground::Black) return {};
    if (const uint32_t asked = msaaSamples(mode); asked > 1) {
        for (uint32_t n = asked; n >= 2; n /= 2)
            if (sampleCounts & n) {
                AntialiasingPlan p;
                p.mode = n == 8 ? Antialiasing::Msaa8 : n == 4 ? Antialiasing::Msaa4 : Antialiasing::Msaa2;
                p.samples = n;
                p.resolve = true;
                return p;
            }
        mode = Antialiasing::Fxaa;
    }
    return {mode == Antialiasing::Ssaa ? 2u : 1u, true, mode};
}

namespace {

vk::DescriptorSetBuilder sourceSet(VkImageView color, VkSampler sampler) {
    vk::DescriptorSetBuilder b;
    b.image(0, "frame", color, sampler, VK_SHADER_STAGE_FRAGMENT_BIT);
    return b;
}

VkPipeline antialiasPipeline(Frame& f, Antialiasing mode) {
    RendererGpu& g = f.g;
    const bool linear = f.s.linearOutput;
    vk::UniquePipeline& pipeline = g.antialias[size_t(mode == Antialiasing::Ssaa) * 2 + size_t(linear)];
    if (!pipeline) {
        vk::GraphicsPipelineDesc d;
        d.vert = shaders::fullscreenVert();
        d.frag = shaders::antialiasFrag();
        d.fragConstants = {mode == Antialiasing::Ssaa ? 1u : 0u, linear ? 1u : 0u};
        d.depthWrite = false;
        pipeline = vk::createGraphicsPipeline(f.ctx, g.outputPass.handle(), g.antialiasLayout.handle(), d);
    }
    return pipeline.get();
}

}  // namespace

void buildAntialiasingTarget(vk::VulkanContext& ctx, RendererGpu& g, RenderTarget& t) {
    if (!g.antialiasSetLayout) {
        g.antialiasSetLayout = sourceSet(VK_NULL_HANDLE, g.linear.handle()).buildLayout(ctx);
        const VkDescriptorSetLayout sets[] = {g.antialiasSetLayout.get()};
        g.antialiasLayout = vk::PipelineLayout(ctx, sets);
        const VkFormat colorFormats[] = {vk::kColorFormat};
        g.outputPass = vk::RenderPass(ctx, {colorFormats, VK_FORMAT_UNDEFINED, false, false});
    }
    t.output = vk::Image::colorTarget(ctx, t.width, t.height);
    const VkImageView views[] = {t.output.view()};
    t.outputFramebuffer = vk::Framebuffer(ctx, g.outputPass, views, t.width, t.height);
    t.source = sourceSet(t.color.view(), g.linear.handle()).build(ctx);
}

void buildResolveTarget(vk::VulkanContext& ctx, RenderTarget& t) {
    t.output = vk::Image::resolveTarget(ctx, t.width, t.height);
}

void addResolvePass(Frame& f, const AntialiasingPlan& plan) {
    if (!plan.resolve) return;
    RenderTarget& t = *f.g.target;
    const VkImage source = t.color.handle(), dest = t.output.handle();
    const uint32_t w = t.width, h = t.height;
    f.g.graph.addPass({"resolve", {{kColor, Access::TransferRead}, {kOutput, Access::TransferWrite}}, {}},
                      [source, dest, w, h](VkCommandBuffer c) { copyColor(c, source, dest, w, h, true); });
}

void addAntialiasPass(Frame& f, const AntialiasingPlan& plan) {
    if (!plan.pass) return;
    RenderTarget& t = *f.g.target;
    const VkPipeline pipeline = antialiasPipeline(f, plan.mode);
    PassInfo info{"antialias", {{kColor, Access::FragmentSampledRead}, {kOutput, Access::ColorAttachmentClear}},
                  t.source.bindingNames()};
    f.g.graph.addPass(std::move(info), [&f, &t, pipeline](VkCommandBuffer c) {
        VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
        rbi.renderPass = f.g.outputPass.handle();
        rbi.framebuffer = t.outputFramebuffer.handle();
        rbi.renderArea = {{0, 0}, {t.width, t.height}};
        vkCmdBeginRenderPass(c, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        setViewport(c, t.width, t.height);
        vkCmdBindPipeline(c, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
        const VkDescriptorSet set = t.source.handle();
        vkCmdBindDescriptorSets(c, VK_PIPELINE_BIND_POINT_GRAPHICS, f.g.antialiasLayout.handle(), 0, 1, &set, 0,
                                nullptr);
        vkCmdDraw(c, 3, 1, 0, 0);
        vkCmdEndRenderPass(c);
    });
}

}  // namespace terralux::features
