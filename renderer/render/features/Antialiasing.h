#pragma once
// The picture views' anti-aliasing (camera.antialiasing; docs/lighting.md, "Anti-aliasing"): the
// frame is drawn into the colour target, then one full-screen pass writes the output image the
// read-back and the swapchain take, either filtering it (fxaa) or averaging its 2 x 2 samples a
// pixel (ssaa, the target twice the output's width and height). msaa: the colour and depth
// targets hold 2, 4 or 8 samples a pixel and a resolve writes the output image. Off, or a data
// view: no pass, the colour target is the output.

#include <cstdint>

#include "render/Frame.h"

namespace terralux {

namespace features {

// What a frame of `view` does with `mode`: the colour target's pixels a pixel along each side
// (1 or 2), its samples a pixel (msaa), whether a pass filters it into the output image or a
// resolve averages its samples into it, and the mode drawn (an msaa mode the device lacks
// becomes the largest count it has below, or fxaa).
struct AntialiasingPlan {
    uint32_t scale = 1;
    bool pass = false;
    Antialiasing mode = Antialiasing::Off;
    uint32_t samples = 1;
    bool resolve = false;
};
// `sampleCounts`: the device's VkSampleCountFlags for a colour and depth framebuffer.
AntialiasingPlan antialiasingPlan(Antialiasing mode, const DebugView& view, uint32_t sampleCounts);

// Adds the resolve of the multisampled kColor into kOutput (plan.resolve).
void addResolvePass(Frame& f, const AntialiasingPlan& plan);
// The output image a resolve writes (`width` x `height`).
void buildResolveTarget(vk::VulkanContext& ctx, RenderTarget& t);

// The output image (`width` x `height`) and the set that reads `color` into it.
void buildAntialiasingTarget(vk::VulkanContext& ctx, RendererGpu& g, RenderTarget& t);
// Adds the pass from kColor into kOutput; the frame's target must have been built for `plan`.
void addAntialiasPass(Frame& f, const AntialiasingPlan& plan);

}  // namespace features
}  // namespace terralux
