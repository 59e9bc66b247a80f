#pragma once
// Light propagation volumes and the local lights: the volumes on the GPU, the block and lights the
// terrain's LPV set binds, and the propagation pass for volumes the renderer propagates.

#include <memory>
#include <vector>

#include "render/Frame.h"
#include "scene/SceneDescription.h"

namespace terralux {

namespace lpv {
class Volumes;  // lpv/Lpv.h
}

// Present only while volumes are bound. Every cascade's light volume (its three channels one
// after another, Lpv.h's layout) and geometry volume, uploaded once per update; the block's
// cascade records come with them. Volumes left to the renderer to propagate upload their
// injected light instead (to `light`, and to region 0 of `work`), and the first frame or sample
// that reads `light` runs the propagation pass into it (`steps` > 0 until then).
struct LpvResources {
    std::shared_ptr<const lpv::Volumes> volumes;
    vk::Buffer light, geometry;
    blocks::LpvBlock block;
    vk::Buffer work, scales, propagationBlock;
    vk::DescriptorSet propagationSet;
    int steps = 0;
    uint32_t cells = 0;  // cascades x 32^3
    double viewRange = 0.0;  // lpv::lightRange of cascade 0: the LPV views' white point
};

namespace features {

// The point and spot lights the lit views add (at least one record: the buffer is never empty).
std::vector<blocks::LocalLightRecord> packLocalLights(const std::vector<LocalLight>& lights, bool used);
// The terrain's LPV block for this frame: the volumes' (or none) with the frame's local lights.
blocks::LpvBlock packLpv(const Frame& f);
// The volumes' light and geometry uploaded with the block's cascades; for volumes left to the
// renderer to propagate, the work regions, send scales and the propagation pass's set and
// pipeline too. Null for no volumes.
std::unique_ptr<LpvResources> buildLpv(vk::VulkanContext& ctx, RendererGpu& g,
                                       std::shared_ptr<const lpv::Volumes> volumes);
// The owed propagation steps (lpv_propagate.comp), timed where the device writes timestamps.
void recordLpvPropagation(RendererGpu& g, VkCommandBuffer cb);
// Those steps as the frame's pass, once, before anything reads the light.
void addLpvPropagationPass(Frame& f);

}  // namespace features
}  // namespace terralux
