#pragma once
// Every lighting parameter of a Terralux scene, in one place (docs/lighting.md). The project JSON,
// `--set`, the UI and the bake all read these fields; defaults here are the documented ones.

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include "bake/PhysicalSky.h"
#include "blocks/limits.h"

namespace terralux {

// Where the terrain's albedo comes from (docs/lighting.md, "Terrain albedo").
enum class AlbedoMode { Constant, Map, Ramp };

// Albedo by elevation and slope. Heights are metres of DEM elevation, strictly increasing, one
// linear RGB colour each; between two stops the colour is interpolated linearly, below the first
// and above the last it is held. Slopes from rockSlopeDeg[0] to [1] blend (smoothstep) to rock.
// Defaults read as a mountain: green-brown valleys, grey-brown alpine ground, snow from 2800 m,
// rock from 35 to 50 degrees. Linear albedos within the measured ranges of Oke, "Boundary Layer
// Climates" (2nd ed., 1987), Table 1.1: grass and soils 0.1-0.25, rock 0.2-0.3, fresh snow
// 0.75-0.95; vegetation sits low because it is darker in the visible than in the broadband.
struct AlbedoRampSettings {
    std::vector<double> heights{0.0, 1800.0, 2600.0, 2800.0};
    std::vector<glm::vec3> colors{{0.12f, 0.14f, 0.07f},
                                  {0.19f, 0.17f, 0.12f},
                                  {0.24f, 0.22f, 0.19f},
                                  {0.80f, 0.82f, 0.85f}};
    glm::vec3 rockColor{0.25f, 0.22f, 0.19f};
    std::array<double, 2> rockSlopeDeg{35.0, 50.0};
};

// The least GGX roughness of the terrain, after the normals' variance widens it: below it a
// heightfield's sun highlight turns to sparkle no mip chain can hold.
inline constexpr double kRoughnessFloor = 0.25;

struct TerrainSettings {
    std::string dem;                 // path; relative paths are relative to the project file
    double verticalScale = 1.0;      // > 0
    // Lambertian, each in [0, 1]: the whole terrain in mode constant, and where a map does not
    // cover the footprint in mode map.
    glm::vec3 albedo{0.3f, 0.3f, 0.3f};
    AlbedoMode albedoMode = AlbedoMode::Ramp;
    std::string albedoMap;           // RGB(A) raster for mode map; relative to the project file
    AlbedoRampSettings ramp;         // mode ramp
    int maxResolution = 0;           // 0 = source resolution; else longest side, area-averaged
    bool skirt = true;               // ground continues beyond the footprint at the border height
    double roughness = 0.6;          // GGX roughness of the sun's highlight, [kRoughnessFloor, 1]
    bool specularAA = true;          // widen the roughness by the normals' variance (Toksvig)
};

// Procedural micro-detail: drawn by the viewport and --render, never by the bake (the bake is
// about light, not texture).
struct DetailSettings {
    bool enabled = true;
    double normalStrength = 0.4;     // slope of the detail bump, [0, 2]
    double scale = 2.0;              // metres per repeat, [0.1, 100]
    double fadeDistance = 300.0;     // metres from the camera where the detail is gone, > 0
    double albedoVariation = 0.1;    // ± share of the albedo, [0, 0.5]
};

// Manual: azimuth and elevation as authored. DateTime: the sun where it stands over the terrain
// at a date and a local time (renderer/scene/SolarPosition.h).
enum class SunMode { Manual, DateTime };

struct SunSettings {
    SunMode mode = SunMode::Manual;
    double azimuthDeg = 135.0;       // clockwise from north (−Z) toward east (+X); mode manual
    double elevationDeg = 35.0;      // above the horizon, [−90, 90]; mode manual
    // Mode date_time: a Gregorian date "YYYY-MM-DD", hours after local midnight on a clock
    // utcOffsetH ahead of UTC (unset: the longitude's nominal zone), at latitude / longitude
    // (unset: the DEM's footprint centre).
    std::string date = "2026-06-21";
    double timeH = 10.0;
    std::optional<double> utcOffsetH;
    std::optional<double> latitudeDeg;
    std::optional<double> longitudeDeg;
    double illuminance = 100000.0;   // E_sun on a surface facing the sun, lux, >= 0 (a clear day)
    glm::vec3 color{1.0f, 0.96f, 0.9f};
    double angularRadiusDeg = 0.27;  // [0, 45]
    // Sky mode physical: the sun's colour and illuminance come from the sky model, and
    // illuminance and color above are not read.
    bool followSky = true;
};

enum class SkyMode { Uniform, Hdr, Physical };

struct SkySettings {
    SkyMode mode = SkyMode::Uniform;
    // The uniform sky: colour (linear RGB, each in [0, 1]) × luminance (cd/m²) per channel, drawn
    // at the sun's scale (uniformRadiance()). With the default sun's 100 klx, a clear day's
    // direct-to-diffuse ratio (docs/lighting.md, "Sun and sky").
    glm::vec3 color{0.6f, 0.73333333f, 1.0f};
    double luminance = 5000.0;           // cd/m², >= 0
    double intensity = 1.0;              // >= 0, every mode

    // The uniform sky's radiance in scene-linear units: colour × luminance × kSceneUnitsPerLux ×
    // intensity (docs/lighting.md, "Units").
    glm::vec3 uniformRadiance() const { return color * float(luminance * kSceneUnitsPerLux * intensity); }
    std::string hdr;                     // equirectangular image, for mode hdr
    double rotationDeg = 0.0;            // turns the HDR about +Y
    double turbidity = 3.0;              // mode physical: haze, [1.7, 10]
};

// Surface: a quadtree over the terrain-following layer, refined where the interpolation error is
// high (docs/lighting.md, "Surface placement"); it shares the adaptive settings that refine it.
enum class ProbePlacement { Terrain, Box, Adaptive, Surface };

// Placements whose leaves an error tolerance refines (the adaptive.* settings apply).
inline bool refinedByError(ProbePlacement p) { return p == ProbePlacement::Adaptive || p == ProbePlacement::Surface; }
// Placements whose probes stand height_offset above the surface.
inline bool followsSurface(ProbePlacement p) { return p == ProbePlacement::Terrain || p == ProbePlacement::Surface; }

// The project-file spelling of a placement.
inline const char* placementName(ProbePlacement p) {
    switch (p) {
        case ProbePlacement::Terrain: return "terrain";
        case ProbePlacement::Box: return "box";
        case ProbePlacement::Adaptive: return "adaptive";
        case ProbePlacement::Surface: return "surface";
    }
    return "terrain";
}

// Adaptive octree placement (seed 001): cubic cells from max_cell_size down to min_cell_size over
// a box; cells that overlap the terrain surface band go down to the minimum, open air stays
// coarse, one probe per leaf at its centre. The .shprobe grid is the box at the minimum cell size.
// Surface volumes read min_cell_size, max_cell_size (the quadtree's squares; unset: 1/256 and
// 1/8 of the footprint's longer side, the DEM cell at least), tolerance and the budgets; the box,
// band and move settings are the octree's alone.
struct AdaptiveVolumeSettings {
    // Unset = the DEM's cell size (the larger axis), but at least 1/128 of the box's longer
    // horizontal side (autoMinCellSize). Probes closer than the terrain samples see no lighting
    // detail the terrain can produce (docs/lighting.md's 0.5 m suits rooms, not DEMs); the floor
    // keeps a whole SRTM tile in tens of thousands of probes instead of millions.
    std::optional<double> minCellSize;
    // Unset = 16 x min_cell_size, the ratio of docs/lighting.md's terrain example (2 m / 32 m).
    // Must be min_cell_size x 2^k: octree cells halve.
    std::optional<double> maxCellSize;
    // Auto box: the terrain footprint from the lowest terrain up to the highest + this, metres.
    double heightRange = 100.0;
    // Explicit box edge lengths (x, y, z), from the volume's origin; unset = the auto box. The
    // box grows to whole min cells.
    std::optional<glm::vec3> size;
    // A cell overlaps the surface when it reaches within this height above it; unset = one
    // min cell.
    std::optional<double> surfaceBand;
    // The size the surface band forces cells down to; below it only the error tolerance splits
    // them. Unset = min_cell_size (the band is all minimum cells). At least min_cell_size; taken
    // as the largest min_cell_size x 2^k at or below it, at most max_cell_size.
    std::optional<double> surfaceCellSize;
    // Relative interpolation error that splits a leaf (docs/lighting.md); unset = geometric only.
    std::optional<double> tolerance;
    std::optional<int> maxProbes;            // budget for the refinement; unset = none
    std::optional<long long> maxBytes;       // .shprobe file size budget; unset = none
    // A minimum-size leaf whose centre is inside the terrain moves its probe up by at most this
    // share of the cell edge; beyond that it keeps no probe. [0, 0.5] keeps probes in their leaf.
    double maxMoveShare = 0.25;
};

struct ProbeVolumeSettings {
    std::string name = "probes";     // file stem of its .shprobe: [A-Za-z0-9_-]+
    bool enabled = true;
    ProbePlacement placement = ProbePlacement::Terrain;
    // Terrain: (nx, nz) probes; Box: (nx, ny, nz) cells, one probe at each centre. Adaptive and
    // surface volumes ignore grid_dims and spacing; adaptive volumes height_offset too.
    std::array<int, 3> gridDims{8, 1, 8};
    // Terrain: (x, z) of the first probe; Box and Adaptive: (x, y, z) of the min corner.
    // Unset = auto-span (Adaptive: the footprint's min corner at the lowest terrain). Surface
    // volumes always cover the footprint.
    std::optional<glm::vec3> origin;
    // Terrain: (sx, sz) between probes; Box: cube edge in .x. Unset = auto-span.
    std::optional<glm::vec3> spacing;
    double heightOffset = 5.0;       // terrain and surface placement: metres above the triangle surface
    std::optional<int> rayCount;     // unset = the bake quality preset decides
    std::optional<double> fallbackBlendDistance;  // unset = 2 * min(spacing)
    AdaptiveVolumeSettings adaptive;
    // Relative interpolation error the bake meets at the 95th percentile of the error map
    // (docs/lighting.md, "Asking for an accuracy"): it chooses grid_dims (terrain) or
    // adaptive.tolerance (adaptive) and replaces what they say. Unset = they stand.
    std::optional<double> targetError;
};

// How a reflection probe stores its environment (docs/lighting.md, "Reflection probes").
enum class ReflectionEncoding {
    Faces,    // six face colours: the mean radiance over each cube face
    Cubemap,  // a cube map per probe, GGX-prefiltered into a mip chain by roughness
};

// The project-file spelling of an encoding.
inline const char* reflectionEncodingName(ReflectionEncoding e) {
    return e == ReflectionEncoding::Cubemap ? "cubemap" : "faces";
}

// Seed 000's limit on a reflection grid's probes.
inline constexpr int kMaxReflectionProbes = 256;

// Terrain-local reflection probes (seed 000's TV5.3): a (nx, nz) grid placed like a terrain probe
// volume, each probe baked from the heightfield into `encoding`.
struct ReflectionProbeSettings {
    bool enabled = false;
    std::array<int, 2> gridDims{4, 4};           // product <= kMaxReflectionProbes
    std::optional<glm::vec2> origin;             // (x, z) of the first probe; unset = auto-span
    std::optional<glm::vec2> spacing;            // (sx, sz) between probes, > 0; unset = auto-span
    double heightOffset = 5.0;                   // metres above the traced surface
    int rayCount = 16;                           // rays per cube texel
    // The albedo of the ground a probe sees below its horizon where nothing is traced (past the
    // footprint with the skirt off), lit by the open sky and the sun.
    glm::vec3 groundColor{0.22f, 0.18f, 0.14f};
    double strength = 1.0;                       // [0, 1]: how far the probes replace the sky's specular
    std::optional<double> fallbackBlendDistance; // unset = 2 * min(spacing)
    ReflectionEncoding encoding = ReflectionEncoding::Cubemap;
    int resolution = 32;                         // cubemap texels a side of mip 0: a power of two, 8..128
    // Up to 8 probe indices (scene order) the simvx box records carry; empty = the first 8.
    std::vector<int> simvxSubset;
};

enum class QualityPreset { Draft, Standard, High, Reference };
enum class ShEncoding { Radiance, Irradiance };

// Largest interpolation-error map side (BakeSettings::errorMapResolution).
inline constexpr int kMaxErrorMapResolution = 512;

struct BakeSettings {
    QualityPreset quality = QualityPreset::Standard;
    std::optional<int> rays;          // per probe; unset = preset
    std::optional<int> bounces;       // 0 = sky visibility only; unset = preset
    ShEncoding encoding = ShEncoding::Radiance;
    // Window SH just enough that irradiance is never negative (a truncated L2 projection of
    // strongly directional light rings below zero); probes already non-negative are untouched.
    bool deringing = true;
    // Points along the longer side of each volume's interpolation-error map (the interpolation-error debug view);
    // 0 = no map. Each point costs one probe bake.
    int errorMapResolution = 64;
    // Relative Monte Carlo and truncation error the bake aims at: chooses rays and bounces and
    // replaces what rays, bounces and the preset say (docs/lighting.md). Unset = they stand.
    std::optional<double> targetError;
};

struct ExportSettings {
    std::string outDir = "bake";      // relative to the project file
    bool gltf = true;
    double defaultScale = 1.0;
    double defaultAmbient = 0.1;
};

enum class SplitMode { Practical, Manual };
enum class ShadowFilter { Pcss, Pcf, Hard };
// A filter's project-file name.
inline const char* shadowFilterName(ShadowFilter f) {
    return f == ShadowFilter::Pcss ? "pcss" : f == ShadowFilter::Pcf ? "pcf" : "hard";
}

// Cascaded sun shadows (docs/lighting.md, "Shadows"). Cascades cover the view from the near plane
// to the shadow distance; each is a square orthographic depth map fitted to its slice of the view
// as a bounding sphere and snapped to its texels.
struct ShadowSettings {
    bool enabled = true;
    int cascades = 4;                          // 1..4
    SplitMode splitMode = SplitMode::Practical;
    // Practical split scheme (Zhang et al. 2006): C_i = λ·C_log + (1 − λ)·C_uni; λ weights the
    // logarithmic term.
    double splitLambda = 0.75;
    // Manual: the cascades − 1 inner split distances (metres from the camera), strictly
    // increasing and below the shadow distance; unset in practical mode.
    std::optional<std::vector<double>> splits;
    // Shadow distance; unset = the farthest terrain in view.
    std::optional<double> maxDistance;
    int mapResolution = 2048;                  // texels a side, 512..4096
    double depthBias = 1.5;                    // texels of the cascade, along the light
    double normalBias = 0.3;                   // texels of the cascade, along the surface normal
    ShadowFilter filter = ShadowFilter::Pcss;
    // Share of each cascade's depth slice, at its far end, over which its shadow blends into the
    // next cascade's (0: a hard switch).
    double cascadeBlend = 0.1;
    // Where a cascade cannot draw the shadows the DEM's relief casts at this sun
    // (shadow_math.glsl, shadowTakesHorizon), the terrain's own shadow comes from its horizon in
    // the sun's azimuth at every DEM vertex instead (docs/lighting.md, "Shadows").
    bool heightfield = true;
};

// Exponential height fog (docs/lighting.md, "Height fog"): extinction
// σ(h) = density · exp(−(h − base_height) / scale_height).
struct FogSettings {
    bool enabled = true;
    double density = 2.0e-5;                   // 1/m at the base height
    double scaleHeight = 1200.0;               // m over which the density falls by e; 0 = uniform
    std::optional<double> baseHeight;          // metres; unset = the lowest terrain
    // The ambient light the fog scatters toward the camera: colour (linear RGB, each in [0, 1]) ×
    // luminance (cd/m²) per channel, drawn at the sun's scale (ambientRadiance()). Unset = the
    // sky's mean radiance's colour (divided by its largest channel) and luminance (that channel).
    std::optional<glm::vec3> color;
    std::optional<double> luminance;           // cd/m², >= 0
    double inscatter = 1.0;                    // scales the sun's inscatter
    double anisotropy = 0.6;                   // Henyey–Greenstein g, (−1, 1)

    // The ambient inscatter radiance in scene-linear units, colour × luminance × kSceneUnitsPerLux
    // (docs/lighting.md, "Units"); an unset part reads 0 (resolvedFog sets both).
    glm::vec3 ambientRadiance() const {
        return color.value_or(glm::vec3(0.0f)) * float(luminance.value_or(0.0) * kSceneUnitsPerLux);
    }
    // Sets colour and luminance to stand for `radiance` (scene units): the colour divided by its
    // largest channel, the luminance that channel; black stays black at 0 cd/m².
    void setAmbientRadiance(const glm::vec3& radiance) {
        const float peak = std::max({radiance.x, radiance.y, radiance.z, 0.0f});
        color = peak > 0.0f ? glm::max(radiance / peak, glm::vec3(0.0f)) : glm::vec3(0.0f);
        luminance = double(peak) / kSceneUnitsPerLux;
    }
};

// Horizon ambient occlusion of the terrain (docs/lighting.md, "Horizon ambient occlusion"),
// computed by horizonSkyVisibility (terrain/HorizonAO.h).
struct AoSettings {
    bool enabled = true;
    int directions = 32;                       // azimuths swept, 8..64
    std::optional<double> maxDistance;         // metres the horizon search reaches; unset = unbounded
    double strength = 1.0;                     // [0, 1]: how strongly AO darkens the probe light
};

// One Gerstner wave (docs/lighting.md, "Water"). Exactly one of amplitude and steepness is set:
// steepness is k·A (k = 2π / wavelength), the slope of the wave, so A = steepness / k.
struct GerstnerWave {
    double directionDeg = 0.0;        // the way it travels, clockwise from north (−Z) toward east (+X)
    double wavelength = 10.0;         // metres, > 0
    std::optional<double> amplitude;  // metres, >= 0
    std::optional<double> steepness;  // k·A, [0, 1]
    double phase = 0.0;               // radians at t = 0 and the engine origin
};

enum class WaterReflection { Planar, Sky };

// A lake or sea level: a plane at `level` with Gerstner waves (docs/lighting.md, "Water"). The
// crests never loop: the waves' summed steepness Σ k_i·A_i is at most 1.
struct WaterSettings {
    bool enabled = false;
    std::optional<double> level;                 // engine-space metres; unset = the water the DEM shows (water::autoLevel)
    glm::vec3 color{0.02f, 0.05f, 0.06f};        // deep-water scatter albedo, linear RGB in [0, 1]
    glm::vec3 absorption{0.45f, 0.09f, 0.06f};   // extinction per metre, linear RGB, >= 0
    double roughness = 0.05;                     // GGX, of the sun's highlight on the waves, [0.02, 1]
    std::vector<GerstnerWave> waves;             // at most kMaxWaves
    bool depthAware = false;                     // ω² = g·k·tanh(k·h) with the depth h, not g·k
    // Metres from shore over which the waves grow to full; unset = two DEM cells
    // (water::shoreFadeDistance).
    std::optional<double> shoreFadeDistance;
    WaterReflection reflection = WaterReflection::Planar;
    double reflectionScale = 0.5;                // planar reflection target size / frame size, [0.25, 1]
    double distortion = 0.02;                    // screen-space offset of the reflection per unit of wave slope, [0, 0.2]
    static constexpr int kMaxWaves = TLX_MAX_WAVES;  // what the water pass's block holds
};

// Which indirect light the viewport and --render add to the direct sun (docs/lighting.md,
// "Light propagation volumes"): the baked probes, the LPV, both summed, or none. The bake exports
// it in TERRALUX_lighting; it changes no baked file.
enum class IndirectLighting { Probes, Lpv, Both, None };

struct LightingSettings {
    IndirectLighting indirect = IndirectLighting::Probes;
};

// Light propagation volumes (seed 003, docs/lighting.md "Light propagation volumes"): cascaded
// 32^3 volumes ahead of the camera after Kaplanyan & Dachsbacher, "Cascaded Light Propagation
// Volumes for Real-Time Indirect Illumination" (I3D 2010). Each field is one of the engine's
// console variables (lpv.ini); the ranges are ours where the seed gives none.
struct LpvSettings {
    bool enabled = false;                 // rEx.GI.Method = 1
    // Edge of cascade 0, metres, (0, 1e6]; unset: from the terrain (lpv::autoSize), resolved by
    // lpv::resolvedOn wherever the settings meet their terrain.
    std::optional<double> size;
    double fadeRange = 6.0;               // cells at each cascade's boundary faded out, [0, 16]
    double propagationWeight = 0.01;      // share left after crossing a cascade: w^(1/32) per step, [0, 1]
    int propagationIterations = 4;        // [0, 64]
    int updateInterval = 2;               // frames between updates (the viewport's), [0, 600]
    int cascades = 3;                     // 1..4
    double cascadeRatio = 2.0;            // size divisor between cascades, (1, 16]
    double autoCascadeMinSize = 768.0;    // metres, 0 = off: the ratio grows until the smallest is this size
    double cascadeForwardOffset = 0.35;   // centre ahead of the camera, share of each cascade's size, [0, 1]
    bool localLights = true;              // inject `lights` (point and spot) too
    int quality = 1;                      // 0 linear SH, 1 + ZH3 and leak dampening, 2 + cone-traced specular
    int coneTraceSamples = 6;             // quality 2, [1, 64]
    double indirectIntensity = 1.0;       // final multiplier of the LPV's light, [0, 100]
};

enum class LocalLightType { Point, Spot };

// A point or spot light (KHR_lights_punctual's model). The renderer draws its direct light
// (unshadowed) and the LPV its bounce; the diffuse bake leaves lights out (docs/lighting.md).
struct LocalLight {
    LocalLightType type = LocalLightType::Point;
    glm::vec3 position{0.0f};                 // engine space, metres
    glm::vec3 direction{0.0f, -1.0f, 0.0f};   // spot: where the cone points, engine space (normalised on use)
    glm::vec3 color{1.0f};                    // linear RGB, each in [0, 1]
    // Luminous intensity I in candela (KHR_lights_punctual's unit, exported as it is): the
    // illuminance in lux on a surface facing the light 1 m away (E = I / d^2 before the range
    // window), drawn at the sun's scale (emitted()). 30 Mcd gives 3 000 lx 100 m away, the
    // default range's end, where the default sun gives 100 000.
    double intensity = 3.0e7;
    double range = 100.0;                     // metres, > 0: the light reaches nothing beyond
    double innerConeDeg = 20.0;               // spot: full intensity inside, [0, 90)
    double outerConeDeg = 30.0;               // spot: nothing outside, (inner, 90]

    // colour × intensity in scene-linear units at 1 m: candela × kSceneUnitsPerLux, the scale
    // of the sun's lux (docs/lighting.md, "Units").
    glm::vec3 emitted() const { return color * float(intensity * kSceneUnitsPerLux); }
};

// How the picture views (beauty, filled, linear) smooth their edges (docs/lighting.md,
// "Anti-aliasing"): fxaa filters the finished frame along its luminance edges (one full-screen
// pass); ssaa draws every pass at twice the width and height and averages each 2 x 2 block (four
// samples a pixel, four times the shading); msaa2/4/8 rasterise 2, 4 or 8 coverage and depth
// samples a pixel, shading once per pixel and triangle, and resolve them (the largest count the
// device offers up to the one asked for; fxaa where it offers none). The data views always keep
// one exact sample a pixel.
enum class Antialiasing { Off, Fxaa, Ssaa, Msaa2, Msaa4, Msaa8 };
// A mode's project-file name.
inline const char* antialiasingName(Antialiasing a) {
    switch (a) {
        case Antialiasing::Off: return "off";
        case Antialiasing::Fxaa: return "fxaa";
        case Antialiasing::Ssaa: return "ssaa";
        case Antialiasing::Msaa2: return "msaa2";
        case Antialiasing::Msaa4: return "msaa4";
        case Antialiasing::Msaa8: return "msaa8";
    }
    return "off";
}
// The samples a pixel an msaa mode asks for; 1 for the others.
inline uint32_t msaaSamples(Antialiasing a) {
    return a == Antialiasing::Msaa2 ? 2u : a == Antialiasing::Msaa4 ? 4u : a == Antialiasing::Msaa8 ? 8u : 1u;
}

// How the camera finds its exposure (docs/lighting.md, "Exposure"): manual at camera.ev100, or
// metered from the frame: average (the geometric mean luminance of the whole frame) or histogram
// (the mean log luminance between the frame's 10th and 90th percentiles).
enum class ExposureMode { Manual, Average, Histogram };
inline const char* exposureModeName(ExposureMode m) {
    return m == ExposureMode::Manual ? "manual" : m == ExposureMode::Average ? "average" : "histogram";
}

// The EV100 at which one scene unit of luminance displays as 1/1.2 of saturation, the exposure the
// defaults were set for: log2(1 / (1.2 kSceneUnitsPerLux)). The sunny-16 rule's clear day is 15.
inline constexpr double kDefaultEv100 = 14.7616;

// Orbit camera of the viewport and `terralux --render`. Unset target = the footprint centre at
// the mean terrain height; unset radius = frames the whole footprint.
struct CameraSettings {
    std::optional<glm::vec3> target;
    std::optional<double> radius;     // metres, > 0
    double azimuthDeg = 210.0;        // clockwise from north, where the camera stands
    double elevationDeg = 35.0;       // (-90, 90)
    double fovDeg = 45.0;             // vertical, (1, 150)
    ExposureMode exposureMode = ExposureMode::Histogram;
    double ev100 = kDefaultEv100;     // manual exposure, EV at ISO 100
    double exposureEv = 0.0;          // compensation in stops, every mode: 2^EV more displayed light
    double adaptationSeconds = 1.0;   // metered modes, the viewport: time constant toward the meter
    Antialiasing antialiasing = Antialiasing::Fxaa;
};

// A named lighting of the same probe layout (docs/lighting.md, "Lighting scenarios"): its own sun
// and sky, baked into its own .shprobe set beside the project's own lighting (the scenario named
// "default").
struct LightingScenario {
    std::string name = "scenario";  // 1 to 64 of [A-Za-z0-9_-], unique, never "default"
    SunSettings sun;
    SkySettings sky;
};

struct SceneDescription {
    TerrainSettings terrain;
    SunSettings sun;
    SkySettings sky;
    std::vector<ProbeVolumeSettings> probeVolumes{ProbeVolumeSettings{}};
    ReflectionProbeSettings reflectionProbes;
    BakeSettings bake;
    ExportSettings exportSettings;
    CameraSettings camera;
    ShadowSettings shadows;
    FogSettings fog;
    DetailSettings detail;
    AoSettings ao;
    WaterSettings water;
    LightingSettings lighting;
    LpvSettings lpv;
    std::vector<LocalLight> lights;
    std::vector<LightingScenario> scenarios;
};

}  // namespace terralux
