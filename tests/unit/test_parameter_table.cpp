// The parameter table drives the project reader and writer, --set, the schema and the docs:
// these tests hold every row to its own declaration.
#include <array>
#include <cmath>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include "KeptPlacement.h"
#include "ParameterTable.h"
#include "Project.h"
#include "ProjectErrors.h"
#include "bake/ProbePlacement.h"

using namespace terralux;
using nlohmann::json;

namespace {

// The path of a row in a document with one probe volume and one wave.
std::string concrete(const ParameterSpec& s) {
    return s.inList() ? s.listPath() + "[0]." + s.localPath() : s.path;
}

// The defaults with one wave, which sets the one of amplitude and steepness that `spec` is not
// (exactly one of them is set), so that the row's own default reads back.
json baseFor(const ParameterSpec& spec) {
    json doc = defaultProjectJson();
    if (spec.perWave()) {
        json wave = json::object();
        wave[spec.localPath() == "amplitude" ? "steepness" : "amplitude"] = 0.1;
        doc["water"]["waves"] = json::array({wave});
        doc = sceneToJson(sceneFromJson(doc, "base", nullptr));  // every key, as --set finds them
    }
    if (spec.perLight()) {
        doc["lights"] = json::array({json::object()});
        doc = sceneToJson(sceneFromJson(doc, "base", nullptr));
    }
    if (spec.perScenario()) {
        doc["scenarios"] = json::array({json::object()});
        doc = sceneToJson(sceneFromJson(doc, "base", nullptr));
    }
    return doc;
}

std::string errorFor(const ParameterSpec& spec, const json& value) {
    return test::projectErrorFor(concrete(spec), value, baseFor(spec));
}

}  // namespace

// Undo's words for an edit: the row's label and what holds it, never the JSON path.
TEST(ParameterTable, EditLabelsNameTheRowAndItsOwner) {
    json doc = defaultProjectJson();
    doc["probe_volumes"][0]["name"] = "valley";
    EXPECT_EQ(editLabel("probe_volumes[0].grid_dims", doc), "Grid (probes) of volume 'valley'");
    EXPECT_EQ(editLabel("probe_volumes[0].adaptive.max_probes", doc), "Adaptive: max probes of volume 'valley'");
    EXPECT_EQ(editLabel("probe_volumes[3].grid_dims", doc), "Grid (probes) of volume 4");
    EXPECT_EQ(editLabel("probe_volumes[0]", doc), "volume 'valley'");
    EXPECT_EQ(editLabel("fog.scale_height", doc), "Scale height (fog)");
    EXPECT_EQ(editLabel("sun.elevation_deg", doc), "Sun elevation");
    EXPECT_EQ(editLabel("water.waves[1].wavelength", doc),
              findParameter("water.waves[].wavelength")->label + " of wave 2");
    EXPECT_EQ(editLabel("lights[0]", doc), "light 1");
    EXPECT_EQ(editLabel("sun", doc), "the sun");
    // Every row has words of its own.
    for (const auto& spec : parameterTable()) {
        std::string path = spec.path;
        for (size_t at; (at = path.find("[]")) != std::string::npos;) path.replace(at, 2, "[0]");
        EXPECT_NE(editLabel(path, doc), path) << spec.path;
    }
}

TEST(ParameterTable, PathsAreUniqueAndEveryRowIsDeclaredWhole) {
    std::set<std::string> paths;
    for (const auto& s : parameterTable()) {
        EXPECT_TRUE(paths.insert(s.path).second) << s.path;
        EXPECT_FALSE(s.label.empty()) << s.path;
        EXPECT_FALSE(s.description.empty()) << s.path;
        EXPECT_TRUE(s.get && s.set) << s.path;
        if (s.type == ParamType::Choice) {
            EXPECT_GE(s.choices.size(), 2u) << s.path;
        }
        if (s.type == ParamType::Number || s.type == ParamType::Integer) {
            // Every number the UI edits has finite limits, so the dock shows the table's range.
            EXPECT_TRUE(std::isfinite(s.min) && std::isfinite(s.max)) << s.path;
            EXPECT_LT(s.min, s.max) << s.path;
        }
        EXPECT_EQ(findParameter(concrete(s)), &s);
    }
    EXPECT_EQ(findParameter("sun.elevaton_deg"), nullptr);
}

TEST(ParameterTable, EveryDefaultValidatesAndRoundTrips) {
    const json doc = defaultProjectJson();
    const SceneDescription s = sceneFromJson(doc, "defaults", nullptr);
    EXPECT_EQ(sceneToJson(s), doc);
    for (const auto& spec : parameterTable()) {
        // The default written at its path reads back to the same default.
        EXPECT_EQ(errorFor(spec, spec.defaultValue()), "") << spec.path;
        if (spec.perWave() || spec.perLight() || spec.perScenario()) {
            const SceneDescription w = sceneFromJson(baseFor(spec), "defaults", nullptr);
            EXPECT_EQ(spec.get(w, 0), spec.defaultValue()) << spec.path;
        } else {
            EXPECT_EQ(spec.get(s, 0), spec.defaultValue()) << spec.path;
        }
    }
    // A document holding only its format reads as the defaults.
    EXPECT_EQ(sceneToJson(sceneFromJson(json{{"format", "terralux-project"}}, "p", nullptr)), doc);
}

TEST(ParameterTable, EveryBoundIsEnforcedWithItsMessage) {
    int checked = 0;
    for (const auto& spec : parameterTable()) {
        const std::string path = concrete(spec);
        const bool number = spec.type == ParamType::Number || spec.type == ParamType::Integer;
        const bool list = spec.type == ParamType::NumberList || spec.type == ParamType::IntegerList ||
                          spec.type == ParamType::Color;
        const std::string orNull = spec.nullable() ? " or null" : "";
        auto outside = [&](double bound, bool low, bool exclusive) {
            // Just past the bound: the bound itself where it is excluded, else one step beyond.
            const double step = spec.type == ParamType::Integer || spec.type == ParamType::IntegerList
                                    ? std::max(1.0, std::round(std::abs(bound) * 1e-6))
                                    : std::max(1e-6, std::abs(bound) * 1e-6);
            return exclusive ? bound : (low ? bound - step : bound + step);
        };
        if (number) {
            const std::string rule = "must be in " + spec.rangeText() + orNull;
            for (bool low : {true, false}) {
                const double v = low ? outside(spec.min, true, spec.minExclusive)
                                     : outside(spec.max, false, spec.maxExclusive);
                const json value = spec.type == ParamType::Integer ? json((long long)v) : json(v);
                const std::string message = errorFor(spec, value);
                EXPECT_EQ(message.rfind("p.json: " + path + " = ", 0), 0u) << message;
                EXPECT_NE(message.find(": " + rule), std::string::npos) << spec.path << ": " << message;
                ++checked;
            }
            // Inside the bounds is accepted (unless another rule of the row says otherwise).
            EXPECT_EQ(errorFor(spec, spec.defaultValue()), "") << spec.path;
            EXPECT_NE(errorFor(spec, "text"), "") << spec.path;
        }
        if (list && std::isfinite(spec.min)) {
            json value = spec.defaultValue();
            if (value.is_null() || !value.is_array()) continue;
            value[0] = outside(spec.min, true, spec.minExclusive);
            if (spec.type == ParamType::IntegerList) value[0] = (long long)value[0].get<double>();
            const std::string message = errorFor(spec, value);
            EXPECT_EQ(message.rfind("p.json: " + path + "[0] = ", 0), 0u) << spec.path << ": " << message;
            ++checked;
        }
        if (spec.type == ParamType::Choice) {
            EXPECT_EQ(errorFor(spec, "nonsense"),
                      "p.json: " + path + " = \"nonsense\": must be " + spec.rangeText());
            ++checked;
        }
        if (spec.type == ParamType::Boolean) {
            EXPECT_EQ(errorFor(spec, 1), "p.json: " + path + " = 1: must be true or false");
            ++checked;
        }
        if (!spec.nullable()) {
            EXPECT_NE(errorFor(spec, nullptr), "") << spec.path << " must not accept null";
        } else {
            EXPECT_EQ(errorFor(spec, nullptr), "") << spec.path << " accepts null (auto)";
        }
    }
    EXPECT_GT(checked, 60);
}

TEST(ParameterTable, SchemaDescribesEveryLeafAndAcceptsTheDefaults) {
    const json schema = projectSchema();
    EXPECT_EQ(schema["$schema"], "https://json-schema.org/draft/2020-12/schema");
    EXPECT_EQ(schema["additionalProperties"], false);
    for (const auto& spec : parameterTable()) {
        const json* node = &schema;
        std::string rest = spec.path;
        if (spec.inList()) {
            std::string list = spec.listPath();
            for (size_t dot; (dot = list.find('.')) != std::string::npos; list = list.substr(dot + 1))
                node = &(*node)["properties"][list.substr(0, dot)];
            node = &(*node)["properties"][list]["items"];
            rest = spec.localPath();
        }
        for (size_t dot; (dot = rest.find('.')) != std::string::npos; rest = rest.substr(dot + 1))
            node = &(*node)["properties"][rest.substr(0, dot)];
        const json& leaf = (*node)["properties"][rest];
        ASSERT_TRUE(leaf.is_object()) << spec.path;
        EXPECT_TRUE(leaf.contains("description")) << spec.path;
        EXPECT_EQ(leaf["default"], spec.defaultValue()) << spec.path;
        const json& inner = spec.nullable() ? leaf["anyOf"][0] : leaf;
        if (spec.type == ParamType::Number || spec.type == ParamType::Integer) {
            EXPECT_EQ(inner[spec.minExclusive ? "exclusiveMinimum" : "minimum"], spec.min) << spec.path;
            EXPECT_EQ(inner[spec.maxExclusive ? "exclusiveMaximum" : "maximum"], spec.max) << spec.path;
        }
        if (spec.type == ParamType::Choice) {
            EXPECT_EQ(inner["enum"], json(spec.choices)) << spec.path;
        }
    }
}

TEST(ParameterTable, ReferenceListsEveryRow) {
    const std::string md = parameterReferenceMarkdown();
    for (const auto& spec : parameterTable())
        EXPECT_NE(md.find("| `" + spec.path + "` |"), std::string::npos) << spec.path;
}

// The names the study and the report write for a shadow filter and a reflection encoding are the
// ones a project file reads back as that value.
TEST(ParameterTable, EnumNamesReadBackAsTheirValues) {
    for (ShadowFilter f : {ShadowFilter::Pcss, ShadowFilter::Pcf, ShadowFilter::Hard}) {
        json doc = defaultProjectJson();
        applyOverride(doc, std::string("shadows.filter=") + shadowFilterName(f));
        EXPECT_EQ(sceneFromJson(doc, "test", nullptr).shadows.filter, f) << shadowFilterName(f);
    }
    for (ReflectionEncoding e : {ReflectionEncoding::Faces, ReflectionEncoding::Cubemap}) {
        json doc = defaultProjectJson();
        applyOverride(doc, std::string("reflection_probes.encoding=") + reflectionEncodingName(e));
        EXPECT_EQ(sceneFromJson(doc, "test", nullptr).reflectionProbes.encoding, e) << reflectionEncodingName(e);
    }
}

TEST(ParameterTable, SunAndSkyRowsAreReadByTheirSkyMode) {
    auto read = [](const SceneDescription& s, const char* path) { return findParameter(path)->isRead(s, 0); };
    SceneDescription s;  // uniform
    for (const char* path : {"sky.color", "sky.intensity", "sun.illuminance", "sun.color"})
        EXPECT_TRUE(read(s, path)) << path;
    for (const char* path : {"sky.turbidity", "sun.follow_sky", "sky.hdr", "sky.rotation_deg"})
        EXPECT_FALSE(read(s, path)) << path;
    s.sky.mode = SkyMode::Hdr;  // the sun follows the image: nothing of the authored sun is read
    const std::vector<const char*> placed = {"sun.mode", "sun.illuminance", "sun.color", "sun.angular_radius_deg"};
    const std::vector<const char*> manual = {"sun.azimuth_deg", "sun.elevation_deg"};
    const std::vector<const char*> dated = {"sun.date", "sun.time_h", "sun.utc_offset_h", "sun.latitude_deg", "sun.longitude_deg"};
    for (SunMode mode : {SunMode::Manual, SunMode::DateTime}) {
        s.sun.mode = mode;
        for (const char* path : {"sky.hdr", "sky.rotation_deg", "sun.follow_sky"}) EXPECT_TRUE(read(s, path)) << path;
        for (const auto* rows : {&placed, &manual, &dated})
            for (const char* path : *rows) EXPECT_FALSE(read(s, path)) << path;
        for (const char* path : {"sky.turbidity", "sky.color"}) EXPECT_FALSE(read(s, path)) << path;
        s.sun.followSky = false;  // the image whole, and the authored sun
        for (const char* path : placed) EXPECT_TRUE(read(s, path)) << path;
        for (const char* path : mode == SunMode::Manual ? manual : dated) EXPECT_TRUE(read(s, path)) << path;
        s.sun.followSky = true;
    }
    s.sun.mode = SunMode::Manual;
    // A scenario's image sky hides its own sun's rows alike.
    SceneDescription withScenario;
    withScenario.scenarios.push_back(LightingScenario{});
    withScenario.scenarios[0].name = "noon";
    withScenario.scenarios[0].sky.mode = SkyMode::Hdr;
    EXPECT_FALSE(findParameter("scenarios[].sun.azimuth_deg")->isRead(withScenario, 0));
    EXPECT_TRUE(findParameter("sun.azimuth_deg")->isRead(withScenario, 0));
    s.sky.mode = SkyMode::Physical;
    // The physical sky's sun stands where it is placed, at its authored size.
    for (const char* path : {"sun.mode", "sun.azimuth_deg", "sun.angular_radius_deg"}) EXPECT_TRUE(read(s, path)) << path;
    for (const char* path : {"sky.turbidity", "sky.intensity", "sun.follow_sky"}) EXPECT_TRUE(read(s, path)) << path;
    for (const char* path : {"sky.color", "sky.hdr", "sky.rotation_deg", "sun.illuminance", "sun.color"})
        EXPECT_FALSE(read(s, path)) << path;
    s.sun.followSky = false;
    for (const char* path : {"sun.illuminance", "sun.color"}) EXPECT_TRUE(read(s, path)) << path;
}

TEST(ParameterTable, WaterRowsBelongToTheWaterDockAndFollowWaterEnabled) {
    int rows = 0;
    for (const auto& spec : parameterTable()) {
        if (spec.path.rfind("water.", 0) != 0) continue;
        const ParameterDock dock = parameterDock(spec);
        EXPECT_EQ(dock.objectName, "dock.water") << spec.path;
        EXPECT_EQ(dock.title, "Water") << spec.path;
        // The waves are the wave editor's, not dock rows.
        EXPECT_EQ(spec.uiRow, !spec.perWave()) << spec.path;
        ++rows;
    }
    EXPECT_EQ(rows, 15);
    SceneDescription s;
    EXPECT_TRUE(findParameter("water.enabled")->isRead(s, 0));
    EXPECT_FALSE(findParameter("water.level")->isRead(s, 0));
    s.water.enabled = true;
    EXPECT_TRUE(findParameter("water.level")->isRead(s, 0));
    EXPECT_TRUE(findParameter("water.reflection_scale")->isRead(s, 0));
    s.water.reflection = WaterReflection::Sky;
    EXPECT_FALSE(findParameter("water.reflection_scale")->isRead(s, 0));
    EXPECT_FALSE(findParameter("water.distortion")->isRead(s, 0));
    // What the bake reads redoes the preview bake; the rest is the renderer's.
    EXPECT_EQ(invalidatedBy("water.waves"), unsigned(kUpload));
    EXPECT_EQ(invalidatedBy("water.waves[1].amplitude"), unsigned(kUpload));
    EXPECT_EQ(invalidatedBy("water.color"), unsigned(kUpload | kRebake));
    EXPECT_EQ(invalidatedBy("water"), unsigned(kUpload | kRebake));
}

TEST(ParameterTable, WavesAreAListOfObjectsUnderTheSteepnessRule) {
    json doc = defaultProjectJson();
    EXPECT_EQ(doc["water"]["waves"], json::array());
    doc["water"]["waves"] = json::parse(R"([
        {"direction_deg": 45, "wavelength": 20, "steepness": 0.3},
        {"wavelength": 6.283185307179586, "amplitude": 0.25, "phase": 1.5}])");
    const SceneDescription s = sceneFromJson(doc, "p.json", nullptr);
    ASSERT_EQ(s.water.waves.size(), 2u);
    EXPECT_EQ(s.water.waves[0].directionDeg, 45.0);
    EXPECT_EQ(s.water.waves[0].steepness, 0.3);
    EXPECT_FALSE(s.water.waves[0].amplitude);
    EXPECT_EQ(s.water.waves[1].amplitude, 0.25);
    EXPECT_EQ(s.water.waves[1].phase, 1.5);
    EXPECT_EQ(s.water.waves[1].directionDeg, 0.0);  // absent keys take their defaults
    // Written back whole, and read again the same.
    const json written = sceneToJson(s);
    EXPECT_EQ(written["water"]["waves"][1],
              json::parse(R"({"amplitude": 0.25, "direction_deg": 0.0, "phase": 1.5, "steepness": null,
                               "wavelength": 6.283185307179586})"));
    EXPECT_EQ(sceneToJson(sceneFromJson(written, "again", nullptr)), written);

    // --set edits one key of one wave, or the whole list; the set's rule names the list.
    const std::string loop = test::projectErrorFor("water.waves[1].amplitude", 0.75, written);
    EXPECT_EQ(loop.substr(0, 23), "p.json: water.waves = [");
    EXPECT_NE(loop.find("...: summed steepness Σ k·A must be <= 1, or the crests loop (is 1.05)"), std::string::npos) << loop;
    EXPECT_EQ(test::projectErrorFor("water.waves[1].amplitude", 0.7, written), "");  // Σ = 1 exactly
    EXPECT_EQ(test::projectErrorFor("water.waves", json::array(), written), "");

    // Exactly one of amplitude and steepness.
    EXPECT_EQ(test::projectErrorFor("water.waves[0].amplitude", 0.5, written),
              "p.json: water.waves[0].steepness = 0.3: must be null when amplitude is set (exactly one of amplitude and steepness)");
    EXPECT_EQ(test::projectErrorFor("water.waves[1].amplitude", nullptr, written),
              "p.json: water.waves[1].steepness = null: must be set when amplitude is null (exactly one of amplitude and steepness)");
    // At most 8, each an object, keys checked with a suggestion.
    json nine = defaultProjectJson();
    nine["water"]["waves"] = json::array();
    for (int i = 0; i < 9; ++i) nine["water"]["waves"].push_back({{"steepness", 0.01}});
    EXPECT_NE(test::projectErrorFor("water.enabled", true, nine).find(": must hold at most 8 waves (has 9)"),
              std::string::npos);
    EXPECT_EQ(test::projectErrorFor("water.waves", json::array({1}), defaultProjectJson()),
              "p.json: water.waves[0] = 1: must be an object");
    EXPECT_EQ(test::projectErrorFor("water.waves", "calm", defaultProjectJson()),
              "p.json: water.waves = \"calm\": must be an array");
    EXPECT_EQ(test::projectErrorFor("water.waves", json::parse(R"([{"wavelenght": 3, "steepness": 0.1}])"),
                                    defaultProjectJson()),
              "p.json: unknown key 'water.waves[0].wavelenght' (did you mean 'water.waves[].wavelength'?)");
}

TEST(ParameterTable, LpvRowsAreTheConsoleVariablesWithTheirRules) {
    // Every lpv row names its console variable (or the post-process setting) in its description.
    int rows = 0;
    for (const auto& spec : parameterTable()) {
        if (spec.path.rfind("lpv.", 0) != 0) continue;
        EXPECT_TRUE(spec.description.find("rEx.") != std::string::npos ||
                    spec.path == "lpv.indirect_intensity") << spec.path;
        // The console variable the tooltips show is lpv.ini's, and the one the description names.
        if (spec.path != "lpv.indirect_intensity") {
            EXPECT_EQ(spec.description.rfind(spec.consoleVariable + ":", 0), 0u) << spec.path;
        }
        EXPECT_TRUE(spec.uiRow) << spec.path;
        EXPECT_EQ(parameterDock(spec).objectName, "dock.lpv") << spec.path;
        ++rows;
    }
    EXPECT_EQ(rows, 14);
    const json doc = defaultProjectJson();
    EXPECT_EQ(test::projectErrorFor("lpv.cascades", 5, doc), "p.json: lpv.cascades = 5: must be in [1, 4]");
    EXPECT_EQ(test::projectErrorFor("lpv.size", 0, doc), "p.json: lpv.size = 0: must be in (0, 1000000] or null");
    EXPECT_EQ(test::projectErrorFor("lpv.cascade_ratio", 1, doc), "p.json: lpv.cascade_ratio = 1: must be in (1, 16]");
    EXPECT_EQ(test::projectErrorFor("lpv.quality", 3, doc), "p.json: lpv.quality = 3: must be in [0, 2]");
    EXPECT_EQ(test::projectErrorFor("lpv.cone_trace_samples", 0, doc),
              "p.json: lpv.cone_trace_samples = 0: must be in [1, 64]");
    EXPECT_EQ(test::projectErrorFor("lpv.propagation_weight", -0.5, doc),
              "p.json: lpv.propagation_weight = -0.5: must be in [0, 1]");
    EXPECT_EQ(test::projectErrorFor("lighting.indirect", "all", doc),
              "p.json: lighting.indirect = \"all\": must be one of probes | lpv | both | none");
    EXPECT_EQ(test::projectErrorFor("lpv.auto_cascade_min_size", 0, doc), "");  // 0 = off
    EXPECT_EQ(test::projectErrorFor("lpv.propagation_iterations", 0, doc), "");
}

TEST(ParameterTable, LightsAreAListOfObjectsWithTheSpotRules) {
    json doc = defaultProjectJson();
    EXPECT_EQ(doc["lights"], json::array());
    doc["lights"] = json::parse(R"([
        {"position": [10, 900, -20], "intensity": 5000, "range": 150},
        {"type": "spot", "position": [0, 800, 0], "direction": [0, -1, 0], "color": [1, 0.5, 0.25],
         "inner_cone_deg": 10, "outer_cone_deg": 25}])");
    const SceneDescription s = sceneFromJson(doc, "p.json", nullptr);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].type, LocalLightType::Point);
    EXPECT_EQ(s.lights[0].range, 150.0);
    EXPECT_EQ(s.lights[1].type, LocalLightType::Spot);
    EXPECT_EQ(s.lights[1].outerConeDeg, 25.0);
    const json written = sceneToJson(s);
    EXPECT_EQ(sceneToJson(sceneFromJson(written, "again", nullptr)), written);
    EXPECT_EQ(test::projectErrorFor("lights[1].outer_cone_deg", 10, written),
              "p.json: lights[1].outer_cone_deg = 10: must be above inner_cone_deg (10)");
    EXPECT_EQ(test::projectErrorFor("lights[1].direction", json::array({0, 0, 0}), written),
              "p.json: lights[1].direction = [0,0,0]: must not be the zero vector");
    EXPECT_EQ(test::projectErrorFor("lights[0].range", 0, written), "p.json: lights[0].range = 0: must be in (0, 1000000]");
    EXPECT_EQ(test::projectErrorFor("lights[1].inner_cone_deg", 90, written),
              "p.json: lights[1].inner_cone_deg = 90: must be in [0, 90)");
    EXPECT_EQ(test::projectErrorFor("lights[0].color", json::array({2, 1, 1}), written),
              "p.json: lights[0].color[0] = 2: three components, each in [0, 1]");
    // A point light keeps cone angles it does not read, unchecked against each other.
    EXPECT_EQ(test::projectErrorFor("lights[0].outer_cone_deg", 5, written), "");
    EXPECT_EQ(test::projectErrorFor("lights", json::parse(R"([{"typ": "spot"}])"), defaultProjectJson()),
              "p.json: unknown key 'lights[0].typ' (did you mean 'lights[].type'?)");
}

// The values a dock shows for an "auto" origin and spacing are the grid as placed now: the
// placement kept between edits follows an edit of the volume, and each terrain keeps its own.
TEST(ParameterTable, AutoValuesFollowTheVolumeAndTheTerrain) {
    const ParameterSpec* origin = findParameter("probe_volumes[].origin");
    const ParameterSpec* spacing = findParameter("probe_volumes[].spacing");
    ASSERT_TRUE(origin && origin->resolved && spacing && spacing->resolved);
    auto ramp = [](int n, double cell, float slope) {
        std::vector<float> h(size_t(n) * n);
        for (size_t i = 0; i < h.size(); ++i) h[i] = slope * float(i % size_t(n));
        return Heightfield(n, n, cell, cell, std::move(h));
    };
    SceneDescription s;
    auto placed = [&](const Heightfield& hf) {
        const ProbeLayout l = placeProbes(s.probeVolumes.at(0), hf);
        return std::array<float, 4>{l.positions.at(0).x, l.positions.at(0).z, l.spacing.x, l.spacing.z};
    };
    const Heightfield a = ramp(65, 10.0, 0.5f), b = ramp(65, 30.0, 2.0f);
    for (int pass = 0; pass < 2; ++pass) {
        for (int n : {8, 16, 8}) {
            s.probeVolumes.at(0).gridDims = {n, 1, n};
            for (const Heightfield* hf : {&a, &b}) {
                const json o = origin->resolved(s, *hf, 0), d = spacing->resolved(s, *hf, 0);
                const std::array<float, 4> p = placed(*hf);
                ASSERT_EQ(o.size(), 2u);
                ASSERT_EQ(d.size(), 2u);
                EXPECT_FLOAT_EQ(o[0].get<float>(), p[0]) << n;
                EXPECT_FLOAT_EQ(o[1].get<float>(), p[1]) << n;
                EXPECT_FLOAT_EQ(d[0].get<float>(), p[2]) << n;
                EXPECT_FLOAT_EQ(d[1].get<float>(), p[3]) << n;
            }
        }
    }
    // The two terrains and the two grids place differently, so a value kept for the wrong one
    // would show.
    s.probeVolumes.at(0).gridDims = {8, 1, 8};
    EXPECT_NE(origin->resolved(s, a, 0), origin->resolved(s, b, 0));
    const json coarse = spacing->resolved(s, a, 0);
    s.probeVolumes.at(0).gridDims = {16, 1, 16};
    EXPECT_NE(spacing->resolved(s, a, 0), coarse);
}

// The docks, the window's estimate and the viewport's markers ask for a volume's placement on
// every edit: it is placed once per volume and terrain, as placeProbes places it, and refused
// as placeProbes refuses it; any other failure is thrown as it is. What is kept stays within
// its count and bytes.
TEST(KeptPlacement, APlacementIsKeptPerVolumeAndTerrain) {
    auto slope = [](float rise) {
        std::vector<float> h(size_t(33) * 33);
        for (size_t i = 0; i < h.size(); ++i) h[i] = rise * float(i / 33);
        return Heightfield(33, 33, 20.0, 20.0, std::move(h));
    };
    const Heightfield a = slope(1.0f), b = slope(3.0f);
    SceneDescription s;
    s.probeVolumes.at(0).gridDims = {6, 1, 5};
    const auto first = keptPlacement(s, 0, a);
    const ProbeLayout direct = placeProbes(s.probeVolumes.at(0), a);
    EXPECT_EQ(first->positions, direct.positions);
    EXPECT_EQ(first->cellProbe, direct.cellProbe);
    EXPECT_EQ(keptPlacement(s, 0, a), first);  // kept
    const Heightfield copy = a;                // a copy is the same terrain
    EXPECT_EQ(keptPlacement(s, 0, copy), first);
    const auto other = keptPlacement(s, 0, b);  // another terrain: placed on it
    EXPECT_NE(other, first);
    EXPECT_EQ(other->positions, placeProbes(s.probeVolumes.at(0), b).positions);
    s.probeVolumes.at(0).gridDims = {7, 1, 5};  // another volume: placed again
    EXPECT_EQ(keptPlacement(s, 0, a)->positions.size(), 35u);
    // A volume the bake refuses throws placeProbes' message, kept or not.
    s.probeVolumes.at(0).heightOffset = -1.0e6;
    std::string refused;
    try {
        placeProbes(s.probeVolumes.at(0), a);
    } catch (const PlacementError& e) {
        refused = e.what();
    }
    ASSERT_FALSE(refused.empty());
    for (int i = 0; i < 2; ++i) {
        try {
            keptPlacement(s, 0, a);
            ADD_FAILURE() << "not refused";
        } catch (const PlacementError& e) {
            EXPECT_EQ(std::string(e.what()), refused);
        }
    }
    // No such volume: not a refusal of the bake's.
    EXPECT_THROW(keptPlacement(s, 3, a), std::out_of_range);
    EXPECT_GE(keptPlacements(), 1u);
    EXPECT_LE(keptPlacements(), kKeptPlacements);
    EXPECT_LE(keptPlacementBytes(), kKeptPlacementBytes);
}
