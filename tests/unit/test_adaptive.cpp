// Adaptive octree placement (issue: only the probes a scene needs, never one inside the terrain):
// the geometric rules on real DEMs, the occupancy grid per docs/formats.md, the interpolation model,
// the error-driven refinement and its budget, the acceptance numbers against a uniform grid, and
// the whole bake's determinism and report.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <numbers>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "BakeJob.h"
#include "DemImport.h"
#include "ShProbeFile.h"
#include "TestScenes.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/SphereSampling.h"

using namespace terralux;
using terralux::test::bump;
using terralux::test::expectRefinementKeptItsTrials;
using terralux::test::fieldBaker;
using terralux::test::flat;
namespace fs = std::filesystem;

namespace {

const fs::path kDems = fs::path(TERRALUX_TEST_DATA) / "dem";


ProbeVolumeSettings adaptive(std::optional<double> minCell = std::nullopt,
                             std::optional<double> maxCell = std::nullopt) {
    ProbeVolumeSettings v;
    v.placement = ProbePlacement::Adaptive;
    v.adaptive.minCellSize = minCell;
    v.adaptive.maxCellSize = maxCell;
    return v;
}

// An adaptive volume over the cube of edge `edge` centred on the origin in x and z, from y = 0.
ProbeVolumeSettings adaptiveCube(double minCell, double maxCell, float edge) {
    ProbeVolumeSettings v = adaptive(minCell, maxCell);
    v.origin = glm::vec3(-0.5f * edge, 0.0f, -0.5f * edge);
    v.adaptive.size = glm::vec3(edge);
    return v;
}

size_t cellIndex(const ProbeLayout& L, uint32_t x, uint32_t y, uint32_t z) {
    return x + size_t(y) * L.cellDims[0] + size_t(z) * L.cellDims[0] * L.cellDims[1];
}

glm::vec3 cellCentre(const ProbeLayout& L, uint32_t x, uint32_t y, uint32_t z) {
    return L.cellOrigin + L.cellSize * glm::vec3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f);
}

bool leafContains(const OctreeLeaf& l, uint32_t x, uint32_t y, uint32_t z) {
    return x >= l.x && x < l.x + l.edge() && y >= l.y && y < l.y + l.edge() && z >= l.z &&
           z < l.z + l.edge();
}

// Every rule of the issue that the geometry alone decides, checked cell by cell.
void expectPlacementRules(const ProbeLayout& L, const Heightfield& hf, double maxMoveShare) {
    ASSERT_TRUE(L.octree.has_value());
    const AdaptiveOctree& t = *L.octree;
    ASSERT_EQ(t.leaves.size(), L.positions.size());
    const uint32_t X = L.cellDims[0], Y = L.cellDims[1], Z = L.cellDims[2];
    ASSERT_EQ(L.cellProbe.size(), size_t(X) * Y * Z);

    // No probe with its centre below the terrain; moved probes stay in their leaf, within the cap.
    size_t moved = 0;
    for (size_t i = 0; i < L.positions.size(); ++i) {
        if (!L.valid[i]) continue;
        const glm::vec3& p = L.positions[i];
        EXPECT_GT(p.y, hf.surfaceHeight(p.x, p.z)) << "probe " << i;
        const OctreeLeaf& l = t.leaves[i];
        const float edge = L.cellSize * float(l.edge());
        const glm::vec3 centre = L.cellOrigin + L.cellSize * (glm::vec3(float(l.x), float(l.y), float(l.z)) +
                                                              0.5f * float(l.edge()));
        if (t.probe[i] == LeafProbe::Moved) {
            ++moved;
            EXPECT_EQ(l.level, 0);
            EXPECT_GT(p.y, centre.y);
            EXPECT_LE(p.y - centre.y, float(maxMoveShare) * edge * 1.0001f);
        } else {
            EXPECT_EQ(t.probe[i], LeafProbe::Centre);
            EXPECT_NEAR(p.y, centre.y, 1e-3f * edge);
        }
        EXPECT_NEAR(p.x, centre.x, 1e-3f * edge);
        EXPECT_NEAR(p.z, centre.z, 1e-3f * edge);
    }
    EXPECT_EQ(moved, t.moved);

    // Leaves never overlap and stay inside the box.
    std::vector<uint8_t> covered(L.cellProbe.size(), 0);
    for (const OctreeLeaf& l : t.leaves) {
        ASSERT_LE(l.x + l.edge(), X);
        ASSERT_LE(l.y + l.edge(), Y);
        ASSERT_LE(l.z + l.edge(), Z);
        for (uint32_t z = l.z; z < l.z + l.edge(); ++z)
            for (uint32_t y = l.y; y < l.y + l.edge(); ++y)
                for (uint32_t x = l.x; x < l.x + l.edge(); ++x) {
                    ASSERT_EQ(covered[cellIndex(L, x, y, z)], 0) << "cell " << x << "," << y << "," << z;
                    covered[cellIndex(L, x, y, z)] = 1;
                }
    }

    // Every cell whose centre is above the terrain maps to a probe whose leaf contains it; cells
    // wholly inside the terrain hold -1; cells partly above (a ground object can stand in them)
    // hold a probe, their own or the first one above in their column.
    size_t above = 0, borrowed = 0;
    for (uint32_t z = 0; z < Z; ++z)
        for (uint32_t x = 0; x < X; ++x) {
            const glm::vec3 c0 = cellCentre(L, x, 0, z);
            const float ground = hf.surfaceHeight(c0.x, c0.z);
            const SurfaceRange range = surfaceRange(hf, c0.x - 0.5 * L.cellSize, c0.x + 0.5 * L.cellSize,
                                                    c0.z - 0.5 * L.cellSize, c0.z + 0.5 * L.cellSize);
            for (uint32_t y = 0; y < Y; ++y) {
                const int32_t probe = L.cellProbe[cellIndex(L, x, y, z)];
                const glm::vec3 c = cellCentre(L, x, y, z);
                const float top = c.y + 0.5f * L.cellSize;
                if (c.y > ground) {
                    ++above;
                    ASSERT_GE(probe, 0) << "above-terrain cell " << x << "," << y << "," << z;
                    ASSERT_TRUE(L.valid[size_t(probe)]);
                    EXPECT_TRUE(leafContains(t.leaves[size_t(probe)], x, y, z));
                } else if (top <= range.lo) {
                    EXPECT_EQ(probe, -1) << "buried cell " << x << "," << y << "," << z;
                } else if (probe >= 0 && !leafContains(t.leaves[size_t(probe)], x, y, z)) {
                    ++borrowed;
                    // The first probe above, in the same column.
                    const OctreeLeaf& l = t.leaves[size_t(probe)];
                    EXPECT_TRUE(x >= l.x && x < l.x + l.edge() && z >= l.z && z < l.z + l.edge());
                    EXPECT_GT(l.y, y);
                }
            }
        }
    EXPECT_EQ(above, t.uniformProbes);
    EXPECT_EQ(borrowed, t.borrowed);
}

// The .shprobe of a layout, with a distinct SH per probe, as the bake compacts it.
ShProbeGrid gridOf(const ProbeLayout& L) {
    ShProbeGrid g;
    g.dims = glm::uvec3(L.cellDims[0], L.cellDims[1], L.cellDims[2]);
    g.origin = L.cellOrigin;
    g.spacing = L.cellSize;
    std::vector<int32_t> compact(L.positions.size(), -1);
    for (size_t i = 0; i < L.positions.size(); ++i) {
        if (!L.valid[i]) continue;
        compact[i] = int32_t(g.probes.size());
        ShProbeRecord r;
        r.coeffs[0] = L.positions[i];
        g.probes.push_back(r);
    }
    for (int32_t c : L.cellProbe) g.occupancy.push_back(c < 0 ? -1 : compact[size_t(c)]);
    return g;
}

class RealDem : public ::testing::TestWithParam<const char*> {};

}  // namespace

TEST_P(RealDem, NoProbeInsideEveryCellMappedLeavesDisjointFileReadsBack) {
    const DemImportResult dem = importDem((kDems / GetParam()).string());
    const Heightfield& hf = dem.heightfield;
    const ProbeVolumeSettings v = adaptive();
    const ProbeLayout L = placeProbes(v, hf);
    // Defaults: the DEM cell (these crops are under 128 cells a side), 16 times that, a band of
    // one cell.
    const double cell = std::max(hf.cellSizeX(), hf.cellSizeZ());
    EXPECT_DOUBLE_EQ(L.octree->minCell, cell);
    EXPECT_DOUBLE_EQ(L.octree->maxCell, 16.0 * cell);
    EXPECT_DOUBLE_EQ(L.octree->surfaceBand, cell);
    EXPECT_FLOAT_EQ(L.cellSize, float(cell));
    EXPECT_FLOAT_EQ(L.fallbackBlendDistance, float(2.0 * cell));
    // The auto box: the footprint from the lowest terrain to 100 m above the highest, whole cells.
    EXPECT_FLOAT_EQ(L.cellOrigin.x, hf.minX());
    EXPECT_FLOAT_EQ(L.cellOrigin.y, hf.minHeight());
    EXPECT_FLOAT_EQ(L.cellOrigin.z, hf.minZ());
    EXPECT_EQ(L.cellDims[1], uint32_t(std::ceil((hf.maxHeight() + 100.0 - hf.minHeight()) / cell - 1e-6)));
    EXPECT_GE(L.cellOrigin.x + L.cellSize * float(L.cellDims[0]), hf.maxX() - 1e-3f);
    expectPlacementRules(L, hf, v.adaptive.maxMoveShare);
    EXPECT_LT(L.validCount(), L.octree->uniformProbes);
    // The uniform count is what a box grid at the minimum cell size over the same box keeps.
    ProbeVolumeSettings box;
    box.placement = ProbePlacement::Box;
    box.gridDims = {int(L.cellDims[0]), int(L.cellDims[1]), int(L.cellDims[2])};
    box.spacing = glm::vec3(L.cellSize);
    box.origin = L.cellOrigin;
    EXPECT_EQ(placeProbes(box, hf).validCount(), L.octree->uniformProbes);

    const fs::path file = fs::temp_directory_path() / (std::string("terralux_adaptive_") + GetParam() + ".shprobe");
    const ShProbeGrid grid = gridOf(L);
    writeShProbeFile(file, grid);
    EXPECT_EQ(fs::file_size(file), L.fileBytes());
    const ShProbeGrid back = readShProbeFile(file);
    EXPECT_EQ(back, grid);
    fs::remove(file);
    std::cout << GetParam() << ": " << L.validCount() << " probes (" << L.octree->moved << " moved, "
              << L.octree->borrowed << " borrowing cells) vs " << L.octree->uniformProbes
              << " for a uniform grid of " << cell << " m\n";
}
INSTANTIATE_TEST_SUITE_P(Fixtures, RealDem,
                         ::testing::Values("bigtujunga_utm11_crop.tif", "n42e001_voids_crop.tif",
                                           "rainier_crop.tif", "orkhon_crop.asc"),
                         [](const auto& info) {
                             std::string n = info.param;
                             return n.substr(0, n.find('_'));
                         });

TEST(AdaptivePlacement, FullSharedDemFollowsTheRules) {
    const fs::path dem = fs::path(TERRALUX_SHARED_DATA) / "dem" / "srtm_bigtujunga30m_utm11.tif";
    if (!fs::exists(dem)) GTEST_SKIP() << "shared DEM not present: " << dem;
    DemImportOptions options;
    options.maxResolution = 400;
    const DemImportResult d = importDem(dem.string(), options);
    ProbeVolumeSettings v = adaptive();
    v.adaptive.maxMoveShare = 0.5;
    const ProbeLayout L = placeProbes(v, d.heightfield);
    expectPlacementRules(L, d.heightfield, 0.5);
}

TEST(AdaptivePlacement, SurfaceBandGoesToTheMinimumAndOpenAirStaysCoarse) {
    // Flat ground at 100 m; cells of 10 m to 80 m from y = 0 to 400: the band reaches 110 m.
    const Heightfield hf = flat(41, 10.0, 100.0f);
    ProbeVolumeSettings v = adaptiveCube(10.0, 80.0, 400.0f);
    const ProbeLayout L = placeProbes(v, hf);
    ASSERT_EQ(L.cellDims, (std::array<uint32_t, 3>{40, 40, 40}));
    for (const OctreeLeaf& l : L.octree->leaves) {
        const double y0 = 10.0 * l.y, y1 = y0 + 10.0 * l.edge();
        EXPECT_GT(y1, 100.0);  // nothing wholly below the ground
        if (l.level > 0) {
            EXPECT_GE(y0, 110.0);  // coarse cells only above the band
        } else {
            EXPECT_LT(y0, 120.0);  // minimum cells only where a parent reached into it
        }
    }
    // Per 80 m column: the root [80, 160) reaches the band; its 40 m child [80, 120) too, whose
    // 20 m child [80, 100) is buried and [100, 120) splits into 10 m cells (8 x 8 x 2); the 40 m
    // cells [120, 160) stay (2 x 2); 80 m roots above 160 m (3).
    EXPECT_EQ(L.validCount(), 25u * (128 + 4 + 3));
    std::map<int, size_t> byLevel;
    for (const OctreeLeaf& l : L.octree->leaves) ++byLevel[l.level];
    EXPECT_EQ(byLevel[3], 25u * 3);
    EXPECT_EQ(byLevel[2], 25u * 4);
    EXPECT_EQ(byLevel[1], 0u);
    EXPECT_EQ(byLevel[0], 25u * 128);
}

TEST(AdaptivePlacement, CentreInsideIsMovedUpOrBorrowsTheProbeAbove) {
    ProbeVolumeSettings v = adaptive(10.0, 10.0);
    v.origin = glm::vec3(-20.0f, 0.0f, -20.0f);
    v.adaptive.size = glm::vec3(40.0f, 30.0f, 40.0f);
    // Ground at 5.5 m: the first layer's centres (5 m) are 0.5 m inside; moved to 5.5 + 0.2.
    {
        const Heightfield hf = flat(9, 10.0, 5.5f);
        const ProbeLayout L = placeProbes(v, hf);
        EXPECT_EQ(L.octree->moved, 16u);
        EXPECT_EQ(L.octree->borrowed, 0u);
        for (size_t i = 0; i < L.positions.size(); ++i)
            if (L.octree->leaves[i].y == 0) {
                EXPECT_EQ(L.octree->probe[i], LeafProbe::Moved);
                EXPECT_FLOAT_EQ(L.positions[i].y, 5.7f);
            }
        expectPlacementRules(L, hf, v.adaptive.maxMoveShare);
    }
    // Ground at 8 m: a 3.2 m move is over the 2.5 m cap, so the cell points at the probe above.
    {
        const Heightfield hf = flat(9, 10.0, 8.0f);
        const ProbeLayout L = placeProbes(v, hf);
        EXPECT_EQ(L.octree->moved, 0u);
        EXPECT_EQ(L.octree->borrowed, 16u);
        EXPECT_EQ(L.validCount(), 32u);
        EXPECT_EQ(L.positions.size() - L.validCount(), 16u);
        const int32_t bottom = L.cellProbe[cellIndex(L, 1, 0, 2)];
        const int32_t above = L.cellProbe[cellIndex(L, 1, 1, 2)];
        EXPECT_EQ(bottom, above);
        EXPECT_FLOAT_EQ(L.positions[size_t(above)].y, 15.0f);
        expectPlacementRules(L, hf, v.adaptive.maxMoveShare);
        // With a cap of half the cell, the same probes move instead.
        ProbeVolumeSettings half = v;
        half.adaptive.maxMoveShare = 0.5;
        const ProbeLayout M = placeProbes(half, hf);
        EXPECT_EQ(M.octree->moved, 16u);
        EXPECT_EQ(M.octree->borrowed, 0u);
        // A box one cell high has nothing above to borrow: the cells hold -1.
        ProbeVolumeSettings low = v;
        low.adaptive.size = glm::vec3(40.0f, 10.0f, 40.0f);
        const ProbeLayout N = placeProbes(low, hf);
        EXPECT_EQ(N.octree->dropped, 16u);
        EXPECT_EQ(N.validCount(), 0u);
        EXPECT_TRUE(std::all_of(N.cellProbe.begin(), N.cellProbe.end(), [](int32_t c) { return c < 0; }));
    }
    // Ground at 25 m under 40 m roots: the root's centre (20 m) is inside, so it splits; of its
    // children the lower ones are buried and the upper ones' centres (30 m) are above; their
    // 10 m children at [20, 30) have their centres inside and move up.
    {
        const Heightfield hf = flat(9, 10.0, 25.0f);
        ProbeVolumeSettings big = adaptive(10.0, 40.0);
        big.origin = glm::vec3(-20.0f, 0.0f, -20.0f);
        big.adaptive.size = glm::vec3(40.0f, 80.0f, 40.0f);
        big.adaptive.surfaceBand = 0.0;
        const ProbeLayout L = placeProbes(big, hf);
        EXPECT_EQ(L.octree->splitForInside, 1u);
        EXPECT_EQ(L.octree->moved, 16u);
        expectPlacementRules(L, hf, big.adaptive.maxMoveShare);
    }
}

// The default settings place a moderate octree on every DEM a user is likely to import: the
// committed crops and, when the shared data is there, whole SRTM tiles (90 m over 110 km, where
// the DEM cell alone made 5.6 M probes or overflowed the occupancy grid).
class DefaultAdaptiveOnDem : public ::testing::TestWithParam<const char*> {};

TEST_P(DefaultAdaptiveOnDem, PlacesTensOfThousandsOfProbes) {
    const std::string name = GetParam();
    const bool shared = name.rfind("shared/", 0) == 0;
    const fs::path file = shared ? fs::path(TERRALUX_SHARED_DATA) / "dem" / name.substr(7) : kDems / name;
    if (!fs::exists(file)) GTEST_SKIP() << file << " is absent (shared data not installed)";
    const DemImportResult dem = importDem(file.string());
    const Heightfield& hf = dem.heightfield;
    ProbeLayout L;
    ASSERT_NO_THROW(L = placeProbes(adaptive(), hf));
    const double longer = std::max(double(hf.maxX()) - hf.minX(), double(hf.maxZ()) - hf.minZ());
    EXPECT_DOUBLE_EQ(L.octree->minCell,
                     std::max({double(hf.cellSizeX()), double(hf.cellSizeZ()), longer / 128.0}));
    EXPECT_LE(std::max(L.cellDims[0], L.cellDims[2]), 129u);
    EXPECT_GE(L.validCount(), 1000u);
    EXPECT_LE(L.validCount(), 100000u);
    EXPECT_LE(L.fileBytes(), 20ull << 20);
    std::cout << name << ": " << L.validCount() << " probes, min cell " << L.octree->minCell << " m\n";
}
INSTANTIATE_TEST_SUITE_P(Dems, DefaultAdaptiveOnDem,
                         ::testing::Values("bigtujunga_utm11_crop.tif", "n42e001_voids_crop.tif",
                                           "rainier_crop.tif", "orkhon_crop.asc", "shared/N42E001.hgt",
                                           "shared/mt_rainier_90m.tif", "shared/srtm_bigtujunga30m_utm11.tif",
                                           "shared/topotoolbox_exampleDEM.asc"),
                         [](const auto& info) {
                             std::string n = info.param;
                             if (n.rfind("shared/", 0) == 0) n = "shared_" + n.substr(7);
                             n = n.substr(0, n.find('.'));
                             for (char& c : n)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return n;
                         });

TEST(AdaptivePlacement, SettingsTheTerrainDecidesAreChecked) {
    const Heightfield hf = flat(11, 30.0, 0.0f);
    auto message = [&](const ProbeVolumeSettings& v) {
        try {
            placeProbes(v, hf);
        } catch (const PlacementError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    ProbeVolumeSettings v = adaptive(std::nullopt, 100.0);
    v.name = "valley";
    EXPECT_EQ(message(v), "probe_volumes 'valley': adaptive.max_cell_size = 100 must be "
                          "min_cell_size (30, the auto size) times 2^k, k in [0, 16]");
    v = adaptive(0.25);
    v.name = "fine";
    EXPECT_EQ(message(v), "probe_volumes 'fine': occupancy grid of 576000000 cells (1200 x 400 x "
                          "1200 of 0.25 m) exceeds 67108864; raise adaptive.min_cell_size or "
                          "shrink the box");
    v = adaptive(30.0, 120.0);
    v.name = "tight";
    const ProbeLayout unlimited = placeProbes(v, hf);
    v.adaptive.maxProbes = 10;
    EXPECT_EQ(message(v), "probe_volumes 'tight': the surface band alone needs " +
                              std::to_string(unlimited.validCount()) +
                              " probes, more than adaptive.max_probes = 10; raise it, "
                              "adaptive.min_cell_size or adaptive.surface_cell_size");
    v.adaptive.maxProbes = int(unlimited.validCount());
    EXPECT_EQ(message(v), "");
    v.adaptive.maxProbes.reset();
    v.adaptive.maxBytes = 1000;
    EXPECT_EQ(message(v), "probe_volumes 'tight': the surface band alone needs " +
                              std::to_string(unlimited.fileBytes()) +
                              " bytes, more than adaptive.max_bytes = 1000; raise it, "
                              "adaptive.min_cell_size or adaptive.surface_cell_size");
    // One cap per placement: an adaptive volume holds at most kMaxVolumeProbes valid probes, as a
    // box grid holds that many cells, whether adaptive.max_probes is set or not.
    v = adaptive(1.0, 4.0);
    v.name = "dense";
    v.adaptive.size = glm::vec3(300.0f, 8.0f, 300.0f);
    v.origin = glm::vec3(-150.0f, -4.0f, -150.0f);
    const std::string dense = message(v);
    EXPECT_NE(dense.find("probe_volumes 'dense': the surface band alone needs "), std::string::npos) << dense;
    EXPECT_NE(dense.find(" probes, more than an adaptive volume's limit of 65536; raise adaptive.min_cell_size"),
              std::string::npos) << dense;
    v = adaptive(30.0, 120.0);
    v.name = "band";
    v.adaptive.surfaceCellSize = 20.0;
    EXPECT_EQ(message(v), "probe_volumes 'band': adaptive.surface_cell_size = 20 must be at least "
                          "min_cell_size (30)");
    // An explicit box grows to whole minimum cells.
    v = adaptive(30.0, 120.0);
    v.origin = glm::vec3(-100.0f, -50.0f, -100.0f);
    v.adaptive.size = glm::vec3(95.0f, 30.0f, 60.0f);
    const ProbeLayout L = placeProbes(v, hf);
    EXPECT_EQ(L.cellDims, (std::array<uint32_t, 3>{4, 1, 2}));
    EXPECT_EQ(L.cellOrigin, glm::vec3(-100.0f, -50.0f, -100.0f));
}

TEST(Interpolation, TrilinearOverCellCentresLeavesOutEmptyCells) {
    ProbeLayout L;
    L.cellDims = {3, 1, 1};
    L.cellSize = 2.0f;
    L.cellOrigin = glm::vec3(0.0f);
    L.cellProbe = {0, 1, -1};
    L.positions = {{1, 1, 1}, {3, 1, 1}};
    L.valid = {1, 1};
    const std::vector<sh::ShRgb> probes = {sh::projectConstant(glm::vec3(1.0f)),
                                           sh::projectConstant(glm::vec3(3.0f))};
    auto radiance = [&](const glm::vec3& p) {
        sh::ShRgb out;
        EXPECT_TRUE(interpolateProbes(L, probes, p, out));
        return sh::evalRadiance(out, glm::vec3(0, 1, 0)).x;
    };
    EXPECT_NEAR(radiance({1.0f, 1.0f, 1.0f}), 1.0f, 1e-5f);   // a cell centre: its own probe
    EXPECT_NEAR(radiance({2.5f, 0.3f, 1.9f}), 2.5f, 1e-5f);   // 3/4 of the way to the next
    EXPECT_NEAR(radiance({0.2f, 1.0f, 1.0f}), 1.0f, 1e-5f);   // beyond the first centre: clamped
    EXPECT_NEAR(radiance({4.5f, 1.0f, 1.0f}), 3.0f, 1e-5f);   // the empty cell is left out
    sh::ShRgb none;
    L.cellProbe = {-1, -1, -1};
    EXPECT_FALSE(interpolateProbes(L, probes, {3.0f, 1.0f, 1.0f}, none));
}

namespace {

TEST(AdaptivePlacement, SurfaceCellSizeStopsTheBandAtItsSize) {
    // The band test's scene: flat ground at 100 m, cells of 10 m to 80 m from y = 0 to 400.
    const Heightfield hf = flat(41, 10.0, 100.0f);
    ProbeVolumeSettings v = adaptiveCube(10.0, 80.0, 400.0f);
    const size_t allMinimum = placeProbes(v, hf).validCount();
    v.adaptive.surfaceCellSize = 10.0;
    EXPECT_EQ(placeProbes(v, hf).validCount(), allMinimum);
    // 30 m stands for the 20 m cells below it. Per 80 m column: the root [80, 160) reaches the
    // band and is larger than 20 m; its 40 m child [80, 120) has its centre on the ground and
    // splits, into the buried [80, 100) and the 20 m leaves [100, 120) (2 x 2 each, 16 in all);
    // the 40 m cells [120, 160) (4) and the 80 m roots above (3) stay.
    v.adaptive.surfaceCellSize = 30.0;
    const ProbeLayout L = placeProbes(v, hf);
    EXPECT_DOUBLE_EQ(L.octree->surfaceCell, 20.0);
    EXPECT_EQ(allMinimum, 25u * (128 + 4 + 3));
    EXPECT_EQ(L.validCount(), 25u * (16 + 4 + 3));
    for (const OctreeLeaf& l : L.octree->leaves) EXPECT_GE(l.level, 1);
    expectPlacementRules(L, hf, v.adaptive.maxMoveShare);
    // Past max_cell_size it is max_cell_size: the band forces nothing, and the roots [80, 160),
    // whose centres are above the ground, stay whole under the 3 above them.
    v.adaptive.surfaceCellSize = 1000.0;
    const ProbeLayout open = placeProbes(v, hf);
    EXPECT_DOUBLE_EQ(open.octree->surfaceCell, 80.0);
    EXPECT_EQ(open.validCount(), 25u * (1 + 3));
}

}  // namespace

TEST(Refinement, SplitsWhereLightingVariesAndReusesTheOctantBakes) {
    const Heightfield hf = flat(41, 10.0, 0.0f);
    ProbeVolumeSettings v = adaptiveCube(10.0, 160.0, 480.0f);
    v.adaptive.tolerance = 0.05;
    const glm::vec3 hot(-100.0f, 300.0f, 100.0f);
    auto field = [&](const glm::vec3& p) { return 1.0f + 2.0f * bump(p, hot, 60.0f); };
    size_t baked = 0;
    const AdaptiveBake a = bakeAdaptive(v, hf, fieldBaker(field, &baked));
    const ProbeLayout geometric = placeProbes(v, hf);
    expectRefinementKeptItsTrials(a, geometric.validCount(), baked, 8, 0.05);
    expectPlacementRules(a.layout, hf, v.adaptive.maxMoveShare);
    // Splits happen near the bump only; far from it the air keeps the largest cells: every
    // 160 m root above the ground band whose centre is over 350 m away is still one leaf.
    size_t farRoots = 0;
    for (int rz = 0; rz < 3; ++rz)
        for (int ry = 1; ry < 3; ++ry)
            for (int rx = 0; rx < 3; ++rx) {
                const OctreeLeaf root{uint32_t(16 * rx), uint32_t(16 * ry), uint32_t(16 * rz), 4};
                const glm::vec3 centre = v.origin.value() + 160.0f * (glm::vec3(float(rx), float(ry), float(rz)) + 0.5f);
                if (glm::length(centre - hot) <= 350.0f) continue;
                ++farRoots;
                const auto& leaves = a.layout.octree->leaves;
                EXPECT_NE(std::find(leaves.begin(), leaves.end(), root), leaves.end())
                    << centre.x << "," << centre.y << "," << centre.z;
            }
    EXPECT_GE(farRoots, 2u);
    // Every leaf larger than the minimum is within the tolerance at its octant centres now.
    for (size_t i = 0; i < a.layout.positions.size(); ++i) {
        const OctreeLeaf& l = a.layout.octree->leaves[i];
        if (l.level == 0) continue;
        const float own = field(a.layout.positions[i]);
        const float quarter = 0.25f * a.layout.cellSize * float(l.edge());
        for (int o = 0; o < 8; ++o) {
            const glm::vec3 q = a.layout.positions[i] +
                                quarter * glm::vec3(o & 1 ? 1 : -1, o & 2 ? 1 : -1, o & 4 ? 1 : -1);
            EXPECT_LE(std::abs(own - field(q)) / field(q), 0.05f + 1e-4f);
        }
    }
    // The SH handed back belongs to each probe's own position.
    for (size_t i = 0; i < a.layout.positions.size(); ++i) {
        if (!a.layout.valid[i]) continue;
        EXPECT_NEAR(sh::evalRadiance(a.bake.sh[i], glm::vec3(0, 1, 0)).x,
                    field(a.layout.positions[i]), 1e-4f);
    }
}

TEST(Refinement, BudgetStopsItWorstLeavesFirst) {
    const Heightfield hf = flat(33, 10.0, 0.0f);
    ProbeVolumeSettings v = adaptiveCube(10.0, 80.0, 320.0f);
    v.adaptive.tolerance = 0.01;
    // Two bumps in the air, the stronger in the leaf [0, 80)^2 x [240, 320).
    const glm::vec3 strong(40.0f, 280.0f, 40.0f), weak(-120.0f, 280.0f, -120.0f);
    auto field = [&](const glm::vec3& p) {
        return 1.0f + 1.0f * bump(p, strong, 30.0f) + 0.2f * bump(p, weak, 30.0f);
    };
    const size_t before = placeProbes(v, hf).validCount();
    v.adaptive.maxProbes = int(before + 7);  // room for exactly one split
    const AdaptiveBake a = bakeAdaptive(v, hf, fieldBaker(field));
    ASSERT_TRUE(a.refinement.has_value());
    EXPECT_TRUE(a.refinement->budgetReached);
    EXPECT_EQ(a.refinement->leavesSplit, 1u);
    EXPECT_GT(a.refinement->leavesOverTolerance, 0u);
    EXPECT_EQ(a.layout.validCount(), before + 7);
    // The split leaf is the one around the strong bump.
    bool strongSplit = false, weakSplit = false;
    for (const OctreeLeaf& l : a.layout.octree->leaves) {
        if (l.level != 2) continue;
        const glm::vec3 lo = a.layout.cellOrigin + 10.0f * glm::vec3(float(l.x), float(l.y), float(l.z));
        auto inside = [&](const glm::vec3& p) {
            return glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThan(p, lo + 40.0f));
        };
        strongSplit = strongSplit || inside(strong);
        weakSplit = weakSplit || inside(weak);
    }
    EXPECT_TRUE(strongSplit);
    EXPECT_FALSE(weakSplit);
    // A byte budget stops it the same way.
    v.adaptive.maxProbes.reset();
    v.adaptive.maxBytes = (long long)(48 + 160 * (before + 7) + 4 * 32 * 32 * 32);
    const AdaptiveBake b = bakeAdaptive(v, hf, fieldBaker(field));
    EXPECT_EQ(b.layout.validCount(), before + 7);
    EXPECT_EQ(b.layout.fileBytes(), uint64_t(*v.adaptive.maxBytes));
}

TEST(Refinement, CoarseSurfaceCellsSplitOnlyWhereTheGroundsLightVaries) {
    // Flat ground at 0; the light varies in one spot 30 m above it. With the band's cells as
    // large as the largest, the error alone decides where the ground gets small cells.
    const Heightfield hf = flat(41, 10.0, 0.0f);
    ProbeVolumeSettings v = adaptiveCube(10.0, 160.0, 480.0f);
    v.adaptive.surfaceCellSize = 160.0;
    v.adaptive.tolerance = 0.05;
    const glm::vec3 hot(-100.0f, 30.0f, 100.0f);
    auto field = [&](const glm::vec3& p) { return 1.0f + 2.0f * bump(p, hot, 40.0f); };
    const AdaptiveBake a = bakeAdaptive(v, hf, fieldBaker(field));
    v.adaptive.surfaceCellSize.reset();
    const size_t allMinimum = placeProbes(v, hf).validCount();
    ASSERT_TRUE(a.refinement.has_value());
    EXPECT_GT(a.refinement->leavesSplit, 0u);
    EXPECT_LT(a.layout.validCount(), allMinimum / 4);
    expectPlacementRules(a.layout, hf, v.adaptive.maxMoveShare);
    // Minimum cells only near the bright spot; the ground far from it keeps 160 m cells.
    size_t nearMinimum = 0, farCoarse = 0;
    for (size_t i = 0; i < a.layout.positions.size(); ++i) {
        const OctreeLeaf& l = a.layout.octree->leaves[i];
        const float d = glm::length(a.layout.positions[i] - hot);
        if (l.level == 0) {
            EXPECT_LT(d, 160.0f);
            ++nearMinimum;
        }
        farCoarse += l.level == 4 && l.y == 0 && d > 250.0f;
    }
    EXPECT_GT(nearMinimum, 0u);
    EXPECT_GT(farCoarse, 0u);
    // A budget the band of minimum cells alone exceeds, halfway between the coarse geometry and
    // the unbudgeted refinement: the coarse band fits it, and the refinement stops within it,
    // having split the worst leaves, those around the spot.
    v.adaptive.surfaceCellSize = 160.0;
    const size_t coarse = placeProbes(v, hf).validCount();
    v.adaptive.maxProbes = int((coarse + a.layout.validCount()) / 2);
    const AdaptiveBake budgeted = bakeAdaptive(v, hf, fieldBaker(field));
    EXPECT_TRUE(budgeted.refinement->budgetReached);
    EXPECT_GT(budgeted.layout.validCount(), coarse);
    EXPECT_LE(budgeted.layout.validCount(), size_t(*v.adaptive.maxProbes));
    for (size_t i = 0; i < budgeted.layout.positions.size(); ++i) {
        if (budgeted.layout.octree->leaves[i].level < 4) {
            EXPECT_LT(glm::length(budgeted.layout.positions[i] - hot), 250.0f);
        }
    }
    v.adaptive.surfaceCellSize.reset();
    EXPECT_THROW(placeProbes(v, hf), PlacementError);
}

TEST(Refinement, OctantsInsideTheTerrainDoNotSplitALeaf) {
    // Flat ground at 100 m; the 80 m leaves [80, 160) of a 80 m band have their lower octants'
    // centres on the ground, where a probe would see the terrain from inside (a fifth of the
    // light here). Above the ground the light is uniform, so nothing should split.
    const Heightfield hf = flat(41, 10.0, 100.0f);
    ProbeVolumeSettings v = adaptiveCube(10.0, 80.0, 400.0f);
    v.adaptive.surfaceCellSize = 80.0;
    v.adaptive.tolerance = 0.05;
    auto field = [&](const glm::vec3& p) { return p.y > hf.surfaceHeight(p.x, p.z) ? 1.0f : 0.2f; };
    const AdaptiveBake a = bakeAdaptive(v, hf, fieldBaker(field));
    ASSERT_TRUE(a.refinement.has_value());
    EXPECT_GT(a.refinement->leavesTested, 0u);
    EXPECT_EQ(a.refinement->leavesSplit, 0u);
    EXPECT_EQ(a.layout.validCount(), placeProbes(v, hf).validCount());
}

TEST(Refinement, SameResultWithOneAndTwoThreads) {
    const DemImportResult dem = importDem((kDems / "orkhon_crop.asc").string());
    const Heightfield& hf = dem.heightfield;
    const HeightfieldTracer tracer(hf);
    const BakeLighting L = test::skyAndSun(tracer);
    ProbeVolumeSettings v = adaptive();
    v.adaptive.tolerance = 0.01;
    auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        const IrradianceCache cache(L, 32, 16, 2, 0, {});
        return bakeAdaptive(v, hf, seededBaker(L, &cache, 1, 32, 77, {}));
    };
    const AdaptiveBake a = run(1), b = run(2);
    EXPECT_GT(a.refinement->leavesSplit, 0u);
    EXPECT_EQ(a.layout.octree->leaves, b.layout.octree->leaves);
    EXPECT_EQ(a.layout.positions, b.layout.positions);
    EXPECT_EQ(a.layout.cellProbe, b.layout.cellProbe);
    ASSERT_EQ(a.bake.sh.size(), b.bake.sh.size());
    EXPECT_EQ(std::memcmp(a.bake.sh.data(), b.bake.sh.data(), a.bake.sh.size() * sizeof(sh::ShRgb)), 0);
}

// The acceptance numbers: over the steepest committed DEM crop (Big Tujunga, 1020 m of
// relief over 2.9 km, 30 m cells), an error-driven adaptive volume at 2 % holds at most a quarter
// of the probes of a uniform grid at its minimum cell size, and its interpolation error is within
// the tolerance at 95 % of sampled points; the geometric octree alone is not.
TEST(AdaptiveBake, QuarterOfTheUniformProbesWithinToleranceOnARealDem) {
    const DemImportResult dem = importDem((kDems / "bigtujunga_utm11_crop.tif").string());
    const Heightfield& hf = dem.heightfield;
    const HeightfieldTracer tracer(hf);
    const BakeLighting L = test::skyAndSun(tracer);
    const IrradianceCache cache(L, 64, 32, 2, 0, {});
    const ProbeBaker baker = seededBaker(L, &cache, 1, 256, 99, {});
    const double tolerance = 0.02;
    ProbeVolumeSettings v = adaptive();  // 30 m to 480 m cells
    const AdaptiveBake geometric = bakeAdaptive(v, hf, baker);
    v.adaptive.tolerance = tolerance;
    const AdaptiveBake refined = bakeAdaptive(v, hf, baker);
    const size_t uniform = refined.layout.octree->uniformProbes;
    const InterpolationError eg =
        measureInterpolationError(geometric.layout, geometric.bake.sh, hf, baker, 512, 7, tolerance);
    const InterpolationError er =
        measureInterpolationError(refined.layout, refined.bake.sh, hf, baker, 512, 7, tolerance);
    std::cout << "uniform grid at 30 m: " << uniform << " probes\n"
              << "geometric octree: " << geometric.layout.validCount() << " probes, interpolation error p95 "
              << 100 * eg.p95 << " %, within " << 100 * tolerance << " % at " << 100 * *eg.withinTolerance
              << " % of " << eg.points << " points\n"
              << "error-driven at 2 %: " << refined.layout.validCount() << " probes ("
              << 100.0 * double(refined.layout.validCount()) / double(uniform)
              << " % of uniform), p95 " << 100 * er.p95 << " %, within tolerance at "
              << 100 * *er.withinTolerance << " % of " << er.points << " points\n";
    RecordProperty("uniform_probes", std::to_string(uniform));
    RecordProperty("adaptive_probes", std::to_string(refined.layout.validCount()));
    RecordProperty("within_tolerance_share", std::to_string(*er.withinTolerance));
    EXPECT_EQ(er.uncovered, 0u);
    EXPECT_LE(4 * refined.layout.validCount(), uniform);
    EXPECT_GE(*er.withinTolerance, 0.95);
    EXPECT_LE(er.p95, tolerance);
    EXPECT_GT(eg.p95, tolerance);  // the refinement is what brings it under
    EXPECT_GT(refined.refinement->leavesSplit, 0u);
}

namespace {

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("terralux_adaptive_" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string bytesOf(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

Project orkhonProject(const fs::path& out) {
    Project p;
    p.scene.terrain.dem = (kDems / "orkhon_crop.asc").string();
    p.scene.bake.quality = QualityPreset::Draft;
    p.scene.exportSettings.outDir = out.string();
    ProbeVolumeSettings& v = p.scene.probeVolumes[0];
    v.name = "valley";
    v.placement = ProbePlacement::Adaptive;
    v.adaptive.tolerance = 0.05;
    ProbeVolumeSettings grid;
    grid.name = "grid";
    grid.gridDims = {6, 1, 5};
    p.scene.probeVolumes.push_back(grid);
    return p;
}

}  // namespace

TEST(AdaptiveBake, SameBytesWithOneAndTwoThreadsAndAReportThatSaysWhatHappened) {
    const fs::path dir = tempDir("threads");
    BakeRequest one{orkhonProject(dir / "one"), 1, false, {}};
    BakeRequest two{orkhonProject(dir / "two"), 2, false, {}};
    const BakeOutcome a = runBake(one, {}, nullptr);
    runBake(two, {}, nullptr);
    for (const char* f : {"sh_coeffs/valley.shprobe", "sh_coeffs/grid.shprobe",
                          "sh_coeffs/valley.probes.json", "sh_coeffs/grid.probes.json"})
        EXPECT_EQ(bytesOf(dir / "one" / f), bytesOf(dir / "two" / f)) << f;

    const nlohmann::json& r = a.report;
    ASSERT_EQ(r["volumes"].size(), 2u);
    const nlohmann::json& v = r["volumes"][0];
    EXPECT_EQ(v["placement"], "adaptive");
    EXPECT_EQ(v["validity"]["probes_with_rays_from_below"], 0);
    EXPECT_EQ(v["moved_probes"], v["adaptive"]["moved_probes"]);
    EXPECT_TRUE(v["split_for_inside"].is_number_unsigned());
    EXPECT_EQ(v["adaptive"]["refinement"]["tolerance"], 0.05);
    // Unset, the surface band goes down to the minimum cell, and the report says so.
    EXPECT_EQ(v["adaptive"]["surface_cell_size"], v["adaptive"]["min_cell_size"]);
    EXPECT_EQ(v["interpolation_error"]["points"], 256);
    EXPECT_EQ(v["interpolation_error"]["uncovered_points"], 0);
    EXPECT_TRUE(v["interpolation_error"]["within_tolerance"].is_number());
    EXPECT_GT(v["interpolation_error"]["rays"].get<uint64_t>(), 0u);
    // The ground error map of view 56, its points all covered by probes.
    EXPECT_EQ(v["error_map"]["size"][0].get<int>(), 64);
    EXPECT_EQ(v["error_map"]["uncovered"], 0);
    EXPECT_GT(v["error_map"]["mean"].get<double>(), 0.0);
    EXPECT_GE(v["error_map"]["p95"].get<double>(), v["error_map"]["mean"].get<double>());
    const ShProbeGrid g = readShProbeFile(dir / "one" / "sh_coeffs/valley.shprobe");
    EXPECT_EQ(v["probes"], g.probes.size());
    EXPECT_EQ(g.dims.x, v["grid"]["dims"][0].get<uint32_t>());
    // The two volumes overlap; the engine reads "grid.shprobe" first (file-name order).
    ASSERT_EQ(r["overlaps"].size(), 1u);
    EXPECT_EQ(r["overlaps"][0]["engine_reads_first"], "grid");
    EXPECT_EQ(r["overlaps"][0]["volumes"], (nlohmann::json{"grid", "valley"}));
    EXPECT_GT(r["overlaps"][0]["cells_of_second_shadowed_by_first"].get<size_t>(), 0u);
    fs::remove_all(dir);
}

TEST(AdaptiveBake, TerrainGridFileMapsEveryCellAboveTheGroundToItsColumn) {
    const fs::path dir = tempDir("terrain");
    Project p;
    p.scene.terrain.dem = (kDems / "bigtujunga_utm11_crop.tif").string();
    p.scene.bake.quality = QualityPreset::Draft;
    p.scene.exportSettings.outDir = dir.string();
    p.scene.probeVolumes[0].gridDims = {12, 1, 9};
    p.scene.probeVolumes[0].heightOffset = 50.0;  // clear of the triangle surface everywhere
    runBake(BakeRequest{p, 0, false, {}}, {}, nullptr);
    const ShProbeGrid g = readShProbeFile(dir / "sh_coeffs/probes.shprobe");
    const DemImportResult dem = importDem(p.scene.terrain.dem);
    const Heightfield& hf = dem.heightfield;
    const float sx = (hf.maxX() - hf.minX()) / 11.0f, sz = (hf.maxZ() - hf.minZ()) / 8.0f;
    // Points just above the ground anywhere (an object standing there) and high in the air find
    // the probe of their nearest column; every probe is above the ground here, so indices match.
    ASSERT_EQ(g.probes.size(), 12u * 9u);
    Rng rng(4);
    for (int i = 0; i < 4000; ++i) {
        const float x = hf.minX() + (hf.maxX() - hf.minX()) * rng.next();
        const float z = hf.minZ() + (hf.maxZ() - hf.minZ()) * rng.next();
        const float ground = hf.surfaceHeight(x, z);
        const float top = g.origin.y + g.spacing * float(g.dims.y);
        const float y = i % 2 ? ground + 0.1f : ground + (top - ground) * rng.next();
        const glm::uvec3 c = glm::uvec3((glm::vec3(x, y, z) - g.origin) / g.spacing);
        ASSERT_TRUE(c.x < g.dims.x && c.y < g.dims.y && c.z < g.dims.z);
        // A cell belongs to the column nearest its centre.
        const float cx = g.origin.x + g.spacing * (float(c.x) + 0.5f);
        const float cz = g.origin.z + g.spacing * (float(c.z) + 0.5f);
        const int column = std::clamp(int(std::lround((cz - hf.minZ()) / sz)), 0, 8) * 12 +
                           std::clamp(int(std::lround((cx - hf.minX()) / sx)), 0, 11);
        EXPECT_EQ(g.occupancy[g.cellIndex(c.x, c.y, c.z)], column) << x << " " << y << " " << z;
    }
    // A cell holds -1 only if no part of it is above the ground.
    for (uint32_t cz = 0; cz < g.dims.z; ++cz)
        for (uint32_t cy = 0; cy < g.dims.y; ++cy)
            for (uint32_t cx = 0; cx < g.dims.x; ++cx) {
                if (g.occupancy[g.cellIndex(cx, cy, cz)] >= 0) continue;
                for (int s = 0; s < 64; ++s) {
                    const glm::vec3 q = g.origin + g.spacing * (glm::vec3(float(cx), float(cy), float(cz)) +
                                                                glm::vec3(rng.next(), rng.next(), rng.next()));
                    EXPECT_LE(q.y, hf.surfaceHeight(q.x, q.z));
                }
            }
    fs::remove_all(dir);
}

TEST(AdaptiveBake, DryRunEstimatesWithoutWriting) {
    const fs::path dir = tempDir("dry") / "out";
    BakeRequest request{orkhonProject(dir), 0, false, {}};
    const BakeEstimate e = estimateBake(request);
    EXPECT_FALSE(fs::exists(dir));
    ASSERT_EQ(e.volumes.size(), 2u);
    const VolumeEstimate& v = e.volumes[0];
    const ProbeLayout L = placeProbes(request.project.scene.probeVolumes[0],
                                      importDem(request.project.scene.terrain.dem).heightfield);
    EXPECT_EQ(v.probes, L.validCount());
    EXPECT_EQ(v.bytes, L.fileBytes());
    EXPECT_TRUE(v.refines);
    EXPECT_EQ(v.probesMax, L.octree->uniformProbes + L.octree->moved);
    EXPECT_GT(v.seconds, 0.0);
    EXPECT_GT(v.secondsMax, v.seconds);
    EXPECT_EQ(e.volumes[1].probes,
              placeProbes(request.project.scene.probeVolumes[1],
                          importDem(request.project.scene.terrain.dem).heightfield).validCount());
    EXPECT_GT(e.probeRaysPerSecond, 0.0);
    EXPECT_GE(e.seconds, e.cacheSeconds + v.seconds);
}

TEST(BoxGrid, EveryCellPartlyAboveTheGroundNamesAProbe) {
    const DemImportResult dem = importDem((kDems / "bigtujunga_utm11_crop.tif").string());
    const Heightfield& hf = dem.heightfield;
    ProbeVolumeSettings v;
    v.placement = ProbePlacement::Box;
    v.gridDims = {24, 10, 16};
    const ProbeLayout L = placeProbes(v, hf);
    ASSERT_GT(L.borrowedCells, 0u) << "cells straddling the ground with their centre inside";
    size_t straddling = 0;
    Rng rng(11);
    for (uint32_t z = 0; z < L.cellDims[2]; ++z)
        for (uint32_t y = 0; y < L.cellDims[1]; ++y)
            for (uint32_t x = 0; x < L.cellDims[0]; ++x) {
                const size_t c = cellIndex(L, x, y, z);
                const int32_t probe = L.cellProbe[c];
                if (probe >= 0) {
                    // Its own probe, or the first valid one above in its column.
                    ASSERT_TRUE(L.valid[size_t(probe)]);
                    const glm::vec3 p = L.positions[size_t(probe)];
                    const glm::vec3 centre = cellCentre(L, x, y, z);
                    EXPECT_FLOAT_EQ(p.x, centre.x);
                    EXPECT_FLOAT_EQ(p.z, centre.z);
                    EXPECT_GE(p.y, centre.y);
                    straddling += p.y > centre.y;
                    continue;
                }
                // -1: no part above the ground, or nothing valid above it in the box.
                bool validAbove = false;
                for (uint32_t a = y + 1; a < L.cellDims[1]; ++a) {
                    const int32_t q = L.cellProbe[cellIndex(L, x, a, z)];
                    validAbove = validAbove || (q >= 0 && L.valid[size_t(q)]);
                }
                if (!validAbove) continue;
                for (int s = 0; s < 32; ++s) {
                    const glm::vec3 q = L.cellOrigin + L.cellSize * (glm::vec3(float(x), float(y), float(z)) +
                                                                    glm::vec3(rng.next(), rng.next(), rng.next()));
                    EXPECT_LE(q.y, hf.surfaceHeight(q.x, q.z) + 1e-3f) << x << " " << y << " " << z;
                }
            }
    EXPECT_EQ(straddling, L.borrowedCells);
}
