#pragma once
// Sun, sky and height fog: their blocks (the lights set) and the sky pass behind the terrain.

#include "render/Frame.h"

namespace terralux::features {

// The sun and the sky's radiance as SH.
blocks::SunSkyBlock packSunSky(const RenderSettings& s);
// Height fog with its base height and colour resolved.
blocks::AtmosphereBlock packAtmosphere(const FogSettings& fog);
// The sky pipeline for the frame's fog, built on first use (the water's reflection draws it too).
VkPipeline skyPipeline(Frame& f, uint32_t samples);
// Draws the sky where the terrain left the far plane.
void addSkyPass(Frame& f);

}  // namespace terralux::features
