// The TERRALUX_lighting glTF extension: the authored sections as the project writes them, the sun
// the bake lights with, the cascade splits of the project's camera, fog's resolved auto values,
// and the extension's place in scene.gltf (used, never required).

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include "GltfExport.h"
#include "ImageFile.h"
#include "ParameterTable.h"
#include "Project.h"
#include "SceneLighting.h"
#include "bake/PhysicalSky.h"
#include "scene/ShadowCascades.h"
#include "water/Water.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace terralux;

namespace {

// A hilly 40 × 30 terrain of 25 m cells between about 80 and 420 m.
Heightfield makeTerrain() {
    const int w = 40, d = 30;
    std::vector<float> h(size_t(w) * size_t(d));
    for (int r = 0; r < d; ++r)
        for (int c = 0; c < w; ++c)
            h[size_t(r) * size_t(w) + size_t(c)] =
                float(250.0 + 120.0 * std::sin(0.21 * c) * std::cos(0.17 * r) + 2.0 * r);
    return Heightfield(w, d, 25.0, 25.0, std::move(h));
}

// The default project with `--set`-style edits.
Project projectWith(const std::vector<std::string>& sets) {
    json doc = defaultProjectJson();
    for (const auto& s : sets) applyOverride(doc, s);
    Project p;
    p.scene = sceneFromJson(doc, "--set", nullptr);
    return p;
}

// A section less the keys the extension adds to it.
json authoredPart(json section) {
    for (auto it = section.begin(); it != section.end();)
        it = it.key().starts_with("computed_") || it.key().starts_with("resolved_") ? section.erase(it)
                                                                                     : std::next(it);
    return section;
}

glm::vec3 vec3Of(const json& a) {
    return {float(a.at(0).get<double>()), float(a.at(1).get<double>()), float(a.at(2).get<double>())};
}

const std::vector<std::string> kEdits = {"shadows.cascades=3", "fog.enabled=true", "fog.density=0.0001",
                                         "sun.elevation_deg=12", "camera.exposure_ev=-1.5",
                                         "sky.intensity=2"};

}  // namespace

TEST(LightingExtension, AuthoredSectionsAreTheProjectAsWritten) {
    const Heightfield hf = makeTerrain();
    const Project p = projectWith(kEdits);
    const json ext = lightingExtension(p, hf);
    const json printed = sceneToJson(p.scene);
    for (const char* section : {"sky", "shadows", "fog"}) {
        ASSERT_TRUE(ext.contains(section)) << section;
        EXPECT_EQ(authoredPart(ext[section]), printed[section]) << section;
    }
    EXPECT_EQ(ext["shadows"]["cascades"], 3);
    EXPECT_EQ(ext["fog"]["enabled"], true);
    EXPECT_EQ(ext["exposure_ev"], printed["camera"]["exposure_ev"]);
    EXPECT_EQ(ext["exposure_ev"].get<double>(), -1.5);
    EXPECT_EQ(ext["sky"]["hdr"], "");
}

TEST(LightingExtension, SurfaceCarriesRoughnessAoAndDetail) {
    const Heightfield hf = makeTerrain();
    const Project p = projectWith({"terrain.roughness=0.45", "terrain.specular_aa=false", "ao.directions=16",
                                   "ao.max_distance=800", "ao.strength=0.7", "detail.scale=3.5"});
    const json surface = lightingExtension(p, hf).at("surface");
    const json printed = sceneToJson(p.scene);
    EXPECT_EQ(surface["roughness"].get<double>(), 0.45);
    EXPECT_EQ(surface["roughness_floor"].get<double>(), kRoughnessFloor);
    EXPECT_EQ(surface["specular_aa"], false);
    EXPECT_EQ(surface["ao"], printed["ao"]);
    EXPECT_EQ(surface["ao"]["directions"], 16);
    EXPECT_EQ(surface["ao"]["max_distance"].get<double>(), 800.0);
    EXPECT_EQ(surface["detail"], printed["detail"]);
    EXPECT_EQ(surface["detail"]["scale"].get<double>(), 3.5);
    EXPECT_EQ(surface.size(), 5u);
}

TEST(LightingExtension, TheSunIsTheOneTheBakeLightsWith) {
    const Heightfield hf = makeTerrain();
    const Project p = projectWith(kEdits);
    const json sun = lightingExtension(p, hf)["sun"];
    const json authored = sceneToJson(p.scene)["sun"];
    EXPECT_EQ(sun["azimuth_deg"], authored["azimuth_deg"]);
    EXPECT_EQ(sun["elevation_deg"], authored["elevation_deg"]);
    EXPECT_EQ(sun["illuminance"], authored["illuminance"]);
    // The shortest decimals of the renderer's floats are the authored ones again.
    EXPECT_EQ(sun["color"], authored["color"]);
    EXPECT_EQ(sun["angular_radius_deg"], authored["angular_radius_deg"]);
    const glm::vec3 d = vec3Of(sun["direction"]);
    EXPECT_EQ(d, sunDirection(135.0, 12.0));
    EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
    EXPECT_GT(d.y, 0.0f);

    // Whatever lights the bake is what is written, the authored angles beside it.
    BakeLighting l = lightingOf(p, hf);
    l.sun.direction = sunDirection(200.0, 40.0);
    l.sun.illuminance = glm::vec3(6.0f, 4.5f, 3.0f);
    l.sun.angularRadius = 0.01f;
    const json driven = lightingExtension(p, hf, l)["sun"];
    EXPECT_EQ(vec3Of(driven["direction"]), l.sun.direction);
    // Illuminance in lux, as authored; times the scene units per lux, what the bake lit with.
    const glm::vec3 drivenScene = vec3Of(driven["color"]) * sceneUnitsOfLux(driven["illuminance"].get<double>());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(drivenScene[c], l.sun.illuminance[c], 1e-6f * l.sun.illuminance[c]);
    EXPECT_NEAR(driven["angular_radius_deg"].get<double>(), 0.01 * 180.0 / std::numbers::pi, 1e-6);
    EXPECT_EQ(driven["elevation_deg"], authored["elevation_deg"]);
    // An authored illuminance of 0 leaves the scale to the colour.
    const json dark = lightingExtension(projectWith({"sun.illuminance=0"}), hf, l)["sun"];
    EXPECT_EQ(dark["illuminance"].get<double>(), 1.0);
    EXPECT_EQ(vec3Of(dark["color"]), l.sun.illuminance / sceneUnitsOfLux(1.0));
}

// An image sky with a sun in it, with sun.follow_sky: the sun the bake and the renderer light
// with is the image's glow, the sky they keep is the image less it, and the extension writes that
// sun; off, the image lights whole beside the authored sun.
TEST(LightingExtension, UnderAnImageSkyTheSunFollowsTheImagesGlow) {
    // A 64 x 32 EXR sky of 1.0 with a 2 x 2-texel sun of 12 800,
    // the texels' centres at azimuth -61.9 degrees (u = 21/64) and 16.9 degrees up (v = 13/32).
    const fs::path hdr = fs::temp_directory_path() / ("terralux_image_sun_" + std::to_string(getpid()) + ".exr");
    std::vector<float> rgba(size_t(64) * 32 * 4, 1.0f);
    for (int y : {12, 13})
        for (int x : {20, 21})
            for (int c = 0; c < 3; ++c) rgba[(size_t(y) * 64 + size_t(x)) * 4 + size_t(c)] = 12800.0f;
    writeImage(hdr, 64, 32, rgba);
    // The terrain has no CRS: a date_time sun could not be placed, and is not read.
    const Heightfield hf = makeTerrain();
    const std::vector<std::string> sets = {"sky.mode=hdr", "sky.hdr=" + hdr.string(), "sun.azimuth_deg=100",
                                           "sun.elevation_deg=50", "sun.mode=date_time", "sun.illuminance=3000",
                                           "sun.angular_radius_deg=2"};
    const Project p = projectWith(sets);
    const BakeLighting l = lightingOf(p, hf);
    EXPECT_GT(glm::dot(l.sun.direction, sunDirection(-61.875, 16.875)), std::cos(0.5 * std::numbers::pi / 180.0));
    EXPECT_FALSE(l.sky.hasGlow());
    EXPECT_GT(l.sky.takenGlowShare(), 0.9f);
    // The glow's light: the 2 x 2 texels' 12 800 less the threshold the sky keeps (a few times
    // 1.0), over their solid angle (rows 12 and 13 of 32, 2 of 64 columns), all within 4 degrees of
    // the sun's direction (cosines over 0.997).
    double omega = 0.0;
    for (int y : {12, 13})
        omega += 2.0 * (2.0 * std::numbers::pi / 64.0) * (std::cos(std::numbers::pi * y / 32.0) - std::cos(std::numbers::pi * (y + 1) / 32.0));
    EXPECT_GT(l.sun.illuminance.x, 0.997 * (12800.0 - 12.0) * omega);
    EXPECT_LT(l.sun.illuminance.x, 12800.0 * omega);
    const ImageSun read = imageSunOf(l);
    EXPECT_NEAR(read.azimuthDeg, -61.875, 0.5);
    EXPECT_NEAR(read.elevationDeg, 16.875, 0.5);
    // sky.intensity scales the image, and so its sun.
    const BakeLighting bright = lightingOf(projectWith({"sky.mode=hdr", "sky.hdr=" + hdr.string(), "sky.intensity=2"}), hf);
    EXPECT_FLOAT_EQ(bright.sun.illuminance.x, 2.0f * l.sun.illuminance.x);
    EXPECT_EQ(bright.sun.direction, l.sun.direction);

    // Exported as lit: the image's sun in lux, its colour normalised to it, its size; no date's
    // resolution (the authored date_time is not read), and no error for the place it lacks.
    const json sun = lightingExtension(p, hf)["sun"];
    EXPECT_EQ(vec3Of(sun["direction"]), l.sun.direction);
    EXPECT_NEAR(sun["illuminance"].get<double>(), read.illuminanceLux, 1e-6 * read.illuminanceLux);
    const glm::vec3 exported = vec3Of(sun["color"]) * sceneUnitsOfLux(sun["illuminance"].get<double>());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(exported[c], l.sun.illuminance[c], 1e-5f * l.sun.illuminance[c]);
    EXPECT_NEAR(sun["angular_radius_deg"].get<double>(), double(l.sun.angularRadius) * 180.0 / std::numbers::pi, 1e-5);
    EXPECT_GT(sun["angular_radius_deg"].get<double>(), 3.0);  // the 2 x 2 texels' 6.4, not the authored 2
    EXPECT_EQ(sun["follow_sky"], true);
    for (auto it = sun.begin(); it != sun.end(); ++it) EXPECT_FALSE(it.key().starts_with("resolved_")) << it.key();
    EXPECT_NO_THROW(checkSunPlaces(p.scene, hf));

    // Off: the authored sun, and the image whole with its glow.
    const BakeLighting whole = lightingOf(projectWith({"sky.mode=hdr", "sky.hdr=" + hdr.string(), "sun.azimuth_deg=100",
                                                       "sun.elevation_deg=50", "sun.follow_sky=false"}),
                                          hf);
    EXPECT_EQ(whole.sun.direction, sunDirection(100.0, 50.0));
    EXPECT_TRUE(whole.sky.hasGlow());
    EXPECT_EQ(whole.sky.takenGlowShare(), 0.0f);
    fs::remove(hdr);
}

TEST(LightingExtension, ComputedSplitsAreTheProjectCamerasCascades) {
    const Heightfield hf = makeTerrain();
    const glm::vec3 lo(hf.minX(), hf.minHeight(), hf.minZ()), hi(hf.maxX(), hf.maxHeight(), hf.maxZ());
    // Whole metres inside the default view's shadow range, for manual splits and max_distance.
    const json whole = lightingExtension(projectWith({}), hf)["shadows"]["computed_range"];
    const double nearest = whole[0].get<double>(), farthest = whole[1].get<double>();
    auto inside = [&](double share) { return std::round(nearest + share * (farthest - nearest)); };
    for (int cascades = 1; cascades <= 4; ++cascades) {
        for (const std::string mode : {"practical", "manual", "max_distance"}) {
            SCOPED_TRACE(mode + " " + std::to_string(cascades));
            std::vector<std::string> sets = {"shadows.cascades=" + std::to_string(cascades)};
            std::vector<double> manual;
            if (mode == "manual" && cascades > 1) {
                json splits = json::array();
                for (int i = 1; i < cascades; ++i) splits.push_back(inside(0.2 * i));
                manual = splits.get<std::vector<double>>();
                sets.push_back("shadows.split_mode=manual");
                sets.push_back("shadows.splits=" + splits.dump());
            }
            if (mode == "max_distance") sets.push_back("shadows.max_distance=" + json(inside(0.7)).dump());
            const Project p = projectWith(sets);
            const json shadows = lightingExtension(p, hf)["shadows"];
            const json& splits = shadows["computed_splits"];
            const json& range = shadows["computed_range"];
            ASSERT_EQ(splits.size(), size_t(cascades));
            ASSERT_EQ(range.size(), 2u);
            EXPECT_LT(range[0].get<double>(), splits[0].get<double>());
            for (size_t i = 1; i < splits.size(); ++i)
                EXPECT_GT(splits[i].get<double>(), splits[i - 1].get<double>()) << i;
            EXPECT_EQ(splits.back(), range[1]);
            EXPECT_EQ(shadows["computed_for_aspect"].get<double>(), 16.0 / 9.0);

            const CascadeRange expected = cascadeRange(
                p.scene.shadows, OrbitCamera::fromSettings(p.scene.camera, hf), 16.0f / 9.0f, lo, hi);
            EXPECT_EQ(splits, json(expected.ends));
            EXPECT_EQ(range, json({expected.nearDistance, expected.farDistance}));
            EXPECT_EQ(shadows["computed_fades_out"].get<bool>(), mode == "max_distance");
            for (size_t i = 0; i < manual.size(); ++i) EXPECT_EQ(splits[i].get<double>(), manual[i]) << i;
            if (mode == "max_distance") {
                EXPECT_EQ(range[1].get<double>(), inside(0.7));
            }
        }
    }
}

TEST(LightingExtension, TheHorizonMapsCascadeFollowsTheSunAndTheRule) {
    // The first cascade handing the terrain's shadow to the horizon map: the exported index is
    // the rule applied to the project camera's cascades, earlier as the sun sinks, and absent
    // with the setting off.
    const Heightfield hf = makeTerrain();
    const glm::vec3 lo(hf.minX(), hf.minHeight(), hf.minZ()), hi(hf.maxX(), hf.maxHeight(), hf.maxZ());
    int previous = -1;
    for (const double elevation : {80.0, 35.0, 12.0, 5.0, 1.0}) {
        const Project p = projectWith({"sun.elevation_deg=" + json(elevation).dump()});
        const json shadows = lightingExtension(p, hf)["shadows"];
        ASSERT_TRUE(shadows.contains("computed_heightfield_from_cascade")) << elevation;
        const int from = shadows["computed_heightfield_from_cascade"].get<int>();
        const glm::vec3 sun = sunDirection(p.scene.sun.azimuthDeg, elevation);
        const CascadeRange range =
            cascadeRange(p.scene.shadows, OrbitCamera::fromSettings(p.scene.camera, hf), 16.0f / 9.0f, lo, hi);
        const std::vector<Cascade> cascades = fitCascades(range, OrbitCamera::fromSettings(p.scene.camera, hf),
                                                          16.0f / 9.0f, sun, p.scene.shadows.mapResolution, lo, hi);
        const float cell = std::max((hf.maxX() - hf.minX()) / float(hf.width() - 1), (hf.maxZ() - hf.minZ()) / float(hf.depth() - 1));
        EXPECT_EQ(shadows["computed_heightfield_cell"].get<double>(), double(cell)) << elevation;
        int expected = int(cascades.size());
        const double tanE = std::tan(elevation * std::numbers::pi / 180.0);
        for (size_t i = 0; i < cascades.size(); ++i)
            if (0.75 * cascades[i].texelSize / tanE > cell) {
                expected = int(i);
                break;
            }
        EXPECT_EQ(from, expected) << elevation;
        if (previous >= 0) {
            EXPECT_LE(from, previous) << elevation;
        }
        previous = from;
    }
    EXPECT_LT(previous, 4) << "at a 1° sun some cascade hands over";
    const json off = lightingExtension(projectWith({"shadows.heightfield=false"}), hf)["shadows"];
    EXPECT_FALSE(off.contains("computed_heightfield_from_cascade"));
    EXPECT_EQ(off["heightfield"], false);
}

TEST(LightingExtension, FogResolvesItsAutoValues) {
    const Heightfield hf = makeTerrain();
    json fog = lightingExtension(projectWith(kEdits), hf)["fog"];
    EXPECT_TRUE(fog["base_height"].is_null());
    EXPECT_TRUE(fog["color"].is_null());
    EXPECT_EQ(float(fog["resolved_base_height"].get<double>()), hf.minHeight());
    // The mean radiance of the default uniform sky, (0.6, 0.733, 1) × 5000 cd/m² = (0.09, 0.11, 0.15)
    // scene units, × 2: its colour and, in the largest channel, 10 000 cd/m².
    EXPECT_TRUE(fog["luminance"].is_null());
    const glm::vec3 mean = vec3Of(fog["resolved_color"]);
    EXPECT_NEAR(mean.r, 0.6f, 1e-5f);
    EXPECT_NEAR(mean.g, 0.733333f, 1e-5f);
    EXPECT_NEAR(mean.b, 1.0f, 1e-5f);
    EXPECT_NEAR(fog["resolved_luminance"].get<double>(), 10000.0, 0.05);

    fog = lightingExtension(projectWith({"fog.base_height=-12.5", "fog.color=0.1,0.2,0.3", "fog.luminance=250"}), hf)["fog"];
    EXPECT_EQ(fog["resolved_base_height"], fog["base_height"]);
    EXPECT_EQ(fog["resolved_base_height"].get<double>(), -12.5);
    EXPECT_EQ(fog["resolved_color"], fog["color"]);
    EXPECT_EQ(fog["resolved_color"], json({0.1, 0.2, 0.3}));
    EXPECT_EQ(fog["resolved_luminance"], fog["luminance"]);
    EXPECT_EQ(fog["resolved_luminance"].get<double>(), 250.0);
}

TEST(LightingExtension, IsAUsedNeverRequiredSceneExtension) {
    const fs::path dir = fs::temp_directory_path() / ("terralux_test_lighting_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    const Heightfield hf = makeTerrain();
    const Project p = projectWith(kEdits);
    GltfSceneInput in;
    in.heightfield = &hf;
    in.lighting = lightingExtension(p, hf);
    exportGltfScene(dir, in);

    std::ifstream file(dir / "scene.gltf");
    const json doc = json::parse(file);
    const json& used = doc["extensionsUsed"];
    EXPECT_NE(std::find(used.begin(), used.end(), "TERRALUX_lighting"), used.end());
    EXPECT_FALSE(doc.contains("extensionsRequired"));
    EXPECT_EQ(doc["scenes"][0]["extensions"]["TERRALUX_lighting"], in.lighting);

    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    EXPECT_TRUE(loader.LoadASCIIFromFile(&model, &err, &warn, (dir / "scene.gltf").string())) << err;
    EXPECT_EQ(warn, "");
    EXPECT_TRUE(model.extensionsRequired.empty());
    ASSERT_EQ(model.scenes.size(), 1u);
    EXPECT_TRUE(model.scenes[0].extensions.count("TERRALUX_lighting"));
    EXPECT_FALSE(model.extensions.count("TERRALUX_lighting"));
    fs::remove_all(dir);
}

TEST(LightingExtension, TheCameraExposureRoundTripsThroughTheProjectAndTheGltf) {
    // A manual EV100 and a metered mode, saved, loaded and exported: scene.gltf carries what was
    // authored, with the scale of the units its lights are in.
    const fs::path dir = fs::temp_directory_path() / ("terralux_test_exposure_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const Heightfield hf = makeTerrain();
    for (const char* mode : {"manual", "histogram"}) {
        Project p = projectWith({std::string("camera.exposure_mode=\"") + mode + "\"", "camera.ev100=12.5",
                                 "camera.exposure_ev=0.7", "camera.adaptation_s=2.5"});
        saveProject(p, dir / "p.terralux.json");
        std::vector<std::string> warnings;
        const Project loaded = loadProject(dir / "p.terralux.json", &warnings);
        EXPECT_EQ(exposureModeName(loaded.scene.camera.exposureMode), std::string(mode));
        EXPECT_EQ(loaded.scene.camera.ev100, 12.5);
        EXPECT_EQ(loaded.scene.camera.adaptationSeconds, 2.5);
        GltfSceneInput in;
        in.heightfield = &hf;
        in.lighting = lightingExtension(loaded, hf);
        exportGltfScene(dir / "out", in);
        std::ifstream file(dir / "out" / "scene.gltf");
        const json ext = json::parse(file)["scenes"][0]["extensions"]["TERRALUX_lighting"];
        EXPECT_EQ(ext["exposure_mode"], mode);
        EXPECT_EQ(ext["ev100"].get<double>(), 12.5);
        EXPECT_EQ(ext["exposure_ev"].get<double>(), 0.7);
        EXPECT_EQ(ext["adaptation_s"].get<double>(), 2.5);
        // The rule docs/formats.md gives an engine: one scene unit is 1 / scene_units_per_lux lux.
        EXPECT_FLOAT_EQ(ext["scene_units_per_lux"].get<float>(), kSceneUnitsPerLux);
    }
    fs::remove_all(dir);
}

TEST(LightingExtension, WaterIsEverySettingWithTheLevelAndTheWavesResolved) {
    const Heightfield hf = makeTerrain();
    // Off (the default): no water key at all.
    EXPECT_FALSE(lightingExtension(projectWith({}), hf).contains("water"));

    const Project p = projectWith({"water.enabled=true", "water.depth_aware=true", "water.shore_fade_distance=12",
                                   R"(water.waves=[{"direction_deg":90,"wavelength":20,"steepness":0.2},)"
                                   R"({"direction_deg":180,"wavelength":5,"amplitude":0.1,"phase":1}])"});
    const json w = lightingExtension(p, hf).at("water");
    const json printed = sceneToJson(p.scene).at("water");
    // The authored part is the project's section, wave for wave.
    json authored = authoredPart(w);
    for (json& wave : authored.at("waves")) wave = authoredPart(wave);
    EXPECT_EQ(authored, printed);
    EXPECT_EQ(w["depth_aware"], true);
    // The shore fade as set, and left null: two of the DEM's cells (25 m here; 81 m cells would
    // get 162 m, where the former fixed 50 m was under one cell).
    EXPECT_EQ(w["resolved_shore_fade_distance"].get<double>(), 12.0);
    const json unset = lightingExtension(projectWith({"water.enabled=true"}), hf).at("water");
    EXPECT_TRUE(unset["shore_fade_distance"].is_null());
    EXPECT_EQ(unset["resolved_shore_fade_distance"].get<double>(), 2.0 * std::max(hf.cellSizeX(), hf.cellSizeZ()));
    EXPECT_EQ(unset["resolved_shore_fade_distance"].get<double>(), 50.0);
    // This rolling terrain shows no water surface: the auto level resolves to none (null).
    EXPECT_TRUE(w["level"].is_null());
    EXPECT_FALSE(water::autoLevel(hf).level.has_value());
    EXPECT_TRUE(w["resolved_level"].is_null());
    // A flat lake in it resolves to the lake's surface, in metres.
    std::vector<float> lake = hf.heights();
    for (int r = 5; r < 25; ++r)
        for (int c = 25; c < 40; ++c) lake[size_t(r) * 40 + size_t(c)] = std::min(lake[size_t(r) * 40 + size_t(c)], 140.5f);
    const Heightfield withLake(40, 30, 25.0, 25.0, lake);
    ASSERT_TRUE(water::autoLevel(withLake).level.has_value());
    EXPECT_EQ(lightingExtension(p, withLake).at("water")["resolved_level"].get<double>(), 140.5);
    // Each wave: unit direction (x, z), amplitude, k = 2π/λ and the deep-water ω = √(g·k).
    const json& east = w["waves"][0];
    EXPECT_NEAR(east["resolved_direction"][0].get<double>(), 1.0, 1e-15);
    EXPECT_NEAR(east["resolved_direction"][1].get<double>(), 0.0, 1e-15);
    EXPECT_NEAR(east["resolved_k"].get<double>(), 2.0 * std::numbers::pi / 20.0, 1e-15);
    EXPECT_NEAR(east["resolved_amplitude"].get<double>(), 0.2 * 20.0 / (2.0 * std::numbers::pi), 1e-15);
    EXPECT_NEAR(east["resolved_omega"].get<double>(), std::sqrt(9.81 * 2.0 * std::numbers::pi / 20.0), 1e-12);
    const json& south = w["waves"][1];
    EXPECT_NEAR(south["resolved_direction"][1].get<double>(), 1.0, 1e-15);
    EXPECT_EQ(south["resolved_amplitude"].get<double>(), 0.1);
    // A set level is written as authored.
    const json set = lightingExtension(projectWith({"water.enabled=true", "water.level=312.25"}), hf).at("water");
    EXPECT_EQ(set["resolved_level"].get<double>(), 312.25);
    EXPECT_EQ(set["waves"], json::array());
}
