#pragma once
// Sun, sky and height fog: their blocks (the lights set) and the sky pass behind the terrain.

#include "render/Frame.h"
#include "render/PipelineSet.h"

namespace terralux::features {

// The sun and the sky's radiance as SH.
blocks::SunSkyBlock packSunSky(const RenderSettings& s);
// Height fog with its base height and colour resolved.
blocks::AtmosphereBlock packAtmosphere(const FogSettings& fog);
// The sky pipeline's variant for the frame's fog, and its build for a pass of `samples` a pixel,
// which may run on a worker (PipelineSet).
int skyVariant(bool fog);
PipelineSet::Build skyPipelineBuild(const vk::VulkanContext& ctx, const RendererGpu& g, int variant, uint32_t samples);
// The sky pipeline for the frame's fog, built on first use (the water's reflection draws it too).
VkPipeline skyPipeline(Frame& f, uint32_t samples);
// Draws the sky where the terrain left the far plane.
void addSkyPass(Frame& f);

}  // namespace terralux::features
