// Terrain albedo: the sRGB decoding, the ramp, maps draped over a DEM in its own CRS and in a
// geographic one, partial and missing overlap, and the bake's bounce light from a varying albedo.

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstdint>
#include <numbers>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>

#include <unistd.h>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>

#include "AlbedoImport.h"
#include "BakeJob.h"
#include "DemImport.h"
#include "Project.h"
#include "ShaderMath.h"
#include "TerrainLoading.h"
#include "TestScenes.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "terrain/SurfaceAlbedo.h"

namespace fs = std::filesystem;
using namespace terralux;

namespace {

const fs::path kData = fs::path(TERRALUX_TEST_DATA) / "dem";
const std::string kDem = (kData / "bigtujunga_utm11_crop.tif").string();
const std::string kUtmMap = (kData / "albedo_utm11.tif").string();
const std::string kGeoMap = (kData / "albedo_wgs84_rgba16.tif").string();

// The maps' colour bands (tests/data/dem/SOURCES.md): upper elevation bound and 8-bit sRGB.
struct Band {
    float below;
    std::array<int, 3> srgb;
};
constexpr Band kBands[] = {{850, {34, 102, 51}}, {1100, {153, 119, 68}}, {1350, {128, 128, 140}}, {1e9f, {245, 245, 250}}};

int bandOf(float elevation) {
    int b = 0;
    while (elevation >= kBands[b].below) ++b;
    return b;
}

glm::vec3 linearOf(int band) {
    const auto& c = kBands[band].srgb;
    return {srgbToLinear(c[0] / 255.0f), srgbToLinear(c[1] / 255.0f), srgbToLinear(c[2] / 255.0f)};
}

// Every vertex whose neighbours within `ring` cells share its band must have that band's colour
// exactly (bilinear of equal texels); returns how many were checked.
size_t checkBands(const Heightfield& hf, const SurfaceAlbedo& a, int ring) {
    size_t checked = 0;
    for (int r = ring; r < hf.depth() - ring; ++r)
        for (int c = ring; c < hf.width() - ring; ++c) {
            const int band = bandOf(hf.at(c, r));
            bool uniform = true;
            for (int dr = -ring; dr <= ring && uniform; ++dr)
                for (int dc = -ring; dc <= ring && uniform; ++dc) uniform = bandOf(hf.at(c + dc, r + dr)) == band;
            if (!uniform) continue;
            const glm::vec3 got = a.at(hf, hf.xOf(c), hf.zOf(r)), want = linearOf(band);
            for (int k = 0; k < 3; ++k)
                EXPECT_NEAR(got[k], want[k], 1e-5f) << "vertex (" << c << ", " << r << ") at " << hf.at(c, r) << " m";
            ++checked;
        }
    return checked;
}

// A colour as the field stores it: its nearest 8-bit sRGB code, decoded.
glm::vec3 stored(const glm::vec3& f) {
    return {linearOfSrgb8(srgb8(f.x)), linearOfSrgb8(srgb8(f.y)), linearOfSrgb8(srgb8(f.z))};
}
bool isFallback(const glm::vec3& v, const glm::vec3& f) { return v == stored(f); }
std::vector<glm::vec3> texels(const SurfaceAlbedo& a) {
    std::vector<glm::vec3> out;
    for (size_t i = 0; i < a.texels(); ++i) out.push_back(a.texel(i));
    return out;
}

// A fallback no map holds.
const glm::vec3 kMagenta(1.0f, 0.0f, 1.0f);

// Drapes `map` over `hf`, which it covers with room to spare: the field is width x height and
// holds no fallback anywhere.
SurfaceAlbedo drapeCovering(const std::string& map, const Heightfield& hf, int width, int height) {
    SurfaceAlbedo a = importAlbedoMap(map, hf, kDem, kMagenta);
    EXPECT_EQ(a.width, width);
    EXPECT_EQ(a.height, height);
    size_t fallbacks = 0;
    for (const glm::vec3& v : texels(a)) fallbacks += isFallback(v, kMagenta);
    EXPECT_EQ(fallbacks, 0u);
    return a;
}

}  // namespace

TEST(Srgb, DecodingIsTheExactEotf) {
    EXPECT_EQ(srgbToLinear(0.0f), 0.0f);
    EXPECT_EQ(srgbToLinear(1.0f), 1.0f);
    // The linear toe: 0.04045 / 12.92.
    EXPECT_FLOAT_EQ(srgbToLinear(0.04045f), 0.0031308050f);
    EXPECT_FLOAT_EQ(srgbToLinear(10.0f / 255.0f), 0.0030352698f);
    // The power segment: ((v + 0.055) / 1.055)^2.4.
    EXPECT_FLOAT_EQ(srgbToLinear(0.5f), 0.21404114f);
    EXPECT_FLOAT_EQ(srgbToLinear(128.0f / 255.0f), 0.21586050f);
    EXPECT_FLOAT_EQ(srgbToLinear(188.0f / 255.0f), 0.50288646f);
    // Encoding inverts it: every 8-bit level survives the round trip, as the field stores it too.
    for (int v = 0; v < 256; ++v) {
        EXPECT_EQ(std::lround(linearToSrgb(srgbToLinear(v / 255.0f)) * 255.0f), v) << v;
        EXPECT_EQ(srgb8(linearOfSrgb8(uint8_t(v))), v) << v;
    }
}

// srgb8 searches a table of the formula's thresholds: the same byte as the formula for every
// float, sampled densely over [0, 1] (every 61st bit pattern, 17 million values) and beyond.
TEST(Srgb, EncodingByTableIsTheFormulasByte) {
    auto formula = [](float v) { return uint8_t(std::lround(linearToSrgb(v) * 255.0f)); };
    size_t differ = 0, checked = 0;
    for (uint32_t b = 0; b <= std::bit_cast<uint32_t>(1.0f); b += 61, ++checked)
        differ += srgb8(std::bit_cast<float>(b)) != formula(std::bit_cast<float>(b));
    // Each code's first float and the one before it, where a rounding slip would show.
    for (int v = 1; v < 256; ++v) {
        float x = srgbToLinear((float(v) - 0.5f) / 255.0f);
        for (int k = 0; k < 64; ++k, x = std::nextafter(x, 2.0f), ++checked)
            differ += srgb8(x) != formula(x);
    }
    EXPECT_EQ(differ, 0u) << "of " << checked;
    EXPECT_EQ(srgb8(-1.0f), 0);
    EXPECT_EQ(srgb8(std::nanf("")), 0);
    EXPECT_EQ(srgb8(2.0f), 255);
    EXPECT_EQ(srgb8(INFINITY), 255);
}

// The ramp field skips acos where the slope is clearly outside the rock blend and fills rows in
// parallel: texel for texel what the plain formula gives, on rough ground whose slopes span
// 0 to 80 degrees (so every case of the blend is hit).
TEST(Ramp, FieldIsThePlainFormulaTexelForTexel) {
    const int n = 300;
    std::vector<float> h(size_t(n) * n);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            h[size_t(r) * n + c] = float(1500.0 + 900.0 * std::sin(c * 0.07) * std::cos(r * 0.05) +
                                         40.0 * std::sin(c * 1.3 + r * 0.9));
    const Heightfield hf(n, n, 30.0, 30.0, h);
    const AlbedoRampSettings ramp;
    const SurfaceAlbedo a = rampAlbedo(hf, ramp, 1.0, glm::vec3(0.3f));
    ASSERT_EQ(a.width, n);
    int rock = 0, blend = 0, ground = 0, differ = 0;
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const double slope =
                std::acos(std::clamp(double(hf.vertexNormal(c, r).y), -1.0, 1.0)) * 180.0 / std::numbers::pi;
            rock += slope > ramp.rockSlopeDeg[1];
            ground += slope < ramp.rockSlopeDeg[0];
            blend += slope >= ramp.rockSlopeDeg[0] && slope <= ramp.rockSlopeDeg[1];
            SurfaceAlbedo plain;
            plain.resize(1, 1);
            plain.setTexel(0, rampColor(ramp, double(hf.at(c, r)), slope));
            const size_t i = size_t(r) * size_t(n) + size_t(c);
            differ += std::memcmp(&a.srgb[3 * i], plain.srgb.data(), 3) != 0;
        }
    EXPECT_GT(rock, 1000);
    EXPECT_GT(blend, 1000);
    EXPECT_GT(ground, 1000);
    EXPECT_EQ(differ, 0);
}

TEST(Ramp, SnowAboveTheLineRockOnSteepSlopesGroundBelow) {
    const AlbedoRampSettings ramp;  // the defaults: snow from 2800 m, rock 35-50 degrees
    EXPECT_EQ(rampColor(ramp, 3000.0, 0.0), ramp.colors.back());
    EXPECT_EQ(rampColor(ramp, -50.0, 0.0), ramp.colors.front());
    EXPECT_EQ(rampColor(ramp, 2000.0, 60.0), ramp.rockColor);
    // Halfway between two stops, halfway between their colours; the rock blend is smoothstep.
    const glm::vec3 mid = rampColor(ramp, 2700.0, 0.0);
    EXPECT_NEAR(mid.x, 0.5f * (ramp.colors[2].x + ramp.colors[3].x), 1e-6f);
    const glm::vec3 halfRock = rampColor(ramp, 3000.0, 42.5);
    EXPECT_NEAR(halfRock.y, 0.5f * (ramp.colors[3].y + ramp.rockColor.y), 1e-6f);
    EXPECT_EQ(rampColor(ramp, 3000.0, 35.0), ramp.colors.back());

    // Over a heightfield: a flat plateau at 3000 m is snow, a 60-degree face below the line is rock,
    // whatever vertical exaggeration the terrain is lit with.
    const int n = 16;
    const double cell = 10.0;
    std::vector<float> h(size_t(n) * n);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            h[size_t(r) * n + c] = c < n / 2 ? 3000.0f : float(2000.0 + (c - n / 2) * cell * std::tan(60.0 * M_PI / 180.0));
    for (double scale : {1.0, 2.0}) {
        std::vector<float> scaled = h;
        for (float& v : scaled) v = float(v * scale);
        const Heightfield hf(n, n, cell, cell, scaled);
        const glm::vec3 fallback(0.5f);
        const SurfaceAlbedo a = rampAlbedo(hf, ramp, scale, fallback);
        ASSERT_EQ(a.width, n);
        ASSERT_EQ(a.height, n);
        EXPECT_EQ(a.at(hf, hf.xOf(2), hf.zOf(5)), stored(ramp.colors.back())) << "scale " << scale;
        // Slope is as lit: at 2x, the 60-degree face is steeper still, and rock either way.
        EXPECT_EQ(a.at(hf, hf.xOf(12), hf.zOf(5)), stored(ramp.rockColor)) << "scale " << scale;
    }
}

TEST(Ramp, FilledVoidsTakeTheColourOfTheGroundAroundThem) {
    // A 60-degree rock face below the snow line whose middle was nodata and was filled flat at
    // 3000 m: by its own height and slope the fill would be snow, a pale blob on grey rock.
    const AlbedoRampSettings ramp;
    const int n = 24;
    const double cell = 10.0;
    std::vector<float> h(size_t(n) * n);
    std::vector<uint8_t> mask(size_t(n) * n, 0);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const bool hole = c >= 8 && c < 16 && r >= 8 && r < 16;
            h[size_t(r) * n + c] = hole ? 3000.0f : float(1000.0 + c * cell * std::tan(60.0 * M_PI / 180.0));
            mask[size_t(r) * n + c] = hole ? 1 : 0;
        }
    Heightfield hf(n, n, cell, cell, h);
    const SurfaceAlbedo unmarked = rampAlbedo(hf, ramp, 1.0, glm::vec3(0.3f));
    EXPECT_EQ(unmarked.at(hf, hf.xOf(12), hf.zOf(12)), stored(ramp.colors.back())) << "without the mask, snow";
    hf.setNodataMask(mask);
    const SurfaceAlbedo a = rampAlbedo(hf, ramp, 1.0, glm::vec3(0.3f));
    for (int r = 8; r < 16; ++r)
        for (int c = 8; c < 16; ++c) {
            const glm::vec3 got = a.texel(size_t(r) * size_t(n) + size_t(c));
            EXPECT_NEAR(got.x, ramp.rockColor.x, 0.01f) << c << ", " << r;
            EXPECT_NEAR(got.z, ramp.rockColor.z, 0.01f) << c << ", " << r;
        }
    // Outside the void nothing changes.
    for (size_t t = 0; t < a.texels(); ++t)
        if (!mask[t]) {
            EXPECT_EQ(a.texel(t), unmarked.texel(t)) << t;
        }
}

TEST(Ramp, LargeTerrainsGetAtMostTheLargestFieldSide) {
    // 5000 x 3 vertices climbing from 0 to 4999 m eastward: 4096 texels across, and the corner
    // texels are the corner vertices' colours (the first stop, and snow).
    const int w = 5000, d = 3;
    std::vector<float> h(size_t(w) * d);
    for (int r = 0; r < d; ++r)
        for (int c = 0; c < w; ++c) h[size_t(r) * w + c] = float(c);
    const Heightfield hf(w, d, 1000.0, 1000.0, h);  // 1000 m cells: a gentle slope, no rock
    const AlbedoRampSettings ramp;
    const SurfaceAlbedo a = rampAlbedo(hf, ramp, 1.0, glm::vec3(0.3f));
    EXPECT_EQ(a.width, kMaxSurfaceAlbedoSide);
    EXPECT_EQ(a.height, 2);
    EXPECT_EQ(a.at(hf, hf.minX(), hf.minZ()), stored(ramp.colors.front()));
    EXPECT_EQ(a.at(hf, hf.maxX(), hf.maxZ()), stored(ramp.colors.back()));
}

TEST(SurfaceAlbedo, TexelCentresSpanTheFootprintCornerToCorner) {
    const Heightfield hf = test::flat(5, 10.0, 0.0f);  // x, z in [-20, 20]
    SurfaceAlbedo a;
    a.resize(3, 2);
    // Code 128 (0.21586) is stored exactly; 0.2 is stored as its nearest code.
    const float c128 = linearOfSrgb8(128);
    EXPECT_NEAR(c128, 0.21586050f, 1e-7f);
    const glm::vec3 texels[] = {glm::vec3(0.0f), glm::vec3(c128), glm::vec3(1.0f),
                                glm::vec3(0.2f), glm::vec3(0.2f), glm::vec3(0.2f)};
    for (size_t i = 0; i < 6; ++i) a.setTexel(i, texels[i]);
    EXPECT_EQ(a.srgb[3], 128);
    EXPECT_EQ(a.at(hf, -20.0f, -20.0f), glm::vec3(0.0f));         // texel (0, 0): north-west corner
    EXPECT_EQ(a.at(hf, 0.0f, -20.0f), glm::vec3(c128));           // texel (1, 0)
    EXPECT_EQ(a.at(hf, 20.0f, -20.0f), glm::vec3(1.0f));          // texel (2, 0): north-east corner
    EXPECT_EQ(a.at(hf, 20.0f, 20.0f), stored(glm::vec3(0.2f)));   // texel (2, 1): south-east corner
    EXPECT_NEAR(stored(glm::vec3(0.2f)).x, 0.2f, 0.0021f);        // within the encoding's step
    EXPECT_NEAR(a.at(hf, 10.0f, -20.0f).x, (c128 + 1.0f) / 2.0f, 1e-6f);  // between texels: bilinear
    EXPECT_EQ(a.at(hf, 500.0f, -500.0f), glm::vec3(1.0f)); // beyond: clamped to the border
    EXPECT_EQ(a.maximum(), glm::vec3(1.0f));
    EXPECT_EQ(SurfaceAlbedo{}.at(hf, 0.0f, 0.0f), glm::vec3(0.3f));  // empty: the fallback
}

TEST(AlbedoMap, UtmMapLiesOnTheDemItWasColouredFrom) {
    const Heightfield hf = importDem(kDem).heightfield;
    // The map's own 15 m over the 2850 x 1890 m footprint, texel centres on its corners; it
    // covers the footprint with 600 m to spare.
    const SurfaceAlbedo a = drapeCovering(kUtmMap, hf, 191, 127);
    EXPECT_GT(checkBands(hf, a, 1), size_t(3000));
    // Known points: the lowest and the highest vertex of the crop (569 m and 1589 m).
    int lo = 0, hi = 0;
    for (int i = 0; i < hf.width() * hf.depth(); ++i) {
        if (hf.heights()[i] < hf.heights()[lo]) lo = i;
        if (hf.heights()[i] > hf.heights()[hi]) hi = i;
    }
    const glm::vec3 low = a.at(hf, hf.xOf(lo % hf.width()), hf.zOf(lo / hf.width()));
    const glm::vec3 high = a.at(hf, hf.xOf(hi % hf.width()), hf.zOf(hi / hf.width()));
    EXPECT_NEAR(low.y, linearOf(0).y, 1e-5f);
    EXPECT_NEAR(high.x, linearOf(3).x, 1e-5f);
}

TEST(AlbedoMap, GeographicSixteenBitMapIsReprojectedOntoTheDem) {
    const Heightfield hf = importDem(kDem).heightfield;
    // The map's pixel in the DEM's CRS is the one gdalwarp picks for it (`gdalwarp -t_srs
    // EPSG:32611`: 19.5725 m): 2850 / 19.5725 + 1 and 1890 / 19.5725 + 1 texels.
    const SurfaceAlbedo a = drapeCovering(kGeoMap, hf, 146, 97);
    // The map went through two nearest-neighbour resamplings (SOURCES.md): band edges moved by up
    // to a pixel, so only vertices two cells inside a band are checked.
    EXPECT_GT(checkBands(hf, a, 2), size_t(2000));
}

TEST(AlbedoMap, PartialOverlapFallsBackWhereTheMapEnds) {
    Heightfield hf = importDem(kDem).heightfield;
    // Moved east by its own width: only its western 570 m lie on the map's 600 m margin.
    hf.geo.easting += 2880.0;
    const glm::vec3 fallback = kMagenta;
    const SurfaceAlbedo a = importAlbedoMap(kUtmMap, hf, kDem, fallback);
    const float zMid = 0.5f * (hf.minZ() + hf.maxZ());
    EXPECT_EQ(a.at(hf, hf.maxX(), zMid), fallback);
    EXPECT_EQ(a.at(hf, hf.minX() + 1000.0f, zMid), fallback);
    const glm::vec3 west = a.at(hf, hf.minX() + 200.0f, zMid);
    EXPECT_FALSE(isFallback(west, fallback));
    bool isBand = false;
    for (int b = 0; b < 4; ++b) isBand = isBand || glm::all(glm::lessThan(glm::abs(west - linearOf(b)), glm::vec3(1e-5f)));
    EXPECT_TRUE(isBand) << west.x << ", " << west.y << ", " << west.z;
    size_t fallbacks = 0;
    for (const glm::vec3& v : texels(a)) fallbacks += isFallback(v, fallback);
    EXPECT_GT(fallbacks, a.texels() * 3 / 4);
    EXPECT_LT(fallbacks, a.texels() * 9 / 10);
}

TEST(AlbedoMap, NoOverlapNamesBothFiles) {
    Heightfield hf = importDem(kDem).heightfield;
    hf.geo.easting += 100000.0;
    try {
        importAlbedoMap(kGeoMap, hf, "valley.tif", glm::vec3(0.3f));
        FAIL() << "no error";
    } catch (const AlbedoMapError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("terrain.albedo_map: " + kGeoMap), std::string::npos) << m;
        EXPECT_NE(m.find("does not overlap the DEM valley.tif"), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

TEST(AlbedoMap, CrsOnOneSideOnlyBandsAndMissingFilesAreErrors) {
    Heightfield hf = importDem(kDem).heightfield;
    auto message = [&](const std::string& map, const Heightfield& terrain) {
        try {
            importAlbedoMap(map, terrain, "valley.tif", glm::vec3(0.3f));
        } catch (const AlbedoMapError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    Heightfield local = hf;
    local.geo.crsWkt.clear();
    EXPECT_EQ(message(kUtmMap, local),
              "terrain.albedo_map: " + kUtmMap + ": has a CRS but the DEM valley.tif has none; give both a CRS "
              "(the map is reprojected onto the DEM) or neither (the map is stretched over the DEM)");
    EXPECT_EQ(message(kDem, hf), "terrain.albedo_map: " + kDem + ": has 1 band; an albedo map needs 3 (RGB) or 4 (RGBA)");
    const std::string missing = (kData / "nope.tif").string();
    EXPECT_EQ(message(missing, hf), "terrain.albedo_map: " + missing + ": no such file");
    EXPECT_THROW(checkAlbedoMap(missing), AlbedoMapError);
    EXPECT_NO_THROW(checkAlbedoMap(kGeoMap));
}

TEST(AlbedoMap, ProjectModesBuildTheFieldTheBakeUses) {
    Project p;
    p.scene.terrain.dem = kDem;
    const Heightfield hf = loadProjectTerrain(p).heightfield;
    EXPECT_EQ(p.scene.terrain.albedoMode, AlbedoMode::Ramp);  // the default: terrain, not grey
    p.scene.terrain.albedoMode = AlbedoMode::Constant;
    EXPECT_EQ(surfaceAlbedoOf(p, hf), nullptr);
    p.scene.terrain.albedoMode = AlbedoMode::Ramp;
    const auto ramp = surfaceAlbedoOf(p, hf);
    ASSERT_TRUE(ramp);
    EXPECT_EQ(ramp->width, hf.width());
    p.scene.terrain.albedoMode = AlbedoMode::Map;
    p.scene.terrain.albedoMap = kUtmMap;
    const auto map = surfaceAlbedoOf(p, hf);
    ASSERT_TRUE(map);
    EXPECT_EQ(map->width, 191);
    EXPECT_EQ(surfaceAlbedoOf(p, hf), map);  // the same file and footprint: imported once
    p.scene.terrain.albedo = glm::vec3(0.5f);
    EXPECT_NE(surfaceAlbedoOf(p, hf), map);  // a new fallback is a new field
}

TEST(AlbedoParameters, RoundTripThroughTheProjectFile) {
    const fs::path dir = fs::temp_directory_path() / ("terralux_test_albedo_" + std::to_string(::getpid()));
    fs::create_directories(dir / "maps");
    Project p;
    p.scene.terrain.albedoMode = AlbedoMode::Ramp;
    p.scene.terrain.albedoMap = (dir / "maps" / "ortho.tif").string();
    p.scene.terrain.ramp.heights = {100.0, 2500.5, 3000.0};
    p.scene.terrain.ramp.colors = {{0.1f, 0.2f, 0.3f}, {0.4f, 0.5f, 0.6f}, {0.7f, 0.8f, 0.9f}};
    p.scene.terrain.ramp.rockColor = {0.33f, 0.22f, 0.11f};
    p.scene.terrain.ramp.rockSlopeDeg = {30.0, 45.5};
    saveProject(p, dir / "a.terralux.json");
    // The map is written relative to the project file, like the DEM.
    const nlohmann::json doc = nlohmann::json::parse(std::ifstream(dir / "a.terralux.json"));
    EXPECT_EQ(doc["terrain"]["albedo_map"], "maps/ortho.tif");
    EXPECT_EQ(doc["terrain"]["ramp_colors"], nlohmann::json({0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9}));
    const Project back = loadProject(dir / "a.terralux.json", nullptr);
    nlohmann::json a = sceneToJson(back.scene)["terrain"], b = sceneToJson(p.scene)["terrain"];
    a.erase("albedo_map");
    b.erase("albedo_map");
    EXPECT_EQ(a, b);
    EXPECT_EQ(back.albedoMapPath(), dir / "maps" / "ortho.tif");
    fs::remove_all(dir);
}

TEST(AlbedoBake, InputsFollowTheModeAndTheMapFile) {
    Project p;
    p.scene.terrain.albedoMode = AlbedoMode::Constant;
    const nlohmann::json constant = bakeInputs(p);
    Project rampEdited = p;
    rampEdited.scene.terrain.ramp.rockSlopeDeg = {20.0, 30.0};
    EXPECT_EQ(bakeInputs(rampEdited), constant);  // the ramp is not read in mode constant
    rampEdited.scene.terrain.albedoMode = AlbedoMode::Ramp;
    EXPECT_TRUE(bakeInputDifferences(constant, bakeInputs(rampEdited)).size() > 0);
    Project map = p;
    map.scene.terrain.albedoMode = AlbedoMode::Map;
    map.scene.terrain.albedoMap = kUtmMap;
    const nlohmann::json inputs = bakeInputs(map);
    EXPECT_EQ(inputs["files"]["terrain.albedo_map"]["path"], fs::path(kUtmMap).lexically_normal().generic_string());
    EXPECT_EQ(inputs["files"]["terrain.albedo_map"]["bytes"], fs::file_size(kUtmMap));
}

namespace {

// SH coefficients of a bake, as bits, for exact comparisons.
std::vector<uint32_t> bitsOf(const ProbeBake& b) {
    std::vector<uint32_t> out;
    for (const auto& s : b.sh)
        for (const glm::vec3& c : s.c)
            for (int k = 0; k < 3; ++k) {
                uint32_t u;
                std::memcpy(&u, &c[k], 4);
                out.push_back(u);
            }
    return out;
}

// FNV-1a over the bits.
uint64_t hashOf(const std::vector<uint32_t>& bits) {
    uint64_t h = 1469598103934665603ull;
    for (uint32_t u : bits)
        for (int k = 0; k < 4; ++k) h = (h ^ ((u >> (8 * k)) & 0xFF)) * 1099511628211ull;
    return h;
}

struct BounceScene {
    Heightfield hf;
    std::unique_ptr<HeightfieldTracer> tracer;
    BakeLighting L;
    std::vector<glm::vec3> probes{{0.0f, 4.0f, 0.0f}, {150.0f, 4.0f, 150.0f}};
    std::vector<uint8_t> valid{1, 1};

    BounceScene() : hf(test::flat(64, 5.0, 0.0f)) {
        tracer = std::make_unique<HeightfieldTracer>(hf);
        L = test::skyAndSun(*tracer);
    }
    ProbeBake bake() const {
        const IrradianceCache cache(L, 32, 32, 2, 1, BakeControl{});
        return bakeProbes(L, &cache, 2, probes, valid, 256, 7, BakeControl{});
    }
    ProbeBake reference() const { return referenceProbes(L, 2, probes, valid, 256, 7, BakeControl{}); }
};

// Irradiance on a surface facing down: the light the ground below sends up.
float fromBelow(const sh::ShRgb& s) { return glsl::rec709Luminance(sh::evalIrradiance(s, glm::vec3(0.0f, -1.0f, 0.0f))); }

}  // namespace

TEST(AlbedoBake, BrightGroundNearAProbeRaisesItsBounceLight) {
    BounceScene scene;
    const ProbeBake grey = scene.bake();
    const ProbeBake greyReference = scene.reference();

    // Snow-bright (0.85) within 40 m of the first probe, the constant grey elsewhere.
    auto field = std::make_shared<SurfaceAlbedo>();
    field->resize(64, 64);
    field->fallback = scene.L.albedo;
    for (int r = 0; r < 64; ++r)
        for (int c = 0; c < 64; ++c)
            field->setTexel(size_t(r) * 64 + size_t(c), std::hypot(scene.hf.xOf(c), scene.hf.zOf(r)) < 40.0f
                                                            ? glm::vec3(0.85f)
                                                            : scene.L.albedo);
    scene.L.surface = field;
    const ProbeBake bright = scene.bake();
    const ProbeBake brightReference = scene.reference();

    // Under the first probe the ground is 0.85 / 0.3 times brighter (and its own bounces add a
    // little more); the second probe, 200 m away, sees almost only the grey.
    EXPECT_GT(fromBelow(bright.sh[0]), 2.5f * fromBelow(grey.sh[0]));
    EXPECT_GT(fromBelow(brightReference.sh[0]), 2.5f * fromBelow(greyReference.sh[0]));
    EXPECT_LT(fromBelow(bright.sh[1]), 1.05f * fromBelow(grey.sh[1]));
    // The reference follows the brightest albedo for its path length.
    EXPECT_EQ(scene.L.maxAlbedo(), stored(glm::vec3(0.85f)));
}

TEST(AlbedoBake, ConstantModeIsBitIdenticalToTheBakeBeforeAlbedoFields) {
    BounceScene scene;
    const std::vector<uint32_t> before = bitsOf(scene.bake());
    // No field and an empty field are the constant path.
    scene.L.surface = std::make_shared<SurfaceAlbedo>();
    EXPECT_EQ(bitsOf(scene.bake()), before);
    // The bytes of this scene's bake, pinned so that work on the albedo path cannot move the
    // constant mode: first pinned before terrain albedo fields existed (commit 80e5b82), pinned
    // again when the probes' rays became two randomly turned lattices, when probes became
    // seeded by their position (the sampler, not albedo), when a probe ray's terrain hit
    // began to gather its own indirect light (the cache's use, not albedo) and when the sky
    // became the rays' control variate (the estimator, not albedo).
    EXPECT_EQ(hashOf(before), 0x8070fbd94b872a98ull) << std::hex << hashOf(before);
    EXPECT_EQ(hashOf(bitsOf(scene.reference())), 0xd03c911d3049d434ull) << std::hex << hashOf(bitsOf(scene.reference()));
}
