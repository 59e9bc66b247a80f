// Lighting scenarios: the project's rules for them, and bakes that write each scenario's probes
// with the default's layout, listed in the glTF scene.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "BakeJob.h"
#include "GltfExport.h"
#include "ParameterTable.h"
#include "Project.h"
#include "SceneLighting.h"
#include "ShProbeFile.h"

using namespace terralux;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

const fs::path kCrop = fs::path(TERRALUX_TEST_DATA) / "dem" / "bigtujunga_utm11_crop.tif";

std::string errorOf(const json& doc) {
    try {
        (void)sceneFromJson(doc, "p.json", nullptr);
    } catch (const ProjectError& e) {
        return e.what();
    }
    return "";
}

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() /
                       ("terralux_scenarios_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(d);
    return d;
}

std::string bytesOf(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

// A quick bake of the committed crop: a 6 x 6 terrain grid at draft quality.
json cropDocument(const fs::path& out) {
    json doc = defaultProjectJson();
    doc["terrain"]["dem"] = kCrop.string();
    doc["probe_volumes"][0]["grid_dims"] = {6, 6};
    doc["bake"]["quality"] = "draft";
    doc["bake"]["error_map_resolution"] = 0;
    doc["export"]["out_dir"] = out.string();
    return doc;
}

const json kDusk = {{"name", "dusk"},
                    {"sun", {{"azimuth_deg", 250.0}, {"elevation_deg", 6.0}, {"illuminance", 50000.0}}},
                    {"sky", {{"intensity", 0.4}, {"color", {0.12, 0.09, 0.08}}}}};

}  // namespace

TEST(Scenarios, NamesAreUniqueAndNeverDefault) {
    json doc = defaultProjectJson();
    doc["scenarios"] = json::array({kDusk, kDusk});
    EXPECT_EQ(errorOf(doc), "p.json: scenarios[1].name = \"dusk\": must be unique among scenarios and not \"default\" "
                            "(the project's own sun and sky)");
    doc["scenarios"] = json::array({json{{"name", "default"}}});
    EXPECT_NE(errorOf(doc).find("scenarios[0].name = \"default\""), std::string::npos);
    doc["scenarios"] = json::array({json{{"name", "dusk.late"}}});
    EXPECT_NE(errorOf(doc).find("scenarios[0].name = \"dusk.late\": must be 1-64 letters"), std::string::npos);
    doc["scenarios"] = json::array();
    for (int i = 0; i <= kMaxScenarios; ++i) {
        std::string name = "s";
        name += std::to_string(i);
        doc["scenarios"].push_back(json{{"name", name}});
    }
    EXPECT_NE(errorOf(doc).find("scenarios = "), std::string::npos);
    EXPECT_NE(errorOf(doc).find("must hold at most 16 scenarios (has 17)"), std::string::npos);
}

TEST(Scenarios, AScenarioHoldsASunAndASkyUnderTheProjectsRules) {
    json doc = defaultProjectJson();
    json bad = kDusk;
    bad["sun"]["elevation_deg"] = 95.0;
    doc["scenarios"] = json::array({bad});
    EXPECT_EQ(errorOf(doc), "p.json: scenarios[0].sun.elevation_deg = 95.0: must be in [-90, 90]");
    bad = kDusk;
    bad["sky"]["mode"] = "hdr";  // without an image: the sky's own rule
    doc["scenarios"] = json::array({bad});
    EXPECT_NE(errorOf(doc).find("scenarios[0].sky.hdr = \"\": must name an image"), std::string::npos);
    // The probe layout is shared: a scenario changes nothing but the light.
    bad = kDusk;
    bad["probe_volumes"] = json::array();
    doc["scenarios"] = json::array({bad});
    EXPECT_NE(errorOf(doc).find("unknown key 'scenarios[0].probe_volumes'"), std::string::npos);

    doc["scenarios"] = json::array({kDusk});
    const SceneDescription s = sceneFromJson(doc, "p.json", nullptr);
    ASSERT_EQ(s.scenarios.size(), 1u);
    EXPECT_EQ(scenarioNames(s), (std::vector<std::string>{"default", "dusk"}));
    const SceneDescription dusk = scenarioScene(s, "dusk");
    EXPECT_EQ(dusk.sun.elevationDeg, 6.0);
    EXPECT_EQ(dusk.sun.azimuthDeg, 250.0);
    EXPECT_EQ(dusk.sky.intensity, 0.4);
    EXPECT_EQ(sceneToJson(dusk)["probe_volumes"], sceneToJson(s)["probe_volumes"]);
    EXPECT_EQ(scenarioScene(s, "default").sun.elevationDeg, s.sun.elevationDeg);
    try {
        (void)scenarioScene(s, "noon");
        FAIL() << "an unknown scenario was accepted";
    } catch (const ProjectError& e) {
        EXPECT_STREQ(e.what(), "scenario 'noon': the project has no such lighting scenario (it has default, dusk)");
    }
    // Written back as read, and an edit of a scenario is an edit the bake reads, by its path.
    EXPECT_EQ(sceneToJson(sceneFromJson(sceneToJson(s), "again", nullptr)), sceneToJson(s));
    Project a, b;
    a.scene = s;
    b.scene = s;
    b.scene.scenarios[0].sun.elevationDeg = 7.0;
    const std::vector<std::string> diff = bakeInputDifferences(bakeInputs(a), bakeInputs(b));
    ASSERT_EQ(diff.size(), 1u);
    EXPECT_NE(diff[0].find("scenarios[0].sun.elevation_deg"), std::string::npos) << diff[0];
    EXPECT_EQ(editLabel("scenarios[0].sun.elevation_deg", sceneToJson(s)), "Sun elevation of scenario 'dusk'");
}

// A scenario's probes are the probes a bake of a project lit as the scenario writes, byte for
// byte: the same layout, seeds and cache, only the light differs.
TEST(Scenarios, AScenariosProbesAreABakeOfItsLighting) {
    const fs::path dir = tempDir("bake");
    json doc = cropDocument(dir / "with");
    doc["scenarios"] = json::array({kDusk});
    Project p;
    p.scene = sceneFromJson(doc, "p.json", nullptr);
    const BakeOutcome out = runBake(BakeRequest{p, 2, false, {}}, {}, nullptr);

    json lit = cropDocument(dir / "lit");
    lit["sun"] = kDusk["sun"];
    lit["sky"] = kDusk["sky"];
    Project q;
    q.scene = sceneFromJson(lit, "lit.json", nullptr);
    (void)runBake(BakeRequest{q, 1, false, {}}, {}, nullptr);

    const fs::path scenarioFile = dir / "with" / "scenarios" / "probes.dusk.shprobe";
    ASSERT_TRUE(fs::exists(scenarioFile));
    EXPECT_EQ(bytesOf(scenarioFile), bytesOf(dir / "lit" / "sh_coeffs" / "probes.shprobe"));
    // The default is the project's own lighting, untouched by the scenario.
    const ShProbeGrid def = readShProbeFile(dir / "with" / "sh_coeffs" / "probes.shprobe");
    const ShProbeGrid dusk = readShProbeFile(scenarioFile);
    EXPECT_EQ(def.dims, dusk.dims);
    EXPECT_EQ(def.occupancy, dusk.occupancy);
    EXPECT_NE(def.probes, dusk.probes);
    // Dusk is darker: less sun and a dimmer sky.
    double e0 = 0.0, e1 = 0.0;
    for (size_t i = 0; i < def.probes.size(); ++i) {
        e0 += def.probes[i].coeffs[0].g;
        e1 += dusk.probes[i].coeffs[0].g;
    }
    EXPECT_LT(e1, 0.6 * e0);

    ASSERT_TRUE(out.report.contains("scenarios"));
    const json& sr = out.report["scenarios"][0];
    EXPECT_EQ(sr["name"], "dusk");
    EXPECT_GT(sr["probe_rays"].get<uint64_t>(), 0u);
    EXPECT_GT(sr["volumes"][0]["standard_error"]["mean"].get<double>(), 0.0);

    // The glTF scene lists the default and the scenario with their files and lighting; seed 001's
    // shProbeGrids is the default's alone.
    std::ifstream in(dir / "with" / "scene.gltf");
    const json gltf = json::parse(in);
    const json& ext = gltf["scenes"][0]["extensions"]["TERRALUX_lighting"];
    ASSERT_EQ(ext["scenarios"].size(), 2u);
    EXPECT_EQ(ext["scenarios"][0]["name"], "default");
    EXPECT_EQ(ext["scenarios"][0]["shProbePaths"], json::array({"sh_coeffs/probes.shprobe"}));
    EXPECT_EQ(ext["scenarios"][1]["name"], "dusk");
    EXPECT_EQ(ext["scenarios"][1]["shProbePaths"], json::array({"scenarios/probes.dusk.shprobe"}));
    EXPECT_EQ(ext["scenarios"][1]["sun"]["elevation_deg"], 6.0);
    EXPECT_EQ(ext["scenarios"][1]["sky"]["intensity"], 0.4);
    EXPECT_EQ(ext["scenarios"][0]["sun"], ext["sun"]);
    const json grids = readShProbeGridEntries(dir / "with" / "scene.gltf");
    ASSERT_EQ(grids.size(), 1u);
    EXPECT_EQ(grids[0]["shProbePath"], "sh_coeffs/probes.shprobe");

    // A bake without the scenario removes its file with the rest of the earlier bake.
    doc["scenarios"] = json::array();
    p.scene = sceneFromJson(doc, "p.json", nullptr);
    (void)runBake(BakeRequest{p, 2, false, {}}, {}, nullptr);
    EXPECT_FALSE(fs::exists(scenarioFile));
    std::ifstream again(dir / "with" / "scene.gltf");
    EXPECT_FALSE(json::parse(again)["scenes"][0]["extensions"]["TERRALUX_lighting"].contains("scenarios"));
    fs::remove_all(dir);
}

// A scenario's sun that the terrain cannot place (a date and a time over a DEM without a CRS) is
// refused by its scenario's name, before any work.
TEST(Scenarios, ASunThatCannotBePlacedIsRefusedByItsScenario) {
    const Heightfield hf(4, 4, 10.0, 10.0, std::vector<float>(16, 100.0f));  // no CRS
    SceneDescription s;
    LightingScenario noon;
    noon.name = "noon";
    noon.sun.mode = SunMode::DateTime;
    s.scenarios = {noon};
    try {
        checkSunPlaces(s, hf);
        FAIL() << "a sun without a place was accepted";
    } catch (const ProjectError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("scenario 'noon': ", 0), 0u) << e.what();
    }
    s.scenarios[0].sun.latitudeDeg = 46.0;
    s.scenarios[0].sun.longitudeDeg = 7.0;
    EXPECT_NO_THROW(checkSunPlaces(s, hf));
}

TEST(Scenarios, TheExportRefusesAScenarioOfAnotherLayout) {
    const fs::path dir = tempDir("export");
    GltfSceneInput in;
    Heightfield hf(4, 4, 10.0, 10.0, std::vector<float>(16, 100.0f));
    in.heightfield = &hf;
    ShProbeGrid g;
    g.dims = {2, 1, 2};
    g.spacing = 10.0f;
    g.occupancy = {0, 1, 2, 3};
    g.probes.resize(4);
    in.volumes.push_back({"probes", g, ""});
    in.lighting = json::object();
    ShProbeGrid other = g;
    other.spacing = 20.0f;
    in.scenarios.push_back({"dusk", {{"probes", other, ""}}, json::object()});
    try {
        exportGltfScene(dir, in);
        FAIL() << "a scenario of another layout was written";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("scenario 'dusk' must hold the default's volumes with their layout"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "scene.gltf"));
    in.scenarios[0].volumes[0].grid = g;
    const GltfExportResult r = exportGltfScene(dir, in);
    EXPECT_TRUE(fs::exists(dir / "scenarios" / "probes.dusk.shprobe"));
    EXPECT_EQ(exportedFileNames(in).size(), r.files.size());
    fs::remove_all(dir);
}
