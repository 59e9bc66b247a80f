#include <cmath>
#include <filesystem>
#include <fstream>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "Project.h"
#include "ImageFile.h"
#include "SceneLighting.h"
#include "TerrainLoading.h"
#include "bake/PhysicalSky.h"

using namespace terralux;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

std::string errorFor(const std::string& assignment) {
    json doc = defaultProjectJson();
    try {
        applyOverride(doc, assignment);
        sceneFromJson(doc, "p.json", nullptr);
    } catch (const ProjectError& e) {
        return e.what();
    }
    return "";
}

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("terralux_project_" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

}  // namespace

TEST(Project, DefaultsAreLightingMdDefaults) {
    const SceneDescription s = sceneFromJson(defaultProjectJson(), "defaults", nullptr);
    ASSERT_EQ(s.probeVolumes.size(), 1u);
    EXPECT_EQ(s.probeVolumes[0].gridDims[0], 8);
    EXPECT_EQ(s.probeVolumes[0].gridDims[2], 8);
    EXPECT_DOUBLE_EQ(s.probeVolumes[0].heightOffset, 5.0);
    EXPECT_FALSE(s.probeVolumes[0].spacing.has_value());  // auto-span
    EXPECT_EQ(s.sky.color, glm::vec3(0.6f, 0.73333333f, 1.0f));
    EXPECT_DOUBLE_EQ(s.sky.luminance, 5000.0);
    EXPECT_DOUBLE_EQ(s.sky.intensity, 1.0);
    // The sky the defaults were tuned with, before the sky had a unit.
    const glm::vec3 radiance = s.sky.uniformRadiance();
    EXPECT_NEAR(radiance.x, 0.09f, 1e-6f);
    EXPECT_NEAR(radiance.y, 0.11f, 1e-6f);
    EXPECT_NEAR(radiance.z, 0.15f, 1e-6f);
    // A clear day: direct sun on level ground at the default elevation against the uniform sky's
    // irradiance π·L on it lands within the 4-10 : 1 of docs/lighting.md.
    const double direct = s.sun.illuminance * kSceneUnitsPerLux * std::sin(s.sun.elevationDeg * M_PI / 180.0);
    const double diffuse = M_PI * (0.2126 * radiance.x + 0.7152 * radiance.y + 0.0722 * radiance.z);
    EXPECT_GE(direct / diffuse, 4.0);
    EXPECT_LE(direct / diffuse, 10.0);
    EXPECT_TRUE(s.shadows.enabled);
    EXPECT_TRUE(s.fog.enabled);
    EXPECT_EQ(s.camera.exposureEv, 0.0);
    EXPECT_DOUBLE_EQ(s.sun.angularRadiusDeg, 0.27);
    EXPECT_EQ(s.reflectionProbes.gridDims[0], 4);
    EXPECT_EQ(s.reflectionProbes.rayCount, 16);
    EXPECT_EQ(s.reflectionProbes.groundColor, glm::vec3(0.22f, 0.18f, 0.14f));
    EXPECT_DOUBLE_EQ(s.exportSettings.defaultScale, 1.0);
    EXPECT_DOUBLE_EQ(s.exportSettings.defaultAmbient, 0.1);
    EXPECT_TRUE(s.terrain.skirt);
}

// Every rule: the message names the source, the JSON path, the value and the rule.
struct Rule {
    const char* assignment;
    const char* message;
};
class ProjectRules : public ::testing::TestWithParam<Rule> {};
TEST_P(ProjectRules, RejectsWithPathValueAndRule) {
    EXPECT_EQ(errorFor(GetParam().assignment), GetParam().message);
}
INSTANTIATE_TEST_SUITE_P(
    AllRules, ProjectRules,
    ::testing::Values(
        Rule{"probe_volumes[0].grid_dims=[0,8]", "p.json: probe_volumes[0].grid_dims[0] = 0: must be in [1, 65536]"},
        Rule{"probe_volumes[0].grid_dims=[65,64]", "p.json: probe_volumes[0].grid_dims = [65,64]: must be >= 1 each with a product <= 4096 (is 4160)"},
        Rule{"probe_volumes[0].grid_dims=[8]", "p.json: probe_volumes[0].grid_dims = [8]: must be an array of 2 numbers"},
        Rule{"probe_volumes[0].grid_dims=[2.5,8]", "p.json: probe_volumes[0].grid_dims[0] = 2.5: must be an integer"},
        Rule{"probe_volumes[0].height_offset=\"x\"", "p.json: probe_volumes[0].height_offset = \"x\": must be a number"},
        Rule{"probe_volumes[0].ray_count=0", "p.json: probe_volumes[0].ray_count = 0: must be in [1, 1048576] or null"},
        Rule{"probe_volumes[0].spacing=[0,10]", "p.json: probe_volumes[0].spacing[0] = 0: must be in (0, 1000000]"},
        Rule{"probe_volumes[0].spacing=[10,-1]", "p.json: probe_volumes[0].spacing[1] = -1: must be in (0, 1000000]"},
        Rule{"probe_volumes[0].fallback_blend_distance=-1", "p.json: probe_volumes[0].fallback_blend_distance = -1: must be in [0, 10000000] or null"},
        Rule{"probe_volumes[0].name=a/b", "p.json: probe_volumes[0].name = \"a/b\": must be 1-64 letters, digits, '_' or '-' (it names the .shprobe file)"},
        Rule{"probe_volumes[0].placement=cone", "p.json: probe_volumes[0].placement = \"cone\": must be one of terrain | box | adaptive | surface"},
        Rule{"probe_volumes[0].adaptive.min_cell_size=0", "p.json: probe_volumes[0].adaptive.min_cell_size = 0: must be in (0, 1000000] or null"},
        Rule{"probe_volumes[0].adaptive.max_cell_size=-4", "p.json: probe_volumes[0].adaptive.max_cell_size = -4: must be in (0, 10000000] or null"},
        Rule{"probe_volumes[0].adaptive={\"min_cell_size\":30,\"max_cell_size\":100}", "p.json: probe_volumes[0].adaptive.max_cell_size = 100: must be min_cell_size (30) times 2^k, k in [0, 16]"},
        Rule{"probe_volumes[0].adaptive={\"min_cell_size\":32,\"max_cell_size\":16}", "p.json: probe_volumes[0].adaptive.max_cell_size = 16: must be min_cell_size (32) times 2^k, k in [0, 16]"},
        Rule{"probe_volumes[0].adaptive={\"min_cell_size\":1,\"max_cell_size\":131072}", "p.json: probe_volumes[0].adaptive.max_cell_size = 131072: must be min_cell_size (1) times 2^k, k in [0, 16]"},
        Rule{"probe_volumes[0].adaptive.height_range=-1", "p.json: probe_volumes[0].adaptive.height_range = -1: must be in [0, 100000]"},
        Rule{"probe_volumes[0].adaptive.size=[100,0,100]", "p.json: probe_volumes[0].adaptive.size[1] = 0: must be in (0, 10000000]"},
        Rule{"probe_volumes[0].adaptive.size=[100,100]", "p.json: probe_volumes[0].adaptive.size = [100,100]: must be an array of 3 numbers or null"},
        Rule{"probe_volumes[0].adaptive.surface_band=-2", "p.json: probe_volumes[0].adaptive.surface_band = -2: must be in [0, 1000000] or null"},
        Rule{"probe_volumes[0].adaptive.tolerance=0", "p.json: probe_volumes[0].adaptive.tolerance = 0: must be in (0, 1] or null"},
        Rule{"probe_volumes[0].adaptive.tolerance=1.5", "p.json: probe_volumes[0].adaptive.tolerance = 1.5: must be in (0, 1] or null"},
        Rule{"probe_volumes[0].adaptive.max_probes=0", "p.json: probe_volumes[0].adaptive.max_probes = 0: must be in [1, 65536] or null"},
        Rule{"probe_volumes[0].adaptive.max_probes=70000", "p.json: probe_volumes[0].adaptive.max_probes = 70000: must be in [1, 65536] or null"},
        Rule{"probe_volumes[0].adaptive.max_bytes=2.5", "p.json: probe_volumes[0].adaptive.max_bytes = 2.5: must be an integer"},
        Rule{"probe_volumes[0].adaptive.max_bytes=0", "p.json: probe_volumes[0].adaptive.max_bytes = 0: must be in [1, 9007199254740992] or null"},
        Rule{"probe_volumes[0].adaptive.max_move_share=0.6", "p.json: probe_volumes[0].adaptive.max_move_share = 0.6: must be in [0, 0.5]"},
        Rule{"probe_volumes[0].adaptive=3", "p.json: probe_volumes[0].adaptive = 3: must be an object"},
        Rule{"sky.color=[0.5,-1,1]", "p.json: sky.color[1] = -1: three components, each in [0, 1]"},
        Rule{"sky.color=[1,1]", "p.json: sky.color = [1,1]: must be an array of 3 numbers"},
        Rule{"sky.color=[0.5,1.5,1]", "p.json: sky.color[1] = 1.5: three components, each in [0, 1]"},
        Rule{"sky.luminance=-1", "p.json: sky.luminance = -1: must be in [0, 10000000]"},
        Rule{"sky.intensity=-0.5", "p.json: sky.intensity = -0.5: must be in [0, 100000]"},
        Rule{"sky.mode=hdr", "p.json: sky.hdr = \"\": must name an image when sky.mode is \"hdr\""},
        Rule{"sky.mode=sunny", "p.json: sky.mode = \"sunny\": must be one of uniform | hdr | physical"},
        Rule{"sky.turbidity=12", "p.json: sky.turbidity = 12: must be in [1.7, 10]"},
        Rule{"sky.turbidity=1", "p.json: sky.turbidity = 1: must be in [1.7, 10]"},
        Rule{"sun.follow_sky=1", "p.json: sun.follow_sky = 1: must be true or false"},
        Rule{"reflection_probes.grid_dims=[17,16]", "p.json: reflection_probes.grid_dims = [17,16]: must be >= 1 each with a product <= 256 (is 272)"},
        Rule{"reflection_probes.grid_dims=[0,1]", "p.json: reflection_probes.grid_dims[0] = 0: must be in [1, 256]"},
        Rule{"reflection_probes.ray_count=0", "p.json: reflection_probes.ray_count = 0: must be in [1, 1048576]"},
        Rule{"reflection_probes.strength=1.5", "p.json: reflection_probes.strength = 1.5: must be in [0, 1]"},
        Rule{"reflection_probes.ground_color=[1,1,-0.1]", "p.json: reflection_probes.ground_color[2] = -0.1: three components, each in [0, 1]"},
        Rule{"sun.elevation_deg=91", "p.json: sun.elevation_deg = 91: must be in [-90, 90]"},
        Rule{"sun.illuminance=-1", "p.json: sun.illuminance = -1: must be in [0, 10000000]"},
        Rule{"sun.angular_radius_deg=50", "p.json: sun.angular_radius_deg = 50: must be in [0, 45]"},
        Rule{"terrain.vertical_scale=0", "p.json: terrain.vertical_scale = 0: must be in (0, 100]"},
        Rule{"terrain.albedo=[0.5,1.2,0.5]", "p.json: terrain.albedo[1] = 1.2: three components, each in [0, 1]"},
        Rule{"terrain.max_resolution=1", "p.json: terrain.max_resolution = 1: must be 0 (off) or >= 2"},
        Rule{"terrain.skirt=maybe", "p.json: terrain.skirt = \"maybe\": must be true or false"},
        Rule{"bake.quality=ultra", "p.json: bake.quality = \"ultra\": must be one of draft | standard | high | reference"},
        Rule{"bake.bounces=17", "p.json: bake.bounces = 17: must be in [0, 16] or null"},
        Rule{"bake.rays=0", "p.json: bake.rays = 0: must be in [1, 1048576] or null"},
        Rule{"bake.sh_encoding=rgb", "p.json: bake.sh_encoding = \"rgb\": must be one of radiance | irradiance"},
        Rule{"export.out_dir=\"\"", "p.json: export.out_dir = \"\": must name a folder"},
        Rule{"export.default_ambient=-0.1", "p.json: export.default_ambient = -0.1: must be in [0, 100]"},
        Rule{"camera.elevation_deg=90", "p.json: camera.elevation_deg = 90: must be in [-89.9, 89.9]"},
        Rule{"camera.fov_deg=0.5", "p.json: camera.fov_deg = 0.5: must be in [1, 150]"},
        Rule{"camera.radius=0", "p.json: camera.radius = 0: must be in (0, 100000000] or null"},
        Rule{"camera.target=[1,2]", "p.json: camera.target = [1,2]: must be an array of 3 numbers or null"},
        Rule{"version=9", "p.json: version = 9: is newer than this Terralux reads (8); open it with a newer Terralux"},
        Rule{"version=0", "p.json: version = 0: must be an integer >= 1"}));

TEST(Project, BoxVolumesValidateThreeDims) {
    EXPECT_EQ(errorFor("probe_volumes[0].placement=box"),
              "p.json: probe_volumes[0].grid_dims = [8,8]: must be an array of 3 numbers");
    json doc = defaultProjectJson();
    applyOverride(doc, "probe_volumes[0].placement=box");
    applyOverride(doc, "probe_volumes[0].grid_dims=4,2,4");
    applyOverride(doc, "probe_volumes[0].spacing=25");
    const SceneDescription s = sceneFromJson(doc, "p.json", nullptr);
    EXPECT_EQ(s.probeVolumes[0].placement, ProbePlacement::Box);
    EXPECT_EQ(s.probeVolumes[0].gridDims, (std::array<int, 3>{4, 2, 4}));
    EXPECT_FLOAT_EQ(s.probeVolumes[0].spacing->x, 25.f);
}

TEST(Project, AdaptiveVolumesTakeTheirSettingsFromJsonAndSet) {
    const SceneDescription d = sceneFromJson(defaultProjectJson(), "defaults", nullptr);
    const AdaptiveVolumeSettings& a = d.probeVolumes[0].adaptive;
    EXPECT_FALSE(a.minCellSize.has_value());   // the DEM cell size
    EXPECT_FALSE(a.maxCellSize.has_value());   // 16 x min_cell_size
    EXPECT_DOUBLE_EQ(a.heightRange, 100.0);
    EXPECT_FALSE(a.surfaceBand.has_value());   // one min cell
    EXPECT_FALSE(a.tolerance.has_value());     // geometric only
    EXPECT_FALSE(a.maxProbes.has_value());
    EXPECT_FALSE(a.maxBytes.has_value());
    EXPECT_DOUBLE_EQ(a.maxMoveShare, 0.25);

    json doc = defaultProjectJson();
    for (const char* set :
         {"probe_volumes[0].placement=adaptive", "probe_volumes[0].origin=-100,500,-200",
          "probe_volumes[0].adaptive.min_cell_size=30", "probe_volumes[0].adaptive.max_cell_size=480",
          "probe_volumes[0].adaptive.height_range=250", "probe_volumes[0].adaptive.size=3000,1200,2000",
          "probe_volumes[0].adaptive.surface_band=45", "probe_volumes[0].adaptive.tolerance=0.03",
          "probe_volumes[0].adaptive.max_probes=40000", "probe_volumes[0].adaptive.max_bytes=9000000000",
          "probe_volumes[0].adaptive.max_move_share=0.5"})
        applyOverride(doc, set);
    const SceneDescription s = sceneFromJson(doc, "--set", nullptr);
    const ProbeVolumeSettings& v = s.probeVolumes[0];
    EXPECT_EQ(v.placement, ProbePlacement::Adaptive);
    EXPECT_EQ(*v.origin, glm::vec3(-100.f, 500.f, -200.f));
    EXPECT_DOUBLE_EQ(*v.adaptive.minCellSize, 30.0);
    EXPECT_DOUBLE_EQ(*v.adaptive.maxCellSize, 480.0);
    EXPECT_DOUBLE_EQ(v.adaptive.heightRange, 250.0);
    EXPECT_EQ(*v.adaptive.size, glm::vec3(3000.f, 1200.f, 2000.f));
    EXPECT_DOUBLE_EQ(*v.adaptive.surfaceBand, 45.0);
    EXPECT_DOUBLE_EQ(*v.adaptive.tolerance, 0.03);
    EXPECT_EQ(*v.adaptive.maxProbes, 40000);
    EXPECT_EQ(*v.adaptive.maxBytes, 9000000000ll);
    EXPECT_DOUBLE_EQ(v.adaptive.maxMoveShare, 0.5);
    // Written back as read; grid_dims and spacing, which adaptive volumes ignore, are not
    // validated against the adaptive placement.
    EXPECT_EQ(sceneToJson(sceneFromJson(sceneToJson(s), "again", nullptr)), sceneToJson(s));
    applyOverride(doc, "probe_volumes[0].grid_dims=4,2,4");
    EXPECT_NO_THROW(sceneFromJson(doc, "--set", nullptr));
    EXPECT_EQ(errorFor("probe_volumes[0].placement=adaptive").size(), 0u);
}

TEST(Project, OverridesReachEveryParameterAndRejectUnknownPaths) {
    json doc = defaultProjectJson();
    applyOverride(doc, "sun.elevation_deg=12.5");
    applyOverride(doc, "probe_volumes[0].grid_dims=16,16");
    applyOverride(doc, "sky.hdr=skies/noon.hdr");
    const SceneDescription s = sceneFromJson(doc, "--set", nullptr);
    EXPECT_DOUBLE_EQ(s.sun.elevationDeg, 12.5);
    EXPECT_EQ(s.probeVolumes[0].gridDims[0], 16);
    EXPECT_EQ(s.sky.hdr, "skies/noon.hdr");

    auto err = [&](const std::string& a) {
        try {
            applyOverride(doc, a);
        } catch (const ProjectError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(err("sun.elevaton_deg=3"),
              "--set sun.elevaton_deg: unknown parameter 'sun.elevaton_deg' (did you mean 'sun.elevation_deg'?)");
    EXPECT_EQ(err("sun.zenith=3"),
              "--set sun.zenith: unknown parameter 'sun.zenith' (terralux --print-project lists them)");
    EXPECT_EQ(err("probe_volumes[3].grid_dims=[2,2]"),
              "--set probe_volumes[3].grid_dims: unknown parameter 'probe_volumes[3]' (there are 1)");
    EXPECT_EQ(err("sun"), "--set sun: expected key.path=value");
    EXPECT_EQ(err("=3"), "--set =3: expected key.path=value");
}

TEST(Project, UnknownKeysAreErrorsNamingTheKey) {
    // A misspelt key in a file must not bake with the default.
    auto err = [](const json& doc) {
        try {
            sceneFromJson(doc, "p.json", nullptr);
        } catch (const ProjectError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(err({{"sun", {{"elevaton_deg", 20}}}}),
              "p.json: unknown key 'sun.elevaton_deg' (did you mean 'sun.elevation_deg'?)");
    EXPECT_EQ(err({{"postprocess", 1}}), "p.json: unknown key 'postprocess' (terralux --print-project lists them)");
    EXPECT_EQ(err({{"probe_volumes", {{{"name", "a"}, {"grid_dim", {4, 4}}}}}}),
              "p.json: unknown key 'probe_volumes[0].grid_dim' (did you mean 'probe_volumes[].grid_dims'?)");
    EXPECT_EQ(err({{"probe_volumes", {{{"adaptive", {{"tolerence", 0.1}}}}}}}),
              "p.json: unknown key 'probe_volumes[0].adaptive.tolerence' (did you mean 'probe_volumes[].adaptive.tolerance'?)");
    EXPECT_EQ(err({{"sun", 3}}), "p.json: sun = 3: must be an object");
    // An editor's schema reference is allowed at the top.
    EXPECT_EQ(err({{"$schema", "./terralux.schema.json"}, {"sun", {{"elevation_deg", 20}}}}), "");
}

TEST(Project, PartialVolumesTakeTheDefaults) {
    json doc = {{"probe_volumes", {{{"name", "valley"}}, {{"name", "ridge"}, {"grid_dims", {4, 4}}}}}};
    const SceneDescription s = sceneFromJson(doc, "p.json", nullptr);
    ASSERT_EQ(s.probeVolumes.size(), 2u);
    EXPECT_EQ(s.probeVolumes[0].name, "valley");
    EXPECT_EQ(s.probeVolumes[0].gridDims[0], 8);
    EXPECT_EQ(s.probeVolumes[1].gridDims[0], 4);
    json dup = {{"probe_volumes", {{{"name", "a"}}, {{"name", "a"}}}}};
    EXPECT_THROW(sceneFromJson(dup, "p.json", nullptr), ProjectError);
}

TEST(Project, SaveLoadIsLosslessAndPathsStayRelative) {
    const fs::path dir = tempDir("roundtrip");
    fs::create_directories(dir / "dems");
    Project p;
    p.baseDir = dir;
    p.scene.terrain.dem = "dems/a.tif";
    p.scene.terrain.albedo = {0.1f, 0.2f, 0.3f};
    p.scene.sun.elevationDeg = 7.25;
    p.scene.probeVolumes[0].spacing = glm::vec3(40.f, 40.f, 55.f);
    p.scene.probeVolumes[0].origin = glm::vec3(-100.f, 0.f, 250.f);
    p.scene.probeVolumes[0].rayCount = 333;
    ProbeVolumeSettings box;
    box.name = "air";
    box.placement = ProbePlacement::Box;
    box.gridDims = {3, 2, 5};
    box.origin = glm::vec3(1.f, 2.f, 3.f);
    box.spacing = glm::vec3(12.5f);
    p.scene.probeVolumes.push_back(box);
    ProbeVolumeSettings octree;
    octree.name = "octree";
    octree.placement = ProbePlacement::Adaptive;
    octree.origin = glm::vec3(-10.f, 20.f, -30.f);
    octree.adaptive.minCellSize = 16.0;
    octree.adaptive.maxCellSize = 256.0;
    octree.adaptive.size = glm::vec3(320.f, 160.f, 480.f);
    octree.adaptive.tolerance = 0.04;
    octree.adaptive.maxBytes = 1ll << 40;
    p.scene.probeVolumes.push_back(octree);
    p.scene.bake.bounces = 3;
    p.scene.camera.target = glm::vec3(10.f, 500.f, -20.f);
    p.scene.camera.radius = 2500.0;
    p.scene.camera.fovDeg = 30.0;

    saveProject(p, dir / "a.terralux.json");
    const Project q = loadProject(dir / "a.terralux.json", nullptr);
    EXPECT_EQ(projectToJson(q), projectToJson(p));
    EXPECT_EQ(q.demPath(), dir / "dems/a.tif");

    saveProject(q, dir / "b.terralux.json");
    const Project r = loadProject(dir / "b.terralux.json", nullptr);
    EXPECT_EQ(projectToJson(r), projectToJson(p));
    std::ifstream a(dir / "a.terralux.json"), b(dir / "b.terralux.json");
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(a), {}),
              std::string(std::istreambuf_iterator<char>(b), {}));
    // Nothing temporary left beside it.
    for (const auto& e : fs::directory_iterator(dir))
        EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos);
}

TEST(Project, BadFilesAreOneLineErrors) {
    const fs::path dir = tempDir("bad");
    std::ofstream(dir / "broken.json") << "{\n  \"sun\": {\n    \"elevation_deg\": 10,\n  }\n}\n";
    try {
        loadProject(dir / "broken.json", nullptr);
        FAIL();
    } catch (const ProjectError& e) {
        // The line and column of the stray '}', and the parser's reason.
        const std::string m = e.what();
        EXPECT_NE(m.find("broken.json: not valid JSON at line 4, column 3: syntax error"), std::string::npos) << m;
        EXPECT_NE(m.find("unexpected '}'"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    EXPECT_THROW(loadProject(dir / "missing.json", nullptr), ProjectError);
    std::ofstream(dir / "array.json") << "[1,2]";
    EXPECT_THROW(loadProject(dir / "array.json", nullptr), ProjectError);
}

TEST(Project, EffectiveProjectAppliesFileThenOverrides) {
    const fs::path dir = tempDir("effective");
    std::ofstream(dir / "p.json") << R"({"sun": {"elevation_deg": 20}, "terrain": {"dem": "x.tif"}})";
    const Project p = loadEffectiveProject((dir / "p.json").string(), {"sun.azimuth_deg=90"}, "", nullptr);
    EXPECT_DOUBLE_EQ(p.scene.sun.elevationDeg, 20.0);
    EXPECT_DOUBLE_EQ(p.scene.sun.azimuthDeg, 90.0);
    EXPECT_EQ(p.demPath(), dir / "x.tif");
    EXPECT_THROW(loadEffectiveProject((dir / "p.json").string(), {"sun.elevation_deg=100"}, "", nullptr),
                 ProjectError);
}

TEST(Project, PhysicalSkyRoundTrips) {
    json doc = defaultProjectJson();
    EXPECT_EQ(doc["sky"]["mode"], "uniform");
    applyOverride(doc, "sky.mode=physical");
    applyOverride(doc, "sky.turbidity=4.5");
    applyOverride(doc, "sun.follow_sky=false");
    const SceneDescription s = sceneFromJson(doc, "--set", nullptr);
    EXPECT_EQ(s.sky.mode, SkyMode::Physical);
    EXPECT_DOUBLE_EQ(s.sky.turbidity, 4.5);
    EXPECT_FALSE(s.sun.followSky);
    const json written = sceneToJson(s);
    EXPECT_EQ(written["sky"]["mode"], "physical");
    EXPECT_EQ(written["sky"]["turbidity"], 4.5);
    EXPECT_EQ(written["sun"]["follow_sky"], false);
    EXPECT_EQ(sceneToJson(sceneFromJson(written, "again", nullptr)), written);
}

// A terrain for the lighting calls whose sun is manual: they do not read it.
const Heightfield& flatGround() {
    static const Heightfield hf(4, 4, 10.0, 10.0, std::vector<float>(16, 0.0f));
    return hf;
}

TEST(SceneLighting, PhysicalSkyDrivesSkyAndSun) {
    Project p;
    p.scene.sky.mode = SkyMode::Physical;
    p.scene.sky.turbidity = 3.0;
    p.scene.sky.color = glm::vec3(1.0f, 0.0f, 0.0f);  // not read in mode physical
    p.scene.sky.luminance = 1.0e5;
    const size_t before = physicalSkyBuilds();
    const BakeLighting a = lightingOf(p, flatGround());
    EXPECT_EQ(physicalSkyBuilds(), before + 1);
    EXPECT_FALSE(a.sky.isUniform());
    EXPECT_GT(a.sky.openIrradianceUp().z, a.sky.openIrradianceUp().x) << "a clear sky is blue";
    const PhysicalSky model(a.sun.direction, 3.0);
    EXPECT_EQ(a.sun.illuminance, model.sunIlluminance());

    // Intensity exposes sky and sun alike and reuses the cached sky; so does any other edit.
    p.scene.sky.intensity = 2.0;
    p.scene.terrain.albedo = glm::vec3(0.5f);
    const BakeLighting b = lightingOf(p, flatGround());
    EXPECT_EQ(physicalSkyBuilds(), before + 1);
    for (int c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(b.sky.openIrradianceUp()[c], 2.0f * a.sky.openIrradianceUp()[c]);
        EXPECT_FLOAT_EQ(b.sun.illuminance[c], 2.0f * a.sun.illuminance[c]);
    }
    // The sun's direction and the turbidity shape it.
    p.scene.sun.elevationDeg = 20.0;
    skyOf(p, flatGround());
    EXPECT_EQ(physicalSkyBuilds(), before + 2);
    p.scene.sky.turbidity = 6.0;
    skyOf(p, flatGround());
    EXPECT_EQ(physicalSkyBuilds(), before + 3);

    // Without follow_sky the sun is the project's own.
    p.scene.sun.followSky = false;
    EXPECT_EQ(lightingOf(p, flatGround()).sun.illuminance, p.scene.sun.color * sceneUnitsOfLux(p.scene.sun.illuminance));
    p.scene.sky.mode = SkyMode::Uniform;
    p.scene.sun.followSky = true;  // read only in mode physical
    EXPECT_EQ(lightingOf(p, flatGround()).sun.illuminance, p.scene.sun.color * sceneUnitsOfLux(p.scene.sun.illuminance));
}

TEST(SceneLighting, HdrSkyIsReadOnceUntilWhatShapesItChanges) {
    const fs::path dir = fs::temp_directory_path() / "terralux_sky_cache";
    fs::create_directories(dir);
    const fs::path hdr = dir / "sky.exr";
    std::vector<float> rgba(16 * 8 * 4, 1.0f);
    writeImage(hdr, 16, 8, rgba);
    Project p;
    p.scene.sky.mode = SkyMode::Hdr;
    p.scene.sky.hdr = hdr.string();
    const size_t before = hdrSkyReads();
    const Sky first = skyOf(p, flatGround());
    EXPECT_EQ(hdrSkyReads(), before + 1);
    p.scene.sun.elevationDeg = 7.0;
    p.scene.camera.azimuthDeg = 10.0;
    const Sky again = skyOf(p, flatGround());
    EXPECT_EQ(hdrSkyReads(), before + 1) << "a sun or camera edit read the HDR again";
    EXPECT_EQ(first.sh().c[0], again.sh().c[0]);
    // Intensity scales the cached environment exactly as filtering the scaled image would; the
    // uniform sky's colour and luminance do not touch an HDR sky.
    p.scene.sky.color = glm::vec3(1.0f, 0.5f, 0.25f);
    p.scene.sky.luminance = 123.0;
    p.scene.sky.intensity = 4.0;
    const Sky tinted = skyOf(p, flatGround());
    EXPECT_EQ(hdrSkyReads(), before + 1) << "an intensity edit read the HDR again";
    std::vector<float> rgb(16 * 8 * 3);
    for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = 4.0f;
    const Sky direct = Sky::equirect(rgb, 16, 8, 1.0f, 0.0f);
    for (size_t k = 0; k < direct.sh().c.size(); ++k)
        for (int ch = 0; ch < 3; ++ch)
            EXPECT_NEAR(tinted.sh().c[k][ch], direct.sh().c[k][ch], 1e-4f * std::abs(direct.sh().c[0][ch]));
    const glm::vec3 toward = glm::normalize(glm::vec3(0.3f, 0.5f, -0.8f));
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(tinted.radiance(toward)[ch], direct.radiance(toward)[ch], 1e-5f);
        EXPECT_NEAR(tinted.radiance(toward, 0.5f)[ch], direct.radiance(toward, 0.5f)[ch], 1e-5f);
        EXPECT_NEAR(tinted.openIrradianceUp()[ch], direct.openIrradianceUp()[ch], 1e-4f);
    }
    p.scene.sky.rotationDeg = 90.0;
    skyOf(p, flatGround());
    EXPECT_EQ(hdrSkyReads(), before + 2) << "a rotation is a new environment";
    // The file rewritten on disk (other size) is read again even with the same settings.
    rgba.assign(32 * 16 * 4, 2.0f);
    writeImage(hdr, 32, 16, rgba);
    const Sky rewritten = skyOf(p, flatGround());
    EXPECT_EQ(hdrSkyReads(), before + 3);
    EXPECT_GT(rewritten.sh().c[0].x, 1.5f * first.sh().c[0].x);
    fs::remove_all(dir);
}

TEST(Project, AmbientOcclusionSectionDefaultsValidationAndRoundTrip) {
    const SceneDescription d = sceneFromJson(defaultProjectJson(), "defaults", nullptr);
    EXPECT_TRUE(d.ao.enabled);
    EXPECT_EQ(d.ao.directions, 32);
    EXPECT_FALSE(d.ao.maxDistance.has_value());  // unbounded
    EXPECT_DOUBLE_EQ(d.ao.strength, 1.0);
    EXPECT_TRUE(defaultProjectJson()["ao"]["max_distance"].is_null());

    const std::string few = errorFor("ao.directions=4");
    EXPECT_NE(few.find("ao.directions"), std::string::npos) << few;
    EXPECT_NE(few.find("4"), std::string::npos) << few;
    EXPECT_NE(few.find("64"), std::string::npos) << few;
    EXPECT_NE(errorFor("ao.directions=16.5").find("ao.directions"), std::string::npos);
    EXPECT_NE(errorFor("ao.strength=1.5").find("ao.strength"), std::string::npos);
    EXPECT_NE(errorFor("ao.max_distance=0").find("ao.max_distance"), std::string::npos);
    EXPECT_NE(errorFor("ao.max_distance=-5").find("ao.max_distance"), std::string::npos);
    EXPECT_EQ(errorFor("ao.max_distance=2500"), "");

    json doc = defaultProjectJson();
    doc["ao"] = {{"enabled", false}, {"directions", 12}, {"max_distance", 1500.5}, {"strength", 0.25}};
    const SceneDescription s = sceneFromJson(doc, "p.json", nullptr);
    EXPECT_FALSE(s.ao.enabled);
    EXPECT_EQ(s.ao.directions, 12);
    ASSERT_TRUE(s.ao.maxDistance);
    EXPECT_DOUBLE_EQ(*s.ao.maxDistance, 1500.5);
    EXPECT_DOUBLE_EQ(s.ao.strength, 0.25);
    EXPECT_EQ(sceneToJson(s)["ao"], doc["ao"]);
}

TEST(ProjectVersions, EveryOlderVersionHasOneMigrationStep) {
    const auto& steps = projectMigrations();
    ASSERT_EQ(steps.size(), size_t(kProjectVersion - 1));
    for (int v = 1; v < kProjectVersion; ++v) EXPECT_EQ(steps[size_t(v - 1)].from, v);
}

TEST(ProjectVersions, VersionSevenImageSkiesKeepTheAuthoredSunBesideTheWholeImage) {
    // Version 7 lit an image sky whole with the authored sun; version 8's sun.follow_sky (default
    // true) would take the image's sun instead, so a version-7 image sky gets it false.
    const json v7 = {{"version", 7},
                     {"sky", {{"mode", "hdr"}, {"hdr", "noon.hdr"}}},
                     {"scenarios", json::array({json{{"name", "dusk"}, {"sky", {{"mode", "hdr"}, {"hdr", "dusk.hdr"}}}},
                                                json{{"name", "grey"}, {"sky", {{"mode", "uniform"}}}}})}};
    std::vector<std::string> notes;
    const json migrated = migrateProjectJson(v7, "old.json", &notes);
    EXPECT_EQ(migrated["sun"]["follow_sky"], false);
    EXPECT_EQ(migrated["scenarios"][0]["sun"]["follow_sky"], false);
    EXPECT_FALSE(migrated["scenarios"][1].contains("sun"));
    ASSERT_EQ(notes.size(), 2u);
    EXPECT_EQ(notes[1], "old.json: version 7 migrated to 8: scenarios[0].sun.follow_sky set to false: version 7 lit the image "
                        "whole with the authored sun");
    // A version-7 uniform or physical sky, and a current image sky, keep the default.
    EXPECT_TRUE(sceneFromJson(json{{"version", 7}, {"sky", {{"mode", "physical"}}}}, "old.json", nullptr).sun.followSky);
    EXPECT_TRUE(sceneFromJson(json{{"version", kProjectVersion}, {"sky", {{"mode", "hdr"}, {"hdr", "a.hdr"}}}}, "new.json", nullptr)
                    .sun.followSky);
    // A sun that is not an object is left for the check to name.
    json bad = v7;
    bad["sun"] = "east";
    EXPECT_EQ(migrateProjectJson(bad, "old.json", nullptr)["sun"], "east");
}

TEST(ProjectVersions, VersionOneWithoutAnAlbedoModeKeepsItsConstantAlbedo) {
    // A version-1 file from before the albedo modes: its terrain was terrain.albedo everywhere.
    const json v1 = {{"format", "terralux-project"}, {"version", 1}, {"terrain", {{"albedo", {0.4, 0.35, 0.3}}}}};
    std::vector<std::string> notes;
    const json migrated = migrateProjectJson(v1, "old.json", &notes);
    EXPECT_EQ(migrated["version"], kProjectVersion);
    EXPECT_EQ(migrated["terrain"]["albedo_mode"], "constant");
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], "old.json: version 1 migrated to 2: terrain.albedo_mode set to \"constant\", what version 1 drew without it");
    const SceneDescription s = sceneFromJson(v1, "old.json", nullptr);
    EXPECT_EQ(s.terrain.albedoMode, AlbedoMode::Constant);
    // A version-1 file that chose a mode keeps it; a current file without one gets the ramp.
    json chose = v1;
    chose["terrain"]["albedo_mode"] = "ramp";
    EXPECT_EQ(sceneFromJson(chose, "old.json", nullptr).terrain.albedoMode, AlbedoMode::Ramp);
    json current = v1;
    current["version"] = 2;
    EXPECT_EQ(sceneFromJson(current, "new.json", nullptr).terrain.albedoMode, AlbedoMode::Ramp);
    json unversioned = v1;
    unversioned.erase("version");
    EXPECT_EQ(sceneFromJson(unversioned, "new.json", nullptr).terrain.albedoMode, AlbedoMode::Ramp);
}

TEST(ProjectVersions, VersionOneGroundColourBecomesAnAlbedo) {
    const json v1 = {{"version", 1},
                     {"terrain", {{"albedo_mode", "ramp"}}},
                     {"reflection_probes", {{"ground_color", {2.0, 0.5, 1.5}}}}};
    std::vector<std::string> notes;
    const SceneDescription s = sceneFromJson(v1, "old.json", &notes);
    EXPECT_EQ(s.reflectionProbes.groundColor, glm::vec3(1.0f, 0.5f, 1.0f));
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_NE(notes[0].find("reflection_probes.ground_color clamped to [0, 1]"), std::string::npos);
    // The same colour in a version-2 file is refused: there it is an albedo.
    json v2 = v1;
    v2["version"] = 2;
    EXPECT_THROW(sceneFromJson(v2, "new.json", nullptr), ProjectError);
}

// Version 2 wrote the fog's falloff as 1/m (its default 1/1200 printed as 0.0008333333333333334);
// version 3 writes the scale height in metres, and an older file keeps its fog.
TEST(ProjectVersions, VersionTwoFogFalloffBecomesAScaleHeight) {
    const json v2 = {{"version", 2}, {"fog", {{"height_falloff", 0.002}}}};
    std::vector<std::string> notes;
    const SceneDescription s = sceneFromJson(v2, "old.json", &notes);
    EXPECT_DOUBLE_EQ(s.fog.scaleHeight, 500.0);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], "old.json: version 2 migrated to 3: fog.height_falloff 0.002 is fog.scale_height 500.0 m");
    json uniform = v2;
    uniform["fog"]["height_falloff"] = 0.0;
    EXPECT_EQ(sceneFromJson(uniform, "old.json", nullptr).fog.scaleHeight, 0.0);
    // The old default is the new one, and the new file prints a number a person would type.
    json old = v2;
    old["fog"]["height_falloff"] = 1.0 / 1200.0;
    EXPECT_NEAR(sceneFromJson(old, "old.json", nullptr).fog.scaleHeight, 1200.0, 1e-9);
    EXPECT_EQ(defaultProjectJson()["fog"]["scale_height"], 1200.0);
    EXPECT_FALSE(defaultProjectJson()["fog"].contains("height_falloff"));
    // The old key in a current file is unknown; a bad old value is named under the new key.
    json current = v2;
    current["version"] = kProjectVersion;
    EXPECT_THROW(sceneFromJson(current, "new.json", nullptr), ProjectError);
    json bad = v2;
    bad["fog"]["height_falloff"] = "steep";
    try {
        sceneFromJson(bad, "old.json", nullptr);
        ADD_FAILURE() << "a string falloff was accepted";
    } catch (const ProjectError& e) {
        EXPECT_NE(std::string(e.what()).find("fog.scale_height"), std::string::npos) << e.what();
    }
}

TEST(ProjectVersions, SavingWritesTheCurrentVersion) {
    const fs::path dir = tempDir("versions");
    {
        std::ofstream(dir / "old.json") << R"({"format": "terralux-project", "version": 1, "sun": {"elevation_deg": 20}})";
    }
    std::vector<std::string> warnings;
    Project p = loadProject(dir / "old.json", &warnings);
    EXPECT_EQ(p.scene.terrain.albedoMode, AlbedoMode::Constant);
    EXPECT_EQ(warnings.size(), 1u);
    saveProject(p, dir / "old.json");
    std::ifstream in(dir / "old.json");
    const json saved = json::parse(in);
    EXPECT_EQ(saved["version"], kProjectVersion);
    EXPECT_EQ(saved["terrain"]["albedo_mode"], "constant");
    warnings.clear();
    EXPECT_EQ(loadProject(dir / "old.json", &warnings).scene.terrain.albedoMode, AlbedoMode::Constant);
    EXPECT_TRUE(warnings.empty());
}

// Found by fuzz_project: a --set value that is not UTF-8 used to escape as a JSON type error while
// its refusal was being worded. It is refused up front, naming the byte.
TEST(Project, OverrideThatIsNotUtf8IsRefused) {
    EXPECT_EQ(errorFor("probe_volumes[0].name=gr\x9d"),
              "--set: byte 24 (0x9D) of the assignment is not UTF-8; parameters and paths must be UTF-8 text");
    EXPECT_NE(errorFor("terrain.dem=\xC0\xAF.tif"), "");         // overlong '/'
    EXPECT_NE(errorFor("terrain.dem=\xED\xA0\x80.tif"), "");     // a surrogate
    EXPECT_NE(errorFor("terrain.dem=x\xE2\x82"), "");            // truncated
    EXPECT_EQ(errorFor("terrain.dem=caf\xC3\xA9.tif").find("not UTF-8"), std::string::npos);
    EXPECT_NE(errorFor("probe_volumes[99999999999999999999].name=a").find("bad index"), std::string::npos);
}

// Version 3 wrote the sun's illuminance in scene units (its default 3); version 4 writes lux, and
// an older file, its scenarios' suns included, keeps its light.
TEST(ProjectVersions, VersionThreeSunIlluminanceBecomesLux) {
    const json v3 = {{"version", 3},
                     {"sun", {{"illuminance", 3.0}}},
                     {"scenarios", {{{"name", "dusk"}, {"sun", {{"illuminance", 1.2}}}}, {{"name", "grey"}, {"sky", {{"intensity", 2.0}}}}}}};
    std::vector<std::string> notes;
    const SceneDescription s = sceneFromJson(v3, "old.json", &notes);
    EXPECT_EQ(s.sun.illuminance, 100000.0);
    ASSERT_EQ(s.scenarios.size(), 2u);
    EXPECT_EQ(s.scenarios[0].sun.illuminance, 40000.0);
    ASSERT_EQ(notes.size(), 2u);
    EXPECT_EQ(notes[0], "old.json: version 3 migrated to 4: sun.illuminance 3.0 is 100000.0 lx");
    EXPECT_EQ(notes[1], "old.json: version 3 migrated to 4: scenarios[0].sun.illuminance 1.2 is 40000.0 lx");
    // The same light: the bake's scene units are what version 3 wrote.
    EXPECT_EQ(sunOf(s.sun).illuminance, s.sun.color * 3.0f);
    EXPECT_EQ(defaultProjectJson()["sun"]["illuminance"], 100000.0);
    // A current file means lux.
    json current = v3;
    current["version"] = kProjectVersion;
    EXPECT_EQ(sceneFromJson(current, "new.json", nullptr).sun.illuminance, 3.0);
}

// Version 4 wrote a light's intensity in scene units at 1 m (its default 1000); version 5 writes
// candela, as KHR_lights_punctual exports it, and an older file keeps its light.
TEST(ProjectVersions, VersionFourLightIntensityBecomesCandela) {
    const json v4 = {{"version", 4},
                     {"lights", {{{"intensity", 1000.0}, {"range", 150.0}}, {{"type", "spot"}}}}};
    std::vector<std::string> notes;
    const SceneDescription s = sceneFromJson(v4, "old.json", &notes);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_NEAR(s.lights[0].intensity, 1000.0 / kSceneUnitsPerLux, 1e-3);
    EXPECT_EQ(s.lights[1].intensity, LocalLight{}.intensity);  // unset: the default, in candela
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], "old.json: version 4 migrated to 5: lights[0].intensity 1000.0 is 33333333.333 cd");
    // The same light: what the renderer and the LPV emit is what version 4 wrote.
    EXPECT_NEAR(s.lights[0].emitted().x, 1000.0f, 1e-3f);
    // A current file means candela.
    json current = v4;
    current["version"] = kProjectVersion;
    EXPECT_EQ(sceneFromJson(current, "new.json", nullptr).lights[0].intensity, 1000.0);
}

// Version 5 wrote the uniform sky as a radiance in scene units (its default (0.09, 0.11, 0.15));
// version 6 writes a colour in [0, 1] and a luminance in cd/m², and an older file, its scenarios'
// skies included, keeps its sky.
TEST(ProjectVersions, VersionFiveSkyColourBecomesColourAndLuminance) {
    const json v5 = {{"version", 5},
                     {"sky", {{"color", {0.3, 0.6, 1.5}}, {"intensity", 2.0}}},
                     {"scenarios", {{{"name", "night"}, {"sky", {{"color", {0.0, 0.0, 0.0}}}}},
                                    {{"name", "grey"}, {"sky", {{"intensity", 0.5}}}}}}};
    std::vector<std::string> notes;
    const SceneDescription s = sceneFromJson(v5, "old.json", &notes);
    EXPECT_EQ(s.sky.color, glm::vec3(0.2f, 0.4f, 1.0f));
    EXPECT_DOUBLE_EQ(s.sky.luminance, 50000.0);
    ASSERT_EQ(s.scenarios.size(), 2u);
    EXPECT_EQ(s.scenarios[0].sky.luminance, 0.0);
    EXPECT_EQ(s.scenarios[0].sky.uniformRadiance(), glm::vec3(0.0f));
    // An unset colour was version 5's default, which is the current default sky.
    EXPECT_EQ(s.scenarios[1].sky.color, SkySettings{}.color);
    EXPECT_EQ(s.scenarios[1].sky.luminance, SkySettings{}.luminance);
    ASSERT_EQ(notes.size(), 2u);
    EXPECT_EQ(notes[0], "old.json: version 5 migrated to 6: sky.color [0.3,0.6,1.5] is [0.2,0.4,1.0] at 50000.0 cd/m²");
    EXPECT_EQ(notes[1], "old.json: version 5 migrated to 6: scenarios[0].sky.color [0.0,0.0,0.0] is [0.0,0.0,0.0] at 0.0 cd/m²");
    // The same sky: the radiance the bake lights with is what version 5 wrote, times its intensity.
    const glm::vec3 radiance = s.sky.uniformRadiance();
    EXPECT_NEAR(radiance.x, 0.6f, 1e-6f);
    EXPECT_NEAR(radiance.y, 1.2f, 1e-6f);
    EXPECT_NEAR(radiance.z, 3.0f, 1e-6f);
    const SceneDescription defaults = sceneFromJson(json{{"version", 5}}, "old.json", nullptr);
    EXPECT_EQ(defaults.sky.uniformRadiance(), SkySettings{}.uniformRadiance());
    // A current file means a colour: a component above 1 is refused, naming the rule.
    json current = v5;
    current["version"] = kProjectVersion;
    try {
        sceneFromJson(current, "new.json", nullptr);
        ADD_FAILURE() << "a colour above 1 was accepted";
    } catch (const ProjectError& e) {
        EXPECT_EQ(std::string(e.what()), "new.json: sky.color[2] = 1.5: three components, each in [0, 1]");
    }
}

TEST(ProjectVersions, VersionSixFogColourBecomesColourAndLuminance) {
    const json v6 = {{"version", 6}, {"fog", {{"color", {0.03, 0.06, 0.15}}, {"density", 1e-4}}}};
    std::vector<std::string> notes;
    const SceneDescription s = sceneFromJson(v6, "old.json", &notes);
    ASSERT_TRUE(s.fog.color && s.fog.luminance);
    EXPECT_EQ(*s.fog.color, glm::vec3(0.2f, 0.4f, 1.0f));
    EXPECT_DOUBLE_EQ(*s.fog.luminance, 5000.0);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], "old.json: version 6 migrated to 7: fog.color [0.03,0.06,0.15] is [0.2,0.4,1.0] at 5000.0 cd/m²");
    // The same fog: the radiance it scatters is what version 6 wrote.
    const glm::vec3 radiance = s.fog.ambientRadiance();
    EXPECT_NEAR(radiance.x, 0.03f, 1e-7f);
    EXPECT_NEAR(radiance.y, 0.06f, 1e-7f);
    EXPECT_NEAR(radiance.z, 0.15f, 1e-7f);
    // An unset colour stays unset: the sky's mean, colour and luminance both.
    const SceneDescription unset = sceneFromJson(json{{"version", 6}, {"fog", {{"density", 1e-4}}}}, "old.json", nullptr);
    EXPECT_FALSE(unset.fog.color);
    EXPECT_FALSE(unset.fog.luminance);
    // A current file means a colour: a component above 1 is refused, naming the rule.
    json current = {{"version", kProjectVersion}, {"fog", {{"color", {0.5, 1.5, 0.2}}}}};
    try {
        sceneFromJson(current, "new.json", nullptr);
        ADD_FAILURE() << "a colour above 1 was accepted";
    } catch (const ProjectError& e) {
        EXPECT_EQ(std::string(e.what()), "new.json: fog.color[1] = 1.5: three components, each in [0, 1]");
    }
}
