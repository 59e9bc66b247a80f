// Probe diagnostics (validity and interpolation-error views, leaf overlay): what describeProbes
// takes from a layout, the interpolation-error map over the ground, and the sidecar file that
// carries both beside the .shprobe.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "DemImport.h"
#include "ProbeDiagnosticsFile.h"
#include "TestScenes.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ProbeDiagnostics.h"

using namespace terralux;
using terralux::test::fieldBaker;
using terralux::test::flat;
namespace fs = std::filesystem;

namespace {

// A .shprobe grid of `count` probes over `dims` cells (the sidecar is checked against it).
ShProbeGrid gridOf(size_t count, glm::uvec3 dims) {
    ShProbeGrid g;
    g.dims = dims;
    g.probes.resize(count);
    for (size_t i = 0; i < count; ++i) g.probes[i].coeffs[0] = glm::vec3(float(i));
    g.occupancy.assign(size_t(dims.x) * dims.y * dims.z, count ? 0 : -1);
    return g;
}

uint64_t digestOf(const ShProbeGrid& g) { return shProbeDigest(encodeShProbe(g)); }

const fs::path kDems = fs::path(TERRALUX_TEST_DATA) / "dem";



std::vector<sh::ShRgb> bakeField(const ProbeLayout& L, const std::function<float(const glm::vec3&)>& f) {
    return fieldBaker(f)(L.positions, std::vector<uint64_t>(L.positions.size(), 0)).sh;
}

ProbeVolumeSettings terrainGrid(int n, double offset = 5.0) {
    ProbeVolumeSettings v;
    v.gridDims = {n, 1, n};
    v.heightOffset = offset;
    return v;
}

}  // namespace

TEST(DescribeProbes, AdaptiveLayoutGivesFileOrderMovesAndLeaves) {
    const DemImportResult dem = importDem((kDems / "bigtujunga_utm11_crop.tif").string());
    const Heightfield& hf = dem.heightfield;
    ProbeVolumeSettings v;
    v.placement = ProbePlacement::Adaptive;
    v.adaptive.maxMoveShare = 0.5;
    const ProbeLayout L = placeProbes(v, hf);
    // Standard errors by placed probe: the file order keeps those of the valid ones.
    std::vector<float> se(L.positions.size());
    for (size_t i = 0; i < se.size(); ++i) se[i] = float(i);
    const ProbeDiagnostics d = describeProbes(L, se);
    ASSERT_GT(L.octree->moved, 0u) << "the fixture must exercise moved probes";
    ASSERT_EQ(d.standardError.size(), L.validCount());
    for (size_t i = 0, k = 0; i < L.positions.size(); ++i)
        if (L.valid[i]) {
            EXPECT_EQ(d.standardError[k++], float(i));
        }
    EXPECT_LT(L.validCount(), L.positions.size()) << "the fixture must leave some leaves without a probe";
    // One entry per .shprobe record, in record order: the valid probes in placement order.
    ASSERT_EQ(d.positions.size(), L.validCount());
    ASSERT_EQ(d.moved.size(), L.validCount());
    size_t k = 0, moved = 0;
    for (size_t i = 0; i < L.positions.size(); ++i) {
        if (!L.valid[i]) continue;
        EXPECT_EQ(d.positions[k], L.positions[i]);
        EXPECT_EQ(d.moved[k] == 1, L.octree->probe[i] == LeafProbe::Moved) << "probe " << k;
        moved += d.moved[k];
        ++k;
    }
    EXPECT_EQ(moved, L.octree->moved);
    EXPECT_TRUE(d.rejected.empty()) << "adaptive leaves never keep a probe inside the terrain";
    // Every leaf, in metres; each probe lies in its own leaf (moved ones inside it too).
    ASSERT_EQ(d.leaves.size(), L.octree->leaves.size());
    for (size_t i = 0; i < L.positions.size(); ++i) {
        const glm::vec4& leaf = d.leaves[i];
        EXPECT_FLOAT_EQ(leaf.w, L.cellSize * float(L.octree->leaves[i].edge()));
        if (!L.valid[i]) continue;
        const glm::vec3 p = L.positions[i];
        for (int a = 0; a < 3; ++a) {
            EXPECT_GE(p[a], leaf[a] - 1e-3f) << "probe of leaf " << i;
            EXPECT_LE(p[a], leaf[a] + leaf.w + 1e-3f) << "probe of leaf " << i;
        }
    }
}

TEST(DescribeProbes, TerrainGridProbesBelowTheSurfaceAreRejected) {
    const Heightfield hf = flat(33, 10.0, 100.0f);
    const ProbeLayout L = placeProbes(terrainGrid(4, -2.0), hf);
    const ProbeDiagnostics d = describeProbes(L);
    EXPECT_TRUE(d.positions.empty());
    EXPECT_EQ(d.rejected.size(), 16u);
    EXPECT_TRUE(d.leaves.empty());
    const ProbeDiagnostics ok = describeProbes(placeProbes(terrainGrid(4), hf));
    EXPECT_EQ(ok.positions.size(), 16u);
    EXPECT_TRUE(ok.rejected.empty());
    for (uint8_t m : ok.moved) EXPECT_EQ(m, 0);
}

TEST(ErrorMap, CoversTheFootprintTheGridAndTerrainShare) {
    const Heightfield hf = flat(101, 10.0, 0.0f);  // 1000 m square around the origin
    const ProbeLayout L = placeProbes(terrainGrid(8), hf);
    const ErrorMap m = errorMapGrid(L, hf, 64, 5.0f);
    EXPECT_EQ(m.nx, 64u);
    EXPECT_EQ(m.nz, 64u);
    EXPECT_EQ(m.error.size(), 64u * 64u);
    EXPECT_FLOAT_EQ(m.height, 5.0f);
    // Point centres of 64 cells across the shared footprint.
    const float x0 = std::max(L.cellOrigin.x, hf.minX());
    EXPECT_NEAR(m.x0, x0 + 0.5f * m.step, 1e-3f);
    EXPECT_NEAR(m.x0 + m.step * 63.0f, std::min(L.cellOrigin.x + L.cellSize * float(L.cellDims[0]), hf.maxX()) - 0.5f * m.step, 1e-2f);
    EXPECT_TRUE(errorMapGrid(L, hf, 0, 5.0f).empty());

    // A box grid over half the terrain: a map over that half, square spacing, fewer rows.
    ProbeVolumeSettings box;
    box.placement = ProbePlacement::Box;
    box.gridDims = {10, 2, 5};
    box.spacing = glm::vec3(100.0f);
    box.origin = glm::vec3(-500.0f, 10.0f, -500.0f);
    const ProbeLayout B = placeProbes(box, hf);
    const ErrorMap half = errorMapGrid(B, hf, 40, 1.0f);
    EXPECT_EQ(half.nx, 40u);
    EXPECT_EQ(half.nz, 20u);
    // Entirely beside the terrain: no map.
    box.origin = glm::vec3(5000.0f, 10.0f, 0.0f);
    EXPECT_TRUE(errorMapGrid(placeProbes(box, hf), hf, 40, 1.0f).empty());
}

TEST(ErrorMap, ZeroForUniformLightAndLargestWhereLightChangesFastest) {
    const Heightfield hf = flat(101, 10.0, 0.0f);
    const ProbeLayout L = placeProbes(terrainGrid(8), hf);
    auto constant = [](const glm::vec3&) { return 1.0f; };
    const ErrorMap zero = measureErrorMap(L, bakeField(L, constant), hf, fieldBaker(constant), 32, 5.0f, 1);
    const ErrorMapStats z = errorMapStats(zero);
    EXPECT_EQ(z.points, 32u * 32u);
    EXPECT_LT(z.max, 1e-5);

    // A narrow bright spot midway between four probes (1000 m / 7 apart): the grid cannot
    // represent it, and the map says where.
    const float s = 1000.0f / 7.0f;
    const glm::vec3 spot(-500.0f + 4.5f * s, 5.0f, -500.0f + 2.5f * s);
    auto field = [spot](const glm::vec3& p) {
        const glm::vec3 d = (p - spot) / 40.0f;
        return 1.0f + 4.0f * std::exp(-glm::dot(d, d));
    };
    const std::vector<sh::ShRgb> probes = bakeField(L, field);
    const ErrorMap m = measureErrorMap(L, probes, hf, fieldBaker(field), 32, 5.0f, 1);
    size_t worst = 0;
    for (size_t i = 0; i < m.error.size(); ++i)
        if (m.error[i] > m.error[worst]) worst = i;
    const glm::vec2 at(m.x0 + m.step * float(worst % m.nx), m.z0 + m.step * float(worst / m.nx));
    EXPECT_LT(glm::length(at - glm::vec2(spot.x, spot.z)), 1.5f * m.step) << "worst point " << at.x << ", " << at.y;
    EXPECT_GT(m.error[worst], 0.5f);
    // Each value is docs/lighting.md's interpolation error at that point.
    for (size_t i = 0; i < m.error.size(); i += 97) {
        const glm::vec3 p(m.x0 + m.step * float(i % m.nx), 5.0f, m.z0 + m.step * float(i / m.nx));
        sh::ShRgb interpolated;
        ASSERT_TRUE(interpolateProbes(L, probes, p, interpolated));
        EXPECT_NEAR(m.error[i], relativeIrradianceError(interpolated, sh::projectConstant(glm::vec3(field(p)))), 1e-5f);
    }
}

TEST(ErrorMap, FinerTerrainGridsInterpolateBetterOnARealDem) {
    const DemImportResult dem = importDem((kDems / "bigtujunga_utm11_crop.tif").string());
    const Heightfield& hf = dem.heightfield;
    const HeightfieldTracer tracer(hf);
    const BakeLighting lighting = test::skyAndSun(tracer);
    const IrradianceCache cache(lighting, 48, 32, 2, 0, {});
    const ProbeBaker baker = seededBaker(lighting, &cache, 1, 256, 5, {});
    double previous = INFINITY;
    for (int n : {4, 16, 48}) {
        const ProbeLayout L = placeProbes(terrainGrid(n), hf);
        const ProbeBake bake = baker(L.positions, std::vector<uint64_t>(L.positions.size(), 0));
        const ErrorMapStats s = errorMapStats(measureErrorMap(L, bake.sh, hf, baker, 24, 5.0f, 3));
        EXPECT_EQ(s.uncovered, 0u);
        EXPECT_LT(s.mean, previous) << n << " x " << n << " probes";
        std::cout << n << " x " << n << " terrain grid: ground interpolation error mean " << 100 * s.mean
                  << " %, p95 " << 100 * s.p95 << " %\n";
        previous = s.mean;
    }
}

TEST(ProbeDiagnosticsFile, ReadsBackWhatItWrites) {
    ProbeDiagnostics d;
    d.positions = {{1.0f, 2.0f, 3.0f}, {-4.5f, 6.25f, 1000.125f}, {0.0f, 0.0f, 0.0f}};
    d.moved = {0, 1, 0};
    d.rejected = {{7.0f, -8.0f, 9.0f}};
    d.leaves = {{0.0f, 0.0f, 0.0f, 30.0f}, {30.0f, 0.0f, 0.0f, 60.0f}};
    d.errorMap.nx = 3;
    d.errorMap.nz = 2;
    d.errorMap.x0 = -10.0f;
    d.errorMap.z0 = 20.0f;
    d.errorMap.step = 2.5f;
    d.errorMap.height = 5.0f;
    d.errorMap.error = {0.0f, 0.125f, NAN, 0.5f, 2.0f, 0.03125f};
    const ShProbeGrid grid = gridOf(3, {4, 2, 3});
    const std::string text = encodeProbeDiagnostics(d, "valley", grid);
    const ProbeDiagnostics back = decodeProbeDiagnostics(text, "valley.probes.json", grid, digestOf(grid));
    EXPECT_EQ(back.positions, d.positions);
    EXPECT_EQ(back.moved, d.moved);
    EXPECT_EQ(back.rejected, d.rejected);
    EXPECT_EQ(back.leaves, d.leaves);
    EXPECT_EQ(back.errorMap.nx, 3u);
    EXPECT_EQ(back.errorMap.nz, 2u);
    EXPECT_FLOAT_EQ(back.errorMap.step, 2.5f);
    EXPECT_FLOAT_EQ(back.errorMap.height, 5.0f);
    for (size_t i = 0; i < 6; ++i) {
        if (std::isnan(d.errorMap.error[i])) {
            EXPECT_TRUE(std::isnan(back.errorMap.error[i]));
        } else {
            EXPECT_FLOAT_EQ(back.errorMap.error[i], d.errorMap.error[i]);
        }
    }

    // The standard errors are optional: absent, none come back; present, each does.
    EXPECT_TRUE(back.standardError.empty());
    EXPECT_EQ(text.find("standard_error"), std::string::npos);
    d.standardError = {0.0125f, 0.5f, 0.0f};
    const ProbeDiagnostics withSe =
        decodeProbeDiagnostics(encodeProbeDiagnostics(d, "valley", grid), "valley.probes.json", grid, digestOf(grid));
    EXPECT_EQ(withSe.standardError, d.standardError);
    d.standardError.clear();

    const fs::path file = fs::temp_directory_path() / probeDiagnosticsFileName("terralux_diag_test");
    EXPECT_EQ(file.filename(), "terralux_diag_test.probes.json");
    std::ofstream(file) << text;
    EXPECT_EQ(readProbeDiagnosticsFile(file, grid, digestOf(grid)).moved, d.moved);
    // Short decimals: millimetres and millionths, not binary noise.
    EXPECT_NE(text.find("[1.0,2.0,3.0,-4.5,6.25,1000.125,0.0,0.0,0.0]"), std::string::npos) << text;
    fs::remove(file);
}

TEST(ProbeDiagnosticsFile, RejectsWhatDoesNotBelongToTheShProbe) {
    ProbeDiagnostics d;
    d.positions = {{1.0f, 2.0f, 3.0f}, {4.0f, 5.0f, 6.0f}};
    d.moved = {0, 1};
    d.errorMap.nx = 2;
    d.errorMap.nz = 1;
    d.errorMap.error = {0.1f, 0.2f};
    const ShProbeGrid grid = gridOf(2, {2, 1, 1});
    const std::string good = encodeProbeDiagnostics(d, "v", grid);
    auto error = [&](const std::string& text, size_t count = 2, glm::uvec3 gd = glm::uvec3(2, 1, 1),
                     std::optional<uint64_t> digest = std::nullopt) {
        try {
            const ShProbeGrid g = gridOf(count, gd);
            decodeProbeDiagnostics(text, "v.probes.json", g, digest ? *digest : digestOf(grid));
        } catch (const ProbeDiagnosticsError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    auto edited = [&](const std::string& key, const nlohmann::json& value) {
        nlohmann::json j = nlohmann::json::parse(good);
        if (key.rfind("error_map.", 0) == 0)
            j["error_map"][key.substr(10)] = value;
        else
            j[key] = value;
        return j.dump();
    };
    EXPECT_EQ(error(good), "accepted");
    EXPECT_EQ(error("{").rfind("v.probes.json: not JSON", 0), 0u) << error("{");
    EXPECT_EQ(error(good, 3), "v.probes.json: probe_count 2 does not match the .shprobe's 3 probes (a sidecar of another bake)");
    EXPECT_EQ(error(good, 2, {2, 2, 1}), "v.probes.json: grid_dims [2,1,1] do not match the .shprobe's [2,2,1] (a sidecar of another bake)");
    // Same layout, other coefficients (another bake of the same grid): the digest tells.
    ShProbeGrid other = grid;
    other.probes[1].coeffs[4] = glm::vec3(0.5f);
    const std::string otherDigest = error(good, 2, {2, 1, 1}, digestOf(other));
    EXPECT_EQ(otherDigest.rfind("v.probes.json: shprobe_fnv1a64 \"", 0), 0u) << otherDigest;
    EXPECT_NE(otherDigest.find("does not match the .shprobe's"), std::string::npos) << otherDigest;
    EXPECT_EQ(error(edited("format", "other")), "v.probes.json: format is \"other\", expected \"terralux-probe-diagnostics\"");
    EXPECT_EQ(error(edited("version", 2)), "v.probes.json: version 2 is not supported (this build reads 1)");
    EXPECT_EQ(error(edited("positions", {1, 2})), "v.probes.json: 'positions' must hold a multiple of 3 numbers (holds 2)");
    EXPECT_EQ(error(edited("moved", {5})), "v.probes.json: 'moved' holds 5, not a probe index below 2");
    EXPECT_EQ(error(edited("standard_error", {0.1})), "v.probes.json: standard_error holds 1 values, expected 2");
    EXPECT_EQ(error(edited("standard_error", {0.1, -1})), "v.probes.json: standard_error holds -1.000000, must be >= 0");
    EXPECT_EQ(error(edited("leaves", {0, 0, 0, 0})), "v.probes.json: leaf 0 has edge 0.000000, must be > 0");
    EXPECT_EQ(error(edited("error_map.error", {0.1})), "v.probes.json: error_map: error holds 1 values, size [2,1] needs 2");
    EXPECT_EQ(error(edited("error_map.error", {0.1, -0.5})), "v.probes.json: error_map: error holds -0.500000, must be >= 0");
    EXPECT_EQ(error(edited("error_map.step", 0)), "v.probes.json: error_map: step 0 must be a number >= 0.001 (m)");
    EXPECT_EQ(error(edited("error_map.step", 1e-50)), "v.probes.json: error_map: step 1e-50 must be a number >= 0.001 (m)");
    EXPECT_EQ(error(edited("positions", {1, 2, 1e300, 4, 5, 6})), "v.probes.json: 'positions' holds 1e+300, not a finite number");
    EXPECT_EQ(error(edited("error_map.error", {0.1, "x"})), "v.probes.json: error_map: 'error' holds \"x\", not a finite number");
    nlohmann::json missing = nlohmann::json::parse(good);
    missing.erase("leaves");
    EXPECT_EQ(error(missing.dump()), "v.probes.json: missing 'leaves'");
    nlohmann::json noStep = nlohmann::json::parse(good);
    noStep["error_map"].erase("step");
    EXPECT_EQ(error(noStep.dump()), "v.probes.json: error_map: missing 'step'");
    EXPECT_EQ(error(edited("error_map", 3)), "v.probes.json: 'error_map' must be an object, not 3");
    EXPECT_EQ(error(edited("error_map.origin", {1, 2, 3, 4})),
              "v.probes.json: error_map: size [2,1] and origin [1,2,3,4] must be 2 numbers each");
    try {
        readProbeDiagnosticsFile("/nonexistent/v.probes.json", grid, digestOf(grid));
        ADD_FAILURE() << "a missing file was read";
    } catch (const ProbeDiagnosticsError& e) {
        EXPECT_STREQ(e.what(), "/nonexistent/v.probes.json: cannot open (No such file or directory)");
    }
    // FNV-1a 64 of "a" (the published test vector).
    const uint8_t a = 'a';
    EXPECT_EQ(shProbeDigest(std::span<const uint8_t>(&a, 1)), 0xaf63dc4c8601ec8cull);
}
