// Surface placement (docs/lighting.md, "Surface placement"): the quadtree over the
// terrain-following layer, its occupancy grid, its error-driven refinement and budget, the points
// its interpolation error is measured at, and target_error choosing its tolerance in a whole bake.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "BakeJob.h"
#include "DemImport.h"
#include "ParameterTable.h"
#include "Project.h"
#include "ShProbeFile.h"
#include "TestScenes.h"
#include "bake/AdaptivePlacement.h"

using namespace terralux;
using terralux::test::bump;
using terralux::test::expectRefinementKeptItsTrials;
using terralux::test::fieldBaker;
using terralux::test::flat;
namespace fs = std::filesystem;

namespace {

const fs::path kDems = fs::path(TERRALUX_TEST_DATA) / "dem";

ProbeVolumeSettings surface(std::optional<double> minCell = std::nullopt, std::optional<double> maxCell = std::nullopt) {
    ProbeVolumeSettings v;
    v.placement = ProbePlacement::Surface;
    v.adaptive.minCellSize = minCell;
    v.adaptive.maxCellSize = maxCell;
    return v;
}

// The leaf over each minimum column, -1 where none: every column of the footprint has exactly one.
std::vector<int> leafOfColumn(const ProbeLayout& L) {
    std::vector<int> of(size_t(L.cellDims[0]) * L.cellDims[2], -1);
    for (size_t i = 0; i < L.octree->leaves.size(); ++i) {
        const OctreeLeaf& l = L.octree->leaves[i];
        EXPECT_EQ(l.y, 0u);
        for (uint32_t z = l.z; z < l.z + l.edge(); ++z)
            for (uint32_t x = l.x; x < l.x + l.edge(); ++x) {
                EXPECT_LT(x, L.cellDims[0]);
                EXPECT_LT(z, L.cellDims[2]);
                int& c = of[size_t(z) * L.cellDims[0] + x];
                EXPECT_EQ(c, -1) << "two leaves over column " << x << "," << z;
                c = int(i);
            }
    }
    return of;
}

// The placement's rules: probes height_offset above the surface at their leaf's centre, leaves
// tiling the footprint, each column's cells above the lowest ground naming its leaf's probe.
void expectSurfaceRules(const ProbeLayout& L, const Heightfield& hf, double offset) {
    ASSERT_TRUE(L.octree.has_value());
    ASSERT_TRUE(L.octree->surface);
    const std::vector<int> of = leafOfColumn(L);
    EXPECT_EQ(std::count(of.begin(), of.end(), -1), 0);
    for (size_t i = 0; i < L.positions.size(); ++i) {
        ASSERT_TRUE(L.valid[i]);
        const OctreeLeaf& l = L.octree->leaves[i];
        const glm::vec3& p = L.positions[i];
        EXPECT_NEAR(p.x, L.cellOrigin.x + L.cellSize * (float(l.x) + 0.5f * float(l.edge())), 1e-3f * L.cellSize);
        EXPECT_NEAR(p.z, L.cellOrigin.z + L.cellSize * (float(l.z) + 0.5f * float(l.edge())), 1e-3f * L.cellSize);
        const float above = p.y - hf.surfaceHeight(p.x, p.z);
        EXPECT_GE(above, float(offset) * 0.999f);
        EXPECT_LE(above, float(offset) + L.maxLift + 1e-2f);
    }
    const size_t layer = size_t(L.cellDims[0]) * L.cellDims[1];
    EXPECT_GT(L.cellOrigin.y + L.cellSize * float(L.cellDims[1]),
              std::max_element(L.positions.begin(), L.positions.end(),
                               [](const glm::vec3& a, const glm::vec3& b) { return a.y < b.y; })->y);
    for (uint32_t z = 0; z < L.cellDims[2]; ++z)
        for (uint32_t x = 0; x < L.cellDims[0]; ++x) {
            const double x0 = L.cellOrigin.x + double(L.cellSize) * x, z0 = L.cellOrigin.z + double(L.cellSize) * z;
            const float lowest = surfaceRange(hf, x0, x0 + L.cellSize, z0, z0 + L.cellSize).lo;
            for (uint32_t y = 0; y < L.cellDims[1]; ++y) {
                const bool above = L.cellOrigin.y + L.cellSize * float(y + 1) > lowest;
                EXPECT_EQ(L.cellProbe[x + size_t(y) * L.cellDims[0] + z * layer], above ? of[z * L.cellDims[0] + x] : -1);
            }
        }
}

class SurfaceOnDem : public ::testing::TestWithParam<const char*> {};

}  // namespace

TEST_P(SurfaceOnDem, LeavesTileTheFootprintProbesFollowTheGroundFileReadsBack) {
    const Heightfield hf = importDem((kDems / GetParam()).string()).heightfield;
    const ProbeVolumeSettings v = surface();
    const ProbeLayout L = placeProbes(v, hf);
    // The auto squares: half the DEM cell (these crops' occupancy grids are far under the
    // budget), up to the largest power-of-two multiple within 1/8 of the longer side.
    const double cell = 0.5 * std::max(hf.cellSizeX(), hf.cellSizeZ());
    const double side = std::max(hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ());
    EXPECT_DOUBLE_EQ(L.octree->minCell, cell);
    EXPECT_LE(L.octree->maxCell, side / 8.0);
    EXPECT_GT(2.0 * L.octree->maxCell, side / 8.0);
    EXPECT_FLOAT_EQ(L.fallbackBlendDistance, float(2.0 * cell));
    EXPECT_EQ(L.octree->uniformProbes, size_t(L.cellDims[0]) * L.cellDims[2]);
    expectSurfaceRules(L, hf, v.heightOffset);
    // Without a tolerance only whole roots and the squares the footprint's edge cuts.
    size_t roots = 0;
    for (const OctreeLeaf& l : L.octree->leaves) roots += l.level == L.octree->levels;
    EXPECT_GE(roots, 16u);

    ShProbeGrid g;
    g.dims = glm::uvec3(L.cellDims[0], L.cellDims[1], L.cellDims[2]);
    g.origin = L.cellOrigin;
    g.spacing = L.cellSize;
    g.probes.resize(L.validCount());
    g.occupancy = L.compactedOccupancy();
    const fs::path file = fs::temp_directory_path() / (std::string("terralux_surface_") + GetParam() + ".shprobe");
    writeShProbeFile(file, g);
    EXPECT_EQ(fs::file_size(file), L.fileBytes());
    EXPECT_EQ(readShProbeFile(file), g);
    fs::remove(file);
}
INSTANTIATE_TEST_SUITE_P(Fixtures, SurfaceOnDem,
                         ::testing::Values("bigtujunga_utm11_crop.tif", "n42e001_voids_crop.tif", "rainier_crop.tif",
                                           "orkhon_crop.asc"),
                         [](const auto& info) {
                             std::string n = info.param;
                             return n.substr(0, n.find('_'));
                         });

TEST(SurfacePlacement, AutoSquaresKeepTheOccupancyGridOfALargeDemWithinItsBudget) {
    // 2 000 x 2 000 cells of 50 m with 3 km of relief: half cells would need 1.5 G cells.
    std::vector<float> h(size_t(2001) * 2001);
    for (size_t i = 0; i < h.size(); ++i) h[i] = float(3000.0 * double(i % 2001) / 2000.0);
    const Heightfield hf(2001, 2001, 50.0, 50.0, std::move(h));
    const ProbeLayout L = placeProbes(surface(), hf);
    const double cells = double(L.cellDims[0]) * L.cellDims[1] * L.cellDims[2];
    EXPECT_LE(cells, kAutoSurfaceCells);
    EXPECT_GT(cells, 0.9 * kAutoSurfaceCells);  // no coarser than the budget needs
    EXPECT_GT(L.octree->minCell, 25.0);
    EXPECT_LE(L.octree->maxCell, 100000.0 / 8.0);
    EXPECT_GT(L.octree->maxCell, 100000.0 / 16.0);
}

TEST(SurfacePlacement, RefusesProbesOnOrInTheGroundAndMaxNotAPowerOfTwo) {
    const Heightfield hf = flat(33, 10.0, 0.0f);
    ProbeVolumeSettings v = surface(10.0, 80.0);
    v.heightOffset = 0.0;
    try {
        placeProbes(v, hf);
        FAIL() << "a surface volume at height_offset 0 was placed";
    } catch (const PlacementError& e) {
        EXPECT_NE(std::string(e.what()).find("height_offset = 0 must be above 0"), std::string::npos) << e.what();
    }
    v.heightOffset = 5.0;
    v.adaptive.maxCellSize = 70.0;
    EXPECT_THROW(placeProbes(v, hf), PlacementError);
}

TEST(SurfaceRefinement, SplitsOnlyWhereTheGroundsLightVariesAndKeepsTheQuadrantBakes) {
    // Flat ground; the light varies around one spot near the ground in a corner.
    const Heightfield hf = flat(65, 10.0, 0.0f);
    ProbeVolumeSettings v = surface(10.0, 160.0);
    v.adaptive.tolerance = 0.05;
    const glm::vec3 hot(-200.0f, 5.0f, 200.0f);
    auto field = [&](const glm::vec3& p) { return 1.0f + 2.0f * bump(p, hot, 60.0f); };
    size_t baked = 0;
    const AdaptiveBake a = bakeAdaptive(v, hf, fieldBaker(field, &baked));
    const ProbeLayout geometric = placeProbes(v, hf);
    EXPECT_EQ(geometric.validCount(), 16u);
    expectRefinementKeptItsTrials(a, geometric.validCount(), baked, 4, 0.05);
    expectSurfaceRules(a.layout, hf, v.heightOffset);
    size_t nearMinimum = 0, farRoots = 0;
    for (size_t i = 0; i < a.layout.positions.size(); ++i) {
        const OctreeLeaf& l = a.layout.octree->leaves[i];
        const glm::vec3& p = a.layout.positions[i];
        const float d = glm::length(glm::vec2(p.x - hot.x, p.z - hot.z));
        if (l.level == 0) {
            EXPECT_LT(d, 200.0f);
            ++nearMinimum;
        }
        farRoots += l.level == 4 && d > 300.0f;
        // Every leaf larger than the minimum meets the tolerance at its quadrant centres.
        if (l.level == 0) continue;
        const float own = field(p);
        const float quarter = 0.25f * a.layout.cellSize * float(l.edge());
        for (int o = 0; o < 4; ++o) {
            const glm::vec3 q(p.x + (o & 1 ? quarter : -quarter), p.y, p.z + (o & 2 ? quarter : -quarter));
            EXPECT_LE(std::abs(own - field(q)) / field(q), 0.05f + 1e-4f);
        }
    }
    EXPECT_GT(nearMinimum, 0u);
    EXPECT_GE(farRoots, 6u);
    // The SH handed back belongs to each probe's own position.
    for (size_t i = 0; i < a.layout.positions.size(); ++i)
        EXPECT_NEAR(sh::evalRadiance(a.bake.sh[i], glm::vec3(0, 1, 0)).x, field(a.layout.positions[i]), 1e-4f);

    // A budget of one split splits the worst leaf: the root around the spot.
    v.adaptive.maxProbes = int(geometric.validCount() + 3);
    const AdaptiveBake one = bakeAdaptive(v, hf, fieldBaker(field));
    EXPECT_TRUE(one.refinement->budgetReached);
    EXPECT_EQ(one.refinement->leavesSplit, 1u);
    EXPECT_EQ(one.layout.validCount(), geometric.validCount() + 3);
    for (size_t i = 0; i < one.layout.positions.size(); ++i)
        if (one.layout.octree->leaves[i].level < 4) {
            const glm::vec3& p = one.layout.positions[i];
            EXPECT_LT(glm::length(glm::vec2(p.x - hot.x, p.z - hot.z)), 160.0f);
        }
}

TEST(SurfaceRefinement, InterpolationErrorIsMeasuredInTheLayerTheProbesStandIn) {
    const Heightfield hf = importDem((kDems / "orkhon_crop.asc").string()).heightfield;
    ProbeVolumeSettings v = surface();
    v.heightOffset = 8.0;
    const ProbeLayout L = placeProbes(v, hf);
    std::vector<sh::ShRgb> shs(L.positions.size());
    for (auto& s : shs) s = sh::projectConstant(glm::vec3(1.0f));
    const InterpolationError e =
        measureInterpolationError(L, shs, hf, fieldBaker([](const glm::vec3&) { return 1.0f; }), 200, 7, 0.1);
    ASSERT_EQ(e.points, 200u);
    EXPECT_EQ(e.uncovered, 0u);
    float highest = 0.0f;
    for (const glm::vec3& p : e.positions) {
        const float above = p.y - hf.surfaceHeight(p.x, p.z);
        EXPECT_GT(above, 0.0f);
        EXPECT_LE(above, 16.0f + 1e-3f);
        highest = std::max(highest, above);
    }
    EXPECT_GT(highest, 12.0f);  // the whole layer, not only the probes' height
    EXPECT_NEAR(e.p95, 0.0, 1e-5);
}

TEST(SurfaceBake, TargetErrorChoosesTheToleranceAndTheReportSaysQuadtree) {
    const fs::path out = fs::temp_directory_path() / "terralux_surface_bake";
    fs::remove_all(out);
    nlohmann::json doc = defaultProjectJson();
    doc["terrain"]["dem"] = (kDems / "orkhon_crop.asc").string();
    doc["bake"]["quality"] = "draft";
    doc["bake"]["error_map_resolution"] = 32;
    doc["export"]["out_dir"] = out.string();
    doc["probe_volumes"][0]["placement"] = "surface";
    doc["probe_volumes"][0]["target_error"] = 0.1;
    BakeRequest request;
    request.project.scene = sceneFromJson(doc, "test", nullptr);
    request.threads = 2;
    const BakeOutcome o = runBake(request, {}, nullptr);
    const nlohmann::json& v = o.report["volumes"][0];
    EXPECT_EQ(v["placement"], "surface");
    EXPECT_EQ(v["adaptive"]["tree"], "quadtree");
    EXPECT_EQ(v["target"]["setting"], "adaptive.tolerance");
    EXPECT_TRUE(v["target"]["met"].get<bool>()) << v["target"].dump();
    EXPECT_LE(v["error_map"]["p95"].get<double>(), 0.1);
    EXPECT_EQ(v["error_map"]["height_m"].get<double>(), 5.0);  // the probes' own height
    // Fewer probes than the uniform grid of its smallest squares.
    EXPECT_LT(v["probes"].get<size_t>(), v["adaptive"]["uniform_grid_probes"].get<size_t>() / 2);
    fs::remove_all(out);
}

TEST(SurfaceParameters, TheOctreeOnlySettingsAreNotReadByASurfaceVolume) {
    SceneDescription s;
    s.probeVolumes.resize(1);
    s.probeVolumes[0].placement = ProbePlacement::Surface;
    for (const ParameterSpec& p : parameterTable()) {
        if (p.path.rfind("probe_volumes[].", 0) != 0) continue;
        const bool read = p.isRead(s, 0);
        if (p.path == "probe_volumes[].adaptive.surface_band" || p.path == "probe_volumes[].adaptive.size" ||
            p.path == "probe_volumes[].adaptive.height_range" || p.path == "probe_volumes[].adaptive.max_move_share" ||
            p.path == "probe_volumes[].adaptive.surface_cell_size") {
            EXPECT_FALSE(read) << p.path;
        }
        if (p.path == "probe_volumes[].adaptive.tolerance" || p.path == "probe_volumes[].adaptive.min_cell_size" ||
            p.path == "probe_volumes[].height_offset") {
            EXPECT_TRUE(read) << p.path;
        }
    }
}
