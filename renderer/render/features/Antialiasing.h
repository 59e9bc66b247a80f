#pragma once
// The picture views' anti-aliasing (camera.antialiasing; docs/lighting.md, "Anti-aliasing"): the
// frame is drawn into the colour target, then one full-screen pass writes the output image the
// read-back and the swapchain take, either filtering it (fxaa) or averaging its 2 x 2 samples a
// pixel (ssaa, the target twice the output's width and height). Off, or a data view: no pass,
// the colour target is the output.

#include <cstdint>

#include "render/Frame.h"

namespace terralux {

namespace features {

// What a frame of `view` does with `mode`: the colour target's samples a pixel along each side
// (1 or 2) and whether a pass writes the output image.
struct AntialiasingPlan {
    uint32_t scale = 1;
    bool pass = false;
    Antialiasing mode = Antialiasing::Off;
};
AntialiasingPlan antialiasingPlan(Antialiasing mode, const DebugView& view);

// The output image (`width` x `height`) and the set that reads `color` into it.
void buildAntialiasingTarget(vk::VulkanContext& ctx, RendererGpu& g, RenderTarget& t);
// Adds the pass from kColor into kOutput; the frame's target must have been built for `plan`.
void addAntialiasPass(Frame& f, const AntialiasingPlan& plan);

}  // namespace features
}  // namespace terralux
