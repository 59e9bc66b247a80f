// A region cut into tiles (docs/farm.md): the windows, the halo rule, a tile's bake against the
// untiled bake of the same terrain along the borders, the skip of an unchanged tile, and the merge.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "BakeJob.h"
#include "ProbeDiagnosticsFile.h"
#include "ReflectionProbeFile.h"
#include "ShProbeFile.h"
#include "TerrainLoading.h"
#include "TileMerge.h"
#include "Tiling.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ProbePlacement.h"
#include "bake/SphericalHarmonics.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

const fs::path kCrop = fs::path(TERRALUX_TEST_DATA) / "dem" / "bigtujunga_utm11_crop.tif";

Heightfield ramp(int w, int d) {
    std::vector<float> h(size_t(w) * d);
    for (int r = 0; r < d; ++r)
        for (int c = 0; c < w; ++c) h[size_t(r) * w + c] = float(100.0 * std::sin(0.3 * c) * std::cos(0.2 * r) + 3.0 * c);
    return Heightfield(w, d, 30.0, 25.0, h);
}

fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("terralux_tiles_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    return dir;
}

// The region the bake tests cut: the crop at 65 x 43 vertices (64 x 42 cells), whose 9 x 7 terrain
// grid puts a probe every 8 x 7 cells, so a 2 x 2 cut's tiles (32 x 21 cells) hold the same probes.
Project regionProject(const fs::path& out) {
    Project p;
    p.scene.terrain.dem = kCrop.string();
    p.scene.terrain.maxResolution = 65;
    p.scene.probeVolumes[0].gridDims = {9, 1, 7};
    p.scene.bake.quality = QualityPreset::Draft;
    p.scene.exportSettings.outDir = out.string();
    return p;
}

// Mean interpolation error of a volume's map over its points within `band` metres of x = bx or
// z = bz (near), and over the others (far).
std::pair<double, double> mapMeans(const fs::path& dir, float bx, float bz, float band) {
    std::vector<uint8_t> bytes;
    const ShProbeGrid g = readShProbeFile(dir / "sh_coeffs" / "probes.shprobe", &bytes);
    const ErrorMap m = readProbeDiagnosticsFile(dir / "sh_coeffs" / "probes.probes.json", g, shProbeDigest(bytes)).errorMap;
    double near = 0.0, far = 0.0;
    size_t nn = 0, nf = 0;
    for (uint32_t k = 0; k < m.nz; ++k)
        for (uint32_t i = 0; i < m.nx; ++i) {
            const float e = m.error[size_t(k) * m.nx + i];
            if (!std::isfinite(e)) continue;
            const float x = m.x0 + float(i) * m.step, z = m.z0 + float(k) * m.step;
            if (std::abs(x - bx) < band || std::abs(z - bz) < band) near += e, ++nn;
            else far += e, ++nf;
        }
    return {nn ? near / double(nn) : 0.0, nf ? far / double(nf) : 0.0};
}

struct Probe {
    glm::vec3 position;
    float irradiance = 0.0f;  // luminance of the upward irradiance
    float se = 0.0f;
};

std::vector<Probe> probesIn(const fs::path& dir) {
    std::vector<uint8_t> bytes;
    const ShProbeGrid g = readShProbeFile(dir / "sh_coeffs" / "probes.shprobe", &bytes);
    const ProbeDiagnostics d = readProbeDiagnosticsFile(dir / "sh_coeffs" / "probes.probes.json", g, shProbeDigest(bytes));
    std::vector<Probe> out;
    for (size_t i = 0; i < g.probes.size(); ++i) {
        sh::ShRgb s;
        s.c = g.probes[i].coeffs;
        const glm::vec3 e = sh::evalIrradiance(s, glm::vec3(0, 1, 0));
        out.push_back({d.positions[i], 0.2126f * e.r + 0.7152f * e.g + 0.0722f * e.b, d.standardError.at(i)});
    }
    return out;
}

}  // namespace

TEST(Tiles, AWindowKeepsItsVerticesAndItsSurfaceToTheBit) {
    const Heightfield region = ramp(41, 33);
    const Heightfield w = region.window(7, 5, 20, 17);
    EXPECT_EQ(w.width(), 20);
    for (int r = 0; r < w.depth(); ++r)
        for (int c = 0; c < w.width(); ++c) {
            ASSERT_EQ(w.vertex(c, r), region.vertex(c + 7, r + 5));
            // Inside the window, where central differences see the same neighbours.
            if (c > 0 && r > 0 && c + 1 < w.width() && r + 1 < w.depth()) {
                ASSERT_EQ(w.vertexNormal(c, r), region.vertexNormal(c + 7, r + 5));
            }
        }
    for (float fx : {0.1f, 0.5f, 0.93f})
        for (float fz : {0.2f, 0.77f}) {
            const float x = w.minX() + fx * (w.maxX() - w.minX()), z = w.minZ() + fz * (w.maxZ() - w.minZ());
            EXPECT_EQ(w.surfaceHeight(x, z), region.surfaceHeight(x, z));
            EXPECT_EQ(w.surfaceNormal(x, z), region.surfaceNormal(x, z));
        }
    // A ray inside the window meets the same triangle in both grids, at the same distance.
    const HeightfieldTracer a(region), b(w);
    const glm::vec3 o(0.5f * (w.minX() + w.maxX()), 600.0f, 0.5f * (w.minZ() + w.maxZ()));
    const glm::vec3 dir = glm::normalize(glm::vec3(0.2f, -1.0f, 0.1f));
    RayHit ha, hb;
    ASSERT_TRUE(a.intersect(o, dir, 1e6f, ha));
    ASSERT_TRUE(b.intersect(o, dir, 1e6f, hb));
    EXPECT_EQ(ha.t, hb.t);
    EXPECT_THROW((void)region.window(30, 0, 12, 5), std::invalid_argument);
}

TEST(Tiles, AWindowReadAloneFromTheDemEqualsTheWholeImportCut) {
    // Never the whole raster: a projected, north-up source is read only in the window; a
    // geographic one is warped only there (a virtual warp over the whole grid, warping the
    // blocks read). The window lies in the whole import's grid and engine space.
    const auto filled = [](const Heightfield& hf, int c, int r) {
        return !hf.nodataMask().empty() && hf.nodataMask()[size_t(r) * size_t(hf.width()) + size_t(c)] != 0;
    };
    for (const char* name : {"bigtujunga_utm11_crop.tif", "n42e001_voids_crop.tif", "rainier_crop.tif"}) {
        const std::string path = (fs::path(TERRALUX_TEST_DATA) / "dem" / name).string();
        const bool projected = std::string(name).find("utm") != std::string::npos;
        const DemImportResult whole = importDem(path);
        const DemGrid grid = demGrid(path);
        EXPECT_TRUE(grid.streamed) << name;
        EXPECT_EQ(grid.width, whole.heightfield.width());
        EXPECT_EQ(grid.depth, whole.heightfield.depth());
        EXPECT_DOUBLE_EQ(grid.cellX, whole.heightfield.cellSizeX());
        EXPECT_DOUBLE_EQ(grid.cellZ, whole.heightfield.cellSizeZ());
        // A projected grid's range is its cells'; a warped one's the source's, which bounds it.
        if (projected) {
            EXPECT_FLOAT_EQ(float(grid.minHeight), whole.heightfield.minHeight());
            EXPECT_FLOAT_EQ(float(grid.maxHeight), whole.heightfield.maxHeight());
        } else {
            EXPECT_LE(float(grid.minHeight), whole.heightfield.minHeight()) << name;
            EXPECT_GE(float(grid.maxHeight), whole.heightfield.maxHeight()) << name;
            EXPECT_LT(whole.heightfield.minHeight() - grid.minHeight, 0.02 * (grid.maxHeight - grid.minHeight)) << name;
        }
        DemImportOptions o;
        o.window = GridWindow{9, 5, 30, 21};
        const DemImportResult part = importDem(path, o);
        EXPECT_TRUE(part.source.windowRead) << name;
        const Heightfield cut = whole.heightfield.window(9, 5, 30, 21);
        ASSERT_EQ(part.heightfield.width(), 30);
        ASSERT_EQ(part.heightfield.depth(), 21);
        EXPECT_EQ(part.heightfield.geo.easting, whole.heightfield.geo.easting);
        EXPECT_EQ(part.heightfield.geo.northing, whole.heightfield.geo.northing);
        // A second window overlapping the first by half: every measured cell the two share is
        // the same to the bit, so tiles meet without a seam.
        o.window = GridWindow{18, 12, 30, 21};
        const DemImportResult other = importDem(path, o);
        const double relief = grid.maxHeight - grid.minHeight;
        double worst = 0.0;
        size_t measured = 0, shared = 0;
        for (int r = 0; r < 21; ++r)
            for (int c = 0; c < 30; ++c) {
                const glm::vec3 a = part.heightfield.vertex(c, r), b = cut.vertex(c, r);
                ASSERT_EQ(a.x, b.x);
                ASSERT_EQ(a.z, b.z);
                if (filled(part.heightfield, c, r)) continue;
                ++measured;
                // The whole import warps in its own chunks: the same cell to the warper's
                // approximation (projected: the same sample).
                if (projected) {
                    ASSERT_EQ(a.y, b.y) << name << " " << c << ", " << r;
                }
                worst = std::max(worst, double(std::fabs(a.y - b.y)));
                const int oc = c + 9 - 18, orow = r + 5 - 12;
                if (oc < 0 || orow < 0 || filled(other.heightfield, oc, orow)) continue;
                ++shared;
                ASSERT_EQ(a.y, other.heightfield.vertex(oc, orow).y) << name << " " << c << ", " << r;
            }
        EXPECT_GT(measured, 300u) << name;
        EXPECT_GT(shared, 100u) << name;
        EXPECT_LT(worst, 0.005 * relief) << name;
        std::printf("%s: window against the whole import, worst |dh| %.3f m of %.0f m relief\n", name, worst, relief);
        o.window = GridWindow{grid.width - 3, 0, 4, 4};
        EXPECT_THROW(importDem(path, o), DemError) << name;
    }
}

TEST(Tiles, CoresCoverTheRegionSharingTheirBordersAndTheHaloFollowsTheRelief) {
    const Heightfield region = ramp(101, 57);
    const TileSpec any = parseTiles("3,2", "0/6", std::nullopt);
    const Halo h = haloFor(gridOf(region), std::nullopt);
    EXPECT_NEAR(h.metres, h.relief * std::sqrt(99.0), 1e-6);
    // sin²(atan(relief / halo)) is the share of an upward receiver's hemisphere the terrain beyond can hold.
    EXPECT_NEAR(std::pow(std::sin(std::atan(h.relief / h.metres)), 2.0), kHaloShare, 1e-12);
    for (int iz = 0; iz < 2; ++iz) {
        int nextCol = 0;
        for (int ix = 0; ix < 3; ++ix) {
            TileSpec t = any;
            t.ix = ix, t.iz = iz, t.haloMetres = 100.0;
            const TileWindow w = tileWindow(gridOf(region), t);
            EXPECT_EQ(w.col0, nextCol) << "tiles share their border column";
            nextCol = w.col0 + w.cols - 1;
            EXPECT_LE(w.tracedCol0, w.col0);
            EXPECT_GE(w.tracedCol0 + w.tracedCols, w.col0 + w.cols);
            EXPECT_EQ(w.col0 - w.tracedCol0, ix == 0 ? 0 : 4);  // ceil(100 m / 30 m)
        }
        EXPECT_EQ(nextCol, region.width() - 1);
    }
    EXPECT_EQ(parseTiles("3,2", "4/6", std::nullopt).ix, 1);
    EXPECT_EQ(parseTiles("3,2", "4/6", std::nullopt).iz, 1);
    EXPECT_THROW(parseTiles("3,2", "6/6", std::nullopt), std::invalid_argument);
    EXPECT_THROW(parseTiles("3,2", "1/4", std::nullopt), std::invalid_argument);
    EXPECT_THROW(parseTiles("3,2", "3,0", std::nullopt), std::invalid_argument);
    EXPECT_THROW(parseTiles("0,2", "0/0", std::nullopt), std::invalid_argument);
    TileSpec tooMany = parseTiles("60,2", "0/120", std::nullopt);
    EXPECT_THROW(tileWindow(gridOf(region), tooMany), std::invalid_argument);
}

TEST(Tiles, TheirBakesMatchTheUntiledBakeAlongTheBordersAndMergeIntoOneScene) {
    const fs::path whole = freshDir("whole"), tiled = freshDir("tiled");
    const BakeOutcome w = runBake(BakeRequest{regionProject(whole), 2, false, {}}, {}, nullptr);
    const std::vector<Probe> reference = probesIn(whole);
    ASSERT_EQ(reference.size(), 63u);

    // The halo is derived (about 10 km here, so each tile traces the whole crop) and then set to
    // 300 m, so that each tile traces a window of its own.
    for (const std::optional<double> halo : {std::optional<double>(), std::optional<double>(300.0)}) {
        fs::remove_all(tiled);
        for (int i = 0; i < 4; ++i) {
            BakeRequest r{regionProject(tiled), 2, false, {}};
            r.tile = parseTiles("2,2", std::to_string(i) + "/4", halo);
            r.project.scene.exportSettings.outDir = (tiled / kTilesFolder / tileName(*r.tile)).string();
            const BakeOutcome o = runBake(r, {}, nullptr);
            EXPECT_EQ(o.report["tile"]["halo"]["derived"].get<bool>(), !halo);
            EXPECT_FALSE(unchangedTile(r) == std::nullopt) << "a tile baked is one left alone";
            r.project.scene.sun.elevationDeg = 20.0;
            EXPECT_EQ(unchangedTile(r), std::nullopt) << "a changed input bakes the tile again";
        }
        // Every probe of every tile sits on a probe of the untiled grid; along the borders (where
        // two tiles hold the same probe) they differ from it by their sampling noise, no more.
        double sum = 0.0, worst = 0.0;
        size_t matched = 0, border = 0;
        // Per border segment: the x border's north and south halves, the z border's west and
        // east halves (the crossing's probe counts in all four).
        struct Segment {
            double sum = 0.0, worst = 0.0;
            size_t n = 0;
        };
        std::map<std::string, Segment> segments;
        for (const auto& e : fs::directory_iterator(tiled / kTilesFolder)) {
            if (!e.is_directory()) continue;  // the region's summary (region.json, region.f32)
            for (const Probe& p : probesIn(e.path())) {
                const Probe* q = nullptr;
                for (const Probe& r : reference)
                    if (glm::distance(r.position, p.position) < 0.05f) q = &r;
                ASSERT_NE(q, nullptr) << "tile probe at " << p.position.x << ", " << p.position.z;
                ++matched;
                const double sigma = std::hypot(p.se, q->se) * q->irradiance;
                const double z = std::abs(p.irradiance - q->irradiance) / sigma;
                const bool onBorder = std::abs(p.position.x - reference[4].position.x) < 0.05f ||
                                      std::abs(p.position.z - reference[27].position.z) < 0.05f;
                if (onBorder) {
                    ++border;
                    sum += z;
                    worst = std::max(worst, z);
                    const float bx = reference[4].position.x, bz = reference[27].position.z;
                    std::vector<std::string> in;
                    if (std::abs(p.position.x - bx) < 0.05f) {
                        if (p.position.z <= bz + 0.05f) in.push_back("x border, north half");
                        if (p.position.z >= bz - 0.05f) in.push_back("x border, south half");
                    }
                    if (std::abs(p.position.z - bz) < 0.05f) {
                        if (p.position.x <= bx + 0.05f) in.push_back("z border, west half");
                        if (p.position.x >= bx - 0.05f) in.push_back("z border, east half");
                    }
                    for (const std::string& k : in) {
                        Segment& g = segments[k];
                        g.sum += z;
                        g.worst = std::max(g.worst, z);
                        ++g.n;
                    }
                }
            }
        }
        EXPECT_EQ(matched, 4u * 5 * 4);
        // The interpolation error along the borders, within one probe spacing of them: the tiles'
        // maps against the untiled bake's over the same band, and against the tiles' interiors.
        const float bx = reference[4].position.x, bz = reference[27].position.z;
        const float band = reference[1].position.x - reference[0].position.x;
        double tilesNear = 0.0, tilesFar = 0.0;
        int maps = 0;
        for (const auto& e : fs::directory_iterator(tiled / kTilesFolder)) {
            if (!e.is_directory()) continue;
            const auto [n, f] = mapMeans(e.path(), bx, bz, band);
            tilesNear += n, tilesFar += f, ++maps;
        }
        tilesNear /= maps, tilesFar /= maps;
        const double wholeNear = mapMeans(whole, bx, bz, band).first;
        std::cout << "interpolation error within " << band << " m of the borders: tiles " << tilesNear
                  << " (their interiors " << tilesFar << "), untiled " << wholeNear << "\n";
        EXPECT_LT(tilesNear, 1.25 * wholeNear);
        EXPECT_EQ(border, 2u * 5 * 2 + 2u * 4 * 2 - 4);
        std::cout << "halo " << (halo ? std::to_string(*halo) + " m" : std::string("derived")) << ": " << border
                  << " border probes, |difference| / its standard error mean " << sum / double(border) << ", max "
                  << worst << "\n";
        EXPECT_EQ(segments.size(), 4u);
        for (const auto& [name, g] : segments) {
            std::cout << "  " << name << ": " << g.n << " probes, mean " << g.sum / double(g.n) << ", max " << g.worst << "\n";
            EXPECT_LT(g.worst, 2.0) << name;
        }
        // Within twice the standard error of their difference, every one (without a halo, the
        // skirt standing in for the terrain beyond: mean 0.74, max 2.9). A probe is seeded by its
        // place, so a tile that traces the whole crop (the derived halo) bakes its border probes
        // as the untiled bake does, to the bit; with 300 m, the cache over the tile's own window
        // is all that differs.
        EXPECT_LT(sum / double(border), 0.5) << "halo " << (halo ? *halo : -1.0);
        EXPECT_LT(worst, 2.0) << "halo " << (halo ? *halo : -1.0);
        if (!halo) {
            EXPECT_EQ(worst, 0.0) << "the same rays over the same terrain and cache";
        }
    }

    // The first tile computed the region's summary, the others read it: a tile baked either way
    // writes the same probes, byte for byte.
    {
        const fs::path folder = tiled / kTilesFolder / "tile_001_000";
        auto bytesOf = [](const fs::path& f) {
            std::ifstream in(f, std::ios::binary);
            return std::string(std::istreambuf_iterator<char>(in), {});
        };
        const std::string read = bytesOf(folder / "sh_coeffs" / "probes.shprobe");
        fs::remove(tiled / kTilesFolder / "region.json");
        fs::remove_all(folder);
        BakeRequest r{regionProject(tiled), 1, false, {}};
        r.tile = parseTiles("2,2", "2/4", std::optional<double>(300.0));
        r.project.scene.exportSettings.outDir = folder.string();
        const BakeOutcome o = runBake(r, {}, nullptr);
        EXPECT_EQ(o.report["tile"]["region_summary"], "computed");
        EXPECT_EQ(bytesOf(folder / "sh_coeffs" / "probes.shprobe"), read);
        EXPECT_TRUE(fs::exists(tiled / kTilesFolder / "region.json"));
        // Keyed by the DEM's modification time in Unix nanoseconds, as the report's inputs say it.
        const nlohmann::json summary = nlohmann::json::parse(bytesOf(tiled / kTilesFolder / "region.json"));
        EXPECT_EQ(summary["key"]["mtime_ns"], o.report["inputs"]["files"]["terrain.dem"]["modified_ns"]);
        EXPECT_GT(summary["key"]["mtime_ns"].get<int64_t>(), 0);
    }

    // The merge lists the four tiles' grids, sorted by file name, and their meshes.
    const MergeOutcome m = mergeTiles(tiled);
    EXPECT_EQ(m.tiles, 4);
    EXPECT_EQ(m.grids, 4u);
    std::ifstream in(tiled / "scene.gltf");
    const nlohmann::json g = nlohmann::json::parse(in);
    const auto& grids = g["scenes"][0]["extensions"]["VULKAN_SCHNEE_engine_properties"]["shProbeGrids"];
    EXPECT_EQ(grids[0]["shProbePath"], "tiles/tile_000_000/sh_coeffs/probes.shprobe");
    EXPECT_EQ(grids[3]["shProbePath"], "tiles/tile_001_001/sh_coeffs/probes.shprobe");
    EXPECT_EQ(g["nodes"].size(), 4u);
    EXPECT_EQ(g["buffers"][2]["uri"], "tiles/tile_001_000/scene.bin");
    // Every extension it declares is one it carries: the tiles' TERRALUX_bake stays in the tiles.
    EXPECT_FALSE(g["scenes"][0]["extensions"].contains("TERRALUX_bake"));
    for (const auto& e : g["extensionsUsed"]) EXPECT_NE(e, "TERRALUX_bake");
    EXPECT_NE(std::find(g["extensionsUsed"].begin(), g["extensionsUsed"].end(), "VULKAN_SCHNEE_engine_properties"),
              g["extensionsUsed"].end());
    EXPECT_TRUE(fs::exists(tiled / "tiles.json"));
    EXPECT_EQ(m.report["volumes"][0]["probes"].get<size_t>(), 80u);

    // A tile missing, or one baked from other inputs, is refused by name.
    fs::rename(tiled / kTilesFolder / "tile_001_000", tiled / "aside");
    try {
        mergeTiles(tiled);
        ADD_FAILURE() << "merged an incomplete set";
    } catch (const ProjectError& e) {
        EXPECT_NE(std::string(e.what()).find("1 of 4 tiles missing: tile_001_000"), std::string::npos) << e.what();
    }
    BakeRequest other{regionProject(tiled), 2, false, {}};
    other.project.scene.sun.elevationDeg = 20.0;
    other.tile = parseTiles("2,2", "2/4", std::optional<double>(300.0));
    other.project.scene.exportSettings.outDir = (tiled / kTilesFolder / tileName(*other.tile)).string();
    runBake(other, {}, nullptr);
    try {
        mergeTiles(tiled);
        ADD_FAILURE() << "merged tiles of different inputs";
    } catch (const ProjectError& e) {
        EXPECT_NE(std::string(e.what()).find("tile_001_000 (sun.elevation_deg"), std::string::npos) << e.what();
    }
    fs::remove_all(whole);
    fs::remove_all(tiled);
}

TEST(Tiles, TheDerivedHaloHoldsEveryProbeOfAMountainTileWithinItsShare) {
    // A corner tile of N42E001 (Pyrenees, 2 800 m of relief) cut 3 x 3: the derived halo (about
    // 28 km) leaves out the terrain beyond it, which the rule says can change an upward receiver's
    // light by at most kHaloShare. The same tile baked again with a halo over the whole region
    // traces the same rays from the same probes: the difference is that terrain's, and nothing else.
    const fs::path dem = fs::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (!fs::exists(dem)) GTEST_SKIP() << "shared DEM N42E001.hgt not present";
    const fs::path dir = freshDir("mountain_halo");
    std::map<bool, std::vector<Probe>> probes;
    double derivedHalo = 0.0, relief = 0.0;
    for (const bool whole : {false, true}) {
        BakeRequest r{Project{}, 2, false, {}};
        r.project.scene.terrain.dem = dem.string();
        r.project.scene.terrain.maxResolution = 301;
        r.project.scene.probeVolumes[0].gridDims = {13, 1, 13};
        r.project.scene.bake.quality = QualityPreset::Draft;
        r.tile = parseTiles("3,3", "0/9", whole ? std::optional<double>(1.0e7) : std::nullopt);
        // The whole halo at the DEM's resolution: the near halo's rule is the next test's.
        r.tile->nearHaloMetres = 1.0e7;
        r.project.scene.exportSettings.outDir = (dir / (whole ? "whole" : "derived") / kTilesFolder / "tile_000_000").string();
        const BakeOutcome o = runBake(r, {}, nullptr);
        const nlohmann::json& halo = o.report["tile"]["halo"];
        const nlohmann::json& traced = o.report["tile"]["traced"];
        const int regionCols = o.report["tile"]["region_grid"][0].get<int>(), regionRows = o.report["tile"]["region_grid"][1].get<int>();
        if (!whole) {
            derivedHalo = halo["metres"].get<double>();
            relief = halo["relief_m"].get<double>();
            // The derived halo leaves terrain out on both axes; the other tile traces all of it.
            EXPECT_LT(traced["cols"].get<int>(), regionCols);
            EXPECT_LT(traced["rows"].get<int>(), regionRows);
        } else {
            EXPECT_EQ(traced["cols"].get<int>(), regionCols);
            EXPECT_EQ(traced["rows"].get<int>(), regionRows);
        }
        probes[whole] = probesIn(r.project.scene.exportSettings.outDir);
    }
    ASSERT_FALSE(probes[false].empty());
    ASSERT_EQ(probes[false].size(), probes[true].size());
    double worst = 0.0, mean = 0.0;
    for (size_t i = 0; i < probes[false].size(); ++i) {
        ASSERT_LT(glm::distance(probes[false][i].position, probes[true][i].position), 0.05f);
        const double d = std::abs(probes[false][i].irradiance - probes[true][i].irradiance) / probes[true][i].irradiance;
        worst = std::max(worst, d);
        mean += d / double(probes[false].size());
    }
    std::cout << "N42E001 corner tile of 3 x 3: relief " << relief << " m, derived halo " << derivedHalo << " m, "
              << probes[false].size() << " probes; upward irradiance against the whole region's: mean "
              << 100.0 * mean << " %, max " << 100.0 * worst << " %\n";
    EXPECT_GT(relief, 2000.0);
    EXPECT_NEAR(derivedHalo, relief * std::sqrt(99.0), 1.0);
    EXPECT_LE(worst, kHaloShare);
    fs::remove_all(dir);
}

TEST(Tiles, TheHaloBeyondTheNearHaloTracedOnTheOverviewHoldsEveryProbeWithinItsShare) {
    // The corner tile of N42E001 at the DEM's resolution cut 3 x 3: the derived near halo (a
    // hundred cells of the region's 1 024-sample overview) is read at the DEM's resolution and the
    // rest of the halo traced on the overview. Baked again with the whole halo at the DEM's
    // resolution, the same probes' upward irradiance may differ by what nearHaloFor's rule allows.
    const fs::path dem = fs::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
    if (!fs::exists(dem)) GTEST_SKIP() << "shared DEM N42E001.hgt not present";
    const fs::path dir = freshDir("near_halo");
    std::map<bool, std::vector<Probe>> probes;
    std::map<bool, nlohmann::json> tile;
    for (const bool full : {false, true}) {
        BakeRequest r{Project{}, 2, false, {}};
        r.project.scene.terrain.dem = dem.string();
        r.project.scene.probeVolumes[0].gridDims = {13, 1, 13};
        r.project.scene.bake.quality = QualityPreset::Draft;
        r.tile = parseTiles("3,3", "0/9", std::nullopt);
        if (full) r.tile->nearHaloMetres = 1.0e7;
        r.project.scene.exportSettings.outDir = (dir / (full ? "full" : "near") / kTilesFolder / "tile_000_000").string();
        const BakeOutcome o = runBake(r, {}, nullptr);
        tile[full] = o.report["tile"];
        probes[full] = probesIn(r.project.scene.exportSettings.outDir);
    }
    const nlohmann::json& near = tile[false];
    const double cell = std::max(near["far_window"]["cell_m"][0].get<double>(), near["far_window"]["cell_m"][1].get<double>());
    // The overview is coarser than the DEM, and the near halo a hundred of its cells.
    EXPECT_GT(near["region_grid"][1].get<int>(), kRegionOverview);
    EXPECT_TRUE(near["near_halo"]["far_from_overview"].get<bool>());
    EXPECT_NEAR(near["near_halo"]["metres"].get<double>(), cell / kHaloShare, 1e-6);
    EXPECT_LT(near["near_halo"]["metres"].get<double>(), near["halo"]["metres"].get<double>());
    // It reads less of the DEM; the other reads the whole halo and traces no overview.
    const auto cells = [](const nlohmann::json& w) { return w["cols"].get<double>() * w["rows"].get<double>(); };
    EXPECT_LT(cells(near["traced"]), 0.6 * cells(tile[true]["traced"]));
    EXPECT_EQ(tile[true]["traced"], tile[true]["halo_window"]);
    EXPECT_FALSE(tile[true].contains("far_window"));
    EXPECT_EQ(near["halo_window"], tile[true]["halo_window"]);
    ASSERT_FALSE(probes[false].empty());
    ASSERT_EQ(probes[false].size(), probes[true].size());
    double worst = 0.0, mean = 0.0, changed = 0.0;
    for (size_t i = 0; i < probes[false].size(); ++i) {
        ASSERT_LT(glm::distance(probes[false][i].position, probes[true][i].position), 0.05f);
        const double d = std::abs(probes[false][i].irradiance - probes[true][i].irradiance) / probes[true][i].irradiance;
        worst = std::max(worst, d);
        mean += d / double(probes[false].size());
        changed += d > 0.0;
    }
    std::cout << "N42E001 corner tile of 3 x 3 at " << near["region_grid"].dump() << ": halo "
              << near["halo"]["metres"].get<double>() << " m, near halo " << near["near_halo"]["metres"].get<double>()
              << " m (overview cell " << cell << " m); DEM cells read " << cells(near["traced"]) << " against "
              << cells(tile[true]["traced"]) << "; " << probes[false].size() << " probes, " << changed
              << " changed; upward irradiance against the whole halo at the DEM's resolution: mean " << 100.0 * mean
              << " %, max " << 100.0 * worst << " %\n";
    // The far ring is traced: some probe sees it.
    EXPECT_GT(changed, 0.0);
    EXPECT_LE(worst, kHaloShare);
    fs::remove_all(dir);
}

TEST(Tiles, ANearHaloReadsLessOfTheDemAndTracesTheRestOnTheOverview) {
    // The committed crop is smaller than the overview's 1 024 samples, so the overview is the grid
    // itself and the ring beyond the near halo keeps its geometry: a near halo of 150 m (5 cells)
    // reads about a third of the halo's cells, traces the rest on the overview, and its probes
    // match the whole halo read at the DEM's resolution within the sampling noise of the difference.
    const fs::path dir = freshDir("near_halo_crop");
    std::map<bool, std::vector<Probe>> probes;
    std::map<bool, nlohmann::json> tile;
    for (const bool full : {false, true}) {
        BakeRequest r{regionProject(dir / (full ? "full" : "near")), 2, false, {}};
        r.tile = parseTiles("2,2", "3/4", std::nullopt);
        r.tile->nearHaloMetres = full ? 1.0e7 : 150.0;
        r.project.scene.exportSettings.outDir = (dir / (full ? "full" : "near") / kTilesFolder / tileName(*r.tile)).string();
        const BakeOutcome o = runBake(r, {}, nullptr);
        tile[full] = o.report["tile"];
        probes[full] = probesIn(r.project.scene.exportSettings.outDir);
        if (!full) {
            // Baked again only for another near halo, or when baked under an earlier contract
            // (which read the whole halo at the DEM's resolution).
            EXPECT_NE(unchangedTile(r), std::nullopt);
            BakeRequest other = r;
            other.tile->nearHaloMetres = 200.0;
            EXPECT_EQ(unchangedTile(other), std::nullopt);
            const fs::path report = fs::path(r.project.scene.exportSettings.outDir) / "bake_report.json";
            nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
            j["tile"].erase("contract");
            std::ofstream(report) << j.dump();
            EXPECT_EQ(unchangedTile(r), std::nullopt);
        }
    }
    const nlohmann::json& near = tile[false];
    EXPECT_TRUE(near["near_halo"]["far_from_overview"].get<bool>());
    EXPECT_FALSE(near["near_halo"]["derived"].get<bool>());
    EXPECT_DOUBLE_EQ(near["near_halo"]["metres"].get<double>(), 150.0);
    EXPECT_FALSE(tile[true]["near_halo"]["far_from_overview"].get<bool>());
    EXPECT_FALSE(tile[true].contains("far_window"));
    // The overview over the whole halo: here the region, at the grid's own cells.
    EXPECT_EQ(near["far_window"]["cols"], near["region_grid"][0]);
    EXPECT_EQ(near["far_window"]["rows"], near["region_grid"][1]);
    const auto cells = [](const nlohmann::json& w) { return w["cols"].get<double>() * w["rows"].get<double>(); };
    EXPECT_LT(cells(near["traced"]), 0.6 * cells(tile[true]["traced"]));
    ASSERT_FALSE(probes[false].empty());
    ASSERT_EQ(probes[false].size(), probes[true].size());
    double mean = 0.0, worst = 0.0, changed = 0.0;
    for (size_t i = 0; i < probes[false].size(); ++i) {
        const Probe& a = probes[false][i];
        const Probe& b = probes[true][i];
        ASSERT_LT(glm::distance(a.position, b.position), 0.05f);
        // The standard error of the difference of two independent estimates.
        const double se = std::hypot(double(a.se) * a.irradiance, double(b.se) * b.irradiance);
        const double ratio = std::abs(double(a.irradiance) - b.irradiance) / se;
        mean += ratio / double(probes[false].size());
        worst = std::max(worst, ratio);
        changed += a.irradiance != b.irradiance;
    }
    std::cout << "near halo 150 m against the whole halo: " << probes[false].size() << " probes, " << changed
              << " changed; |difference| / its standard error mean " << mean << ", max " << worst << "\n";
    EXPECT_GT(changed, 0.0);
    EXPECT_LT(mean, 0.5);
    EXPECT_LT(worst, 2.0);
    fs::remove_all(dir);
}

TEST(Tiles, TheMergeListsEachLightingScenarioInTheOrderOfTheGrids) {
    // Two tiles of the crop with a dusk scenario beside the default: the merged scene's
    // TERRALUX_lighting.scenarios lists, per scenario, every tile's file in the order of the
    // sorted shProbeGrids (the default's are the grids themselves), and tiles.json hashes them.
    const fs::path tiled = freshDir("scenarios");
    for (int i = 0; i < 2; ++i) {
        BakeRequest r{regionProject(tiled), 2, false, {}};
        LightingScenario dusk;
        dusk.name = "dusk";
        dusk.sun = r.project.scene.sun;
        dusk.sky = r.project.scene.sky;
        dusk.sun.elevationDeg = 8.0;
        r.project.scene.scenarios = {dusk};
        r.tile = parseTiles("2,1", std::to_string(i) + "/2", std::optional<double>(300.0));
        r.project.scene.exportSettings.outDir = (tiled / kTilesFolder / tileName(*r.tile)).string();
        runBake(r, {}, nullptr);
    }
    const MergeOutcome m = mergeTiles(tiled);
    EXPECT_EQ(m.grids, 2u);
    std::ifstream in(tiled / "scene.gltf");
    const nlohmann::json g = nlohmann::json::parse(in);
    const auto& ext = g["scenes"][0]["extensions"];
    const auto& grids = ext["VULKAN_SCHNEE_engine_properties"]["shProbeGrids"];
    const auto& scenarios = ext["TERRALUX_lighting"]["scenarios"];
    ASSERT_EQ(scenarios.size(), 2u);
    EXPECT_EQ(scenarios[0]["name"], "default");
    EXPECT_EQ(scenarios[1]["name"], "dusk");
    ASSERT_EQ(scenarios[1]["shProbePaths"].size(), grids.size());
    for (size_t k = 0; k < grids.size(); ++k) {
        EXPECT_EQ(scenarios[0]["shProbePaths"][k], grids[k]["shProbePath"]);
        const std::string dusk = scenarios[1]["shProbePaths"][k].get<std::string>();
        const std::string tile = grids[k]["shProbePath"].get<std::string>().substr(0, std::string("tiles/tile_000_000/").size());
        EXPECT_EQ(dusk, tile + "scenarios/probes.dusk.shprobe");
        EXPECT_TRUE(fs::exists(tiled / dusk)) << dusk;
    }
    std::ifstream indexIn(tiled / "tiles.json");
    const nlohmann::json index = nlohmann::json::parse(indexIn);
    size_t hashed = 0;
    for (const auto& t : index["tiles"])
        for (const auto& f : t["files"]) hashed += f["path"].get<std::string>().find("scenarios/") != std::string::npos;
    EXPECT_EQ(hashed, 2u);
    fs::remove_all(tiled);
}

TEST(Tiles, TheMergeListsEveryTilesReflectionProbes) {
    // Two tiles with a 6 x 3 reflection grid for the region: each tile bakes its share over its own
    // footprint, and the merged scene's TERRALUX_lighting.reflection_probes lists both sets (their
    // files through the tile's folder, each set's probes inside its tile), sums the probes and
    // keeps what the tiles share; tiles.json hashes the files; the report sums the probes. The
    // west tile leaves the probes on the border the two share to the east one, so the sets hold
    // every probe once and span the region from edge to edge.
    const fs::path tiled = freshDir("reflections");
    size_t baked = 0;
    for (int i = 0; i < 2; ++i) {
        BakeRequest r{regionProject(tiled), 2, false, {}};
        ReflectionProbeSettings& rp = r.project.scene.reflectionProbes;
        rp.enabled = true;
        rp.gridDims = {6, 3};
        rp.resolution = 8;
        rp.rayCount = 2;
        r.tile = parseTiles("2,1", std::to_string(i) + "/2", std::optional<double>(300.0));
        r.project.scene.exportSettings.outDir = (tiled / kTilesFolder / tileName(*r.tile)).string();
        const BakeOutcome o = runBake(r, {}, nullptr);
        baked += o.report["reflection_probes"]["probes"].get<size_t>();
    }
    const MergeOutcome m = mergeTiles(tiled);
    std::ifstream in(tiled / "scene.gltf");
    const nlohmann::json g = nlohmann::json::parse(in);
    const nlohmann::json& rp = g["scenes"][0]["extensions"]["TERRALUX_lighting"]["reflection_probes"];
    ASSERT_TRUE(rp.contains("sets")) << rp.dump();
    EXPECT_FALSE(rp.contains("uri"));
    EXPECT_EQ(rp["probes"].get<size_t>(), baked);
    EXPECT_EQ(rp["encoding"], "cubemap");
    EXPECT_EQ(rp["face_size"], 8);
    ASSERT_EQ(rp["sets"].size(), 2u);
    std::ifstream indexIn(tiled / "tiles.json");
    const nlohmann::json index = nlohmann::json::parse(indexIn);
    for (size_t k = 0; k < 2; ++k) {
        const nlohmann::json& set = rp["sets"][k];
        const std::string name = k == 0 ? "tile_000_000" : "tile_000_001";
        EXPECT_EQ(set["tile"], name);
        EXPECT_EQ(set["uri"], "tiles/" + name + "/reflection/probes.rprobe");
        for (const char* key : {"uri", "simvx_desktop_uri", "simvx_wire_uri"})
            EXPECT_TRUE(fs::exists(tiled / set[key].get<std::string>())) << set[key];
        const ReflectionProbeSet probes = readReflectionProbeFile(tiled / set["uri"].get<std::string>());
        EXPECT_EQ(probes.probes.size(), set["probes"].get<size_t>());
        const nlohmann::json& t = index["tiles"][k];
        ASSERT_EQ(t["name"], name);
        const float x0 = t["bounds_m"]["min"][0], x1 = t["bounds_m"]["max"][0];
        for (const ReflectionProbe& p : probes.probes) {
            EXPECT_GE(p.position.x, x0 - 1e-3f) << name;
            EXPECT_LE(p.position.x, x1 + 1e-3f) << name;
        }
        bool hashed = false;
        for (const auto& f : t["files"]) hashed |= f["path"] == set["uri"];
        EXPECT_TRUE(hashed) << t.dump();
    }
    EXPECT_EQ(m.report["reflection_probes"]["probes"].get<size_t>(), baked);
    {
        std::vector<glm::vec3> all;
        std::vector<size_t> counts;
        for (size_t k = 0; k < 2; ++k) {
            const ReflectionProbeSet set = readReflectionProbeFile(tiled / rp["sets"][k]["uri"].get<std::string>());
            counts.push_back(set.probes.size());
            for (const ReflectionProbe& p : set.probes) all.push_back(p.position);
        }
        EXPECT_EQ(counts[0] + 3, counts[1]) << "the west tile keeps one column fewer";
        for (size_t a = 0; a < all.size(); ++a)
            for (size_t b = a + 1; b < all.size(); ++b)
                EXPECT_GT(glm::length(glm::vec2(all[a].x - all[b].x, all[a].z - all[b].z)), 1.0f) << a << " " << b;
        float lo = INFINITY, hi = -INFINITY;
        for (const glm::vec3& p : all) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
        EXPECT_NEAR(lo, index["tiles"][0]["bounds_m"]["min"][0].get<float>(), 1e-2f);
        EXPECT_NEAR(hi, index["tiles"][1]["bounds_m"]["max"][0].get<float>(), 1e-2f);
    }
    // A tile baked without them cannot join: the merge names how many lack them.
    {
        const fs::path gltf = tiled / kTilesFolder / "tile_000_001" / "scene.gltf";
        std::ifstream tileIn(gltf);
        nlohmann::json tile = nlohmann::json::parse(tileIn);
        tileIn.close();
        tile["scenes"][0]["extensions"]["TERRALUX_lighting"].erase("reflection_probes");
        std::ofstream(gltf) << tile.dump();
    }
    try {
        mergeTiles(tiled);
        ADD_FAILURE() << "merged tiles of which one has no reflection probes";
    } catch (const ProjectError& e) {
        EXPECT_NE(std::string(e.what()).find("1 of 2 tiles without reflection probes, which tile_000_000 has: tile_000_001; bake them again"),
                  std::string::npos) << e.what();
    }
    // A scene.gltf without its scene is refused, naming the file.
    std::ofstream(tiled / kTilesFolder / "tile_000_001" / "scene.gltf") << R"({"asset": {"version": "2.0"}, "scenes": []})";
    try {
        mergeTiles(tiled);
        ADD_FAILURE() << "merged a tile whose glTF has no scene";
    } catch (const ProjectError& e) {
        EXPECT_NE(std::string(e.what()).find("tile_000_001/scene.gltf: has no scene 0"), std::string::npos) << e.what();
    }
    fs::remove_all(tiled);
}

TEST(Tiles, ASuggestionMeasuredOnATileNamesTheRegionsGrid) {
    // The crop's 9 x 7 grid errs over 10 % on average, so a tile's bake measures a denser grid of
    // its own share, within its share of the 4 096 probes a terrain grid holds; the suggestion it
    // prints asks the project for the region's grid_dims whose share is exactly the grid the tile
    // measured (it named the tile's own, 71 x 57, which the region would hold four times).
    const fs::path tiled = freshDir("suggestion");
    BakeRequest r{regionProject(tiled), 2, false, {}};
    r.tile = parseTiles("2,2", "0/4", std::optional<double>(300.0));
    r.project.scene.exportSettings.outDir = (tiled / kTilesFolder / tileName(*r.tile)).string();
    const BakeOutcome o = runBake(r, {}, nullptr);
    const nlohmann::json& s = o.report["volumes"][0]["suggestions"];
    ASSERT_FALSE(s.empty()) << o.report["volumes"][0].dump();
    const std::string set = s[0]["set"][0].get<std::string>(), tileSet = s[0]["tile_set"][0].get<std::string>();
    std::cout << "suggestion: " << set << " (this tile: " << tileSet << ")\n";
    int nx = 0, nz = 0, tx = 0, tz = 0;
    ASSERT_EQ(std::sscanf(set.c_str(), "probe_volumes[0].grid_dims=%d,%d", &nx, &nz), 2) << set;
    ASSERT_EQ(std::sscanf(tileSet.c_str(), "probe_volumes[0].grid_dims=%d,%d", &tx, &tz), 2) << tileSet;
    EXPECT_GT(nx, tx);
    EXPECT_GT(nz, tz);
    // Within what a terrain grid may hold: the tile searched within its share of the limit.
    EXPECT_LE(nx * nz, kMaxTerrainGridProbes);
    // The region's grid applied to the project gives this tile the grid it measured.
    Project region = regionProject(tiled);
    region.scene.probeVolumes[0].gridDims = {nx, 1, nz};
    const TileWindow w = tileWindow(loadProjectGrid(regionProject(tiled)), *r.tile);
    scaleSceneToTile(region.scene, w);
    EXPECT_EQ(region.scene.probeVolumes[0].gridDims[0], tx);
    EXPECT_EQ(region.scene.probeVolumes[0].gridDims[2], tz);
    // And it delivers: the tile baked again with the region's grid in the project measures, on
    // its own error map, the error the suggestion predicted, within 1.5x (as an untiled
    // suggestion must, BakeSuggestions.TheSuggestedGridDeliversThePredictedError).
    const double predictedMean = s[0]["predicted_error"]["mean"].get<double>();
    const double predictedP95 = s[0]["predicted_error"]["p95"].get<double>();
    BakeRequest again = r;
    again.project.scene.probeVolumes[0].gridDims = {nx, 1, nz};
    again.project.scene.exportSettings.outDir = (tiled / "suggested" / kTilesFolder / tileName(*r.tile)).string();
    const BakeOutcome b = runBake(again, {}, nullptr);
    const nlohmann::json& v = b.report["volumes"][0];
    EXPECT_EQ(v["probes"].get<int>(), tx * tz) << "the tile's share of the region's grid, as measured";
    const double mean = v["error_map"]["mean"].get<double>(), p95 = v["error_map"]["p95"].get<double>();
    std::printf("tile's suggestion predicted %.2f / %.2f %%, the region's grid baked on the tile %.2f / %.2f %%\n",
                100 * predictedMean, 100 * predictedP95, 100 * mean, 100 * p95);
    EXPECT_LT(mean, 1.5 * predictedMean);
    EXPECT_GT(mean, predictedMean / 1.5);
    EXPECT_LT(p95, 1.5 * predictedP95);
    EXPECT_GT(p95, predictedP95 / 1.5);
    fs::remove_all(tiled);
}
