#pragma once
// What one frame draws: the view, the camera, the scene's sections the renderer reads as the
// project has them, and the lights resolved for the frame (TerrainRenderer::render, ::present).

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "bake/Sky.h"
#include "bake/SphericalHarmonics.h"
#include "scene/OrbitCamera.h"
#include "scene/SceneDescription.h"

namespace terralux {

// A line drawn over the frame in front of everything (the viewport's volume bounds and their
// handles), in the display's colour.
struct GizmoLine {
    glm::vec3 a{0.0f}, b{0.0f};
    glm::vec3 color{1.0f};
};

struct RenderSettings {
    uint32_t width = 640, height = 360;
    int debugView = 0;
    bool probes = true;           // false: exactly the image without probes, diffuse or reflection
                                  // (no probe pass, no reflection probes bound)
    bool linearOutput = false;    // scene-linear values for EXR instead of the display encoding
    // render(): the pixels read back as 8-bit codes (RenderedImage::bytes, what a PNG holds)
    // rather than floats (RenderedImage::rgba).
    bool readbackBytes = false;
    OrbitCamera camera;
    glm::vec3 albedo{0.3f};       // the constant albedo (when no albedo map is set)
    // The scene's own sections, read as they are (docs/lighting.md): the terrain's roughness and
    // normal-variance switch, the AO's use and strength, the micro-detail, the water.
    TerrainSettings terrain;
    AoSettings ao;
    DetailSettings detail;
    // The water is drawn where it is enabled and setWater found its level (none: no water pass,
    // nothing bound).
    WaterSettings water;
    double time = 0.0;            // seconds: the waves' phase
    SunLight sun;
    sh::ShRgb skySh;
    // The sky image's radiance factor and rotation in turns (TerrainRenderer::setSkyImage holds
    // its texels).
    glm::vec3 skyImageScale{1.0f};
    float skyImageRotation = 0.0f;
    float exposure = 1.0f;        // multiplies scene light before the tone curve (2^EV)
    // camera.antialiasing: applied to the picture views only (those drawn with the sky behind).
    Antialiasing antialiasing = Antialiasing::Off;
    ShadowSettings shadows;       // the sun's cascades (shadows.enabled false: no shadow pass)
    // Height fog with base height and colour resolved (fog.enabled false: no fog code runs).
    FogSettings fog;
    bool skirt = true;            // terrain.skirt: the traced surface of the sun-visibility view, drawn
                                  // into the shadow maps and, below the horizon, by the sky pass
    bool showProbePositions = false;  // the overlay of setProbePositions (probe-validity always marks
                                      // moved and rejected probes)
    bool showLeaves = false;          // the overlay of setProbeLeaves
    std::vector<GizmoLine> gizmos;    // drawn last, unlit, never hidden by the terrain
    // reflection_probes.strength, [0, 1]: how far bound reflection probes replace the sky's
    // specular (0 draws the image without them, bit for bit).
    float reflectionStrength = 1.0f;
    // lighting.indirect is lpv or both: the bound LPV's irradiance (and at quality 2 its specular)
    // adds to the ambient in the lit views. The LPV views draw a bound LPV whatever this says.
    bool lpvLight = false;
    // Point and spot lights: their direct light, unshadowed (none: no lights code runs).
    std::vector<LocalLight> lights;
    // The rows the terrain's level of detail is chosen for (0: height). The exposure meter, a small
    // copy of a frame, and the viewport's frames drawn below full resolution draw the full
    // frame's levels: they neither rebuild them nor draw the shadow maps again for their own size.
    uint32_t levelOfDetailRows = 0;
    // With levelOfDetailRows (the viewport's frames below full resolution): a picture whose
    // cascades stand draws the levels its shadow maps hold (the full frame's, or a small frame's
    // after the sun moved); where the cascades moved, so that the maps are drawn again anyway, it
    // takes the levels of its own height, coarser and cheaper to cast and to draw.
    bool levelOfDetailYields = false;
    // Off (the viewport's frames): a horizon map for a new sun (shadows.heightfield) is swept on a
    // worker and the frames draw the map held until it lands (TerrainRenderer::sunHorizonSweeping);
    // on, the frame waits for it.
    bool waitForHorizon = true;
    // Off (the viewport's frames): a picture's levels of detail for a new camera are chosen and
    // built on a worker, and the frames draw the set held until it lands
    // (TerrainRenderer::levelOfDetailBuilding); on, the frame chooses its own.
    bool waitForLevelOfDetail = true;
};

}  // namespace terralux
