// The parameter table drives the project reader and writer, --set, the schema and the docs:
// these tests hold every row to its own declaration.
#include <cmath>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include "ParameterTable.h"
#include "Project.h"
#include "ProjectErrors.h"

using namespace terralux;
using nlohmann::json;

namespace {

// The path of a row in a document with one probe volume.
std::string concrete(const ParameterSpec& s) {
    return s.perVolume() ? "probe_volumes[0]." + s.localPath() : s.path;
}

std::string errorFor(const std::string& path, const json& value, const json& base = defaultProjectJson()) {
    return test::projectErrorFor(path, value, base);
}

}  // namespace

TEST(ParameterTable, PathsAreUniqueAndEveryRowIsDeclaredWhole) {
    std::set<std::string> paths;
    for (const auto& s : parameterTable()) {
        EXPECT_TRUE(paths.insert(s.path).second) << s.path;
        EXPECT_FALSE(s.label.empty()) << s.path;
        EXPECT_FALSE(s.description.empty()) << s.path;
        EXPECT_TRUE(s.get && s.set) << s.path;
        if (s.type == ParamType::Choice) EXPECT_GE(s.choices.size(), 2u) << s.path;
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
        EXPECT_EQ(errorFor(concrete(spec), spec.defaultValue()), "") << spec.path;
        EXPECT_EQ(spec.get(s, 0), spec.defaultValue()) << spec.path;
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
                const std::string message = errorFor(path, value);
                EXPECT_EQ(message.rfind("p.json: " + path + " = ", 0), 0u) << message;
                EXPECT_NE(message.find(": " + rule), std::string::npos) << spec.path << ": " << message;
                ++checked;
            }
            // Inside the bounds is accepted (unless another rule of the row says otherwise).
            EXPECT_EQ(errorFor(path, spec.defaultValue()), "") << spec.path;
            EXPECT_NE(errorFor(path, "text"), "") << spec.path;
        }
        if (list && std::isfinite(spec.min)) {
            json value = spec.defaultValue();
            if (value.is_null() || !value.is_array()) continue;
            value[0] = outside(spec.min, true, spec.minExclusive);
            if (spec.type == ParamType::IntegerList) value[0] = (long long)value[0].get<double>();
            const std::string message = errorFor(path, value);
            EXPECT_EQ(message.rfind("p.json: " + path + "[0] = ", 0), 0u) << spec.path << ": " << message;
            ++checked;
        }
        if (spec.type == ParamType::Choice) {
            EXPECT_EQ(errorFor(path, "nonsense"),
                      "p.json: " + path + " = \"nonsense\": must be " + spec.rangeText());
            ++checked;
        }
        if (spec.type == ParamType::Boolean) {
            EXPECT_EQ(errorFor(path, 1), "p.json: " + path + " = 1: must be true or false");
            ++checked;
        }
        if (!spec.nullable()) {
            EXPECT_NE(errorFor(path, nullptr), "") << spec.path << " must not accept null";
        } else {
            EXPECT_EQ(errorFor(path, nullptr), "") << spec.path << " accepts null (auto)";
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
        if (spec.perVolume()) {
            node = &schema["properties"]["probe_volumes"]["items"];
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
            EXPECT_EQ(inner["maximum"], spec.max) << spec.path;
        }
        if (spec.type == ParamType::Choice) EXPECT_EQ(inner["enum"], json(spec.choices)) << spec.path;
    }
}

TEST(ParameterTable, ReferenceListsEveryRow) {
    const std::string md = parameterReferenceMarkdown();
    for (const auto& spec : parameterTable())
        EXPECT_NE(md.find("| `" + spec.path + "` |"), std::string::npos) << spec.path;
}

TEST(ParameterTable, SunAndSkyRowsAreReadByTheirSkyMode) {
    auto read = [](const SceneDescription& s, const char* path) { return findParameter(path)->isRead(s, 0); };
    SceneDescription s;  // uniform
    for (const char* path : {"sky.color", "sky.intensity", "sun.illuminance", "sun.color"})
        EXPECT_TRUE(read(s, path)) << path;
    for (const char* path : {"sky.turbidity", "sun.follow_sky", "sky.hdr", "sky.rotation_deg"})
        EXPECT_FALSE(read(s, path)) << path;
    s.sky.mode = SkyMode::Hdr;
    for (const char* path : {"sky.hdr", "sky.rotation_deg", "sun.illuminance", "sun.color"})
        EXPECT_TRUE(read(s, path)) << path;
    for (const char* path : {"sky.turbidity", "sun.follow_sky", "sky.color"}) EXPECT_FALSE(read(s, path)) << path;
    s.sky.mode = SkyMode::Physical;
    for (const char* path : {"sky.turbidity", "sky.intensity", "sun.follow_sky"}) EXPECT_TRUE(read(s, path)) << path;
    for (const char* path : {"sky.color", "sky.hdr", "sky.rotation_deg", "sun.illuminance", "sun.color"})
        EXPECT_FALSE(read(s, path)) << path;
    s.sun.followSky = false;
    for (const char* path : {"sun.illuminance", "sun.color"}) EXPECT_TRUE(read(s, path)) << path;
}
