#pragma once
// The sun's shadow cascades: their depth maps, their block and the pass that draws them.

#include <memory>
#include <vector>

#include "render/Frame.h"
#include "scene/ShadowCascades.h"

namespace terralux {

// The cascades' depth maps (one layer each) and a framebuffer per layer.
struct ShadowResources {
    vk::Image maps;
    std::vector<vk::Framebuffer> framebuffers;
    int resolution = 0, cascades = 0;
    std::vector<glm::mat4> drawn;  // the light projections the maps hold now (empty: none yet)
    bool drawnSkirt = false;       // whether they hold the skirt (terrain.skirt when drawn)
    uint64_t drawnLod = 0;         // the terrain's levels of detail they hold (Frame::lodSerial)
};

namespace features {

// The sun's cascades as fitted for this frame, with `range`'s near distance and the map
// resolution; from cascade `horizonFrom` on (horizonFirstCascade; cascades.size() for none), the
// horizon map `horizon`.
blocks::ShadowBlock packShadows(const RenderSettings& s, const std::vector<Cascade>& cascades,
                                const CascadeRange& range, int resolution, int horizonFrom,
                                const HorizonMapInfo& horizon);
// `cascades` depth maps of `resolution`² texels, one layer each, with a framebuffer per layer.
std::unique_ptr<ShadowResources> buildShadowMaps(vk::VulkanContext& ctx, const RendererGpu& g, int resolution,
                                                 int cascades);
// Draws the cascades again when their light projections moved (the camera, the sun or a shadow
// setting changed); a still camera keeps the maps it drew.
void addShadowPass(Frame& f);

}  // namespace features
}  // namespace terralux
