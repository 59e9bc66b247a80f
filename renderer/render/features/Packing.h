#pragma once
// Each feature's uniform block, packed from the frame's settings by the one function that writes
// it (docs/ARCHITECTURE.md, "One parameter, end to end"). Plain functions of their inputs: the
// renderer calls them per frame, and a test can call them without a device.

#include <vector>

#include <glm/vec2.hpp>

#include "render/RenderSettings.h"
#include "render/UniformBlocks.h"
#include "scene/DebugViews.h"
#include "scene/ShadowCascades.h"

namespace terralux::features {

// The terrain's extent and maps as the surface block needs them.
struct SurfaceInputs {
    glm::vec2 footprintMin{0.0f}, footprintSpan{0.0f};  // (x, z) of the DEM's footprint, metres
    glm::vec2 normalAoMapSize{1.0f}, albedoMapSize{1.0f};  // texels, level 0
    bool albedoMap = false;  // the albedo map holds the albedo (else s.albedo)
    bool ao = false;         // the normal-AO map holds the horizon AO
    float probeAoLevel = 0.0f;  // the normal-AO mip level as coarse as the finest probes (0: none)
};

// Camera and frame: the view-projection for `extent` (the terrain's largest span, which sets the
// clip planes), the viewport, the view and what the per-vertex attribute holds.
blocks::CameraBlock packCamera(const RenderSettings& s, float extent, const DebugView& view);
// The camera mirrored in the water plane at `level`, drawing scene-linear beauty into a
// `width` × `height` reflection.
blocks::CameraBlock packMirroredCamera(const RenderSettings& s, const blocks::CameraBlock& camera, float extent,
                                       float level, float width, float height);
// Terrain surface and material: albedo, GGX roughness, exposure, AO use, micro-detail.
blocks::SurfaceBlock packSurface(const RenderSettings& s, const SurfaceInputs& in);
// The sun and the sky's radiance as SH.
blocks::SunSkyBlock packSunSky(const RenderSettings& s);
// Height fog with its base height and colour resolved.
blocks::AtmosphereBlock packAtmosphere(const FogSettings& fog);
// The sun's cascades as fitted for this frame, with `range`'s near distance and the map
// resolution.
blocks::ShadowBlock packShadows(const RenderSettings& s, const std::vector<Cascade>& cascades,
                                const CascadeRange& range, int resolution);
// The water's field and mesh as setWater built them.
struct WaterInputs {
    float level = 0.0f;           // engine y
    float shoreFadeDistance = 0;  // metres (water::shoreFadeDistance)
    glm::vec2 fieldSize{1.0f};    // texels of the depth/shore field
    float meshSpacing = 1.0f;     // metres between the water mesh's vertices
};
blocks::WaterBlock packWater(const RenderSettings& s, const WaterInputs& in);
// The point and spot lights the lit views add (at least one record: the buffer is never empty).
std::vector<blocks::LocalLightRecord> packLocalLights(const std::vector<LocalLight>& lights, bool used);
// The probe markers' and octree leaves' overlay.
blocks::OverlayBlock packOverlay(const RenderSettings& s, float smallestLeaf, float smallestLeafPixels);

}  // namespace terralux::features
