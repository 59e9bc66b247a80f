#pragma once
// Cascaded shadow maps for the sun (docs/lighting.md, "Shadows"): where the cascades split the
// view, and each cascade's light projection. Plain maths, no Vulkan: the renderer draws with it
// and the exporters write the split distances an engine needs.

#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "scene/OrbitCamera.h"
#include "scene/SceneDescription.h"

namespace terralux {

// Practical split scheme (Zhang, Sun, Xu & Lau 2006, "Parallel-split shadow maps"):
// C_i = λ·n·(f/n)^(i/N) + (1 − λ)·(n + (f − n)·i/N), i = 1..N: λ weights the logarithmic term.
// Returns the far distance of each of the N cascades (the last is f).
std::vector<double> practicalSplits(double nearDistance, double farDistance, int cascades, double lambda);

// The view range the cascades cover and where each ends. Distances are along the camera's
// forward axis (view depth), metres.
struct CascadeRange {
    double nearDistance = 0.0, farDistance = 0.0;
    std::vector<double> ends;  // one per cascade, increasing; ends.back() == farDistance
    // Whether terrain lies beyond the last cascade (shadows.max_distance ends before it): then the
    // last cascade fades out over its far shadows.cascade_blend, so the shadow distance is no line.
    bool fadesOut = false;
};

// The shadow range of a camera over the terrain box: from the box's least view depth (at least the near
// plane) to shadows.max_distance, or to the farthest terrain when unset; practical splits or the
// manual ones (manual splits beyond the range are clamped into it, keeping their order).
CascadeRange cascadeRange(const ShadowSettings& settings, const OrbitCamera& camera, float aspect,
                          const glm::vec3& boundsMin, const glm::vec3& boundsMax);

// Manual split distances for `cascades` cascades (cascades − 1 of them) where the authored ones no
// longer fit (a switch to manual mode, another cascade count, a shorter shadow distance): the
// leading `authored` distances that still fit (positive, strictly increasing, below
// `maxDistance`), then the inner ends of `practical` beyond them, then even steps to its far end.
// The distances it adds are whole metres where rounding keeps that order.
std::vector<double> fitManualSplits(const std::vector<double>& authored, int cascades,
                                    const CascadeRange& practical, std::optional<double> maxDistance);

struct Cascade {
    glm::mat4 lightViewProj{1.0f};  // world to the map's clip space (x, y in [−1, 1], z in [0, 1])
    double nearDistance = 0.0, farDistance = 0.0;  // the view slice it covers
    float radius = 0.0f;            // of the slice's bounding sphere, metres
    float texelSize = 0.0f;         // metres per shadow-map texel
    float depthRange = 0.0f;        // metres from the map's z = 0 to z = 1 along the light
};

// One cascade per slice of `range`: an orthographic light view around the slice's bounding sphere
// (its radius depends only on the slice, not on where the camera looks), its centre snapped to
// whole texels in light space so that shadows do not shimmer as the camera turns or moves. The
// depth range spans the whole terrain box so every occluder toward the sun is in the map.
std::vector<Cascade> fitCascades(const CascadeRange& range, const OrbitCamera& camera, float aspect,
                                 const glm::vec3& sunDirection, int resolution,
                                 const glm::vec3& boundsMin, const glm::vec3& boundsMax);

// The terrain's horizon map a frame reads (shadows.heightfield): its vertices a row and rows,
// and the metres between them; width 0 for none.
struct HorizonMapInfo {
    int width = 0, height = 0;
    float cell = 0.0f;
};
// The map of a terrain: every DEM vertex up to `maxSide` a side (the surface maps' 4 096), the
// nearest of every k-th beyond, both spanning the footprint corner to corner.
HorizonMapInfo horizonMapOf(int demWidth, int demDepth, float spanX, float spanZ, int maxSide);
// The first of `cascades` (near to far, texels growing) whose map loses shadows longer than the
// horizon map's cell at a sun `sunElevationSin` high (shadow_math.glsl, shadowTakesHorizon):
// from it on the horizon map stands in for the maps. cascades.size() when none does or there is
// no map.
int horizonFirstCascade(const std::vector<Cascade>& cascades, float sunElevationSin, const HorizonMapInfo& map);

}  // namespace terralux
