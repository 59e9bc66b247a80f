// The viewport's bounds and handles (app/VolumeHandles.h): the bounds drawn are where the
// placement puts the probes, and each handle's edit, applied to the project, moves the placed
// probes exactly as the drag did.

#include <cmath>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "DemImport.h"
#include "Project.h"
#include "SceneLighting.h"
#include "SampleTerrain.h"
#include "VolumeHandles.h"
#include "bake/ProbePlacement.h"
#include "bake/ReflectionBake.h"
#include "bake/Sky.h"
#include "water/Water.h"

using namespace terralux;

namespace {

const Heightfield& sample() {
    static const DemImportResult dem = importDemFromMemory(kSampleTerrainName, sampleTerrainBytes(), sampleTerrainSize());
    return dem.heightfield;
}

// The scene of the default project with `assignments` (as `--set` takes them).
SceneDescription sceneWith(const std::vector<std::string>& assignments) {
    nlohmann::json doc = defaultProjectJson();
    for (const std::string& a : assignments) applyOverride(doc, a);
    return sceneFromJson(doc, "test", nullptr);
}

// `scene` after the handle's edit, through the project file's own parsing and rules.
SceneDescription applied(const SceneDescription& scene, const HandleEdit& edit) {
    nlohmann::json doc = sceneToJson(scene);
    for (const auto& [path, value] : edit.values) applyOverride(doc, path + "=" + value.dump());
    return sceneFromJson(doc, "test", nullptr);
}

struct Extent {
    glm::vec3 lo{INFINITY}, hi{-INFINITY};
};
Extent extentOf(const std::vector<glm::vec3>& points) {
    Extent e;
    for (const glm::vec3& p : points) e.lo = glm::min(e.lo, p), e.hi = glm::max(e.hi, p);
    return e;
}

VolumeBounds boundsOf(const SceneDescription& scene, BoundsKind kind) {
    for (const VolumeBounds& b : sceneBounds(scene, sample()))
        if (b.kind == kind) return b;
    ADD_FAILURE() << "no bounds of that kind";
    return {};
}

}  // namespace

TEST(VolumeBounds, TerrainGridBoundsAreItsProbes) {
    for (const auto& set : {std::vector<std::string>{},
                            {"probe_volumes[0].grid_dims=12,5", "probe_volumes[0].origin=-900,-400",
                             "probe_volumes[0].spacing=150,220", "probe_volumes[0].height_offset=40"}}) {
        const SceneDescription scene = sceneWith(set);
        const VolumeBounds b = boundsOf(scene, BoundsKind::ProbeVolume);
        const Extent e = extentOf(placeProbes(scene.probeVolumes[0], sample()).positions);
        EXPECT_EQ(b.name, "volume 'probes'");
        EXPECT_NEAR(b.min.x, e.lo.x, 1e-3);
        EXPECT_NEAR(b.max.x, e.hi.x, 1e-3);
        EXPECT_NEAR(b.min.z, e.lo.z, 1e-3);
        EXPECT_NEAR(b.max.z, e.hi.z, 1e-3);
        // From the lowest ground to above every probe.
        EXPECT_EQ(b.min.y, sample().minHeight());
        EXPECT_GE(b.max.y, e.hi.y - 1e-3f);
    }
}

TEST(VolumeBounds, BoxAdaptiveAndReflectionBoundsFollowTheirPlacement) {
    {
        const SceneDescription scene =
            sceneWith({"probe_volumes[0].placement=box", "probe_volumes[0].grid_dims=6,3,4", "probe_volumes[0].spacing=200"});
        const VolumeBounds b = boundsOf(scene, BoundsKind::ProbeVolume);
        const ProbeLayout L = placeProbes(scene.probeVolumes[0], sample());
        EXPECT_NEAR(glm::distance(b.min, L.cellOrigin), 0.0f, 1e-3f);
        const glm::vec3 far = L.cellOrigin + L.cellSize * glm::vec3(6, 3, 4);
        EXPECT_NEAR(glm::distance(b.max, far), 0.0f, 1e-3f);
    }
    {
        const SceneDescription scene = sceneWith({"probe_volumes[0].placement=adaptive"});
        const VolumeBounds b = boundsOf(scene, BoundsKind::ProbeVolume);
        const ProbeLayout L = placeProbes(scene.probeVolumes[0], sample());
        EXPECT_NEAR(glm::distance(b.min, L.cellOrigin), 0.0f, 1e-2f);
        const Extent e = extentOf(L.positions);
        for (int a = 0; a < 3; ++a) {
            EXPECT_LE(b.min[a], e.lo[a]);
            EXPECT_GE(b.max[a] + L.cellSize, e.hi[a]);  // the octree grows the box to whole min cells
        }
    }
    {
        const SceneDescription scene = sceneWith({"reflection_probes.enabled=true", "reflection_probes.grid_dims=3,5"});
        const VolumeBounds b = boundsOf(scene, BoundsKind::ReflectionGrid);
        const ReflectionLayout L = placeReflectionProbes(scene.reflectionProbes, sample());
        const Extent e = extentOf(L.positions);
        EXPECT_NEAR(b.min.x, e.lo.x, 1e-3);
        EXPECT_NEAR(b.max.z, e.hi.z, 1e-3);
        EXPECT_NEAR(b.max.y, e.hi.y, 1e-3);
    }
    // Water: flat, at its level; off, none.
    {
        const SceneDescription scene = sceneWith({"water.enabled=true", "water.level=420"});
        const VolumeBounds b = boundsOf(scene, BoundsKind::Water);
        EXPECT_EQ(b.min.y, 420.0f);
        EXPECT_EQ(b.max.y, 420.0f);
        EXPECT_EQ(sceneBounds(sceneWith({"probe_volumes[0].enabled=false"}), sample()).size(), 0u);
    }
}

TEST(VolumeHandles, TerrainGridMovesAndResizesAsDragged) {
    const SceneDescription scene = sceneWith({"probe_volumes[0].grid_dims=8,6"});
    const VolumeBounds b = boundsOf(scene, BoundsKind::ProbeVolume);
    const std::vector<glm::vec3> before = placeProbes(scene.probeVolumes[0], sample()).positions;
    const glm::vec3 delta(250.0f, 0.0f, -130.0f);

    const HandleEdit move = dragHandle(scene, sample(), b, HandleRole::Move, delta);
    EXPECT_EQ(move.label, "Move volume 'probes'");
    const std::vector<glm::vec3> moved = placeProbes(applied(scene, move).probeVolumes[0], sample()).positions;
    ASSERT_EQ(moved.size(), before.size());
    for (size_t i = 0; i < moved.size(); ++i) {
        EXPECT_NEAR(moved[i].x, before[i].x + delta.x, 0.02);
        EXPECT_NEAR(moved[i].z, before[i].z + delta.z, 0.02);
    }

    // The max corner follows the pointer; the first probe stays.
    const HandleEdit grow = dragHandle(scene, sample(), b, HandleRole::MaxCorner, delta);
    EXPECT_EQ(grow.label, "Resize volume 'probes'");
    const std::vector<glm::vec3> grown = placeProbes(applied(scene, grow).probeVolumes[0], sample()).positions;
    EXPECT_NEAR(grown.front().x, before.front().x, 0.02);
    EXPECT_NEAR(grown.front().z, before.front().z, 0.02);
    EXPECT_NEAR(grown.back().x, before.back().x + delta.x, 0.05);
    EXPECT_NEAR(grown.back().z, before.back().z + delta.z, 0.05);

    // The min corner follows it; the last probe stays.
    const HandleEdit shrink = dragHandle(scene, sample(), b, HandleRole::MinCorner, delta);
    const std::vector<glm::vec3> shrunk = placeProbes(applied(scene, shrink).probeVolumes[0], sample()).positions;
    EXPECT_NEAR(shrunk.front().x, before.front().x + delta.x, 0.05);
    EXPECT_NEAR(shrunk.front().z, before.front().z + delta.z, 0.05);
    EXPECT_NEAR(shrunk.back().x, before.back().x, 0.05);
    EXPECT_NEAR(shrunk.back().z, before.back().z, 0.05);

    // A corner dragged past the other leaves at least a DEM cell between probes.
    const HandleEdit collapsed = dragHandle(scene, sample(), b, HandleRole::MaxCorner, glm::vec3(-1e6f, 0.0f, -1e6f));
    const SceneDescription collapsedScene = applied(scene, collapsed);
    const ProbeVolumeSettings& v = collapsedScene.probeVolumes[0];
    EXPECT_GE(v.spacing->x, sample().cellSizeX() - 1e-6);

    // Height: the offset above the surface.
    const HandleEdit up = dragHandle(scene, sample(), b, HandleRole::Height, glm::vec3(0.0f, 12.5f, 0.0f));
    EXPECT_EQ(up.label, "Set the height of volume 'probes'");
    EXPECT_DOUBLE_EQ(applied(scene, up).probeVolumes[0].heightOffset, scene.probeVolumes[0].heightOffset + 12.5);
}

TEST(VolumeHandles, BoxAndAdaptiveVolumesKeepTheirCells) {
    const SceneDescription box =
        sceneWith({"probe_volumes[0].placement=box", "probe_volumes[0].grid_dims=6,3,4", "probe_volumes[0].spacing=200"});
    const VolumeBounds b = boundsOf(box, BoundsKind::ProbeVolume);
    // 430 m is two cells (rounded), -190 one fewer.
    const SceneDescription grown = applied(box, dragHandle(box, sample(), b, HandleRole::MaxCorner, {430.0f, 0.0f, -190.0f}));
    EXPECT_EQ(grown.probeVolumes[0].gridDims, (std::array<int, 3>{8, 3, 3}));
    EXPECT_EQ(grown.probeVolumes[0].spacing->x, 200.0f);
    const SceneDescription lower = applied(box, dragHandle(box, sample(), b, HandleRole::MinCorner, {-410.0f, 0.0f, 0.0f}));
    EXPECT_EQ(lower.probeVolumes[0].gridDims[0], 8);
    EXPECT_NEAR(lower.probeVolumes[0].origin->x, b.min.x - 400.0f, 0.01);
    const SceneDescription taller = applied(box, dragHandle(box, sample(), b, HandleRole::Height, {0.0f, 210.0f, 0.0f}));
    EXPECT_EQ(taller.probeVolumes[0].gridDims[1], 4);

    const SceneDescription adaptive = sceneWith({"probe_volumes[0].placement=adaptive"});
    const VolumeBounds a = boundsOf(adaptive, BoundsKind::ProbeVolume);
    const SceneDescription resized =
        applied(adaptive, dragHandle(adaptive, sample(), a, HandleRole::MaxCorner, {-300.0f, 0.0f, -500.0f}));
    EXPECT_NEAR(resized.probeVolumes[0].adaptive.size->x, a.max.x - a.min.x - 300.0f, 0.01);
    EXPECT_NEAR(resized.probeVolumes[0].adaptive.size->z, a.max.z - a.min.z - 500.0f, 0.01);
    EXPECT_NEAR(resized.probeVolumes[0].origin->x, a.min.x, 0.01);

    // A surface volume covers the footprint: its height moves, nothing else.
    const SceneDescription surface = sceneWith({"probe_volumes[0].placement=surface"});
    const VolumeBounds s = boundsOf(surface, BoundsKind::ProbeVolume);
    EXPECT_EQ(handlesOf(s, surface).size(), 1u);
    try {
        dragHandle(surface, sample(), s, HandleRole::Move, {10.0f, 0.0f, 0.0f});
        ADD_FAILURE() << "a surface volume moved";
    } catch (const std::invalid_argument& e) {
        // The refusal names the setting, its value and what may move.
        EXPECT_EQ(std::string(e.what()), "probe_volumes[0].placement = \"surface\": volume 'probes' covers the whole "
                                         "footprint, so only its height (probe_volumes[0].height_offset) moves");
    }
}

TEST(VolumeHandles, ReflectionGridWaterAndSun) {
    const SceneDescription scene = sceneWith({"reflection_probes.enabled=true", "reflection_probes.grid_dims=3,1",
                                              "water.enabled=true", "water.level=420"});
    const VolumeBounds r = boundsOf(scene, BoundsKind::ReflectionGrid);
    const ReflectionLayout before = placeReflectionProbes(scene.reflectionProbes, sample());
    const SceneDescription grown = applied(scene, dragHandle(scene, sample(), r, HandleRole::MaxCorner, {200.0f, 0.0f, 50.0f}));
    const ReflectionLayout after = placeReflectionProbes(grown.reflectionProbes, sample());
    EXPECT_NEAR(after.origin.x, before.origin.x, 0.02);
    EXPECT_NEAR(after.origin.x + 2.0f * after.spacing.x, before.origin.x + 2.0f * before.spacing.x + 200.0f, 0.05);
    EXPECT_NEAR(after.origin.y, before.origin.y, 0.02);  // one probe along z: the first stays

    const VolumeBounds w = boundsOf(scene, BoundsKind::Water);
    const HandleEdit level = dragHandle(scene, sample(), w, HandleRole::Height, {0.0f, -7.25f, 0.0f});
    EXPECT_EQ(level.label, "Set the water level");
    EXPECT_DOUBLE_EQ(*applied(scene, level).water.level, 412.75);
    // Auto water that finds no surface has no level to move; the refusal names the setting.
    const SceneDescription dry = sceneWith({"water.enabled=true"});
    ASSERT_FALSE(water::waterLevel(dry.water, sample()));
    try {
        dragHandle(dry, sample(), w, HandleRole::Height, {0.0f, 5.0f, 0.0f});
        ADD_FAILURE() << "a water level moved where there is none";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()).rfind("water.level = null: ", 0), 0u) << e.what();
    }

    // The sun: the direction dragged to becomes the azimuth and elevation that point there.
    OrbitCamera camera = OrbitCamera::fromSettings(scene.camera, sample());
    const std::optional<VolumeBounds> sun = sunBounds(scene, sample(), camera, 500.0f);
    ASSERT_TRUE(sun);
    EXPECT_NEAR(glm::distance(sun->min, camera.target + 500.0f * sunDirection(scene.sun.azimuthDeg, scene.sun.elevationDeg)),
                0.0f, 1e-2f);
    const glm::vec3 to = sunDirection(281.3, 17.6);
    const SceneDescription moved = applied(scene, dragHandle(scene, sample(), *sun, HandleRole::Sun, to));
    EXPECT_NEAR(moved.sun.azimuthDeg, 281.3, 1e-9);
    EXPECT_NEAR(moved.sun.elevationDeg, 17.6, 1e-9);
    EXPECT_TRUE(sunPath(scene, sample(), camera, 500.0f).empty());

    // A dated sun moves along its day: a direction on the path gives back its time, and the
    // path runs from midnight to midnight through the sun where it stands.
    const SceneDescription dated = sceneWith({"sun.mode=date_time", "sun.date=2026-06-21", "sun.time_h=9.5"});
    const std::vector<glm::vec3> path = sunPath(dated, sample(), camera, 500.0f);
    ASSERT_EQ(path.size(), 97u);
    // Under an image sky the image's sun stands where the image has it: no handle, no path.
    const SceneDescription imaged = sceneWith({"sun.mode=date_time", "sky.mode=hdr", "sky.hdr=noon.hdr"});
    EXPECT_FALSE(sunBounds(imaged, sample(), camera, 500.0f));
    EXPECT_TRUE(sunPath(imaged, sample(), camera, 500.0f).empty());
    SceneDescription placed = imaged;
    placed.sun.followSky = false;
    EXPECT_TRUE(sunBounds(placed, sample(), camera, 500.0f));
    EXPECT_EQ(sunPath(placed, sample(), camera, 500.0f).size(), 97u);
    const std::optional<VolumeBounds> datedSun = sunBounds(dated, sample(), camera, 500.0f);
    ASSERT_TRUE(datedSun);
    EXPECT_LT(glm::distance(path[38], datedSun->min), 0.05f);  // 09:30 is the 38th quarter hour
    EXPECT_LT(path[0].y, camera.target.y);                      // below the horizon at midnight
    EXPECT_GT(path[48].y, camera.target.y + 400.0f);            // high at noon in June at 34° N
    for (double hours : {6.25, 11.0, 16.75}) {
        SceneDescription at = dated;
        at.sun.timeH = hours;
        const SunAngles a = sunAnglesOf(at, sample());
        const HandleEdit e = dragHandle(dated, sample(), *datedSun, HandleRole::Sun, sunDirection(a.azimuthDeg, a.elevationDeg));
        EXPECT_EQ(e.label, "Set the time of day");
        ASSERT_EQ(e.values.size(), 1u);
        EXPECT_EQ(e.values[0].first, "sun.time_h");
        EXPECT_NEAR(e.values[0].second.get<double>(), hours, 0.0101) << hours;
    }
}

TEST(VolumeBounds, LpvCascadesSurroundTheCamera) {
    const SceneDescription off = sceneWith({});
    const OrbitCamera camera = OrbitCamera::fromSettings(off.camera, sample());
    EXPECT_TRUE(lpvBounds(off, sample(), camera).empty());
    const SceneDescription on = sceneWith({"lpv.enabled=true"});
    const std::vector<VolumeBounds> cascades = lpvBounds(on, sample(), camera);
    ASSERT_EQ(cascades.size(), size_t(on.lpv.cascades));
    for (const VolumeBounds& c : cascades) {
        EXPECT_TRUE(handlesOf(c, on).empty());
        for (int a = 0; a < 3; ++a) {
            EXPECT_LT(c.min[a], camera.target[a]);
            EXPECT_GT(c.max[a], camera.target[a]);
        }
    }
}
