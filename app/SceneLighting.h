#pragma once
// The project's sun, sky and terrain albedo as the bake and the renderer use them: one place, so
// the baked probes and the preview light the terrain the same way.

#include <memory>

#include "Project.h"
#include "bake/DiffuseBake.h"
#include "scene/SolarPosition.h"

namespace terralux {

// Uniform sky, the HDR (× intensity, turned by rotation), or the physical
// sky (× intensity). Throws ImageError for an unreadable HDR. HDR skies are cached by path, file
// time and size, and rotation; physical skies by sun direction and turbidity. Tint and intensity
// scale the cached environment, so edits of them and of anything else reuse it.
Sky skyOf(const Project& project, const Heightfield& hf);
// How many times an HDR was read and filtered since start (for tests of the cache).
size_t hdrSkyReads();
// How many times a physical sky was sampled and filtered since start.
size_t physicalSkyBuilds();
// Sun, sky and albedo; the caller sets the tracer. In sky mode physical with sun.follow_sky the
// sun's colour and illuminance are the model's, × sky.intensity; in sky mode hdr with
// sun.follow_sky the sun is the image's glow (Sky::glowSun) and the sky the image without it.
BakeLighting lightingOf(const Project& project, const Heightfield& hf);
// Sky mode hdr with sun.follow_sky: the sun is the image's own (its position, illuminance, colour
// and size are not read).
bool sunFromSkyImage(const SceneDescription& scene);
// The image's sun of lightingOf() under sunFromSkyImage, as a TD reads it: azimuth (engine
// space, clockwise from -Z) and elevation, the illuminance in lux (the Rec. 709 luminance of the
// per-channel illuminance), the angular radius, and the share of the image's luminous flux it took.
struct ImageSun {
    double azimuthDeg = 0.0, elevationDeg = 0.0, illuminanceLux = 0.0, angularRadiusDeg = 0.0, shareOfSky = 0.0;
};
ImageSun imageSunOf(const BakeLighting& lighting);
// The same for any sun, with the share of the image's flux it stands for.
ImageSun imageSunOf(const SunLight& sun, double shareOfSky);

// The lighting of scenario `name` (scenarioScene): its sun and sky, with the tracer, albedo and
// water of `shared` (the default's), so every scenario lights the same terrain.
BakeLighting scenarioLightingOf(const Project& project, const std::string& name, const Heightfield& hf,
                                const BakeLighting& shared);

// Where sun.mode date_time puts the sun over `hf`: the place (latitude and longitude as set, or
// the DEM's footprint centre), the clock's offset (as set, or the longitude's nominal zone), the
// solar position there, and the grid convergence that turns its true azimuth into the engine's.
struct SunPlace {
    double latitudeDeg = 0.0, longitudeDeg = 0.0, utcOffsetH = 0.0;
    double gridConvergenceDeg = 0.0;
    SolarPosition position;
};
// The sun's azimuth (engine space: clockwise from -Z) and elevation as the scene lights with
// them: sun.azimuth_deg and sun.elevation_deg in mode manual; in mode date_time the solar
// position turned by the grid convergence, at its apparent (refracted) elevation, with `place`.
// Throws ProjectError for a date outside the calendar or a place the DEM cannot give.
struct SunAngles {
    double azimuthDeg = 0.0, elevationDeg = 0.0;
    std::optional<SunPlace> place;
};
SunAngles sunAnglesOf(const SceneDescription& scene, const Heightfield& hf);
// sunAnglesOf for the project's sun and every scenario's, so an edit or a bake is refused before
// any work when one of them cannot be placed; a scenario's message starts "scenario '<name>': ".
void checkSunPlaces(const SceneDescription& scene, const Heightfield& hf);

// The fog as the renderer draws it: base height and colour resolved (unset base height = the lowest
// terrain; unset colour = the sky's mean radiance over the sphere).
FogSettings resolvedFog(const FogSettings& fog, const Sky& sky, const Heightfield& terrain);
// The authored sun as a light: direction toward it, illuminance × colour, radius in radians.
SunLight sunOf(const SunSettings& sun);
// The water the bake's probe rays see (BakeWater): unset while water.enabled is off, or when the
// level is "auto" and the DEM shows no water surface (water::autoLevel); else the level resolved
// on `hf`.
std::optional<BakeWater> bakeWaterOf(const Project& project, const Heightfield& hf);

// The scene a bake traces, set up once for the bake, the preview and the study: the project's
// sun, sky and albedo (lightingOf), a tracer over `hf` as terrain.skirt says, the water its rays
// see (bakeWaterOf) and the albedo field (surfaceAlbedoOf). The tracer lives here; `lighting`
// points at it. An albedo map that cannot be read throws ImageError, or with
// `constantAlbedoIfUnreadable` leaves terrain.albedo (as the viewport draws it). `beyond`: the
// terrain around `hf` at a coarser resolution (a tile's far halo), which then holds the skirt.
struct BakeScene {
    std::unique_ptr<HeightfieldTracer> tracer;
    BakeLighting lighting;
};
BakeScene bakeSceneOf(const Project& project, const Heightfield& hf, bool constantAlbedoIfUnreadable = false,
                      const HeightfieldTracer* beyond = nullptr);

// The aspect ratio TERRALUX_lighting's cascade splits are computed for (shadows.computed_for_aspect).
inline constexpr double kLightingExportAspect = 16.0 / 9.0;

// The TERRALUX_lighting glTF extension (docs/formats.md, "glTF scene"): what an engine needs to
// light the terrain as the project does. The sun as `lighting` lights it; the sky, shadows and fog
// sections as the project writes them (sceneToJson), with the cascade splits for the project's
// camera over `hf` and what fog's unset values resolve to; and the exposure.
nlohmann::json lightingExtension(const Project& project, const Heightfield& hf,
                                 const BakeLighting& lighting);
// The same with the project's own lighting (lightingOf).
nlohmann::json lightingExtension(const Project& project, const Heightfield& hf);

}  // namespace terralux
