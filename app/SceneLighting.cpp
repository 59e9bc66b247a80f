#include "SceneLighting.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <list>
#include <mutex>
#include <numbers>

#include <glm/common.hpp>
#include <glm/trigonometric.hpp>

#include "EnvironmentImage.h"
#include "ImageFile.h"
#include "TerrainLoading.h"
#include "bake/HeightfieldTracer.h"
#include "LpvConsoleVariables.h"
#include "lpv/Lpv.h"
#include "bake/PhysicalSky.h"
#include "ParameterTable.h"
#include "ShaderMath.h"
#include "scene/ShadowCascades.h"
#include "scene/SolarPosition.h"
#include "terrain/SurfaceMaps.h"
#include "water/Water.h"

namespace terralux {

namespace {

// An edit of the sun, the sky's intensity, or a camera move must not read and filter the
// HDR again: the last few environments are kept, keyed by file and rotation, and scaled by the
// intensity on the way out. A file rewritten on disk (new time or size) is a new key.
struct SkyKey {
    std::string path;
    std::filesystem::file_time_type time;
    std::uintmax_t size = 0;
    float rotation = 0.0f;
    bool operator==(const SkyKey&) const = default;
};

std::mutex skyMutex;
std::list<std::pair<SkyKey, Sky>> skyCache;  // most recent first
std::atomic<size_t> skyReads{0};
constexpr size_t kSkyCacheEntries = 4;

// Sampling and filtering the physical sky takes tens of milliseconds: it is kept too, keyed by
// what shapes it (the sun's direction and the turbidity); intensity scales it on the way out.
struct PhysicalKey {
    glm::vec3 sun{0.0f};
    double turbidity = 0.0;
    bool operator==(const PhysicalKey&) const = default;
};
std::list<std::pair<PhysicalKey, Sky>> physicalCache;  // most recent first, under skyMutex
std::atomic<size_t> physicalBuilds{0};

glm::vec3 sunDirectionOf(const SceneDescription& scene, const Heightfield& hf) {
    const SunAngles a = sunAnglesOf(scene, hf);
    return sunDirection(a.azimuthDeg, a.elevationDeg);
}

Sky physicalSkyOf(const SceneDescription& scene, const Heightfield& hf) {
    const PhysicalKey key{sunDirectionOf(scene, hf), scene.sky.turbidity};
    {
        std::lock_guard lock(skyMutex);
        for (auto it = physicalCache.begin(); it != physicalCache.end(); ++it)
            if (it->first == key) {
                physicalCache.splice(physicalCache.begin(), physicalCache, it);
                return it->second;
            }
    }
    Sky sky = Sky::physical(PhysicalSky(key.sun, key.turbidity));
    ++physicalBuilds;
    std::lock_guard lock(skyMutex);
    physicalCache.emplace_front(key, sky);
    if (physicalCache.size() > kSkyCacheEntries) physicalCache.pop_back();
    return sky;
}

}  // namespace

size_t hdrSkyReads() { return skyReads.load(); }
size_t physicalSkyBuilds() { return physicalBuilds.load(); }

void checkSunPlaces(const SceneDescription& scene, const Heightfield& hf) {
    if (!sunFromSkyImage(scene)) (void)sunAnglesOf(scene, hf);
    for (const LightingScenario& l : scene.scenarios) {
        try {
            const SceneDescription lit = scenarioScene(scene, l.name);
            if (!sunFromSkyImage(lit)) (void)sunAnglesOf(lit, hf);
        } catch (const ProjectError& e) {
            throw ProjectError("scenario '" + l.name + "': " + e.what());
        }
    }
}

SunAngles sunAnglesOf(const SceneDescription& scene, const Heightfield& hf) {
    const SunSettings& s = scene.sun;
    SunAngles a{s.azimuthDeg, s.elevationDeg, std::nullopt};
    if (s.mode == SunMode::Manual) return a;
    // Validation gave the date's pattern; the calendar and the year range are checked here
    // too, so a scene built in code fails with the same rule.
    const std::optional<CivilDate> date = parseCivilDate(s.date);
    if (!date)
        throw ProjectError("sun.date: \"" + s.date + "\" is not " + civilDateRule());
    if ((!s.latitudeDeg || !s.longitudeDeg) && !hf.geo.located())
        throw ProjectError("sun.mode: date_time places the sun over the DEM" +
                           (scene.terrain.dem.empty() ? std::string() : " " + scene.terrain.dem) +
                           ", which carries no CRS: set sun.latitude_deg and sun.longitude_deg");
    SunPlace place;
    place.latitudeDeg = s.latitudeDeg.value_or(hf.geo.latitudeDeg);
    place.longitudeDeg = s.longitudeDeg.value_or(hf.geo.longitudeDeg);
    place.utcOffsetH = s.utcOffsetH.value_or(nominalUtcOffsetHours(place.longitudeDeg));
    // The engine's north is the DEM grid's; a place given by hand over a DEM without a CRS has
    // none to turn by.
    place.gridConvergenceDeg = hf.geo.located() ? hf.geo.gridConvergenceDeg : 0.0;
    place.position = solarPosition(*date, s.timeH, place.utcOffsetH, place.latitudeDeg, place.longitudeDeg);
    double az = std::fmod(place.position.azimuthDeg - place.gridConvergenceDeg + 360.0, 360.0);
    a.azimuthDeg = az;
    // The sun as seen: refraction lifts it (0.48° at the geometric horizon).
    a.elevationDeg = place.position.apparentElevationDeg;
    a.place = place;
    return a;
}

Sky skyOf(const Project& p, const Heightfield& hf) {
    const SkySettings& s = p.scene.sky;
    if (s.mode == SkyMode::Uniform) return Sky::uniform(s.uniformRadiance());
    // sky.color and sky.luminance are not read: the model gives them; intensity exposes sky and sun alike.
    if (s.mode == SkyMode::Physical) return physicalSkyOf(p.scene, hf).scaled(glm::vec3(float(s.intensity)));
    const std::string path = p.hdrPath().string();
    SkyKey key{path, {}, 0, float(s.rotationDeg)};
    // The image's colour and scale are the sky (sky.color and sky.luminance are the uniform sky's); intensity scales it.
    const glm::vec3 scale(float(s.intensity));
    std::error_code ec;
    key.time = std::filesystem::last_write_time(path, ec);
    key.size = ec ? 0 : std::filesystem::file_size(path, ec);
    {
        std::lock_guard lock(skyMutex);
        for (auto it = skyCache.begin(); it != skyCache.end(); ++it)
            if (it->first == key) {
                skyCache.splice(skyCache.begin(), skyCache, it);
                return it->second.scaled(scale);  // levels are shared: no copy of the image
            }
    }
    RgbImage img = readEquirectImage(path);
    ++skyReads;
    Sky sky = Sky::equirect(std::move(img.rgb), img.width, img.height, 1.0f, float(s.rotationDeg));
    if (!ec) {
        std::lock_guard lock(skyMutex);
        skyCache.emplace_front(key, sky);
        if (skyCache.size() > kSkyCacheEntries) skyCache.pop_back();
    }
    return sky.scaled(scale);
}

FogSettings resolvedFog(const FogSettings& fog, const Sky& sky, const Heightfield& terrain) {
    FogSettings f = fog;
    if (!f.baseHeight) f.baseHeight = double(terrain.minHeight());
    // The mean radiance over the sphere is the SH DC term times Y_00 = 1 / (2√π); what the fog
    // leaves unset of colour and luminance comes from it.
    FogSettings mean;
    mean.setAmbientRadiance(glm::max(sky.sh().c[0] * 0.28209479f, glm::vec3(0.0f)));
    if (!f.color) f.color = mean.color;
    if (!f.luminance) f.luminance = mean.luminance;
    return f;
}

SunLight sunOf(const SunSettings& s) {
    SunLight sun;
    sun.direction = sunDirection(s.azimuthDeg, s.elevationDeg);
    sun.illuminance = s.color * sceneUnitsOfLux(s.illuminance);
    sun.angularRadius = float(s.angularRadiusDeg * std::numbers::pi / 180.0);
    return sun;
}

bool sunFromSkyImage(const SceneDescription& scene) {
    return scene.sky.mode == SkyMode::Hdr && scene.sun.followSky;
}

ImageSun imageSunOf(const SunLight& sun, double shareOfSky) {
    const glm::dvec3 d(sun.direction);
    return {glm::degrees(std::atan2(d.x, -d.z)), glm::degrees(std::asin(std::clamp(d.y, -1.0, 1.0))),
            double(glsl::rec709Luminance(sun.illuminance)) / kSceneUnitsPerLux, glm::degrees(double(sun.angularRadius)),
            shareOfSky};
}

ImageSun imageSunOf(const BakeLighting& l) { return imageSunOf(l.sun, double(l.sky.takenGlowShare())); }

BakeLighting lightingOf(const Project& p, const Heightfield& hf) {
    const SceneDescription& scene = p.scene;
    BakeLighting l;
    l.sky = skyOf(p, hf);
    l.albedo = scene.terrain.albedo;
    if (sunFromSkyImage(scene)) {
        // The image's glow lights as the sun, shadowed by the renderer's maps at the pixel, and
        // the probes keep the rest: a sun baked into probes a kilometre apart smears its shadows.
        // A glow too wide to be a sun, or none, stays in the sky: no sun lights besides it.
        if (l.sky.glowIsSun()) {
            l.sun = l.sky.glowSun();
            l.sky = l.sky.withoutGlow();
        } else {
            l.sun = SunLight{};
        }
        return l;
    }
    l.sun.direction = sunDirectionOf(scene, hf);
    if (scene.sky.mode == SkyMode::Physical && scene.sun.followSky)
        l.sun.illuminance = PhysicalSky(l.sun.direction, scene.sky.turbidity).sunIlluminance() *
                            float(scene.sky.intensity);
    else
        l.sun.illuminance = sunOf(scene.sun).illuminance;
    l.sun.angularRadius = float(scene.sun.angularRadiusDeg * std::numbers::pi / 180.0);
    return l;
}

BakeLighting scenarioLightingOf(const Project& project, const std::string& name, const Heightfield& hf,
                                const BakeLighting& shared) {
    Project lit = project;
    lit.scene = scenarioScene(project.scene, name);
    BakeLighting l = lightingOf(lit, hf);
    l.tracer = shared.tracer;
    l.albedo = shared.albedo;
    l.surface = shared.surface;
    l.water = shared.water;
    return l;
}

std::optional<BakeWater> bakeWaterOf(const Project& p, const Heightfield& hf) {
    const WaterSettings& w = p.scene.water;
    if (!w.enabled) return std::nullopt;
    const std::optional<double> level = water::waterLevel(w, hf);
    if (!level) return std::nullopt;  // "auto" found no water in the DEM
    return BakeWater{float(*level), w.color};
}

BakeScene bakeSceneOf(const Project& project, const Heightfield& hf, bool constantAlbedoIfUnreadable,
                      const HeightfieldTracer* beyond) {
    BakeScene b;
    b.lighting = lightingOf(project, hf);
    b.tracer = std::make_unique<HeightfieldTracer>(
        hf, HeightfieldTracer::Options{beyond ? false : project.scene.terrain.skirt, HeightfieldTracer::Kernel::kAuto, beyond});
    b.lighting.tracer = b.tracer.get();
    b.lighting.water = bakeWaterOf(project, hf);
    try {
        b.lighting.surface = surfaceAlbedoOf(project, hf);
    } catch (const ImageError&) {
        if (!constantAlbedoIfUnreadable) throw;
    }
    return b;
}

namespace {

nlohmann::json shortest(const glm::vec3& v) {
    return {shortestDecimal(v.x), shortestDecimal(v.y), shortestDecimal(v.z)};
}

}  // namespace

nlohmann::json lightingExtension(const Project& p, const Heightfield& hf, const BakeLighting& l) {
    const SceneDescription& scene = p.scene;
    // The project's own writer: the sections read exactly as --print-project prints them, and a
    // parameter added to the table appears here with no edit.
    const nlohmann::json authored = sceneToJson(scene);
    nlohmann::json ext = nlohmann::json::object();
    // Sections an engine takes as authored; a later feature's section is one more name here.
    for (const char* section : {"sky", "shadows", "fog"}) ext[section] = authored.at(section);
    // The camera's exposure as authored, and the scale of the units every light here is in, so an
    // engine exposes the same way: display = scene × 2^exposure_ev / (1.2 × 2^ev100 × scene_units_per_lux).
    for (const char* key : {"exposure_mode", "ev100", "exposure_ev", "adaptation_s"}) ext[key] = authored.at("camera").at(key);
    ext["scene_units_per_lux"] = kSceneUnitsPerLux;

    // The sun as the bake and the renderer light with it (BakeLighting), so a sky model that
    // moves or tints the sun shows here, beside the authored azimuth and elevation; illuminance ×
    // color is the per-channel illuminance they use. Values the authored sun gives exactly stay
    // as authored: recovering them from the floats would only add rounding.
    nlohmann::json& sun = ext["sun"] = authored.at("sun");
    const SunLight asAuthored = sunOf(scene.sun);
    sun["direction"] = shortest(l.sun.direction);
    // A date and a time: where they put the sun, so an engine need not repeat the ephemeris (not
    // read while the sun is the image's).
    const bool imageSun = sunFromSkyImage(scene);
    if (const SunAngles a = imageSun ? SunAngles{} : sunAnglesOf(scene, hf); a.place) {
        sun["resolved_azimuth_deg"] = a.azimuthDeg;
        sun["resolved_elevation_deg"] = a.elevationDeg;
        sun["resolved_true_azimuth_deg"] = a.place->position.azimuthDeg;
        sun["resolved_latitude_deg"] = a.place->latitudeDeg;
        sun["resolved_longitude_deg"] = a.place->longitudeDeg;
        sun["resolved_utc_offset_h"] = a.place->utcOffsetH;
    }
    if (imageSun) {
        // The image's sun in lux (its luminance), its colour normalised to that; none: 0 lx.
        const double lux = imageSunOf(l).illuminanceLux;
        sun["illuminance"] = lux;
        if (lux > 0.0) sun["color"] = shortest(l.sun.illuminance / sceneUnitsOfLux(lux));
    } else if (l.sun.illuminance != asAuthored.illuminance) {
        // The authored scalar (lux) where there is one; the colour carries the rest.
        const double e = scene.sun.illuminance > 0.0 ? scene.sun.illuminance : 1.0;
        sun["illuminance"] = e;
        sun["color"] = shortest(l.sun.illuminance / sceneUnitsOfLux(e));
    }
    if (l.sun.angularRadius != asAuthored.angularRadius)
        sun["angular_radius_deg"] =
            shortestDecimal(float(double(l.sun.angularRadius) * 180.0 / std::numbers::pi));

    // Where the cascades split the project camera's view of the terrain box. They depend on the
    // camera, so an engine with its own camera recomputes them (from split_lambda when practical).
    const OrbitCamera camera = OrbitCamera::fromSettings(scene.camera, hf);
    const glm::vec3 lo(hf.minX(), hf.minHeight(), hf.minZ()), hi(hf.maxX(), hf.maxHeight(), hf.maxZ());
    const CascadeRange range = cascadeRange(scene.shadows, camera, float(kLightingExportAspect), lo, hi);
    nlohmann::json& shadows = ext["shadows"];
    shadows["computed_splits"] = range.ends;
    shadows["computed_range"] = {range.nearDistance, range.farDistance};
    shadows["computed_for_aspect"] = kLightingExportAspect;
    shadows["computed_fades_out"] = range.fadesOut;
    // The first cascade whose texels lose the shadows of the relief a DEM cell resolves at this
    // sun, from which the terrain's horizon map stands in (shadows.heightfield); the cascade count
    // when none does.
    if (scene.shadows.heightfield && scene.shadows.enabled) {
        const std::vector<Cascade> cascades = fitCascades(range, camera, float(kLightingExportAspect), l.sun.direction,
                                                          scene.shadows.mapResolution, lo, hi);
        const HorizonMapInfo map = horizonMapOf(hf.width(), hf.depth(), hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(),
                                                kMaxSurfaceTexels);
        shadows["computed_heightfield_from_cascade"] = horizonFirstCascade(cascades, l.sun.direction.y, map);
        shadows["computed_heightfield_cell"] = shortestDecimal(map.cell);
    }

    // What fog's unset ("auto") values stand for: the lowest terrain, and the sky's mean radiance,
    // L_0 · Y_0 (the DC term spread over 4π steradians; Y_0 = 1/(2√π), docs/lighting.md), as a
    // colour and a luminance.
    const nlohmann::json& fogAuthored = authored.at("fog");
    nlohmann::json& fog = ext["fog"];
    fog["resolved_base_height"] = scene.fog.baseHeight ? fogAuthored.at("base_height")
                                                       : nlohmann::json(shortestDecimal(hf.minHeight()));
    const FogSettings resolved = resolvedFog(scene.fog, l.sky, hf);
    fog["resolved_color"] = scene.fog.color ? fogAuthored.at("color") : shortest(*resolved.color);
    fog["resolved_luminance"] = scene.fog.luminance ? fogAuthored.at("luminance") : nlohmann::json(shortestDecimal(float(*resolved.luminance)));

    // The terrain's specular and occlusion as the renderer shades it (docs/lighting.md, "Terrain
    // surface"): GGX roughness before the normals' variance widens it, whether it does, the floor
    // it never goes below, and the horizon AO and micro-detail settings.
    const nlohmann::json& terrain = authored.at("terrain");
    ext["surface"] = {{"roughness", terrain.at("roughness")},
                      {"roughness_floor", kRoughnessFloor},
                      {"specular_aa", terrain.at("specular_aa")},
                      {"ao", authored.at("ao")},
                      {"detail", authored.at("detail")}};

    // The water as the project writes it, with what an engine would otherwise derive: the level
    // in metres and each wave's direction, amplitude, wave number and deep-water angular
    // frequency (docs/lighting.md, "Water"). No water, no key: such a scene is exported as
    // before water existed.
    if (scene.water.enabled) {
        nlohmann::json& w = ext["water"] = authored.at("water");
        // null when "auto" finds no water surface in the DEM (then no water node either).
        const std::optional<double> level = water::waterLevel(scene.water, hf);
        w["resolved_level"] = scene.water.level ? w.at("level")
                              : level           ? nlohmann::json(shortestDecimal(float(*level)))
                                                : nlohmann::json(nullptr);
        w["resolved_shore_fade_distance"] = scene.water.shoreFadeDistance
                                                ? w.at("shore_fade_distance")
                                                : nlohmann::json(water::shoreFadeDistance(scene.water, hf));
        for (size_t i = 0; i < scene.water.waves.size(); ++i) {
            const water::WaveTerms t = water::waveTerms(scene.water.waves[i]);
            nlohmann::json& wave = w.at("waves").at(i);
            wave["resolved_direction"] = {t.direction.x, t.direction.y};
            wave["resolved_amplitude"] = t.amplitude;
            wave["resolved_k"] = t.k;
            wave["resolved_omega"] = t.omegaDeep;
        }
    }
    // Reflection probes as authored; the bake adds their files and counts (docs/formats.md).
    if (scene.reflectionProbes.enabled) ext["reflection_probes"] = authored.at("reflection_probes");
    // Which indirect light the viewport adds; the light propagation volumes as authored, as the
    // engine's console variables (lpv.ini's values) and with the cascade sizes the rule gives.
    ext["indirect"] = authored.at("lighting").at("indirect");
    if (scene.lpv.enabled) {
        nlohmann::json& lpv = ext["lpv"] = authored.at("lpv");
        // A null size is the terrain's (lpv::autoSize): the console variables carry the metres.
        const LpvSettings resolved = lpv::resolvedOn(scene.lpv, hf);
        lpv["console_variables"] = lpvConsoleVariablesJson(resolved);
        lpv["computed_cascade_ratio"] = lpv::cascadeRatio(resolved);
        lpv["computed_cascade_sizes"] = lpv::cascadeSizes(resolved);
        lpv["ini_uri"] = "lpv.ini";
    }
    return ext;
}

nlohmann::json lightingExtension(const Project& project, const Heightfield& hf) {
    return lightingExtension(project, hf, lightingOf(project, hf));
}

}  // namespace terralux
