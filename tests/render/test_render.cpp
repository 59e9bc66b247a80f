// Render tests on the real Vulkan path (Mesa lavapipe in CI): golden images of every debug view
// and behaviour checks. They skip, saying why, when no Vulkan device exists, and fail on any
// validation-layer message.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <numbers>
#include <optional>
#include <set>
#include <thread>

#include <gdal_priv.h>
#include <glm/matrix.hpp>
#include <gtest/gtest.h>

#include "ImageCompare.h"
#include "ImageFile.h"
#include "ProjectRenderer.h"
#include "ShaderMath.h"
#include "ShProbeFile.h"
#include "TerrainLoading.h"
#include "SceneLighting.h"
#include "bake/PhysicalSky.h"
#include "bake/ReflectionBake.h"
#include "bake/SphericalHarmonics.h"
#include "lpv/Lpv.h"
#include "scene/Exposure.h"
#include "scene/DebugViews.h"
#include "scene/DynamicResolution.h"
#include "scene/ImageCodes.h"
#include "terrain/HorizonAO.h"
#include "render/FrameGraph.h"
#include "render/features/Antialiasing.h"
#include "vk/Descriptors.h"
#include "vk/Image.h"
#include "vk/RenderPass.h"
#include "vk/Sampler.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

const fs::path kGolden = fs::path(TERRALUX_SOURCE_DIR) / "tests" / "render" / "golden";
const fs::path kOut = fs::path(TERRALUX_BINARY_DIR) / "render_out";
constexpr uint32_t kW = 192, kH = 128;

class RenderTest : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        try {
            vk::ContextOptions o;
            o.validation = true;
            ctx_ = std::make_unique<vk::VulkanContext>(o);
        } catch (const vk::VulkanUnavailable& e) {
            skipReason_ = e.what();
        }
        fs::create_directories(kOut);
    }
    static void TearDownTestSuite() { ctx_.reset(); }
    void SetUp() override {
        if (!ctx_) GTEST_SKIP() << "no Vulkan: " << skipReason_;
        messagesBefore_ = ctx_->validationMessageCount();
    }
    void TearDown() override {
        if (!ctx_) return;
        for (size_t i = messagesBefore_; i < ctx_->validationMessageCount(); ++i)
            ADD_FAILURE() << "validation: " << ctx_->validationMessages()[i];
    }

    // The sample terrain with a draft bake of `grid` probes into a per-test output folder.
    static Project sampleProject(const std::string& name, int gx, int gz) {
        Project p = loadEffectiveProject("", {"bake.quality=draft",
                                              "probe_volumes[0].grid_dims=" + std::to_string(gx) + "," + std::to_string(gz)},
                                         "", nullptr);
        p.scene.exportSettings.outDir = (kOut / ("bake_" + name)).string();
        return p;
    }

    static std::unique_ptr<vk::VulkanContext> ctx_;
    static std::string skipReason_;
    size_t messagesBefore_ = 0;
};
std::unique_ptr<vk::VulkanContext> RenderTest::ctx_;
std::string RenderTest::skipReason_;

// A kW x kH request without probes.
RenderRequest unprobed(int view, bool linear) {
    RenderRequest q;
    q.width = kW;
    q.height = kH;
    q.probes = false;
    q.debugView = view;
    q.linearOutput = linear;
    return q;
}

// View 34's colour of cascades 0-3 (shaders/views.glsl, cascadeColour); grey beyond them.
const glm::vec3 kCascadeColours[4] = {{0.90f, 0.25f, 0.20f}, {0.25f, 0.75f, 0.25f}, {0.25f, 0.45f, 0.95f}, {0.95f, 0.85f, 0.20f}};

RenderedImage draw(ProjectRenderer& r, int view, bool probes = true, bool linear = false,
                   uint32_t width = kW, uint32_t height = kH) {
    RenderRequest q = unprobed(view, linear);
    q.probes = probes;
    q.width = width;
    q.height = height;
    return r.render(q);
}

// Two waves, long and short, 0.6 m and 0.15 m high: the mesh moves and the normals ripple.
std::vector<GerstnerWave> testWaves() {
    GerstnerWave a;
    a.directionDeg = 30.0;
    a.wavelength = 40.0;
    a.amplitude = 0.6;
    GerstnerWave b;
    b.directionDeg = 100.0;
    b.wavelength = 9.0;
    b.amplitude = 0.15;
    b.phase = 1.0;
    return {a, b};
}

// Water `above` metres over the lowest terrain of the renderer's heightfield (engine space).
Project withWater(Project p, const ProjectRenderer& r, double above, std::vector<GerstnerWave> waves = {}) {
    p.scene.water.enabled = true;
    p.scene.water.level = double(r.heightfield().minHeight()) + above;
    p.scene.water.waves = std::move(waves);
    return p;
}

// The sample with a lake in its valleys (a fifth of its relief deep) and two waves: every view
// then has water to show.
void addLake(Project& p, ProjectRenderer& r) {
    const Heightfield& hf = r.heightfield();
    p = withWater(p, r, 0.2 * double(hf.maxHeight() - hf.minHeight()), testWaves());
    r.setProject(p);
}

double meanAbsDiff(const RenderedImage& a, const RenderedImage& b) {
    return test::compareImages(a.rgba, b.rgba, a.width, a.height).meanAbs;
}

// A reflection-probe set built from ReflectionBake.h's types (the tests load no reflection bake):
// an nx x nz grid whose cells tile `region` (xz min corner and size; default the footprint),
// probes `above` metres over the surface, boxes half a cell wide and reaching from below the
// lowest terrain as far above the probe. Each face has a colour of its own, scaled per probe; in
// the cubemap encoding (8 texels a side by default) its texels ramp across the face at mip 0 and each
// coarser mip is the 2x2 mean of the one before, so a lookup that took the wrong face, row, column,
// mip or probe shows. `uniform`: every face and texel that radiance instead.
struct ReflectionSetOptions {
    ReflectionEncoding encoding = ReflectionEncoding::Cubemap;
    int nx = 2, nz = 2;
    std::optional<glm::vec3> uniform;
    std::optional<std::pair<glm::vec2, glm::vec2>> region;
    float blendDistance = -1.0f;  // < 0: a quarter of the smaller cell side
    float above = 20.0f;
    int faceSize = 8;
};

std::shared_ptr<ReflectionProbeSet> reflectionSet(const Heightfield& hf, const ReflectionSetOptions& o = {}) {
    auto s = std::make_shared<ReflectionProbeSet>();
    const bool cubemap = o.encoding == ReflectionEncoding::Cubemap;
    const int size = o.faceSize;
    s->encoding = o.encoding;
    s->faceSize = cubemap ? size : 0;
    s->mipCount = cubemap ? cubeMipCount(size) : 1;
    s->dims = {o.nx, o.nz};
    const glm::vec2 lo = o.region ? o.region->first : glm::vec2(hf.minX(), hf.minZ());
    const glm::vec2 span = o.region ? o.region->second : glm::vec2(hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ());
    s->cellSize = span / glm::vec2(float(o.nx), float(o.nz));
    s->origin = lo + 0.5f * s->cellSize;
    s->spacing = glm::vec2(o.nx > 1 ? s->cellSize.x : 0.0f, o.nz > 1 ? s->cellSize.y : 0.0f);
    s->blendDistance = o.blendDistance >= 0.0f ? o.blendDistance : 0.25f * std::min(s->cellSize.x, s->cellSize.y);
    const glm::vec3 base[6] = {{0.60f, 0.10f, 0.10f}, {0.10f, 0.60f, 0.10f}, {0.15f, 0.20f, 0.70f},
                               {0.30f, 0.22f, 0.10f}, {0.55f, 0.50f, 0.10f}, {0.10f, 0.45f, 0.50f}};
    const int n = o.nx * o.nz;
    for (int k = 0; k < o.nz; ++k)
        for (int i = 0; i < o.nx; ++i) {
            ReflectionProbe p;
            p.id = uint32_t(k * o.nx + i);
            const glm::vec2 xz = s->origin + glm::vec2(float(i), float(k)) * s->cellSize;
            p.position = glm::vec3(xz.x, hf.surfaceHeight(xz.x, xz.y) + o.above, xz.y);
            p.halfExtent = glm::vec3(0.5f * s->cellSize.x, p.position.y - hf.minHeight() + o.above, 0.5f * s->cellSize.y);
            const float scale = 1.0f + 0.5f * float(p.id) / float(n);
            for (int f = 0; f < 6; ++f) p.faces[size_t(f)] = o.uniform ? *o.uniform : base[f] * scale;
            if (cubemap) {
                p.texels.resize(s->texelsPerProbe());
                for (int f = 0; f < 6; ++f)
                    for (int y = 0; y < size; ++y)
                        for (int x = 0; x < size; ++x) {
                            const float sx = (float(x) + 0.5f) / float(size), ty = (float(y) + 0.5f) / float(size);
                            p.texels[s->texelOffset(0, f) + size_t(y * size + x)] =
                                o.uniform ? *o.uniform : p.faces[size_t(f)] * (0.5f + sx) * (0.75f + 0.5f * ty);
                        }
                for (int m = 1; m < s->mipCount; ++m) {
                    const int side = cubeMipSize(size, m);
                    for (int f = 0; f < 6; ++f)
                        for (int y = 0; y < side; ++y)
                            for (int x = 0; x < side; ++x) {
                                const glm::vec3* finer = &p.texels[s->texelOffset(m - 1, f)];
                                const size_t w = size_t(2 * side);
                                p.texels[s->texelOffset(m, f) + size_t(y * side + x)] =
                                    0.25f * (finer[size_t(2 * y) * w + size_t(2 * x)] + finer[size_t(2 * y) * w + size_t(2 * x + 1)] +
                                             finer[size_t(2 * y + 1) * w + size_t(2 * x)] +
                                             finer[size_t(2 * y + 1) * w + size_t(2 * x + 1)]);
                            }
                }
            }
            s->probes.push_back(std::move(p));
        }
    return s;
}

// What the terrain shader reads from `s` at p along r, written from docs/lighting.md with the
// bake's evaluate(): the blend weight (strength 1) and the probes' radiance, bilinear over the
// probes around p, each box-projected.
glm::vec3 referenceReflection(const ReflectionProbeSet& s, glm::vec3 p, glm::vec3 r, float roughness, float& weight) {
    const glm::vec2 dims(float(s.dims[0]), float(s.dims[1]));
    const glm::vec2 lo = s.origin - 0.5f * s.cellSize, hi = s.origin + s.spacing * (dims - 1.0f) + 0.5f * s.cellSize;
    const glm::vec2 xz(p.x, p.z);
    const float dist = glm::length(xz - glm::clamp(xz, lo, hi));
    weight = dist <= 0.0f ? 1.0f : s.blendDistance > 0.0f ? std::clamp(1.0f - dist / s.blendDistance, 0.0f, 1.0f) : 0.0f;
    glm::vec3 sum(0.0f);
    float g[2], f[2];
    int i0[2];
    for (int a = 0; a < 2; ++a) {
        const float spacing = s.spacing[a], origin = s.origin[a], q = a == 0 ? p.x : p.z;
        g[a] = std::clamp(spacing > 0.0f ? (q - origin) / spacing : 0.0f, 0.0f, float(s.dims[size_t(a)] - 1));
        i0[a] = std::min(int(std::floor(g[a])), std::max(s.dims[size_t(a)] - 2, 0));
        f[a] = g[a] - float(i0[a]);
    }
    for (int k = 0; k < 4; ++k) {
        const int ox = k & 1, oz = k >> 1;
        const float w = (ox ? f[0] : 1.0f - f[0]) * (oz ? f[1] : 1.0f - f[1]);
        if (w <= 0.0f) continue;
        const int cx = std::min(i0[0] + ox, s.dims[0] - 1), cz = std::min(i0[1] + oz, s.dims[1] - 1);
        const ReflectionProbe& probe = s.probes[size_t(cz * s.dims[0] + cx)];
        // Box projection: from inside the box, the direction from the capture point to where the
        // ray leaves it.
        const glm::vec3 q = p - probe.position;
        glm::vec3 dir = r;
        if (std::abs(q.x) <= probe.halfExtent.x && std::abs(q.y) <= probe.halfExtent.y && std::abs(q.z) <= probe.halfExtent.z) {
            float t = INFINITY;
            for (int a = 0; a < 3; ++a)
                if (r[a] != 0.0f) t = std::min(t, ((r[a] > 0.0f ? probe.halfExtent[a] : -probe.halfExtent[a]) - q[a]) / r[a]);
            dir = q + t * r;
        }
        sum += w * s.evaluate(size_t(cz * s.dims[0] + cx), dir, roughness);
    }
    return sum;
}

// The set the golden images of the reflection views show: 2 x 2 cubemap probes over the middle
// 70 % of the footprint, fading to the sky's over a quarter cell around it.
std::shared_ptr<ReflectionProbeSet> goldenReflections(const Heightfield& hf) {
    ReflectionSetOptions o;
    const glm::vec2 span(hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ());
    o.region = std::make_pair(glm::vec2(hf.minX(), hf.minZ()) + 0.15f * span, 0.7f * span);
    return reflectionSet(hf, o);
}

// Draws view `view` with `set` bound (null: none), keeping the set bound afterwards.
RenderedImage drawWith(ProjectRenderer& r, std::shared_ptr<const ReflectionProbeSet> set, int view,
                       bool linear = false, bool probes = true) {
    r.setReflectionProbes(std::move(set));
    return draw(r, view, probes, linear);
}

}  // namespace

namespace {

// Compares a kW x kH image with the golden `stem`.png (or writes the golden with
// TERRALUX_UPDATE_GOLDENS set).
void checkGolden(const std::string& stem, const RenderedImage& img) {
    const fs::path golden = kGolden / (stem + ".png");
    const fs::path actual = kOut / (stem + ".png");
    writeImage(actual, img.width, img.height, img.rgba);
    if (std::getenv("TERRALUX_UPDATE_GOLDENS")) {
        writeImage(golden, img.width, img.height, img.rgba);
        return;
    }
    ASSERT_TRUE(fs::exists(golden)) << golden << " missing: run tests/render/update_goldens.sh";
    uint32_t gw = 0, gh = 0;
    // Compare what was written (8-bit) with the golden, both through the same quantisation.
    const auto expected = readImageRgba(golden, gw, gh);
    const auto got = readImageRgba(actual, gw, gh);
    ASSERT_EQ(gw, kW);
    ASSERT_EQ(gh, kH);
    const auto d = test::compareImages(got, expected, kW, kH);
    if (d.meanAbs > 2.0 / 255.0 || d.ssim < 0.98) {
        const fs::path diff = kOut / (stem + ".diff.png");
        writeImage(diff, kW, kH, d.diff);
        ADD_FAILURE() << stem << ": mean |diff| " << d.meanAbs * 255.0 << "/255, SSIM " << d.ssim << ", max "
                      << d.maxAbs * 255.0 << "/255 at (" << d.maxX << ", " << d.maxY << "); diff image " << diff;
    }
}

}  // namespace

TEST_F(RenderTest, GoldenImagesOfEveryView) {
    Project p = sampleProject("golden", 8, 8);
    // The LPV views draw the volumes whatever lpv.enabled says, here with light carried across the
    // cascades; they expose for their own light (no other view reads these settings).
    p.scene.lpv.propagationWeight = 1.0;
    p.scene.lpv.indirectIntensity = 4.0;
    ProjectRenderer r(*ctx_, p);
    addLake(p, r);
    ASSERT_EQ(r.loadProbes(true), 1u);
    // The reflection views show a synthetic set (no reflection bake is loaded here); every other
    // view the project as it is, without reflection probes.
    const auto reflections = goldenReflections(r.heightfield());
    for (const auto& v : debugViews()) {
        const bool reflectionView = v.number == kViewReflectionColor || v.number == kViewReflectionWeight;
        r.setReflectionProbes(reflectionView ? reflections : nullptr);
        checkGolden(std::to_string(v.number) + "-" + v.name, draw(r, v.number));
    }
}

TEST_F(RenderTest, ProbesDisabledEqualsTheUnprobedImage) {
    ProjectRenderer withProbes(*ctx_, sampleProject("disabled", 8, 8));
    ASSERT_EQ(withProbes.loadProbes(true), 1u);
    ProjectRenderer without(*ctx_, sampleProject("none", 8, 8));  // no probes loaded at all
    const RenderedImage off = draw(withProbes, kViewBeauty, false);
    const RenderedImage none = draw(without, kViewBeauty, true);
    const RenderedImage on = draw(withProbes, kViewBeauty, true);
    const auto d = test::compareImages(off.rgba, none.rgba, kW, kH);
    EXPECT_LE(d.maxAbs, 1.0 / 255.0);
    // Probes change the ambient term (occluded sky and bounce in place of the open sky): with the
    // sun off, by more than 1 % of the scene-linear image.
    Project dark = sampleProject("disabled", 8, 8);
    dark.scene.sun.illuminance = 0.0;
    withProbes.setProject(dark);
    const RenderedImage onLinear = draw(withProbes, kViewLinear, true, true);
    const RenderedImage offLinear = draw(withProbes, kViewLinear, false, true);
    const RenderedImage albedo = draw(withProbes, kViewAlbedo);
    double diff = 0, sum = 0;
    for (size_t i = 0; i < onLinear.rgba.size(); ++i) {
        if (i % 4 == 3 || albedo.rgba[i - i % 4] <= 0.0f) continue;  // terrain pixels, rgb
        diff += std::abs(onLinear.rgba[i] - offLinear.rgba[i]);
        sum += std::abs(offLinear.rgba[i]);
    }
    EXPECT_GT(diff / sum, 0.01) << "probe lighting changes the image";
    EXPECT_GT(meanAbsDiff(on, off), 0.0);
}

TEST_F(RenderTest, OneByOneGridWeighsOneEverywhere) {
    ProjectRenderer r(*ctx_, sampleProject("one", 1, 1));
    ASSERT_EQ(r.loadProbes(true), 1u);
    const RenderedImage w = draw(r, kViewProbeWeight);
    const RenderedImage albedo = draw(r, kViewAlbedo);
    size_t terrain = 0;
    for (size_t i = 0; i < size_t(kW) * kH; ++i) {
        // Terrain pixels are those the albedo view paints (the background is cleared to black).
        if (albedo.rgba[i * 4] <= 0.0f) continue;
        ++terrain;
        EXPECT_NEAR(w.rgba[i * 4], 1.0f, 1e-3f) << "pixel " << i % kW << "," << i / kW;
        if (std::abs(w.rgba[i * 4] - 1.0f) > 1e-3f) break;
    }
    EXPECT_GT(terrain, size_t(kW) * kH / 4);
}

// A U-shaped valley running north-south: a flat floor, steep walls and flat plateaus, written as
// a projected GeoTIFF so it goes through the same import as any DEM.
fs::path writeValleyDem() {
    const fs::path path = kOut / "u_valley.tif";
    if (fs::exists(path)) return path;
    GDALAllRegister();
    const int n = 65;
    GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(path.c_str(), n, n, 1, GDT_Float32, nullptr);
    double gt[6] = {500000.0, 10.0, 0.0, 4000000.0, 0.0, -10.0};
    ds->SetGeoTransform(gt);
    OGRSpatialReference srs;
    srs.importFromEPSG(32633);
    ds->SetSpatialRef(&srs);
    std::vector<float> h(size_t(n) * n);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const int d = std::abs(c - n / 2);  // floor |d| <= 5, walls up to 16, plateau beyond
            h[size_t(r) * n + size_t(c)] = d <= 5 ? 0.0f : float(std::min(d - 5, 11)) * 60.0f;
        }
    if (ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, n, n, h.data(), n, n, GDT_Float32, 0, 0, nullptr) != CE_None)
        ADD_FAILURE() << "cannot write " << path;
    GDALClose(ds);
    return path;
}

TEST_F(RenderTest, PlateauIsBrighterThanValleyFloorInProbeIrradiance) {
    Project p = sampleProject("valley", 16, 16);
    p.scene.terrain.dem = writeValleyDem().string();
    p.scene.camera.elevationDeg = 89.5;  // straight down: image columns run across the valley
    p.scene.camera.azimuthDeg = 180.0;
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    RenderRequest q;
    q.width = kW;
    q.height = kW;
    q.debugView = kViewProbeIrradiance;
    q.linearOutput = true;
    const RenderedImage img = r.render(q);
    // Mean over a vertical strip of pixels (the valley runs north-south, i.e. along image rows).
    auto strip = [&](uint32_t x0, uint32_t x1) {
        double s = 0;
        size_t count = 0;
        for (uint32_t y = kW / 4; y < 3 * kW / 4; ++y)
            for (uint32_t x = x0; x < x1; ++x) {
                s += img.rgba[(size_t(y) * kW + x) * 4 + 1];
                ++count;
            }
        return s / double(count);
    };
    const double floor = strip(kW / 2 - 3, kW / 2 + 3);
    const double plateauWest = strip(kW / 2 - 40, kW / 2 - 32), plateauEast = strip(kW / 2 + 32, kW / 2 + 40);
    EXPECT_GT(plateauWest, 1.3 * floor) << "floor " << floor << " plateau " << plateauWest;
    EXPECT_GT(plateauEast, 1.3 * floor) << "floor " << floor << " plateau " << plateauEast;
}

TEST_F(RenderTest, SkyColourAndGridChangeProbeIrradiance) {
    auto linearProbeIrradiance = [&](ProjectRenderer& r) { return draw(r, kViewProbeIrradiance, true, true); };
    auto relDiff = [](const RenderedImage& a, const RenderedImage& b) {
        double num = 0, den = 0;
        for (size_t i = 0; i < a.rgba.size(); ++i) {
            if (i % 4 == 3) continue;
            num += std::abs(a.rgba[i] - b.rgba[i]);
            den += std::abs(a.rgba[i]);
        }
        return num / std::max(den, 1e-9);
    };
    ProjectRenderer ra(*ctx_, sampleProject("skyA", 8, 8));
    ASSERT_EQ(ra.loadProbes(true), 1u);
    Project b = sampleProject("skyB", 8, 8);
    b.scene.sky.color = glm::vec3(1.0f, 0.5f, 0.2f);
    b.scene.sky.luminance = 1.0 / kSceneUnitsPerLux;
    ProjectRenderer rb(*ctx_, b);
    ASSERT_EQ(rb.loadProbes(true), 1u);
    ProjectRenderer rc(*ctx_, sampleProject("gridC", 2, 2));
    ASSERT_EQ(rc.loadProbes(true), 1u);
    const RenderedImage ia = linearProbeIrradiance(ra), ib = linearProbeIrradiance(rb), ic = linearProbeIrradiance(rc);
    EXPECT_GT(relDiff(ia, ib), 0.2) << "sky colour";
    EXPECT_GT(relDiff(ia, ic), 0.01) << "probe grid";
}

TEST_F(RenderTest, EveryViewDiffersFromBeauty) {
    Project p = sampleProject("views", 8, 8);
    ProjectRenderer r(*ctx_, p);
    addLake(p, r);
    ASSERT_EQ(r.loadProbes(true), 1u);
    const RenderedImage beauty = draw(r, kViewBeauty);
    for (const auto& v : debugViews()) {
        // The sample has no voids, so the filled view is the beauty image there
        // (FilledViewTintsTheFilledCellsOnly).
        if (v.number == kViewBeauty || v.number == kViewFilled) continue;
        EXPECT_GT(meanAbsDiff(draw(r, v.number), beauty), 2.0 / 255.0) << v.number << " " << v.name;
    }
}

namespace {

// One volume over the whole terrain: 4 x ? x 4 cubic cells, the west half pointing at probe 0,
// the east half at probe 1 (both a constant sky), with diagnostics to fill in.
GpuProbeVolume halves(const Heightfield& hf) {
    GpuProbeVolume v;
    v.name = "probes";  // the sample project's volume, whose overlays this replaces
    const float cell = std::max(hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ()) / 4.0f;
    v.spacing = cell;
    v.origin = glm::vec3(hf.minX(), hf.minHeight() - 1.0f, hf.minZ());
    v.dims = glm::uvec3(4, uint32_t(std::ceil((hf.maxHeight() - hf.minHeight() + 2.0f) / cell)) + 1, 4);
    for (int p = 0; p < 2; ++p) v.coeffs.push_back(sh::projectConstant(glm::vec3(0.5f)).c);
    for (uint32_t z = 0; z < v.dims.z; ++z)
        for (uint32_t y = 0; y < v.dims.y; ++y)
            for (uint32_t x = 0; x < v.dims.x; ++x) v.occupancy.push_back(x < 2 ? 0 : 1);
    v.fallbackBlendDistance = cell;
    ProbeDiagnostics d;
    d.positions = {v.origin + glm::vec3(cell, 2 * cell, 2 * cell), v.origin + glm::vec3(3 * cell, 2 * cell, 2 * cell)};
    d.moved = {0, 0};
    v.diagnostics = d;
    return v;
}

// Pixels the albedo view paints (the background is cleared to black).
std::vector<size_t> terrainPixels(ProjectRenderer& r) {
    const RenderedImage albedo = draw(r, kViewAlbedo);
    std::vector<size_t> out;
    for (size_t i = 0; i < size_t(kW) * kH; ++i)
        if (albedo.rgba[i * 4] > 0.0f) out.push_back(i);
    return out;
}

}  // namespace

TEST_F(RenderTest, ValidityViewShowsWhereMovedProbesLightAndWhereNoProbeIsLeft) {
    ProjectRenderer r(*ctx_, sampleProject("validity", 8, 8));
    const std::vector<size_t> terrain = terrainPixels(r);
    ASSERT_GT(terrain.size(), size_t(kW) * kH / 4);
    auto count = [&](const RenderedImage& img, auto predicate) {
        size_t n = 0;
        for (size_t i : terrain) n += predicate(&img.rgba[i * 4]);
        return n;
    };
    auto cyan = [](const float* c) { return c[2] > c[0] + 0.3f; };
    auto grey = [](const float* c) { return std::abs(c[0] - c[2]) < 0.02f && c[0] > 0.2f; };
    auto red = [](const float* c) { return c[0] > 0.3f && c[1] < 0.2f * c[0] + 0.05f && c[2] < 0.2f * c[0] + 0.05f; };

    GpuProbeVolume v = halves(r.heightfield());
    r.setProbes({v});
    const RenderedImage placed = draw(r, kViewProbeValidity);
    EXPECT_EQ(count(placed, cyan), 0u);
    EXPECT_GT(count(placed, grey), terrain.size() * 9 / 10);

    v.diagnostics->moved = {0, 1};
    r.setProbes({v});
    const RenderedImage moved = draw(r, kViewProbeValidity);
    EXPECT_GT(count(moved, cyan), terrain.size() / 4) << "the east half is lit by a moved probe";
    EXPECT_GT(count(moved, grey), terrain.size() / 4) << "the west half is not";

    GpuProbeVolume empty = v;
    std::fill(empty.occupancy.begin(), empty.occupancy.end(), -1);  // every probe rejected
    r.setProbes({empty});
    EXPECT_GT(count(draw(r, kViewProbeValidity), red), terrain.size() * 9 / 10);
    // A second volume that lights the same ground: nothing is left unlit.
    r.setProbes({empty, v});
    EXPECT_EQ(count(draw(r, kViewProbeValidity), red), 0u);
}

TEST_F(RenderTest, InterpolationErrorViewShowsTheBakedMap) {
    ProjectRenderer r(*ctx_, sampleProject("errormap", 8, 8));
    const Heightfield& hf = r.heightfield();
    const std::vector<size_t> terrain = terrainPixels(r);
    GpuProbeVolume v = halves(hf);
    ErrorMap& m = v.diagnostics->errorMap;
    m.nx = m.nz = 2;
    m.step = hf.maxX() - hf.minX();
    m.x0 = hf.minX();
    m.z0 = hf.minZ();
    m.error = {0.05f, 0.05f, 0.05f, 0.05f};
    r.setProbes({v});
    // EXR: the error itself in red, 1 in green where measured.
    RenderedImage img = draw(r, kViewInterpolationError, true, true);
    for (size_t i : terrain) {
        ASSERT_NEAR(img.rgba[i * 4], 0.05f, 1e-4f) << "pixel " << i;
        ASSERT_NEAR(img.rgba[i * 4 + 1], 1.0f, 1e-3f) << "pixel " << i;  // half-float target
    }

    // West column 0, east column 20 %: every value in between, both ends on the heat ramp.
    m.error = {0.0f, 0.2f, 0.0f, 0.2f};
    r.setProbes({v});
    img = draw(r, kViewInterpolationError, true, true);
    float lo = 1.0f, hi = 0.0f;
    for (size_t i : terrain) {
        lo = std::min(lo, img.rgba[i * 4]);
        hi = std::max(hi, img.rgba[i * 4]);
    }
    EXPECT_LT(lo, 0.01f);
    EXPECT_GT(hi, 0.19f);
    EXPECT_LE(hi, 0.2f + 1e-4f);
    const RenderedImage shown = draw(r, kViewInterpolationError);
    size_t blue = 0, redPixels = 0;
    for (size_t i : terrain) {
        const float* c = &shown.rgba[i * 4];
        const float e = img.rgba[i * 4];
        if (e < 0.005f) blue += c[2] > c[0] + 0.2f && c[2] > c[1];
        if (e > 0.15f) redPixels += c[0] > 0.6f && c[1] < 0.3f && c[2] < 0.3f;
    }
    EXPECT_GT(blue, 0u);
    EXPECT_GT(redPixels, 0u);
    // The map lands where the bake measured it: its east column (x > 0) is the east half, which
    // the probe-validity view shows through the probe that lights it.
    v.diagnostics->moved = {0, 1};
    r.setProbes({v});
    const RenderedImage validity = draw(r, kViewProbeValidity);
    size_t agree = 0, high = 0;
    for (size_t i : terrain) {
        const float* c = &validity.rgba[i * 4];
        const bool east = c[2] > c[0] + 0.3f;
        if (img.rgba[i * 4] > 0.15f) {
            ++high;
            agree += east;
        } else if (img.rgba[i * 4] < 0.05f) {
            ++high;
            agree += !east;
        }
    }
    EXPECT_GT(high, terrain.size() / 3);
    EXPECT_GT(agree, high * 95 / 100);

    // Unmeasured points (no probe around them at bake time): no value, grey.
    m.error.assign(4, NAN);
    r.setProbes({v});
    img = draw(r, kViewInterpolationError, true, true);
    const RenderedImage grey = draw(r, kViewInterpolationError);
    for (size_t i : terrain) {
        ASSERT_NEAR(img.rgba[i * 4 + 1], 0.0f, 1e-3f) << "pixel " << i;
        ASSERT_NEAR(grey.rgba[i * 4], grey.rgba[i * 4 + 2], 1e-3f) << "pixel " << i;
    }
}

TEST_F(RenderTest, LeafOverlayDrawsTheBoundLeaves) {
    ProjectRenderer r(*ctx_, sampleProject("leaves", 8, 8));
    GpuProbeVolume v = halves(r.heightfield());
    const float cell = v.spacing;
    for (int x = 0; x < 4; ++x)
        v.diagnostics->leaves.push_back(glm::vec4(v.origin + glm::vec3(float(x) * cell, 0.0f, 0.0f), cell));
    r.setProbes({v});
    RenderRequest q;
    q.width = kW;
    q.height = kH;
    q.debugView = kViewAlbedo;
    const RenderedImage plain = r.render(q);
    q.leaves = true;
    const RenderedImage lines = r.render(q);
    // Lines are pale yellow at the smallest edge; count the pixels that changed.
    size_t changed = 0;
    for (size_t i = 0; i < size_t(kW) * kH; ++i)
        changed += std::abs(lines.rgba[i * 4 + 2] - plain.rgba[i * 4 + 2]) > 0.1f;
    EXPECT_GT(changed, size_t(kW));
    // Without leaves bound, the overlay draws nothing.
    v.diagnostics->leaves.clear();
    r.setProbes({v});
    EXPECT_EQ(test::compareImages(r.render(q).rgba, plain.rgba, kW, kH).maxAbs, 0.0);
}

// The viewport's gizmo lines (volume bounds and handles): drawn in their colour in front of the
// terrain even where they run beneath it, a larger list the next frame grows the slot's buffer,
// and none leaves the frame as it was.
TEST_F(RenderTest, GizmoLinesDrawInFrontOfTheTerrain) {
    // Exact colours of one-pixel lines: without the picture's anti-aliasing, which blends them.
    Project p = sampleProject("gizmos", 4, 4);
    p.scene.camera.antialiasing = Antialiasing::Off;
    ProjectRenderer r(*ctx_, p);
    const Heightfield& hf = r.heightfield();
    RenderRequest q;
    q.width = kW;
    q.height = kH;
    const RenderedImage plain = r.render(q);
    auto magenta = [](const RenderedImage& img) {
        size_t n = 0;
        for (size_t i = 0; i < size_t(img.width) * img.height; ++i)
            n += img.rgba[i * 4] > 0.95f && img.rgba[i * 4 + 1] < 0.05f && img.rgba[i * 4 + 2] > 0.95f;
        return n;
    };
    ASSERT_EQ(magenta(plain), 0u);
    // 100 m below the lowest ground, across the footprint: hidden by the terrain if depth counted.
    const float below = hf.minHeight() - 100.0f;
    q.gizmos = {{glm::vec3(hf.minX(), below, 0.0f), glm::vec3(hf.maxX(), below, 0.0f), glm::vec3(1.0f, 0.0f, 1.0f)}};
    const size_t one = magenta(r.render(q));
    EXPECT_GT(one, size_t(kW) / 4);
    for (int k = 1; k <= 8; ++k) {
        const float z = hf.minZ() + (hf.maxZ() - hf.minZ()) * float(k) / 9.0f;
        q.gizmos.push_back({glm::vec3(hf.minX(), below, z), glm::vec3(hf.maxX(), below, z), glm::vec3(1.0f, 0.0f, 1.0f)});
    }
    EXPECT_GT(magenta(r.render(q)), 4 * one);
    q.gizmos.clear();
    EXPECT_EQ(test::compareImages(r.render(q).rgba, plain.rgba, kW, kH).maxAbs, 0.0);
}

TEST_F(RenderTest, EditsThatDoNotTouchTheVolumesPlaceNothing) {
    Project p = sampleProject("placements", 6, 6);
    ProjectRenderer r(*ctx_, p);
    const size_t placed = r.placements();
    EXPECT_EQ(placed, 1u);
    p.scene.sun.elevationDeg = 12.0;
    p.scene.sky.intensity *= 2.0;
    p.scene.camera.azimuthDeg = 90.0;
    r.setProject(p);
    EXPECT_EQ(r.placements(), placed) << "a sun, sky or camera edit placed the volumes again";
    p.scene.probeVolumes[0].gridDims = {7, 1, 5};
    r.setProject(p);
    EXPECT_EQ(r.placements(), placed + 1) << "a grid edit must place the volume again";
}

namespace {

// Whether any pass of the frame is, touches or binds anything of the probe subsystem.
std::string probeMention(const std::vector<PassInfo>& passes) {
    for (const auto& p : passes) {
        if (p.name.find("probe") != std::string::npos) return "pass " + p.name;
        for (const auto& b : p.bindings)
            if (b.find("probe") != std::string::npos) return p.name + " binds " + b;
        for (const auto& u : p.uses)
            if (u.resource.find("probe") != std::string::npos) return p.name + " uses " + u.resource;
    }
    return "";
}

std::vector<std::string> passNames(const std::vector<PassInfo>& passes) {
    std::vector<std::string> out;
    for (const auto& p : passes) out.push_back(p.name);
    return out;
}

bool binds(const std::vector<PassInfo>& passes, const std::string& pass, const std::string& binding) {
    for (const auto& p : passes)
        if (p.name == pass)
            for (const auto& b : p.bindings)
                if (b == binding) return true;
    return false;
}

}  // namespace

// Timestamps around every pass of the frame graph: one time per pass, in the frame's order, none
// negative (the ticks only grow), summing to the GPU total, which fits in the frame's wall time.
TEST_F(RenderTest, FrameTimingsArePerPassMonotoneAndWithinTheFrame) {
    if (!(ctx_->timestampPeriod() > 0.0)) GTEST_SKIP() << ctx_->deviceName() << " writes no timestamps";
    Project p = sampleProject("timings", 8, 8);
    p.scene.water.enabled = true;
    p.scene.water.level = 900.0;
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    draw(r, kViewBeauty);
    const RenderedImage img = draw(r, kViewBeauty);
    const FrameTimings& t = r.renderer().lastFrameTimings();
    ASSERT_TRUE(t.gpuTimed());
    EXPECT_EQ(t.passes.size(), r.renderer().lastFramePasses().size());
    double sum = 0;
    for (size_t i = 0; i < t.passes.size() && i < r.renderer().lastFramePasses().size(); ++i) {
        EXPECT_EQ(t.passes[i].name, r.renderer().lastFramePasses()[i].name);
        EXPECT_GE(t.passes[i].gpuMilliseconds, 0.0) << t.passes[i].name;
        EXPECT_LE(t.passes[i].gpuMilliseconds, img.milliseconds) << t.passes[i].name;
        sum += t.passes[i].gpuMilliseconds;
    }
    EXPECT_NEAR(sum, t.gpuMilliseconds, 1e-6 * std::max(1.0, sum));
    EXPECT_GT(t.gpuMilliseconds, 0.0);
    EXPECT_LE(t.gpuMilliseconds, img.milliseconds);
    EXPECT_GT(t.recordMilliseconds, 0.0);
    EXPECT_GT(t.readbackMilliseconds, 0.0);
    EXPECT_LE(t.recordMilliseconds + t.readbackMilliseconds, img.milliseconds);
    // The water and the shadow maps are passes of their own, timed like the rest.
    const std::vector<std::string> names = passNames(r.renderer().lastFramePasses());
    EXPECT_NE(std::find(names.begin(), names.end(), "terrain"), names.end());
    EXPECT_GT(names.size(), 3u);
}

TEST_F(RenderTest, ASceneWithoutProbeVolumesBindsNoProbeResources) {
    using Names = std::vector<std::string>;
    // The passes of one frame each: a fixed exposure, no metering frame drawn before it.
    const auto manual = [](Project p) {
        p.scene.camera.exposureMode = ExposureMode::Manual;
        return p;
    };
    ProjectRenderer without(*ctx_, manual(sampleProject("novolumes", 8, 8)));  // no probes loaded at all
    EXPECT_FALSE(without.renderer().hasProbeResources());
    for (const auto& v : debugViews()) {
        draw(without, v.number);
        const std::string mention = probeMention(without.renderer().lastFramePasses());
        EXPECT_TRUE(mention.empty()) << v.name << ": " << mention;
    }
    // The data views drew every vertex, the picture draws its level of detail: once for its
    // shadow maps, then the frame alone.
    draw(without, kViewBeauty);
    const RenderedImage none = draw(without, kViewBeauty);
    EXPECT_EQ(passNames(without.renderer().lastFramePasses()), (Names{"terrain", "sky", "antialias", "readback"}));

    ProjectRenderer with(*ctx_, manual(sampleProject("volumes", 8, 8)));
    ASSERT_EQ(with.loadProbes(true), 1u);
    EXPECT_TRUE(with.renderer().hasProbeResources());
    // Probes on: the probe pass runs once after the volumes changed; the terrain reads its light.
    // The shadow maps are drawn once too: the camera and the sun stay where they are.
    draw(with, kViewBeauty);
    const auto& first = with.renderer().lastFramePasses();
    EXPECT_EQ(passNames(first), (Names{"probe-vertices", "shadow", "terrain", "sky", "antialias", "readback"}));
    EXPECT_TRUE(binds(first, "probe-vertices", "probe-coefficients"));
    EXPECT_TRUE(binds(first, "terrain", "vertex:probe-light"));
    draw(with, kViewBeauty);
    EXPECT_EQ(passNames(with.renderer().lastFramePasses()), (Names{"terrain", "sky", "antialias", "readback"}));
    EXPECT_TRUE(binds(with.renderer().lastFramePasses(), "terrain", "vertex:probe-light"));
    // Probes off: nothing of them takes part, and the image is the one without volumes.
    const RenderedImage off = draw(with, kViewBeauty, false);
    EXPECT_EQ(probeMention(with.renderer().lastFramePasses()), "");
    EXPECT_EQ(test::compareImages(off.rgba, none.rgba, kW, kH).maxAbs, 0.0);
    // Views that do not read probe light leave the probes out too.
    draw(with, kViewAlbedo);
    EXPECT_EQ(probeMention(with.renderer().lastFramePasses()), "");
    // Unbinding the volumes frees the subsystem.
    with.setProbes({});
    EXPECT_FALSE(with.renderer().hasProbeResources());
    const RenderedImage unbound = draw(with, kViewBeauty);
    EXPECT_EQ(probeMention(with.renderer().lastFramePasses()), "");
    EXPECT_EQ(test::compareImages(unbound.rgba, none.rgba, kW, kH).maxAbs, 0.0);
}

TEST_F(RenderTest, EveryViewRendersFiniteAndNonBlank) {
    Project p = sampleProject("finite", 8, 8);
    ProjectRenderer r(*ctx_, p);
    addLake(p, r);
    ASSERT_EQ(r.loadProbes(true), 1u);
    r.setReflectionProbes(goldenReflections(r.heightfield()));  // the reflection views have probes to show
    for (const auto& v : debugViews())
        for (bool linear : {false, true}) {
            const RenderedImage img = draw(r, v.number, true, linear);
            ASSERT_EQ(img.rgba.size(), size_t(kW) * kH * 4);
            size_t nonFinite = 0, differing = 0;
            for (size_t i = 0; i < img.rgba.size(); ++i) {
                nonFinite += !std::isfinite(img.rgba[i]);
                differing += img.rgba[i] != img.rgba[i % 4];
            }
            EXPECT_EQ(nonFinite, 0u) << v.name << (linear ? " (linear)" : "");
            // The water-only views colour the lake and leave the land flat (a 50th of the image here).
            const size_t least = size_t(kW) * kH / (v.needs.water && !v.needs.waterShading ? 50 : 8);
            EXPECT_GT(differing, least) << v.name << (linear ? " (linear)" : "") << " is blank";
        }
}

// The AO's surface maps made on another thread (the UI's AO worker, with a command pool of its
// own: vk::WorkerCommands) and swapped in without waiting draw the frame the maps made inline do,
// bit for bit, with no validation message (TearDown).
TEST_F(RenderTest, SurfaceMapsMadeOnAWorkerDrawTheSameFrame) {
    Project p = sampleProject("aoworker", 4, 4);
    ProjectRenderer r(*ctx_, p);
    TerrainRenderer& t = r.renderer();
    const HorizonAoSettings settings = *r.wantedAo();
    const std::vector<float> field = horizonSkyVisibility(r.heightfield(), settings);
    t.setAmbientOcclusion(field);
    const RenderedImage inline_ = draw(r, kViewBeauty, false, true);
    t.setAmbientOcclusion({});
    const RenderedImage without = draw(r, kViewBeauty, false, true);
    // Made while this thread draws frames: the queue is shared under its lock, the pools are not.
    TerrainRenderer::SurfaceMapTextures maps;
    std::thread worker([&] {
        const vk::WorkerCommands commands(*ctx_);
        for (int i = 0; i < 3; ++i) maps = TerrainRenderer::prepareSurfaceMaps(*ctx_, r.heightfield(), field);
    });
    for (int i = 0; i < 3; ++i) EXPECT_EQ(draw(r, kViewBeauty, false, true).rgba, without.rgba);
    worker.join();
    EXPECT_TRUE(maps.ao);
    t.setSurfaceMaps(std::move(maps));
    EXPECT_TRUE(t.hasAmbientOcclusion());
    const RenderedImage made = draw(r, kViewBeauty, false, true);
    EXPECT_EQ(made.rgba, inline_.rgba);
    EXPECT_NE(without.rgba, inline_.rgba);  // the AO shows
    // Maps made for another terrain are refused.
    const Heightfield small(4, 4, 30.0, 30.0, std::vector<float>(16, 0.0f));
    TerrainRenderer::SurfaceMapTextures other = TerrainRenderer::prepareSurfaceMaps(*ctx_, small, {});
    EXPECT_THROW(t.setSurfaceMaps(std::move(other)), std::invalid_argument);
    // So are maps of a terrain with as many vertices (the same grid raised 1 m): a vertex count
    // does not name a terrain, its serial does.
    const Heightfield& hf = r.heightfield();
    std::vector<float> raised = hf.heights();
    for (float& h : raised) h += 1.0f;
    const Heightfield twin(hf.width(), hf.depth(), hf.cellSizeX(), hf.cellSizeZ(), raised);
    EXPECT_THROW(t.setSurfaceMaps(TerrainRenderer::prepareSurfaceMaps(*ctx_, twin, field)), std::invalid_argument);
}

// `terralux --render` to a PNG reads the frame back as its 8-bit codes: the same codes the float
// frame rounds to, sample for sample, with no float frame made (RenderRequest::bytes).
TEST_F(RenderTest, AFrameReadBackAsCodesIsTheFloatFrameRounded) {
    Project p = sampleProject("codes", 4, 4);
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    RenderRequest q = unprobed(kViewBeauty, false);
    q.probes = true;
    const RenderedImage floats = r.render(q);
    q.bytes = true;
    const RenderedImage codes = r.render(q);
    EXPECT_TRUE(codes.rgba.empty());
    ASSERT_EQ(floats.rgba.size(), size_t(kW) * kH * 4);
    ASSERT_EQ(codes.bytes.size(), floats.rgba.size());
    size_t differing = 0, distinct = 0;
    std::vector<bool> seen(256, false);
    for (size_t i = 0; i < codes.bytes.size(); ++i) {
        differing += codes.bytes[i] != unitToByte(floats.rgba[i]);
        if (!seen[codes.bytes[i]]) seen[codes.bytes[i]] = true, ++distinct;
    }
    EXPECT_EQ(differing, 0u);
    EXPECT_GT(distinct, 64u);  // a picture, not a flat frame
    // Scene-linear output stays float whatever is asked.
    q.linearOutput = true;
    const RenderedImage linear = r.render(q);
    EXPECT_TRUE(linear.bytes.empty());
    EXPECT_EQ(linear.rgba.size(), floats.rgba.size());
}

// The device layer's target kinds, samplers and image bindings, through the frame graph: a depth
// target drawn (cleared) by a depth-only pass, then read by shaders along with a layered and a
// cube target, with no validation message.
TEST_F(RenderTest, DeviceLayerTargetsSamplersAndImageBindings) {
    const vk::VulkanContext& ctx = *ctx_;
    vk::Image depth = vk::Image::depthTarget(ctx, 64, 64);
    vk::Image cascades = vk::Image::depthTarget(ctx, 64, 64, 4);
    vk::Image layered = vk::Image::layeredTarget(ctx, 32, 32, 3);
    vk::Image cube = vk::Image::cubeTarget(ctx, 16);
    vk::Image color = vk::Image::colorTarget(ctx, 8, 8);
    EXPECT_EQ(cascades.desc().layers, 4u);
    EXPECT_EQ(cube.desc().layers, 6u);
    EXPECT_EQ(depth.aspect(), VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT));
    const vk::Sampler shadow = vk::Sampler::depthBorder(ctx), linear = vk::Sampler::linearClamp(ctx),
                      nearest = vk::Sampler::nearestClamp(ctx);
    vk::Buffer block = vk::Buffer::hostVisible(ctx, 64, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
    vk::Buffer data = vk::Buffer::hostVisible(ctx, 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    constexpr VkShaderStageFlags fragment = VK_SHADER_STAGE_FRAGMENT_BIT;
    const vk::DescriptorSet set = vk::DescriptorSetBuilder()
                                      .uniform(0, "block", block, fragment)
                                      .storage(1, "data", data, fragment)
                                      .image(2, "shadow-map", depth.view(), shadow.handle(), fragment)
                                      .image(3, "cascades", cascades.view(), shadow.handle(), fragment)
                                      .image(4, "layers", layered.view(), linear.handle(), fragment)
                                      .image(5, "cube", cube.view(), linear.handle(), fragment)
                                      .image(6, "color", color.view(), nearest.handle(), fragment)
                                      .build(ctx);
    EXPECT_EQ(set.bindingNames(), (std::vector<std::string>{"block", "data", "shadow-map", "cascades",
                                                            "layers", "cube", "color"}));

    const vk::RenderPass depthOnly(ctx, {{}, vk::kDepthFormat, true, true});
    const VkImageView attachment = depth.view();
    const vk::Framebuffer framebuffer(ctx, depthOnly, {&attachment, 1}, 64, 64);
    FrameGraph graph;
    graph.importImage("shadow-map", depth.handle(), depth.aspect());
    graph.importImage("cascades", cascades.handle(), cascades.aspect(), 4);
    graph.importImage("layers", layered.handle(), layered.aspect(), 3);
    graph.importImage("cube", cube.handle(), cube.aspect(), 6);
    graph.importImage("color", color.handle(), color.aspect());
    graph.addPass({"shadow", {{"shadow-map", Access::DepthAttachmentClear}}, {}}, [&](VkCommandBuffer cb) {
        VkClearValue clear{};
        clear.depthStencil = {1.0f, 0};
        VkRenderPassBeginInfo rbi{};
        rbi.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
        rbi.renderPass = depthOnly.handle();
        rbi.framebuffer = framebuffer.handle();
        rbi.renderArea = {{0, 0}, {64, 64}};
        rbi.clearValueCount = 1;
        rbi.pClearValues = &clear;
        vkCmdBeginRenderPass(cb, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        vkCmdEndRenderPass(cb);
    });
    graph.addPass({"lit",
                   {{"shadow-map", Access::FragmentSampledRead},
                    {"cascades", Access::FragmentSampledRead},
                    {"layers", Access::FragmentSampledRead},
                    {"cube", Access::FragmentSampledRead},
                    {"color", Access::FragmentSampledRead}},
                   set.bindingNames()},
                  nullptr);
    ctx.submitAndWait([&](VkCommandBuffer cb) { graph.execute(cb); });
    EXPECT_EQ(graph.lastFrame().size(), 2u);
}

TEST_F(RenderTest, ProbesAreDecodedWithTheEncodingOfTheBakeNotOfTheProject) {
    Project baked = sampleProject("encoding", 4, 4);
    baked.scene.bake.encoding = ShEncoding::Irradiance;
    ProjectRenderer a(*ctx_, baked);
    ASSERT_EQ(a.loadProbes(true), 1u);
    EXPECT_TRUE(a.staleBake().empty());
    const RenderedImage matching = draw(a, kViewProbeIrradiance, true, true);
    // The project now asks for radiance, but the files hold irradiance until the next bake.
    Project edited = baked;
    edited.scene.bake.encoding = ShEncoding::Radiance;
    ProjectRenderer b(*ctx_, edited);
    ASSERT_EQ(b.loadProbes(false), 1u);
    ASSERT_EQ(b.staleBake().size(), 1u);
    EXPECT_NE(b.staleBake()[0].find("bake.sh_encoding: baked \"irradiance\", now \"radiance\""), std::string::npos)
        << b.staleBake()[0];
    EXPECT_EQ(test::compareImages(draw(b, kViewProbeIrradiance, true, true).rgba, matching.rgba, kW, kH).maxAbs, 0.0);
}

TEST_F(RenderTest, AStaleBakeIsBakedAgainBeforeItIsDrawn) {
    Project p = sampleProject("stale", 4, 4);
    {
        ProjectRenderer first(*ctx_, p);
        ASSERT_EQ(first.loadProbes(true), 1u);
    }
    p.scene.probeVolumes[0].gridDims = {6, 1, 5};
    ProjectRenderer r(*ctx_, p);
    std::string note;
    ASSERT_EQ(r.loadProbes(true, &note), 1u);
    EXPECT_NE(note.find("the bake there is stale: probe_volumes[0].grid_dims: baked [4,4], now [6,5]"), std::string::npos) << note;
    EXPECT_TRUE(r.staleBake().empty());
    EXPECT_EQ(readShProbeFile(p.outDir() / "sh_coeffs" / "probes.shprobe").probes.size(), 30u);
}

// A lighting scenario draws as a project lit that way draws, pixel for pixel; a blend between two
// mixes their probes linearly (the probe-irradiance view halfway is the mean of its two ends).
TEST_F(RenderTest, ScenariosSwitchAndBlendLikeTheirBakes) {
    Project p = sampleProject("scenarios", 5, 5);
    LightingScenario dusk;
    dusk.name = "dusk";
    dusk.sun = p.scene.sun;
    dusk.sky = p.scene.sky;
    dusk.sun.azimuthDeg = 250.0;
    dusk.sun.elevationDeg = 8.0;
    dusk.sun.illuminance = 50000.0;
    dusk.sky.intensity = 0.5;
    p.scene.scenarios = {dusk};
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    RenderRequest q;
    q.width = kW;
    q.height = kH;
    RenderRequest irradiance = q;
    irradiance.debugView = 50;
    irradiance.linearOutput = true;
    const RenderedImage def = r.render(q), defProbes = r.render(irradiance);

    r.setScenarioView({"dusk", "dusk", 0.0f});
    ASSERT_EQ(r.loadProbes(false), 1u);
    const RenderedImage shown = r.render(q), duskProbes = r.render(irradiance);
    EXPECT_GT(test::compareImages(shown.rgba, def.rgba, kW, kH).meanAbs, 0.02);

    Project lit = sampleProject("scenarios_lit", 5, 5);
    lit.scene.sun = dusk.sun;
    lit.scene.sky = dusk.sky;
    ProjectRenderer l(*ctx_, lit);
    ASSERT_EQ(l.loadProbes(true), 1u);
    EXPECT_EQ(test::compareImages(shown.rgba, l.render(q).rgba, kW, kH).maxAbs, 0.0);

    r.setScenarioView({"default", "dusk", 0.0f});
    r.loadProbes(false);
    EXPECT_EQ(test::compareImages(r.render(q).rgba, def.rgba, kW, kH).maxAbs, 0.0);
    r.setScenarioView({"default", "dusk", 1.0f});
    r.loadProbes(false);
    EXPECT_EQ(test::compareImages(r.render(q).rgba, shown.rgba, kW, kH).maxAbs, 0.0);
    r.setScenarioView({"default", "dusk", 0.5f});
    r.loadProbes(false);
    const RenderedImage half = r.render(irradiance);
    std::vector<float> mean(half.rgba.size());
    for (size_t i = 0; i < mean.size(); ++i) mean[i] = 0.5f * (defProbes.rgba[i] + duskProbes.rgba[i]);
    const auto c = test::compareImages(half.rgba, mean, kW, kH);
    EXPECT_LT(c.maxAbs, 2e-3) << "mean " << c.meanAbs;
    // A scenario the project no longer has shows the default.
    r.setScenarioView({"gone", "gone", 0.0f});
    r.loadProbes(false);
    EXPECT_EQ(test::compareImages(r.render(q).rgba, def.rgba, kW, kH).maxAbs, 0.0);
}

TEST_F(RenderTest, ShadowMapsAgreeWithTheTracedSunVisibilityAtTheDefaults) {
    Project p = sampleProject("shadow_agreement", 8, 8);
    ProjectRenderer r(*ctx_, p);
    const ShadowAgreement a = measureShadowAgreement(r, 480, 270);
    EXPECT_GT(a.terrainPixels, 480u * 270u / 5);
    EXPECT_LE(a.disagreeing, 0.03) << "mean |difference| " << a.meanAbsDifference;
    // The traced view is cached per sun: drawing it again traces nothing.
    const size_t traces = r.renderer().sunVisibilityTraces();
    draw(r, kViewSunVisibility, false, true);
    EXPECT_EQ(r.renderer().sunVisibilityTraces(), traces);
    p.scene.sun.azimuthDeg += 20.0;
    r.setProject(p);
    draw(r, kViewSunVisibility, false, true);
    EXPECT_EQ(r.renderer().sunVisibilityTraces(), traces + 1);
}

// The viewport's frames do not wait for a sun edit's horizon map (RenderSettings::waitForHorizon
// off; a 12 M-vertex map takes 275 ms): the sweep runs on a worker while the frames draw the map
// held, the first frame after it has finished takes it, and the map is the one a frame that waits
// sweeps. A frame that waits takes any sweep under way and sweeps its own sun at once.
TEST_F(RenderTest, AViewportFrameDrawsTheHorizonMapHeldWhileTheNextIsSwept) {
    Project p = sampleProject("horizon_async", 4, 4);
    p.scene.sun.elevationDeg = 5.0;
    p.scene.sun.azimuthDeg = 135.0;
    ProjectRenderer r(*ctx_, p);
    const TerrainRenderer& t = r.renderer();
    RenderRequest viewport = unprobed(kViewShadow, true);
    viewport.waitForHorizon = false;
    auto sweepOf = [&](double azimuth) {
        return sunHorizonVisibility(r.heightfield(), sunDirection(azimuth, 5.0), float(0.27 * std::numbers::pi / 180.0), true);
    };
    // An edit of the sun's azimuth, then one viewport frame (which starts its map's sweep).
    auto sunTo = [&](double azimuth) {
        p.scene.sun.azimuthDeg = azimuth;
        r.setProject(p);
        return r.render(viewport);
    };
    auto waitForSweep = [&] {
        for (int i = 0; i < 20000 && !t.sunHorizonSwept(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        return t.sunHorizonSwept();
    };
    r.render(viewport);  // the first map is swept at once: there is none to draw meanwhile
    EXPECT_FALSE(t.sunHorizonSweeping());
    ASSERT_EQ(t.sunHorizonSweeps(), 1u);
    const std::vector<float> first = t.sunHorizonMap();
    ASSERT_EQ(first, sweepOf(135.0));

    const RenderedImage held = sunTo(150.0);
    EXPECT_TRUE(t.sunHorizonSweeping());
    EXPECT_EQ(t.sunHorizonSweeps(), 1u);
    EXPECT_EQ(t.sunHorizonMap(), first);
    ASSERT_TRUE(waitForSweep());
    const RenderedImage swept = r.render(viewport);
    EXPECT_FALSE(t.sunHorizonSweeping());
    EXPECT_EQ(t.sunHorizonSweeps(), 2u);
    EXPECT_EQ(t.sunHorizonMap(), sweepOf(150.0));
    EXPECT_GT(test::compareImages(held.rgba, swept.rgba, kW, kH).meanAbs, 1e-4) << "the frame took the new map";
    // The same frame as one that waited.
    RenderRequest waits = viewport;
    waits.waitForHorizon = true;
    EXPECT_EQ(test::compareImages(r.render(waits).rgba, swept.rgba, kW, kH).maxAbs, 0.0);

    // Two edits while a sweep runs: the frames converge on the last sun.
    sunTo(165.0);
    p.scene.sun.azimuthDeg = 180.0;
    r.setProject(p);
    for (int frame = 0; frame < 4 && t.sunHorizonSweeping(); ++frame) {
        ASSERT_TRUE(waitForSweep());
        r.render(viewport);
    }
    EXPECT_FALSE(t.sunHorizonSweeping());
    EXPECT_EQ(t.sunHorizonMap(), sweepOf(180.0));
    // A frame that waits, with a sweep under way: its own sun's map at once.
    sunTo(200.0);
    EXPECT_TRUE(t.sunHorizonSweeping());
    r.render(waits);
    EXPECT_FALSE(t.sunHorizonSweeping());
    EXPECT_EQ(t.sunHorizonMap(), sweepOf(200.0));
    // The sun back where the map held was swept while another sweep ran: the map held stays.
    sunTo(215.0);
    p.scene.sun.azimuthDeg = 200.0;
    r.setProject(p);
    ASSERT_TRUE(waitForSweep());
    r.render(viewport);
    EXPECT_FALSE(t.sunHorizonSweeping());
    EXPECT_EQ(t.sunHorizonMap(), sweepOf(200.0));
    // A view that reads no horizon map lets a finished sweep go, so the viewport stops waiting.
    sunTo(230.0);
    ASSERT_TRUE(waitForSweep());
    RenderRequest albedo = viewport;
    albedo.debugView = kViewAlbedo;
    r.render(albedo);
    EXPECT_FALSE(t.sunHorizonSweeping());
}

TEST_F(RenderTest, TheHorizonMapIsSweptOncePerSunAndIsTheSweep) {
    // A 5° sun: every cascade of the default framing hands the terrain to the horizon map. It is
    // swept when the sun moves, not when the camera does, and not with the setting off; the
    // shadow view reads it at the vertices as the CPU swept it.
    Project p = sampleProject("horizon_map", 4, 4);
    p.scene.sun.elevationDeg = 5.0;
    p.scene.sun.azimuthDeg = 135.0;
    ProjectRenderer r(*ctx_, p);
    const RenderedImage first = draw(r, kViewShadow, false, true);
    const TerrainRenderer& t = r.renderer();
    ASSERT_EQ(t.sunHorizonSweeps(), 1u);
    const HorizonMapInfo info = t.horizonMapInfo();
    ASSERT_EQ(size_t(info.width) * size_t(info.height), t.sunHorizonMap().size());
    const Heightfield& hf = r.heightfield();
    const std::vector<float> cpu = sunHorizonVisibility(hf, sunDirection(135.0, 5.0), float(0.27 * std::numbers::pi / 180.0), true);
    ASSERT_EQ(cpu.size(), t.sunHorizonMap().size());
    for (size_t i = 0; i < cpu.size(); i += 97) ASSERT_EQ(cpu[i], t.sunHorizonMap()[i]) << i;
    size_t shaded = 0;
    for (float v : cpu) shaded += v < 0.5f;
    EXPECT_GT(shaded, cpu.size() / 20) << "a 5° sun shades the sample's valleys";
    p.scene.camera.azimuthDeg += 15.0;
    r.setProject(p);
    draw(r, kViewShadow, false, true);
    EXPECT_EQ(t.sunHorizonSweeps(), 1u);
    p.scene.sun.azimuthDeg = 150.0;
    r.setProject(p);
    const RenderedImage moved = draw(r, kViewShadow, false, true);
    EXPECT_EQ(t.sunHorizonSweeps(), 2u);
    EXPECT_GT(test::compareImages(moved.rgba, first.rgba, kW, kH).meanAbs, 1e-3);
    p.scene.shadows.heightfield = false;
    p.scene.sun.azimuthDeg = 160.0;
    r.setProject(p);
    const RenderedImage mapsOnly = draw(r, kViewShadow, false, true);
    EXPECT_EQ(t.sunHorizonSweeps(), 2u);
    p.scene.shadows.heightfield = true;
    r.setProject(p);
    const RenderedImage withMap = draw(r, kViewShadow, false, true);
    EXPECT_EQ(t.sunHorizonSweeps(), 3u);
    EXPECT_GT(test::compareImages(mapsOnly.rgba, withMap.rgba, kW, kH).meanAbs, 1e-3) << "the setting changes the frame";
}

// A renderer's first frame that reads the horizon map, in a viewport that must not wait, finds
// it not ready: its sweep starts on a worker, and once it has landed the frame draws with that
// map (no second sweep) the frame a renderer that swept where it recorded draws.
TEST_F(RenderTest, TheFirstHorizonMapIsSweptOnAWorkerBeforeTheFirstFrame) {
    Project p = sampleProject("horizon_first", 4, 4);
    p.scene.sun.elevationDeg = 5.0;
    p.scene.sun.azimuthDeg = 135.0;
    ProjectRenderer inlineRenderer(*ctx_, p);
    const RenderedImage swept = draw(inlineRenderer, kViewShadow, false, true);
    ASSERT_EQ(inlineRenderer.renderer().sunHorizonSweeps(), 1u);
    ProjectRenderer r(*ctx_, p);
    TerrainRenderer& t = r.renderer();
    RenderRequest q = unprobed(kViewShadow, true);
    const RenderSettings s = r.settingsOf(q, r.defaultCamera());
    EXPECT_FALSE(t.sunHorizonReady(s));
    EXPECT_TRUE(t.sunHorizonSweeping());
    EXPECT_EQ(t.sunHorizonSweeps(), 0u);
    for (int i = 0; i < 2000 && !t.sunHorizonSwept(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_FALSE(t.sunHorizonAwaited());
    EXPECT_TRUE(t.sunHorizonReady(s));
    q.waitForHorizon = false;
    const RenderedImage drawn = r.render(q);
    EXPECT_EQ(t.sunHorizonSweeps(), 1u);
    EXPECT_FALSE(t.sunHorizonSweeping());
    EXPECT_EQ(drawn.rgba, swept.rgba);
    // A view without shadows reads no map: ready at once, nothing swept.
    ProjectRenderer albedoOnly(*ctx_, p);
    EXPECT_TRUE(albedoOnly.renderer().sunHorizonReady(albedoOnly.settingsOf(unprobed(kViewAlbedo, true),
                                                                               albedoOnly.defaultCamera())));
    EXPECT_FALSE(albedoOnly.renderer().sunHorizonSweeping());
}

// Shadow maps against the traced sun at low, middle and high suns, from the default framing
// (far) and from a camera a third as far and low over the terrain (near), where a cascade texel
// is smallest and the low sun's slope across it steepest: acne (exactly lit pixels the maps
// darken) and agreement.
struct ShadowCase {
    std::string dem;  // empty: the embedded sample
    double sunDeg;
    bool near;
    bool heightfield = true;  // shadows.heightfield
};

ShadowAgreement shadowCase(vk::VulkanContext& ctx, const ShadowCase& c, uint32_t w, uint32_t h) {
    std::vector<std::string> sets = {"probe_volumes[0].enabled=false", "sun.mode=\"manual\"",
                                     "sun.azimuth_deg=135", "sun.elevation_deg=" + std::to_string(c.sunDeg),
                                     "camera.azimuth_deg=210"};
    if (c.near) sets.push_back("camera.elevation_deg=15");
    if (!c.heightfield) sets.push_back("shadows.heightfield=false");
    Project p = loadEffectiveProject("", sets, c.dem, nullptr);
    p.scene.exportSettings.outDir = (kOut / "bake_shadow_cases").string();
    ProjectRenderer r(ctx, p);
    if (c.near) {
        Project q = p;
        q.scene.camera.radius = double(r.defaultCamera().radius) / 3.0;
        r.setProject(q);
    }
    return measureShadowAgreement(r, w, h);
}

std::string describe(const ShadowCase& c) {
    return (c.dem.empty() ? std::string("sample") : fs::path(c.dem).filename().string()) + " sun " +
           std::to_string(int(c.sunDeg)) + "° " + (c.near ? "near" : "far") + (c.heightfield ? "" : ", maps only");
}

std::string describe(const ShadowCase& c, const ShadowAgreement& a) {
    return describe(c) + ": acne " + std::to_string(100.0 * a.acne) + " % of " + std::to_string(a.tracedLitPixels) +
           " lit pixels, disagreeing " + std::to_string(100.0 * a.disagreeing) + " %, mean |difference| " +
           std::to_string(a.meanAbsDifference);
}

TEST_F(RenderTest, ShadowMapsHaveNoAcneAtLowMiddleAndHighSuns) {
    // Before the receiver plane, 5 to 17 % of the exactly lit pixels were acne in every case, and
    // without the skirt in the maps up to 13 % of the pixels disagreed at a 5° sun, far. The
    // terminator is the mesh's (the normal map's filtered normal left 2 % acne at 480 × 270).
    const fs::path dems = fs::path(TERRALUX_SOURCE_DIR) / "tests" / "data" / "dem";
    for (const std::string& dem : {std::string(), (dems / "n42e001_voids_crop.tif").string(), (dems / "rainier_crop.tif").string()})
        for (double sun : {5.0, 12.0, 35.0})
            for (bool near : {false, true}) {
                const ShadowCase c{dem, sun, near};
                const ShadowAgreement a = shadowCase(*ctx_, c, 480, 270);
                const std::string what = describe(c, a);
                std::cout << what << "\n";
                EXPECT_GT(a.tracedLitPixels, 480u * 270u / 50) << what;
                EXPECT_LE(a.acne, 0.005) << what;
                // The crops, 80 cells filling the view, draw a DEM cell over several pixels: the
                // near cascades' maps draw edges within a cell that the traced visibility,
                // interpolated between vertices, cannot (up to 2.9 % apart, measured).
                EXPECT_LE(a.disagreeing, dem.empty() ? 0.02 : 0.03) << what;
                EXPECT_LE(a.meanAbsDifference, 0.055) << what;
            }
}

TEST_F(RenderTest, WholeMountainTilesAgreeWithTheTracedSunAtLowSuns) {
    // A whole 80 km tile from the default framing: a cascade texel (about 40 m) loses the shadows
    // shorter than 0.75 texel / tan(sun) on the ground, several DEM cells at a low sun, and with
    // the maps alone 10 % of the pixels disagreed with the traced sun at 5° and 12°. The terrain's
    // horizon map stands in for those cascades. Needs the shared DEMs; skips without them.
    const fs::path dems = fs::path(TERRALUX_SHARED_DATA) / "dem";
    size_t cases = 0;
    for (const char* name : {"N42E001.hgt", "mt_rainier_90m.tif"}) {
        const fs::path dem = dems / name;
        if (!fs::exists(dem)) continue;
        for (double sun : {5.0, 12.0, 35.0})
            for (bool near : {false, true}) {
                const ShadowCase c{dem.string(), sun, near};
                const ShadowAgreement a = shadowCase(*ctx_, c, 480, 270);
                const std::string what = describe(c, a);
                std::cout << what << "\n";
                EXPECT_LE(a.acne, 0.005) << what;
                EXPECT_LE(a.disagreeing, 0.02) << what;
                EXPECT_LE(a.meanAbsDifference, 0.03) << what;
                ++cases;
            }
        // The setting does what it says: the maps alone miss the low relief's shadows.
        const ShadowCase mapsOnly{dem.string(), 5.0, false, false};
        const ShadowAgreement a = shadowCase(*ctx_, mapsOnly, 480, 270);
        std::cout << describe(mapsOnly, a) << "\n";
        EXPECT_GT(a.disagreeing, 0.05) << describe(mapsOnly, a);
    }
    if (cases == 0) GTEST_SKIP() << "the shared DEMs are not installed beside the repository";
}

TEST_F(RenderTest, TheSkirtShadowsTheBorderAtALowSunAndGoesWithIt) {
    // A 5° sun from the south-east: the border profile extruded beyond the footprint shades the
    // footprint's edges, as the bake's tracer has it. Turning the skirt off redraws the maps
    // without it: the frame equals a renderer made with the skirt off.
    Project p = sampleProject("skirt_shadow", 4, 4);
    p.scene.sun.azimuthDeg = 135.0;
    p.scene.sun.elevationDeg = 5.0;
    ProjectRenderer r(*ctx_, p);
    const RenderedImage with = draw(r, kViewShadow, false, true);
    p.scene.terrain.skirt = false;
    r.setProject(p);
    const RenderedImage toggled = draw(r, kViewShadow, false, true);
    ProjectRenderer fresh(*ctx_, p);
    const RenderedImage without = draw(fresh, kViewShadow, false, true);
    EXPECT_EQ(test::compareImages(toggled.rgba, without.rgba, kW, kH).maxAbs, 0.0);
    // Red holds the factor, green 1 on terrain: the skirt only darkens.
    size_t terrain = 0, darker = 0, lighter = 0;
    for (size_t i = 0; i + 3 < with.rgba.size(); i += 4) {
        if (with.rgba[i + 1] < 0.5f) continue;
        ++terrain;
        if (with.rgba[i] < without.rgba[i] - 0.5f) ++darker;
        if (with.rgba[i] > without.rgba[i] + 0.5f) ++lighter;
    }
    EXPECT_GT(darker, terrain / 100) << terrain << " terrain pixels";
    EXPECT_LE(lighter, terrain / 1000) << terrain << " terrain pixels";
}

TEST_F(RenderTest, BelowTheHorizonTheSkyPassDrawsTheSkirtsGround) {
    // Fog off, a uniform sky L, a constant albedo ρ: below the horizon beyond the terrain the
    // skirt is level ground, ρ/π·(π·L + E_sun·sin(elevation)); with the skirt off, the horizon's L.
    Project p = sampleProject("ground", 4, 4);
    p.scene.fog.enabled = false;
    p.scene.terrain.albedoMode = AlbedoMode::Constant;
    p.scene.terrain.albedo = glm::vec3(0.25f, 0.3f, 0.35f);
    p.scene.sun.elevationDeg = 30.0;
    ProjectRenderer r(*ctx_, p);
    const RenderedImage on = draw(r, kViewBeauty, false, true);
    p.scene.terrain.skirt = false;
    r.setProject(p);
    const RenderedImage off = draw(r, kViewBeauty, false, true);
    const glm::vec3 sky = p.scene.sky.uniformRadiance();
    const glm::vec3 sun = p.scene.sun.color * sceneUnitsOfLux(p.scene.sun.illuminance);
    const glm::vec3 ground = p.scene.terrain.albedo / std::numbers::pi_v<float> *
                             (std::numbers::pi_v<float> * sky + sun * float(std::sin(30.0 * std::numbers::pi / 180.0)));
    // The bottom corners lie below the horizon, beside the terrain at the default framing.
    for (const uint32_t x : {1u, kW - 2}) {
        const size_t i = (size_t(kH - 2) * kW + x) * 4;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(on.rgba[i + size_t(c)], ground[c], 1e-3f * ground[c] + 1e-6f) << "x " << x << " channel " << c;
            EXPECT_NEAR(off.rgba[i + size_t(c)], sky[c], 1e-3f * sky[c] + 1e-6f) << "x " << x << " channel " << c;
        }
    }
}

TEST_F(RenderTest, ARidgeShadowsTheValleyBehindItAtALowSun) {
    // The U valley with the sun low in the east: the east wall's shadow falls on the floor's east
    // side; the west wall faces the sun.
    Project p = sampleProject("ridge_shadow", 8, 8);
    p.scene.terrain.dem = writeValleyDem().string();
    p.scene.camera.elevationDeg = 89.5;
    p.scene.camera.azimuthDeg = 180.0;
    p.scene.sun.azimuthDeg = 90.0;
    p.scene.sun.elevationDeg = 20.0;
    p.scene.fog.enabled = false;
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    RenderRequest q;
    q.width = kW;
    q.height = kW;
    q.linearOutput = true;
    q.debugView = kViewSunVisibility;
    const RenderedImage traced = r.render(q);
    q.debugView = kViewShadow;
    const RenderedImage mapped = r.render(q);
    q.debugView = kViewLinear;
    const RenderedImage beauty = r.render(q);
    // A floor pixel (image centre row) just east of the valley's axis is shadowed; one on the
    // sunlit west wall's plateau is lit. Columns run west to east.
    size_t shadowedFloor = 0, litFloor = 0;
    double shadowedLight = 0.0, litLight = 0.0;
    for (uint32_t y = kW / 3; y < 2 * kW / 3; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            const size_t i = (size_t(y) * kW + x) * 4;
            if (traced.rgba[i + 1] < 0.5f) continue;
            if (traced.rgba[i] < 0.01f) {
                ++shadowedFloor;
                EXPECT_LT(mapped.rgba[i], 0.5f) << "pixel " << x << "," << y << " is in the traced shadow";
                shadowedLight += beauty.rgba[i + 1];
            } else if (traced.rgba[i] > 0.99f) {
                ++litFloor;
                litLight += beauty.rgba[i + 1];
            }
        }
    ASSERT_GT(shadowedFloor, 50u);
    ASSERT_GT(litFloor, 50u);
    EXPECT_LT(shadowedLight / double(shadowedFloor), 0.5 * litLight / double(litFloor));
}

TEST_F(RenderTest, FarTerrainIsFoggierThanNearTerrain) {
    Project p = sampleProject("fog", 8, 8);
    p.scene.fog.enabled = true;
    // Fog the same at every height: the amount then grows with distance alone.
    p.scene.fog.scaleHeight = 0.0;
    p.scene.fog.density = 1e-4;
    p.scene.camera.elevationDeg = 15.0;
    ProjectRenderer r(*ctx_, p);
    const RenderedImage fog = draw(r, kViewFog, false, true);
    // Mean fog amount of each image row's terrain pixels; rows higher in the image are farther.
    std::vector<double> rows;
    for (uint32_t y = 0; y < kH; ++y) {
        double s = 0;
        size_t n = 0;
        for (uint32_t x = 0; x < kW; ++x) {
            const size_t i = (size_t(y) * kW + x) * 4;
            if (fog.rgba[i + 1] < 0.5f) continue;
            s += fog.rgba[i];
            ++n;
        }
        if (n > kW / 8) rows.push_back(s / double(n));
    }
    ASSERT_GT(rows.size(), size_t(kH / 3));
    const size_t band = rows.size() / 5;
    double farBand = 0, nearBand = 0;
    for (size_t i = 0; i < band; ++i) {
        farBand += rows[i] / double(band);
        nearBand += rows[rows.size() - 1 - i] / double(band);
    }
    EXPECT_GT(farBand, 1.3 * nearBand) << "far " << farBand << " near " << nearBand;
    EXPECT_GT(nearBand, 0.0);
    // Without fog the view is zero on the terrain and no pass binds the fog.
    p.scene.fog.enabled = false;
    r.setProject(p);
    const RenderedImage none = draw(r, kViewFog, false, true);
    for (size_t i = 0; i < none.rgba.size(); i += 4) ASSERT_EQ(none.rgba[i], 0.0f);
    for (const auto& pass : r.renderer().lastFramePasses())
        for (const auto& b : pass.bindings) EXPECT_NE(b, "fog") << pass.name;
}

TEST_F(RenderTest, ShadowsOffDrawsNoShadowPassAndHoldsNoMaps) {
    Project p = sampleProject("no_shadows", 8, 8);
    p.scene.camera.exposureMode = ExposureMode::Manual;  // the passes of one frame, no metering frame
    ProjectRenderer r(*ctx_, p);
    draw(r, kViewBeauty, false);
    EXPECT_TRUE(r.renderer().hasShadowResources());
    const auto passes = passNames(r.renderer().lastFramePasses());
    EXPECT_NE(std::find(passes.begin(), passes.end(), "shadow"), passes.end());
    // The same frame again: the cascades did not move, so the maps are not drawn again.
    draw(r, kViewBeauty, false);
    const auto again = passNames(r.renderer().lastFramePasses());
    EXPECT_EQ(std::find(again.begin(), again.end(), "shadow"), again.end());
    p.scene.shadows.enabled = false;
    r.setProject(p);
    draw(r, kViewBeauty, false);
    EXPECT_FALSE(r.renderer().hasShadowResources());
    for (const auto& pass : r.renderer().lastFramePasses()) {
        EXPECT_NE(pass.name, "shadow");
        for (const auto& b : pass.bindings) EXPECT_EQ(b.find("shadow"), std::string::npos) << pass.name;
    }
}

// The exposure meter reads a view at one size whatever scale the viewport draws it at: a size
// rounded from each scale's own shape gives a 710 x 725 window 131 rows at four scales and 130 at
// a quarter, so a still view drawn small would be metered again.
TEST(MeterSize, OneSizeForAViewAtEveryScaleOfItsWindow) {
    const uint32_t windowWidth = 710, windowHeight = 725;
    std::set<std::pair<uint32_t, uint32_t>> own, window;
    for (double scale : DynamicResolution::kScales) {
        const ScaledSize size = scaledSize(windowWidth, windowHeight, scale);
        RenderRequest r;
        r.width = size.width;
        r.height = size.height;
        own.insert(meterSize(r, ProjectRenderer::kMeterWidth));
        r.windowWidth = windowWidth;
        r.windowHeight = windowHeight;
        window.insert(meterSize(r, ProjectRenderer::kMeterWidth));
    }
    EXPECT_EQ(own.size(), 2u) << "the scales' own shapes no longer round apart: pick another window";
    ASSERT_EQ(window.size(), 1u);
    EXPECT_EQ(*window.begin(), std::make_pair(128u, 131u));
}

// A sun that gives no light (0 lx, or an image sky without a glow) has nothing to shadow: a lit
// view draws no maps for it and looks as it does with shadows off; the shadow view still shows them.
TEST_F(RenderTest, ASunWithoutLightDrawsNoShadowMapsInALitView) {
    Project p = sampleProject("dark_sun", 8, 8);
    p.scene.camera.exposureMode = ExposureMode::Manual;
    p.scene.sky.mode = SkyMode::Uniform;
    p.scene.sun.followSky = false;
    p.scene.sun.illuminance = 0.0;
    ProjectRenderer r(*ctx_, p);
    const RenderedImage dark = draw(r, kViewBeauty, false, true);
    for (const auto& pass : r.renderer().lastFramePasses()) {
        EXPECT_NE(pass.name, "shadow");
        for (const auto& b : pass.bindings) EXPECT_EQ(b.find("shadow"), std::string::npos) << pass.name;
    }
    EXPECT_FALSE(r.renderer().sunHorizonSweeping());
    draw(r, kViewShadow, false, true);
    const auto shown = passNames(r.renderer().lastFramePasses());
    EXPECT_NE(std::find(shown.begin(), shown.end(), "shadow"), shown.end()) << "the shadow view draws no maps";

    p.scene.shadows.enabled = false;
    r.setProject(p);
    const RenderedImage off = draw(r, kViewBeauty, false, true);
    ASSERT_EQ(dark.rgba.size(), off.rgba.size());
    double most = 0.0, sum = 0.0;
    for (size_t i = 0; i < off.rgba.size(); ++i) {
        most = std::max(most, double(std::abs(dark.rgba[i] - off.rgba[i])));
        sum += double(off.rgba[i]);
    }
    EXPECT_GT(sum, 0.0) << "the sky alone lights the terrain";
    EXPECT_LE(most, 1e-6) << "a dark sun's frame differs from the frame with shadows off";

    // The same scene with the sun lit draws its maps in the beauty view.
    p.scene.shadows.enabled = true;
    p.scene.sun.illuminance = 100000.0;
    r.setProject(p);
    draw(r, kViewBeauty, false, true);
    const auto lit = passNames(r.renderer().lastFramePasses());
    EXPECT_NE(std::find(lit.begin(), lit.end(), "shadow"), lit.end()) << "a lit sun's beauty frame draws no maps";
}

namespace {

// A projected GeoTIFF of n x n heights h(column, row) with `cell` metre cells; NaN heights are
// written as the band's nodata value.
fs::path writeDem(const std::string& name, int n, double cell, const std::function<float(int, int)>& h) {
    const fs::path path = kOut / (name + ".tif");
    GDALAllRegister();
    GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(path.c_str(), n, n, 1, GDT_Float32, nullptr);
    double gt[6] = {500000.0, cell, 0.0, 4000000.0, 0.0, -cell};
    ds->SetGeoTransform(gt);
    OGRSpatialReference srs;
    srs.importFromEPSG(32633);
    ds->SetSpatialRef(&srs);
    constexpr float kNodata = -9999.0f;
    ds->GetRasterBand(1)->SetNoDataValue(kNodata);
    std::vector<float> v(size_t(n) * size_t(n));
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            const float x = h(c, r);
            v[size_t(r) * size_t(n) + size_t(c)] = std::isnan(x) ? kNodata : x;
        }
    if (ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, n, n, v.data(), n, n, GDT_Float32, 0, 0, nullptr) != CE_None)
        ADD_FAILURE() << "cannot write " << path;
    GDALClose(ds);
    return path;
}

// Straight down on the terrain, north up, square image: columns run west to east.
Project topDown(Project p, const fs::path& dem) {
    p.scene.terrain.dem = dem.string();
    p.scene.camera.elevationDeg = 89.5;
    p.scene.camera.azimuthDeg = 180.0;
    p.scene.fog.enabled = false;
    return p;
}

RenderedImage drawSquare(ProjectRenderer& r, int view, bool linear, bool probes = true) {
    return draw(r, view, probes, linear, kW, kW);
}

// Mean of channel `c` over image columns [x0, x1) of the middle half of the rows.
double stripMean(const RenderedImage& img, uint32_t x0, uint32_t x1, int c = 0) {
    double sum = 0.0;
    size_t count = 0;
    for (uint32_t y = img.height / 4; y < 3 * img.height / 4; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            sum += img.rgba[(size_t(y) * img.width + x) * 4 + size_t(c)];
            ++count;
        }
    return sum / double(count);
}

}  // namespace

TEST_F(RenderTest, AoIsDarkerOnAValleyFloorThanOnItsRidges) {
    Project p = topDown(sampleProject("ao_valley", 8, 8), writeValleyDem());
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    ASSERT_TRUE(r.renderer().hasAmbientOcclusion());
    const RenderedImage ao = drawSquare(r, kViewAo, true);
    // The footprint spans about 150 pixels: the floor is the middle 30, the plateaus start 40 out.
    const double floor = stripMean(ao, kW / 2 - 15, kW / 2 + 15);
    const double plateauWest = stripMean(ao, kW / 2 - 56, kW / 2 - 48);
    const double plateauEast = stripMean(ao, kW / 2 + 48, kW / 2 + 56);
    // The floor, 110 m wide between walls 660 m high, sees a slot of sky; the plateaus nearly all of it.
    EXPECT_LT(floor, 0.6) << "floor";
    EXPECT_GT(plateauWest, 0.9) << "west plateau";
    EXPECT_GT(plateauEast, 0.9) << "east plateau";

    // The beauty image with AO against without, with the probes and with the sky alone. The sky
    // light of the floor is darkened by the whole AO; probe light only by the AO finer than the
    // probes (the floor is narrower than their spacing). The plateaus' AO is 1: no change there.
    const RenderedImage lit = drawSquare(r, kViewLinear, true), litSky = drawSquare(r, kViewLinear, true, false);
    p.scene.ao.enabled = false;
    r.setProject(p);
    const RenderedImage unlit = drawSquare(r, kViewLinear, true), unlitSky = drawSquare(r, kViewLinear, true, false);
    auto floorOf = [](const RenderedImage& img) { return stripMean(img, kW / 2 - 15, kW / 2 + 15, 1); };
    auto plateauOf = [](const RenderedImage& img) { return stripMean(img, kW / 2 - 56, kW / 2 - 48, 1); };
    std::cout << "floor with / without AO: probes " << floorOf(lit) << " / " << floorOf(unlit) << ", sky alone "
              << floorOf(litSky) << " / " << floorOf(unlitSky) << "\n";
    EXPECT_LT(floorOf(lit), 0.97 * floorOf(unlit));
    EXPECT_LT(floorOf(litSky), 0.7 * floorOf(unlitSky));
    EXPECT_NEAR(plateauOf(lit), plateauOf(unlit), 1e-3 * plateauOf(unlit));
}

TEST_F(RenderTest, FilledViewTintsTheFilledCellsOnly) {
    // A gentle slope with a 17 x 17 hole in the middle.
    const int n = 65;
    const fs::path dem = writeDem("holed", n, 10.0, [&](int c, int r) {
        if (std::abs(c - n / 2) <= 8 && std::abs(r - n / 2) <= 8) return std::nanf("");
        return float(c) * 2.0f + float(r);
    });
    ProjectRenderer r(*ctx_, topDown(sampleProject("holed", 4, 4), dem));
    ASSERT_EQ(r.loadProbes(true), 1u);
    ASSERT_GT(r.heightfield().nodataCount(), 200u);
    const RenderedImage filled = drawSquare(r, kViewFilled, false);
    const RenderedImage beauty = drawSquare(r, kViewBeauty, false);
    auto magenta = [](const RenderedImage& img, uint32_t x, uint32_t y) {
        const float* p = &img.rgba[(size_t(y) * img.width + x) * 4];
        return p[0] - p[1];
    };
    // The image centre is inside the hole: tinted. A quarter of the way in is outside it: untouched.
    EXPECT_GT(magenta(filled, kW / 2, kW / 2), 0.3f);
    EXPECT_LT(std::abs(magenta(beauty, kW / 2, kW / 2)), 0.1f);
    for (uint32_t x : {kW / 2 - 45, kW / 2 + 45}) {
        const size_t i = (size_t(kW / 2) * kW + x) * 4;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(filled.rgba[i + size_t(c)], beauty.rgba[i + size_t(c)], 1.0f / 255.0f) << x;
    }
}

namespace {

// Spatial and temporal sparkle of a grazing-sun highlight: the standard deviation of luminance over
// the brightest tenth of terrain pixels, and the mean change of those pixels when the camera turns
// by a quarter degree.
struct Sparkle {
    double spatial = 0.0, temporal = 0.0;
};

Sparkle sparkleOf(ProjectRenderer& r, const OrbitCamera& camera) {
    const RenderRequest q = unprobed(kViewLinear, true);
    OrbitCamera turned = camera;
    turned.azimuthDeg += 0.25;
    const RenderedImage a = r.render(q, camera), b = r.render(q, turned);
    auto luma = [](const RenderedImage& img, size_t i) {
        return 0.2126 * img.rgba[i * 4] + 0.7152 * img.rgba[i * 4 + 1] + 0.0722 * img.rgba[i * 4 + 2];
    };
    std::vector<std::pair<double, size_t>> pixels;
    for (size_t i = 0; i < size_t(kW) * kH; ++i)
        if (a.rgba[i * 4 + 3] > 0.0f && luma(a, i) > 0.0) pixels.emplace_back(luma(a, i), i);
    std::sort(pixels.rbegin(), pixels.rend());
    pixels.resize(pixels.size() / 10);
    double mean = 0.0;
    for (const auto& [l, i] : pixels) mean += l;
    mean /= double(pixels.size());
    Sparkle s;
    for (const auto& [l, i] : pixels) {
        s.spatial += (l - mean) * (l - mean);
        s.temporal += std::abs(luma(b, i) - l);
    }
    s.spatial = std::sqrt(s.spatial / double(pixels.size())) / mean;
    s.temporal /= double(pixels.size()) * mean;
    return s;
}

}  // namespace

TEST_F(RenderTest, NormalVarianceCalmsSubPixelRidgesAndLeavesAPlaneAlone) {
    // Ridges 12 m apart (six cells, so the vertex normals see them) seen from about a kilometre
    // at a grazing sun: several ridges per pixel.
    const int n = 257;
    const fs::path ridges = writeDem("ridges", n, 2.0, [](int c, int) {
        return 1.2f * std::sin(float(c) * 2.0f * std::numbers::pi_v<float> / 6.0f);
    });
    Project p = sampleProject("ridges", 2, 2);
    p.scene.terrain.dem = ridges.string();
    p.scene.terrain.roughness = kRoughnessFloor;
    p.scene.detail.enabled = false;
    p.scene.shadows.enabled = false;
    p.scene.fog.enabled = false;
    p.scene.camera.elevationDeg = 12.0;
    p.scene.camera.azimuthDeg = 270.0;  // in the west, looking east across the ridges
    p.scene.sun.azimuthDeg = 90.0;      // low in the east: its glint comes back to the camera
    p.scene.sun.elevationDeg = 12.0;
    ProjectRenderer r(*ctx_, p);
    const OrbitCamera camera = r.defaultCamera();
    const Sparkle on = sparkleOf(r, camera);
    p.scene.terrain.specularAA = false;
    r.setProject(p);
    const Sparkle off = sparkleOf(r, camera);
    std::cout << "sparkle with specular_aa on: spatial " << on.spatial << ", temporal " << on.temporal
              << "; off: spatial " << off.spatial << ", temporal " << off.temporal << "\n";
    EXPECT_LT(on.spatial, 0.8 * off.spatial) << "on " << on.spatial << " off " << off.spatial;
    EXPECT_LT(on.temporal, 0.8 * off.temporal) << "on " << on.temporal << " off " << off.temporal;

    // A plane has no normal variance: the image is the same with the widening on or off.
    Project flat = p;
    flat.scene.terrain.dem = writeDem("plane", 65, 10.0, [](int, int) { return 100.0f; }).string();
    ProjectRenderer f(*ctx_, flat);
    const RenderedImage planeOff = draw(f, kViewLinear, false, true);
    flat.scene.terrain.specularAA = true;
    f.setProject(flat);
    const RenderedImage planeOn = draw(f, kViewLinear, false, true);
    EXPECT_EQ(planeOn.rgba, planeOff.rgba);
}

namespace {

// A round basin, 129 x 129 cells of 10 m: 0 m at the centre rising as the square of the
// distance to 82 m in the corners.
fs::path writeBasinDem() {
    return writeDem("basin", 129, 10.0, [](int c, int r) {
        const float dx = float(c) - 64.0f, dz = float(r) - 64.0f;
        return 0.01f * (dx * dx + dz * dz);
    });
}

// Where the ray through the centre of pixel (x, y) meets the plane y = level.
glm::vec2 planePoint(const glm::mat4& invViewProj, uint32_t w, uint32_t h, uint32_t x, uint32_t y, float level) {
    const glm::vec2 ndc((float(x) + 0.5f) / float(w) * 2.0f - 1.0f, (float(y) + 0.5f) / float(h) * 2.0f - 1.0f);
    glm::vec4 a = invViewProj * glm::vec4(ndc, 0.0f, 1.0f), b = invViewProj * glm::vec4(ndc, 1.0f, 1.0f);
    const glm::vec3 p0 = glm::vec3(a) / a.w, p1 = glm::vec3(b) / b.w;
    const float t = (level - p0.y) / (p1.y - p0.y);
    return {p0.x + t * (p1.x - p0.x), p0.z + t * (p1.z - p0.z)};
}

// The water mask of a scene-linear view 100: 1 where water is drawn.
std::vector<uint8_t> waterMask(const RenderedImage& img) {
    std::vector<uint8_t> m(size_t(img.width) * img.height);
    for (size_t i = 0; i < m.size(); ++i) m[i] = img.rgba[4 * i] > 0.5f ? 1 : 0;
    return m;
}

// Whether any pixel within `radius` of (x, y) differs in the mask from (x, y).
bool nearEdge(const std::vector<uint8_t>& m, uint32_t w, uint32_t h, uint32_t x, uint32_t y, int radius) {
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
            const int px = int(x) + dx, py = int(y) + dy;
            if (px < 0 || py < 0 || px >= int(w) || py >= int(h)) continue;
            if (m[size_t(py) * w + size_t(px)] != m[size_t(y) * w + x]) return true;
        }
    return false;
}

}  // namespace

// Top down on a basin with still water: view 100 marks water exactly where the terrain lies
// below the level, up to one pixel at the shore.
TEST_F(RenderTest, WaterMaskIsTheCellsBelowTheLevel) {
    Project p = topDown(sampleProject("water_mask", 2, 2), writeBasinDem());
    ProjectRenderer r(*ctx_, p);
    p = withWater(p, r, 20.0);
    r.setProject(p);
    ASSERT_TRUE(r.renderer().hasWaterResources());
    const RenderedImage img = drawSquare(r, kViewWaterMask, true, false);
    const Heightfield& hf = r.heightfield();
    const float level = float(*p.scene.water.level);
    const float extent = std::max({hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(), hf.maxHeight() - hf.minHeight(), 1.0f});
    const glm::mat4 inv = glm::inverse(r.defaultCamera().viewProjection(1.0f, extent));
    std::vector<uint8_t> expected(size_t(kW) * kW);
    for (uint32_t y = 0; y < kW; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            const glm::vec2 q = planePoint(inv, kW, kW, x, y, level);
            expected[size_t(y) * kW + x] = hf.contains(q.x, q.y) && hf.surfaceHeight(q.x, q.y) < level ? 1 : 0;
        }
    const std::vector<uint8_t> got = waterMask(img);
    size_t water = 0, wrong = 0;
    for (uint32_t y = 0; y < kW; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            const size_t i = size_t(y) * kW + x;
            water += got[i];
            if (got[i] != expected[i] && !nearEdge(expected, kW, kW, x, y, 1)) ++wrong;
        }
    EXPECT_GT(water, size_t(kW) * kW / 10);  // a lake of radius 450 m in a 1.3 km tile
    if (wrong > 0) {
        std::vector<float> shown(img.rgba.size(), 1.0f);
        for (size_t i = 0; i < got.size(); ++i) {
            shown[4 * i] = float(got[i]);
            shown[4 * i + 1] = float(expected[i]);
            shown[4 * i + 2] = 0.0f;
        }
        writeImage(kOut / "water_mask_got_red_expected_green.png", kW, kW, shown);
    }
    EXPECT_EQ(wrong, 0u) << "pixels more than one pixel from the shore on the wrong side";
    // Land in the EXR: 1 in green, 0 in red; water: 1 in both.
    const size_t centre = (size_t(kW / 2) * kW + kW / 2) * 4;
    EXPECT_EQ(img.rgba[centre], 1.0f);
    EXPECT_EQ(img.rgba[centre + 1], 1.0f);
}

// The waves move the water between t = 0 and 1 s; the land away from the shore stays as it was.
TEST_F(RenderTest, WavesMoveTheWaterAndLeaveTheLand) {
    Project p = sampleProject("water_time", 2, 2);
    p.scene.camera.exposureMode = ExposureMode::Manual;  // a meter would follow the waves' light
    p.scene.terrain.dem = writeBasinDem().string();
    p.scene.camera.elevationDeg = 30.0;
    ProjectRenderer r(*ctx_, p);
    p = withWater(p, r, 20.0, testWaves());
    r.setProject(p);
    const std::vector<uint8_t> mask = waterMask(r.render(unprobed(kViewWaterMask, true)));
    RenderRequest q = unprobed(kViewBeauty, false);
    const RenderedImage t0 = r.render(q);
    q.time = 1.0;
    const RenderedImage t1 = r.render(q);
    writeImage(kOut / "water_t0.png", kW, kH, t0.rgba);
    writeImage(kOut / "water_t1.png", kW, kH, t1.rgba);
    size_t waterPixels = 0, waterChanged = 0, landChanged = 0;
    for (uint32_t y = 0; y < kH; ++y)
        for (uint32_t x = 0; x < kW; ++x) {
            const size_t i = size_t(y) * kW + x;
            double d = 0.0;
            for (int c = 0; c < 3; ++c) d += std::abs(t0.rgba[4 * i + size_t(c)] - t1.rgba[4 * i + size_t(c)]);
            if (mask[i]) {
                ++waterPixels;
                if (d > 1.0 / 255.0) ++waterChanged;
            } else if (!nearEdge(mask, kW, kH, x, y, 2) && d > 0.0) {
                ++landChanged;
            }
        }
    ASSERT_GT(waterPixels, 0u);
    // A second moves the 40 m crests by 7.9 m (ω/k = √(g/k)), a pixel here: much of the water
    // changes (the deep, dark middle the least).
    EXPECT_GT(double(waterChanged) / double(waterPixels), 0.3) << waterChanged << " of " << waterPixels;
    EXPECT_EQ(landChanged, 0u);
}

// A planar reflection against the sky's: only water pixels change; and a dark mountain behind
// a lake darkens the water that reflects it, where the sky's reflection stays bright.
TEST_F(RenderTest, PlanarReflectionShowsTheDarkMountainAndChangesOnlyWater) {
    // A flat floor at 0 m, and from row 40 northward a wall rising to 600 m.
    const fs::path dem = writeDem("lake_wall", 129, 10.0, [](int, int r) {
        return r < 40 ? 600.0f * std::min(1.0f, float(40 - r) / 12.0f) : 0.0f;
    });
    Project p = sampleProject("water_reflection", 2, 2);
    p.scene.terrain.dem = dem.string();
    p.scene.terrain.albedoMode = AlbedoMode::Constant;
    p.scene.terrain.albedo = glm::vec3(0.04f);  // a dark mountain
    p.scene.camera.azimuthDeg = 180.0;          // south of the lake, looking north at the wall
    p.scene.camera.elevationDeg = 8.0;
    p.scene.sun.azimuthDeg = 180.0;             // behind the camera: the wall's face is lit
    p.scene.fog.enabled = false;
    // Which pixels change, one by one: without the anti-aliasing that carries an edge's change
    // onto its neighbours.
    p.scene.camera.antialiasing = Antialiasing::Off;
    ProjectRenderer r(*ctx_, p);
    p = withWater(p, r, 5.0);
    // Black, strongly absorbing water: what it shows is its reflection (and the sun's glint).
    p.scene.water.color = glm::vec3(0.0f);
    p.scene.water.absorption = glm::vec3(10.0f);
    r.setProject(p);
    const std::vector<uint8_t> mask = waterMask(r.render(unprobed(kViewWaterMask, true)));
    const RenderRequest q = unprobed(kViewLinear, true);
    const RenderedImage planar = r.render(q);
    p.scene.water.reflection = WaterReflection::Sky;
    r.setProject(p);
    const RenderedImage sky = r.render(q);
    writeImage(kOut / "water_planar.png", kW, kH, planar.rgba);
    writeImage(kOut / "water_sky.png", kW, kH, sky.rgba);
    size_t water = 0, darker = 0, brighter = 0, landChanged = 0;
    for (size_t i = 0; i < mask.size(); ++i) {
        const float a = planar.rgba[4 * i + 1], b = sky.rgba[4 * i + 1];
        if (mask[i]) {
            ++water;
            if (a < 0.7f * b) ++darker;
            if (a > 1.05f * b + 1e-4f) ++brighter;
        } else if (a != b) {
            ++landChanged;
        }
    }
    ASSERT_GT(water, 0u);
    EXPECT_EQ(landChanged, 0u);
    // The wall (far darker than the sky) fills the reflection of the lake's far part; nothing in
    // this scene is brighter than the sky but, at a few pixels, the wall's face where it reflects
    // the sun and the sky toward the mirrored camera: hardly any reflection gains light.
    EXPECT_GT(double(darker) / double(water), 0.05) << darker << " of " << water << " water pixels";
    EXPECT_LE(brighter, water / 200) << brighter << " of " << water << " water pixels";

    // Multisampled (where the device has 4 samples): the frame under the water is resolved for the
    // refraction, the reflection drawn at one sample a pixel, and the water shows the same wall.
    if (!(ctx_->framebufferSampleCounts() & 4u)) return;
    p.scene.water.reflection = WaterReflection::Planar;
    p.scene.camera.antialiasing = Antialiasing::Msaa4;
    r.setProject(p);
    const RenderedImage msaa = r.render(q);
    const std::vector<std::string> names = passNames(r.renderer().lastFramePasses());
    for (const char* pass : {"water-reflection", "water-scene", "water", "resolve"})
        EXPECT_NE(std::find(names.begin(), names.end(), pass), names.end()) << pass;
    size_t msaaDarker = 0;
    for (size_t i = 0; i < mask.size(); ++i)
        if (mask[i] && msaa.rgba[4 * i + 1] < 0.7f * sky.rgba[4 * i + 1]) ++msaaDarker;
    EXPECT_NEAR(double(msaaDarker), double(darker), 0.05 * double(water)) << msaaDarker << " against " << darker;
}

TEST_F(RenderTest, ThePlanarReflectionDrawsHardShadowsWhateverTheFilter) {
    // The lake and the wall of PlanarReflectionShowsTheDarkMountainAndChangesOnlyWater, the wall
    // ribbed so that a low sun from the east casts shadows with penumbrae across its face; black,
    // absorbing water shows only its reflection. The terrain's filter changes the land; the
    // water, reflecting the terrain drawn with the hard filter, stays (drawn with the scene's
    // PCSS, 44 of its 10 056 pixels changed).
    const fs::path dem = writeDem("lake_ribbed_wall", 129, 10.0, [](int c, int r) {
        const float rib = 60.0f * std::max(0.0f, std::sin(float(c) * 0.45f));
        return r < 40 ? (600.0f + rib) * std::min(1.0f, float(40 - r) / 12.0f) : 0.0f;
    });
    Project p = sampleProject("reflection_filter", 2, 2);
    p.scene.terrain.dem = dem.string();
    p.scene.camera.azimuthDeg = 180.0;
    p.scene.camera.elevationDeg = 8.0;
    p.scene.camera.antialiasing = Antialiasing::Off;
    p.scene.camera.exposureMode = ExposureMode::Manual;
    p.scene.sun.mode = SunMode::Manual;
    p.scene.sun.azimuthDeg = 100.0;
    p.scene.sun.elevationDeg = 12.0;
    p.scene.fog.enabled = false;
    ProjectRenderer r(*ctx_, p);
    p = withWater(p, r, 5.0);
    p.scene.water.color = glm::vec3(0.0f);
    p.scene.water.absorption = glm::vec3(10.0f);
    r.setProject(p);
    const uint32_t w = 480, h = 270;
    RenderRequest q = unprobed(kViewWaterMask, true);
    q.width = w;
    q.height = h;
    const std::vector<uint8_t> mask = waterMask(r.render(q));
    q.debugView = kViewLinear;
    std::map<ShadowFilter, RenderedImage> images;
    for (ShadowFilter filter : {ShadowFilter::Pcss, ShadowFilter::Hard}) {
        p.scene.shadows.filter = filter;
        r.setProject(p);
        images[filter] = r.render(q);
    }
    size_t water = 0, waterChanged = 0, landChanged = 0;
    for (size_t i = 0; i < mask.size(); ++i) {
        double d = 0.0;
        for (int c = 0; c < 3; ++c)
            d = std::max(d, double(std::abs(images[ShadowFilter::Pcss].rgba[4 * i + size_t(c)] -
                                            images[ShadowFilter::Hard].rgba[4 * i + size_t(c)])));
        if (mask[i]) {
            ++water;
            waterChanged += d > 1e-4;
        } else {
            landChanged += d > 1e-4;
        }
    }
    ASSERT_GT(water, 5000u);
    EXPECT_GT(landChanged, 500u) << "the filter changes the land's shadows";
    EXPECT_EQ(waterChanged, 0u) << "of " << water << " water pixels";
    writeImage(kOut / "reflection_filter_pcss.png", w, h, images[ShadowFilter::Pcss].rgba);
}

// Without water the frame has no water pass and binds nothing of it.
TEST_F(RenderTest, NoWaterNoWaterPass) {
    ProjectRenderer r(*ctx_, sampleProject("no_water", 2, 2));
    draw(r, kViewBeauty, false);
    EXPECT_FALSE(r.renderer().hasWaterResources());
    for (const auto& pass : r.renderer().lastFramePasses()) {
        EXPECT_EQ(pass.name.find("water"), std::string::npos) << pass.name;
        for (const auto& b : pass.bindings) EXPECT_EQ(b.find("water"), std::string::npos) << pass.name;
    }
}

// Every water setting the renderer reads changes the water it draws and nothing else.
TEST_F(RenderTest, EveryWaterSettingChangesOnlyTheWater) {
    Project p = sampleProject("water_settings", 2, 2);
    p.scene.terrain.dem = writeBasinDem().string();
    p.scene.camera.elevationDeg = 25.0;
    ProjectRenderer r(*ctx_, p);
    p = withWater(p, r, 20.0, testWaves());
    r.setProject(p);
    const std::vector<uint8_t> mask = waterMask(r.render(unprobed(kViewWaterMask, true)));
    RenderRequest q = unprobed(kViewLinear, true);
    q.time = 5.0;
    const RenderedImage base = r.render(q);
    const std::vector<std::pair<const char*, std::function<void(WaterSettings&)>>> edits = {
        {"depth_aware", [](WaterSettings& w) { w.depthAware = true; }},
        {"shore_fade_distance", [](WaterSettings& w) { w.shoreFadeDistance = 400.0; }},
        {"roughness", [](WaterSettings& w) { w.roughness = 0.6; }},
        {"color", [](WaterSettings& w) { w.color = glm::vec3(0.3f, 0.3f, 0.1f); }},
        {"absorption", [](WaterSettings& w) { w.absorption = glm::vec3(0.02f); }},
        {"distortion", [](WaterSettings& w) { w.distortion = 0.15; }},
        {"reflection_scale", [](WaterSettings& w) { w.reflectionScale = 0.25; }},
    };
    for (const auto& [name, edit] : edits) {
        Project changed = p;
        edit(changed.scene.water);
        r.setProject(changed);
        const RenderedImage img = r.render(q);
        size_t waterChanged = 0, landChanged = 0;
        for (size_t i = 0; i < mask.size(); ++i) {
            bool differs = false;
            for (int c = 0; c < 3; ++c) differs |= img.rgba[4 * i + size_t(c)] != base.rgba[4 * i + size_t(c)];
            if (mask[i]) waterChanged += differs;
            else if (!nearEdge(mask, kW, kH, uint32_t(i % kW), uint32_t(i / kW), 2)) landChanged += differs;
        }
        EXPECT_GT(waterChanged, 50u) << name;
        EXPECT_EQ(landChanged, 0u) << name;
    }
}

// ---- Reflection probes -------------------------------------------------------------------------

namespace {

// Whether any pass of the frame touches or binds anything of the reflection probes.
std::string reflectionMention(const std::vector<PassInfo>& passes) {
    for (const auto& p : passes) {
        for (const auto& b : p.bindings)
            if (b.find("reflection-probe") != std::string::npos) return p.name + " binds " + b;
        for (const auto& u : p.uses)
            if (u.resource.find("reflection-probe") != std::string::npos) return p.name + " uses " + u.resource;
    }
    return "";
}

Project withStrength(Project p, double strength) {
    p.scene.reflectionProbes.strength = strength;
    return p;
}

}  // namespace

// Strength 0 draws the image without reflection probes (within 1/255), though the probes are
// bound and read; strength 1 does not.
TEST_F(RenderTest, ReflectionStrengthZeroEqualsTheProbelessImage) {
    Project p = sampleProject("reflection_strength", 8, 8);
    ProjectRenderer r(*ctx_, p);
    addLake(p, r);
    p.scene.water.reflection = WaterReflection::Sky;  // the water reads the probes too
    r.setProject(p);
    const RenderedImage none = drawWith(r, nullptr, kViewBeauty);
    r.setProject(withStrength(p, 0.0));
    const RenderedImage zero = drawWith(r, reflectionSet(r.heightfield()), kViewBeauty);
    EXPECT_TRUE(binds(r.renderer().lastFramePasses(), "terrain", "reflection-probe-records"));
    EXPECT_TRUE(binds(r.renderer().lastFramePasses(), "water", "reflection-probe-cubes"));
    const auto d = test::compareImages(zero.rgba, none.rgba, kW, kH);
    EXPECT_LE(d.maxAbs, 1.0 / 255.0) << "at (" << d.maxX << ", " << d.maxY << ")";
    r.setProject(withStrength(p, 1.0));
    EXPECT_GT(meanAbsDiff(draw(r, kViewBeauty), none), 0.5 / 255.0);
}

// Views 52 and 53 are black without reflection probes; with a set over the footprint the colour
// view shows them on the terrain and the weight view is the strength there.
TEST_F(RenderTest, ReflectionViewsAreBlackWithoutProbesAndShowThemWith) {
    Project p = sampleProject("reflection_views", 2, 2);
    ProjectRenderer r(*ctx_, p);
    const std::vector<size_t> terrain = terrainPixels(r);
    ASSERT_GT(terrain.size(), size_t(kW) * kH / 4);
    for (int view : {kViewReflectionColor, kViewReflectionWeight})
        for (bool linear : {false, true}) {
            const RenderedImage img = drawWith(r, nullptr, view, linear);
            for (size_t i = 0; i < img.rgba.size(); ++i) {
                if (i % 4 == 3) continue;  // alpha
                ASSERT_EQ(img.rgba[i], 0.0f) << "view " << view << " pixel " << i / 4;
            }
        }
    const auto set = reflectionSet(r.heightfield());
    const RenderedImage color = drawWith(r, set, kViewReflectionColor, true);
    size_t lit = 0;
    for (size_t i : terrain) lit += color.rgba[i * 4] > 0.01f && color.rgba[i * 4 + 1] > 0.01f && color.rgba[i * 4 + 2] > 0.01f;
    EXPECT_GT(lit, terrain.size() * 99 / 100);
    r.setProject(withStrength(p, 0.5));
    const RenderedImage weight = draw(r, kViewReflectionWeight);
    for (size_t i : terrain) ASSERT_NEAR(weight.rgba[i * 4], 0.5f, 1e-3f) << "pixel " << i;
    // Half the strength, half the colour.
    const RenderedImage half = draw(r, kViewReflectionColor, true, true);
    for (size_t i : terrain) ASSERT_NEAR(half.rgba[i * 4 + 1], 0.5f * color.rgba[i * 4 + 1], 2e-3f + 2e-3f * color.rgba[i * 4 + 1]);
}

// On a flat plane seen from above, view 52 is what the bake's evaluate() gives through the grid's
// coverage, bilinear blend and box projection (an independent reference), in both encodings.
TEST_F(RenderTest, ReflectionLookupMatchesTheBakeEvaluateOnAFlatPlane) {
    Project p = topDown(sampleProject("reflection_flat", 2, 2), writeDem("flat", 65, 10.0, [](int, int) { return 0.0f; }));
    p.scene.detail.enabled = false;  // the normal is the plane's
    // Smooth enough that the lookup reads the finer mips: there the hardware's seamless filtering
    // is the bake's, while at a cube's corners (a large share of a 2 x 2 mip) Vulkan leaves it to
    // the implementation.
    p.scene.terrain.roughness = 0.25;
    ProjectRenderer r(*ctx_, p);
    const Heightfield& hf = r.heightfield();
    const float extent = std::max({hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(), hf.maxHeight() - hf.minHeight(), 1.0f});
    const OrbitCamera& camera = r.defaultCamera();
    const glm::mat4 inv = glm::inverse(camera.viewProjection(1.0f, extent));
    const float roughness = float(p.scene.terrain.roughness);  // a plane has no normal variance
    for (ReflectionEncoding encoding : {ReflectionEncoding::Cubemap, ReflectionEncoding::Faces}) {
        ReflectionSetOptions o;
        o.encoding = encoding;
        o.nx = 3;
        o.nz = 2;
        o.faceSize = 16;
        // The middle 70 % of the plane: the fade to the sky's lies on it too.
        const glm::vec2 span(hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ());
        o.region = std::make_pair(glm::vec2(hf.minX(), hf.minZ()) + 0.15f * span, 0.7f * span);
        const auto set = reflectionSet(hf, o);
        r.setReflectionProbes(set);
        const RenderedImage img = drawSquare(r, kViewReflectionColor, true);
        size_t checked = 0, off = 0, fading = 0, covered = 0;
        double worst = 0.0;
        for (uint32_t y = 0; y < kW; ++y)
            for (uint32_t x = 0; x < kW; ++x) {
                const glm::vec2 q = planePoint(inv, kW, kW, x, y, 0.0f);
                if (!hf.contains(q.x, q.y)) continue;  // the background
                const glm::vec3 pos(q.x, 0.0f, q.y);
                const glm::vec3 v = glm::normalize(camera.position() - pos);
                const glm::vec3 refl(-v.x, v.y, -v.z);  // reflect(−v, up)
                float w = 0.0f;
                const glm::vec3 radiance = referenceReflection(*set, pos, refl, roughness, w);
                const glm::vec3 expected = radiance * w;
                fading += w > 0.05f && w < 0.95f;
                covered += w > 0.0f;
                const float* got = &img.rgba[(size_t(y) * kW + x) * 4];
                ++checked;
                double e = 0.0;
                for (int c = 0; c < 3; ++c) e = std::max(e, double(std::abs(got[c] - expected[c])) / (0.01 + expected[c]));
                worst = std::max(worst, e);
                off += e > 0.03;
            }
        ASSERT_GT(fading, checked / 20);
        ASSERT_GT(covered, checked / 2);
        // A few pixels may fall on the other side of a face seam or a box wall than the reference.
        EXPECT_LT(off, checked / 100) << (encoding == ReflectionEncoding::Cubemap ? "cubemap" : "faces") << ": worst " << worst;
    }
}

// Binding a set is the only way reflection probes take part: the frames that read the
// environment's specular bind the grid, records and cubes; other views, probes off, and a null set
// bind nothing of them, and unbinding frees them and gives the image without them back.
TEST_F(RenderTest, DisablingReflectionProbesFreesThemAndDropsTheBinding) {
    Project p = sampleProject("reflection_binding", 2, 2);
    ProjectRenderer r(*ctx_, p);
    EXPECT_FALSE(r.renderer().hasReflectionResources());
    EXPECT_EQ(r.renderer().reflectionBytes(), 0u);
    const RenderedImage before = draw(r, kViewBeauty);
    EXPECT_EQ(reflectionMention(r.renderer().lastFramePasses()), "");

    const auto set = reflectionSet(r.heightfield());
    r.setReflectionProbes(set);
    EXPECT_TRUE(r.renderer().hasReflectionResources());
    // Per probe a record of 8 vec4, and its chain of 6 faces in RGBA16F.
    EXPECT_EQ(r.renderer().reflectionBytes(), set->probes.size() * (8 * 16 + set->texelsPerProbe() * 8));
    const RenderedImage with = draw(r, kViewBeauty);
    const auto& passes = r.renderer().lastFramePasses();
    for (const char* b : {"reflection-probe-grid", "reflection-probe-records", "reflection-probe-cubes"})
        EXPECT_TRUE(binds(passes, "terrain", b)) << b;
    EXPECT_GT(meanAbsDiff(with, before), 0.5 / 255.0);
    draw(r, kViewAlbedo);
    EXPECT_EQ(reflectionMention(r.renderer().lastFramePasses()), "") << "a view without specular";
    EXPECT_EQ(test::compareImages(draw(r, kViewBeauty, false).rgba, draw(r, kViewBeauty, false).rgba, kW, kH).maxAbs, 0.0);
    EXPECT_EQ(reflectionMention(r.renderer().lastFramePasses()), "") << "probes off";

    ReflectionSetOptions faces;
    faces.encoding = ReflectionEncoding::Faces;
    r.setReflectionProbes(reflectionSet(r.heightfield(), faces));
    EXPECT_EQ(r.renderer().reflectionBytes(), 4u * 8 * 16) << "the faces encoding uploads records only";

    r.setReflectionProbes(nullptr);
    EXPECT_FALSE(r.renderer().hasReflectionResources());
    EXPECT_EQ(r.renderer().reflectionBytes(), 0u);
    for (const auto& v : debugViews()) {
        draw(r, v.number);
        EXPECT_EQ(reflectionMention(r.renderer().lastFramePasses()), "") << v.name;
    }
    EXPECT_EQ(test::compareImages(draw(r, kViewBeauty).rgba, before.rgba, kW, kH).maxAbs, 0.0);
}

// Reflection probes change the image through the specular alone: what they add does not depend
// on the albedo, it has the sign of the probes' radiance against the sky's, and it is no more
// than the environment BRDF lets through (under 0.15 of the radiance difference here).
TEST_F(RenderTest, ReflectionProbesChangeTheImageThroughTheSpecularOnly) {
    Project p = sampleProject("reflection_specular", 2, 2);
    p.scene.terrain.albedoMode = AlbedoMode::Constant;
    p.scene.camera.antialiasing = Antialiasing::Off;  // pixel by pixel: no filter mixing neighbours
    ProjectRenderer r(*ctx_, p);
    const std::vector<size_t> terrain = terrainPixels(r);
    auto linear = [&](const std::shared_ptr<const ReflectionProbeSet>& set, float albedo, double strength) {
        Project q = withStrength(p, strength);
        q.scene.terrain.albedo = glm::vec3(albedo);
        r.setProject(q);
        return drawWith(r, set, kViewLinear, true);
    };
    const glm::vec3 bright(4.0f), dark(0.0f);
    for (const glm::vec3& radiance : {bright, dark}) {
        ReflectionSetOptions o;
        o.uniform = radiance;
        const auto set = reflectionSet(r.heightfield(), o);
        const RenderedImage a0 = linear(set, 0.1f, 0.0), a1 = linear(set, 0.1f, 1.0);
        const RenderedImage b0 = linear(set, 0.5f, 0.0), b1 = linear(set, 0.5f, 1.0);
        size_t rightWay = 0, sameForBoth = 0;
        for (size_t i : terrain) {
            const float da = a1.rgba[i * 4 + 1] - a0.rgba[i * 4 + 1], db = b1.rgba[i * 4 + 1] - b0.rgba[i * 4 + 1];
            rightWay += radiance.y > 1.0f ? da > 0.0f && da < 0.15f * radiance.y : da < 0.0f;
            sameForBoth += std::abs(da - db) <= 2e-3f + 0.01f * std::abs(da);
        }
        EXPECT_GT(rightWay, terrain.size() * 99 / 100) << "radiance " << radiance.y;
        EXPECT_GT(sameForBoth, terrain.size() * 99 / 100) << "radiance " << radiance.y;
    }
}

// With the sky's reflection the water reflects the nearest reflection probe where the probes
// cover it; land the probes do not reach stays as it was, bit for bit.
TEST_F(RenderTest, WaterInSkyReflectionModeUsesTheProbe) {
    Project p = sampleProject("reflection_water", 2, 2);
    p.scene.terrain.dem = writeBasinDem().string();
    p.scene.camera.elevationDeg = 30.0;
    p.scene.camera.antialiasing = Antialiasing::Off;  // pixel by pixel against the water mask
    ProjectRenderer r(*ctx_, p);
    p = withWater(p, r, 20.0, testWaves());
    p.scene.water.reflection = WaterReflection::Sky;
    r.setProject(p);
    const std::vector<uint8_t> mask = waterMask(r.render(unprobed(kViewWaterMask, true)));
    // One bright probe over the middle 80 % of the basin, no fade: the lake lies under it, the
    // land around it does not.
    const Heightfield& hf = r.heightfield();
    ReflectionSetOptions o;
    o.nx = o.nz = 1;
    o.uniform = glm::vec3(3.0f);
    o.blendDistance = 0.0f;
    const glm::vec2 span(hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ());
    o.region = std::make_pair(glm::vec2(hf.minX(), hf.minZ()) + 0.1f * span, 0.8f * span);
    const auto set = reflectionSet(hf, o);
    const RenderedImage without = drawWith(r, nullptr, kViewLinear, true);
    const RenderedImage with = drawWith(r, set, kViewLinear, true);
    const RenderedImage weight = draw(r, kViewReflectionWeight);
    size_t water = 0, brighter = 0, farLand = 0, landChanged = 0;
    for (size_t i = 0; i < mask.size(); ++i) {
        const float a = without.rgba[4 * i + 1], b = with.rgba[4 * i + 1];
        if (mask[i]) {
            ++water;
            brighter += b > a + 1e-3f;
        } else if (weight.rgba[4 * i] == 0.0f && !nearEdge(mask, kW, kH, uint32_t(i % kW), uint32_t(i / kW), 2)) {
            ++farLand;
            for (int c = 0; c < 3; ++c) landChanged += with.rgba[4 * i + size_t(c)] != without.rgba[4 * i + size_t(c)];
        }
    }
    ASSERT_GT(water, 100u);
    ASSERT_GT(farLand, 100u);
    EXPECT_GT(brighter, water * 9 / 10);
    EXPECT_EQ(landChanged, 0u);
}

// With the probe positions shown, the reflection probes are marked in their own colour (violet);
// without a set, no violet marker.
TEST_F(RenderTest, ReflectionProbeMarkersAreDrawnInTheirOwnColour) {
    Project p = sampleProject("reflection_markers", 2, 2);
    ProjectRenderer r(*ctx_, p);
    RenderRequest q = unprobed(kViewAlbedo, false);
    q.probePositions = true;
    auto violet = [](const RenderedImage& img) {
        size_t n = 0;
        for (size_t i = 0; i < img.rgba.size(); i += 4)
            n += std::abs(img.rgba[i] - 0.70f) < 0.02f && std::abs(img.rgba[i + 1] - 0.30f) < 0.02f &&
                 std::abs(img.rgba[i + 2] - 1.0f) < 0.02f;
        return n;
    };
    EXPECT_EQ(violet(r.render(q)), 0u);
    ReflectionSetOptions o;
    o.nx = 3;
    o.nz = 3;
    r.setReflectionProbes(reflectionSet(r.heightfield(), o));
    const RenderedImage marked = r.render(q);
    EXPECT_TRUE(binds(r.renderer().lastFramePasses(), "overlays", "vertex:reflection-probe-markers"));
    EXPECT_GT(violet(marked), 9u * 4);  // 6 x 6 pixels each, some hidden behind the terrain
    q.probePositions = false;
    EXPECT_EQ(violet(r.render(q)), 0u);
}

namespace {

// The sample with the LPV on and lighting.indirect `indirect`, quality `quality`.
Project lpvProject(Project p, IndirectLighting indirect, int quality = 1) {
    p.scene.lpv.enabled = true;
    p.scene.lpv.quality = quality;
    p.scene.lighting.indirect = indirect;
    return p;
}

double linearSum(const RenderedImage& img) {
    double sum = 0;
    for (size_t i = 0; i < img.rgba.size(); ++i)
        if (i % 4 != 3) sum += img.rgba[i];
    return sum;
}

}  // namespace

TEST_F(RenderTest, LpvViewsDifferFromEachOtherAndShowTheVolumes) {
    Project p = sampleProject("lpv_views", 8, 8);
    // Light that carries across the cascades and shows in the display encoding, seen from close
    // enough that the finer cascades fill much of the frame.
    p.scene.lpv.propagationWeight = 1.0;
    p.scene.lpv.indirectIntensity = 4.0;
    p.scene.camera.radius = 3000.0;
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    const std::vector<int> views = {kViewLpvCascade0, kViewLpvGeometry, kViewLpvAo, kViewLpvAll};
    std::vector<RenderedImage> images;
    for (int v : views) images.push_back(draw(r, v));
    // The LPV views draw volumes even with lpv.enabled off, computed for the camera once.
    EXPECT_FALSE(p.scene.lpv.enabled);
    EXPECT_TRUE(r.renderer().hasLpvResources());
    EXPECT_EQ(r.lpvUpdates(), 1u);
    for (size_t a = 0; a < views.size(); ++a)
        for (size_t b = a + 1; b < views.size(); ++b)
            EXPECT_GT(meanAbsDiff(images[a], images[b]), 1.0 / 255.0) << views[a] << " and " << views[b] << ": "
                                                                       << meanAbsDiff(images[a], images[b]) * 255.0;
    // View 63 marches the geometry volume: valleys are darker than the open ridges (reading the
    // texels at the point alone, it was 0.9999 nearly everywhere).
    {
        const RenderedImage ao = draw(r, kViewLpvAo, true, true);
        size_t covered = 0, shaded = 0;
        double sum = 0, least = 1;
        for (size_t i = 0; i < ao.rgba.size(); i += 4) {
            if (ao.rgba[i + 1] != 1.0f) continue;
            ++covered;
            sum += ao.rgba[i];
            least = std::min(least, double(ao.rgba[i]));
            shaded += ao.rgba[i] < 0.9f;
        }
        ASSERT_GT(covered, ao.rgba.size() / 4 / 10);
        std::cout << "lpv-ao: " << covered << " pixels in cascade 0, mean " << sum / double(covered) << ", least "
                  << least << ", " << shaded << " below 0.9\n";
        EXPECT_GT(double(shaded), 0.03 * double(covered));
        EXPECT_LT(least, 0.8);
        EXPECT_GT(sum / double(covered), 0.75);
    }
    // Lit views do not bind the LPV while lighting.indirect leaves it out.
    draw(r, kViewBeauty);
    for (const PassInfo& pass : r.renderer().lastFramePasses())
        for (const std::string& b : pass.bindings) EXPECT_NE(b, "lpv-light") << pass.name;
}

// At usable settings (the seed's weight and intensity, cascade 0 of 4 km, two cascades, quality 2,
// ratio 3) the LPV views were black: a mean of 1.1/255, and 61 and 64 apart by 0.003/255. They
// now show E/π over cascade 0's light range, the same scale for both, whatever the intensity.
TEST_F(RenderTest, LpvViewsShowTheirLightAtTheSeedsDefaults) {
    Project p = sampleProject("lpv_exposure", 8, 8);
    p.scene.lpv.size = 4000.0;
    p.scene.lpv.cascades = 2;
    p.scene.lpv.quality = 2;
    p.scene.lpv.cascadeRatio = 3.0;
    // Close enough that the finer cascade (1.3 km, centred ahead of the camera) reaches the ground.
    p.scene.camera.radius = 900.0;
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    const std::vector<size_t> terrain = terrainPixels(r);
    const RenderedImage c0 = draw(r, kViewLpvCascade0);
    const RenderedImage all = draw(r, kViewLpvAll);
    const std::optional<double> range = r.renderer().lpvViewRange();
    ASSERT_TRUE(range.has_value());
    auto terrainMean = [&](const RenderedImage& img) {
        double sum = 0;
        for (size_t i : terrain) sum += (img.rgba[i * 4] + img.rgba[i * 4 + 1] + img.rgba[i * 4 + 2]) / 3.0;
        return sum / double(terrain.size());
    };
    auto terrainDiff = [&](const RenderedImage& a, const RenderedImage& b) {
        double sum = 0;
        for (size_t i : terrain)
            for (int c = 0; c < 3; ++c) sum += std::abs(a.rgba[i * 4 + c] - b.rgba[i * 4 + c]) / 3.0;
        return sum / double(terrain.size());
    };
    std::cout << "lpv views: range " << *range << " W/(m2 sr); terrain mean 61 " << terrainMean(c0) * 255.0 << "/255, 64 "
              << terrainMean(all) * 255.0 << "/255, apart " << terrainDiff(c0, all) * 255.0 << "/255\n";
    EXPECT_GT(terrainMean(c0), 20.0 / 255.0);
    EXPECT_GT(terrainMean(all), 20.0 / 255.0);
    // Where the finer cascade covers the ground it adds its detail: the views tell them apart there.
    size_t apart = 0;
    double most = 0;
    for (size_t i : terrain) {
        double d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, double(std::abs(c0.rgba[i * 4 + c] - all.rgba[i * 4 + c])));
        apart += d > 8.0 / 255.0;
        most = std::max(most, d);
    }
    std::cout << "lpv views: " << apart << " of " << terrain.size() << " terrain pixels apart by more than 8/255, most "
              << most * 255.0 << "/255\n";
    EXPECT_GT(double(apart), 0.02 * double(terrain.size()));
    // EXR keeps the physical E/π; the PNG is that over the range through the display curve
    // (tonemap.glsl: ACES fit, then sRGB), not the camera's exposure.
    const RenderedImage linear = draw(r, kViewLpvAll, true, true);
    auto shown = [](double x) { return glsl::srgbEncode(glsl::acesFit(float(x))); };
    double off = 0;
    for (size_t i : terrain) off += std::abs(shown(linear.rgba[i * 4 + 1] / *range) - all.rgba[i * 4 + 1]);
    EXPECT_LT(off / double(terrain.size()), 0.5 / 255.0);
    // The exposure follows the light: four times the intensity draws the same PNG.
    p.scene.lpv.indirectIntensity = 4.0;
    r.setProject(p);
    const RenderedImage brighter = draw(r, kViewLpvAll);
    EXPECT_NEAR(*r.renderer().lpvViewRange(), 4.0 * *range, 1e-6 * *range);
    EXPECT_LT(terrainDiff(brighter, all), 1.0 / 255.0);
}

TEST_F(RenderTest, IndirectNoneEqualsTheImageWithoutIndirectLight) {
    Project p = sampleProject("indirect_none", 8, 8);
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    const RenderedImage unlit = draw(r, kViewLinear, false, true);
    for (bool lpvOn : {false, true}) {
        p.scene.lighting.indirect = IndirectLighting::None;
        p.scene.lpv.enabled = lpvOn;
        r.setProject(p);
        const RenderedImage none = draw(r, kViewLinear, true, true);
        EXPECT_EQ(none.rgba, unlit.rgba) << "lpv.enabled " << lpvOn;
        EXPECT_FALSE(r.renderer().hasLpvResources());
        // An LPV view computes volumes; the next frame that draws none frees them.
        draw(r, kViewLpvAll);
        EXPECT_TRUE(r.renderer().hasLpvResources());
        EXPECT_EQ(draw(r, kViewLinear, true, true).rgba, unlit.rgba);
        EXPECT_FALSE(r.renderer().hasLpvResources());
    }
}

TEST_F(RenderTest, LpvIndirectDiffersFromProbesAndBothSumsThem) {
    Project p = sampleProject("indirect_lpv", 8, 8);
    ProjectRenderer r(*ctx_, p);
    ASSERT_EQ(r.loadProbes(true), 1u);
    // The LPV carries light across its cascades, ten times as strong as physical: the first
    // bounce is a few percent of the sunlit terrain's light, and this makes it plain.
    p.scene.lpv.propagationWeight = 1.0;
    p.scene.lpv.indirectIntensity = 10.0;
    r.setProject(p);
    const std::vector<size_t> terrain = terrainPixels(r);
    const RenderedImage probes = draw(r, kViewLinear, true, true);
    const RenderedImage unlit = draw(r, kViewLinear, false, true);
    r.setProject(lpvProject(p, IndirectLighting::Lpv));
    const RenderedImage lpvImage = draw(r, kViewLinear, true, true);
    EXPECT_TRUE(r.renderer().hasLpvResources());
    r.setProject(lpvProject(p, IndirectLighting::Both));
    const RenderedImage both = draw(r, kViewLinear, true, true);
    EXPECT_EQ(r.lpvUpdates(), 1u) << "the same volumes serve lpv and both";
    double differs = 0, probeLit = 0;
    for (size_t p : terrain)
        for (size_t c = 0; c < 3; ++c) {
            differs += std::abs(lpvImage.rgba[4 * p + c] - probes.rgba[4 * p + c]);
            probeLit += probes.rgba[4 * p + c];
        }
    EXPECT_GT(differs / probeLit, 0.02) << "lpv against probes, share of the probe-lit terrain";
    // lpv adds the LPV's bounce to the sky-lit image; both adds the same to the probe-lit one.
    const double bounce = linearSum(lpvImage) - linearSum(unlit);
    EXPECT_GT(bounce, 0.0);
    EXPECT_NEAR(linearSum(both) - linearSum(probes), bounce, 1e-3 * linearSum(probes));
}

TEST_F(RenderTest, APointLightBrightensTheGroundUnderIt) {
    Project p = sampleProject("point_light", 8, 8);
    ProjectRenderer r(*ctx_, p);
    const OrbitCamera camera = r.defaultCamera();
    const Heightfield& hf = r.heightfield();
    const glm::vec3 ground(camera.target.x, hf.surfaceHeight(camera.target.x, camera.target.z), camera.target.z);
    const RenderedImage dark = draw(r, kViewLinear, false, true);
    LocalLight light;
    light.position = ground + glm::vec3(0.0f, 150.0f, 0.0f);
    light.range = 800.0;
    light.intensity = 6.0e4 / kSceneUnitsPerLux;  // 2 Gcd: 2.7 scene units under it, about the sun's 3
    p.scene.lights = {light};
    r.setProject(p);
    const RenderedImage lit = draw(r, kViewLinear, false, true);
    EXPECT_FALSE(r.renderer().hasLpvResources()) << "direct light needs no LPV";
    // The target projects to the image's centre: the light brightens the ground there, and the
    // ground beyond its range not at all.
    const glm::mat4 vp = camera.viewProjection(float(kW) / float(kH), std::max({hf.maxX() - hf.minX(), hf.maxZ() - hf.minZ(),
                                                                               hf.maxHeight() - hf.minHeight()}));
    const glm::vec4 clip = vp * glm::vec4(ground, 1.0f);
    const int cx = int((clip.x / clip.w * 0.5f + 0.5f) * kW), cy = int((clip.y / clip.w * 0.5f + 0.5f) * kH);
    ASSERT_TRUE(cx > 2 && cx < int(kW) - 3 && cy > 2 && cy < int(kH) - 3);
    double near = 0, before = 0;
    for (int y = cy - 2; y <= cy + 2; ++y)
        for (int x = cx - 2; x <= cx + 2; ++x) {
            const size_t i = (size_t(y) * kW + size_t(x)) * 4;
            near += lit.rgba[i] - dark.rgba[i];
            before += dark.rgba[i];
        }
    EXPECT_GT(near, 0.25 * before) << "the ground under the light";
    const size_t corner = (size_t(4) * kW + 4) * 4;
    EXPECT_EQ(lit.rgba[corner], dark.rgba[corner]);
    // A spot pointing away lights nothing.
    light.type = LocalLightType::Spot;
    light.direction = glm::vec3(0.0f, 1.0f, 0.0f);
    p.scene.lights = {light};
    r.setProject(p);
    const RenderedImage away = draw(r, kViewLinear, false, true);
    EXPECT_EQ(away.rgba, dark.rgba);
}

// A project with the LPV lighting it (lighting.indirect lpv) and a point light above the sample.
Project lpvLit(Project p) {
    p.scene.lpv.enabled = true;
    p.scene.lighting.indirect = IndirectLighting::Lpv;
    LocalLight light;
    light.position = glm::vec3(300.0f, 1700.0f, -200.0f);
    light.range = 900.0;
    light.intensity = 5.0e5 / kSceneUnitsPerLux;
    p.scene.lights = {light};
    return p;
}

// The terrain shader's LPV code against Volumes::evaluate at the same points: the compute pass
// runs lpv.glsl's lpvEvaluate, the function the terrain pass calls.
TEST_F(RenderTest, LpvOnTheGpuMatchesVolumesEvaluate) {
    Project p = lpvLit(sampleProject("lpv_agreement", 8, 8));
    p.scene.lpv.propagationWeight = 0.25;
    ProjectRenderer r(*ctx_, p);
    const Heightfield& hf = r.heightfield();
    for (int quality : {0, 1, 2}) {
        p.scene.lpv.quality = quality;
        r.setProject(p);
        draw(r, kViewLpvAll);
        ASSERT_TRUE(r.renderer().lpv());
        // The renderer propagated the volumes it drew; the CPU reference propagates its own.
        const std::optional<LpvJob> job = r.lpvJob(unprobed(kViewLpvAll, false), r.defaultCamera());
        ASSERT_TRUE(job);
        const auto volumes = job->run(lpv::Propagation::Cpu);
        // Ground points on a grid over the footprint (inside and outside the cascades), some
        // above it, each with the terrain's normal, every third facing the ground instead (there
        // the geometry volume occludes), and a view from the south-west above.
        std::vector<std::array<glm::vec3, 3>> queries;
        for (int k = 0; k < 24; ++k)
            for (int i = 0; i < 24; ++i) {
                const float x = hf.minX() + (float(i) + 0.5f) / 24.0f * (hf.maxX() - hf.minX());
                const float z = hf.minZ() + (float(k) + 0.5f) / 24.0f * (hf.maxZ() - hf.minZ());
                const float lift = (i + k) % 5 == 0 ? 40.0f : 0.0f;
                const glm::vec3 n = hf.surfaceNormal(x, z) * ((i + 2 * k) % 3 == 0 ? -1.0f : 1.0f);
                queries.push_back({glm::vec3(x, hf.surfaceHeight(x, z) + lift, z), n,
                                   glm::normalize(glm::vec3(-0.5f, 0.6f, 0.6f))});
            }
        const std::vector<TerrainRenderer::LpvSample> gpu = r.renderer().sampleLpv(queries);
        ASSERT_EQ(gpu.size(), queries.size());
        double largest = 0, largestSpec = 0, worst = 0, worstSpec = 0, worstAo = 0, leastAo = 1;
        size_t lit = 0;
        std::vector<TerrainRenderer::LpvSample> cpu;
        for (const auto& q : queries) {
            const lpv::Sample c = volumes->evaluate(q[0], q[1], q[2]);
            cpu.push_back({c.irradiance, c.specular, volumes->ambientOcclusion(q[0], q[1])});
        }
        for (size_t i = 0; i < cpu.size(); ++i) {
            largest = std::max(largest, double(glm::length(cpu[i].irradiance)));
            largestSpec = std::max(largestSpec, double(glm::length(cpu[i].specular)));
            lit += glm::length(cpu[i].irradiance) > 0.0f;
            leastAo = std::min(leastAo, double(cpu[i].ao));
        }
        for (size_t i = 0; i < cpu.size(); ++i) {
            worst = std::max(worst, double(glm::length(gpu[i].irradiance - cpu[i].irradiance)) / largest);
            if (largestSpec > 0) worstSpec = std::max(worstSpec, double(glm::length(gpu[i].specular - cpu[i].specular)) / largestSpec);
            worstAo = std::max(worstAo, double(std::abs(gpu[i].ao - cpu[i].ao)));
        }
        std::cout << "quality " << quality << ": " << lit << " of " << cpu.size() << " points lit, largest irradiance "
                  << largest << "; worst |GPU - CPU| / largest: irradiance " << worst << ", specular " << worstSpec
                  << "; AO " << worstAo << " (least AO " << leastAo << ")\n";
        EXPECT_GT(lit, cpu.size() / 4);
        EXPECT_LT(leastAo, 0.5);
        EXPECT_LT(worst, 1e-4) << quality;
        EXPECT_LT(worstAo, 1e-4) << quality;
        if (quality == 2) {
            EXPECT_GT(largestSpec, 0.0);
            EXPECT_LT(worstSpec, 1e-4);
        }
    }
}

// The propagation pass against Volumes::propagate: the light the terrain reads, cell by cell, for
// volumes the renderer propagated and the same volumes propagated on the CPU, and the frame drawn
// with each. The pass runs once: in the first frame that reads the volumes, or before a read-back
// that comes first.
TEST_F(RenderTest, LpvPropagatedOnTheGpuMatchesTheCpu) {
    Project p = lpvLit(sampleProject("lpv_propagation", 8, 8));
    struct Case {
        int cascades, iterations;
        double weight;
        bool readFirst;  // read the light back before any frame
    };
    const bool cpuDevice = ctx_->deviceType() == VK_PHYSICAL_DEVICE_TYPE_CPU;
    for (const Case c : {Case{3, 4, 0.01, false}, Case{1, 0, 0.01, false}, Case{4, 1, 1.0, true},
                         Case{2, 7, 0.3, true}}) {
        p.scene.lpv.cascades = c.cascades;
        p.scene.lpv.propagationIterations = c.iterations;
        p.scene.lpv.propagationWeight = c.weight;
        ProjectRenderer r(*ctx_, p);
        const RenderRequest q = unprobed(kViewLinear, true);
        const std::optional<LpvJob> job = r.lpvJob(q, r.defaultCamera());
        ASSERT_TRUE(job);
        // The product propagates on the CPU's worker on a CPU device, in the pass on a GPU.
        EXPECT_EQ(r.renderer().propagatesLpv(), !cpuDevice);
        EXPECT_EQ(job->propagation, cpuDevice ? lpv::Propagation::Cpu : lpv::Propagation::Renderer);
        const auto gpuVolumes = job->run(lpv::Propagation::Renderer);
        const auto cpuVolumes = job->run(lpv::Propagation::Cpu);
        EXPECT_FALSE(gpuVolumes->propagated());
        const glm::vec3 up(0.0f, 1.0f, 0.0f);
        EXPECT_THROW(gpuVolumes->evaluate(glm::vec3(0.0f), up, up), std::logic_error);
        r.setLpv(gpuVolumes, job->key);
        const auto passes = [&] {
            const std::vector<PassInfo>& frame = r.renderer().lastFramePasses();
            return std::count_if(frame.begin(), frame.end(), [](const PassInfo& i) { return i.name == "lpv-propagate"; });
        };
        std::vector<float> got;
        if (c.readFirst) got = r.renderer().readLpvLight();
        const RenderedImage first = r.render(q);
        EXPECT_EQ(passes(), !c.readFirst && c.iterations > 0 ? 1 : 0);
        r.render(q);
        EXPECT_EQ(passes(), 0) << "propagated once";
        if (c.iterations > 0 && ctx_->timestampPeriod() > 0.0) {
            const std::optional<double> ms = r.renderer().lpvPropagationMilliseconds();
            ASSERT_TRUE(ms);
            EXPECT_GT(*ms, 0.0);
        }
        if (!c.readFirst) got = r.renderer().readLpvLight();

        // Cascade by cascade, against each one's largest coefficient.
        size_t offset = 0;
        for (size_t k = 0; k < cpuVolumes->cascades().size(); ++k) {
            const lpv::Cascade& cas = cpuVolumes->cascades()[k];
            const std::vector<float>& expected = cas.accumulated;
            ASSERT_LE(offset + expected.size(), got.size());
            const lpv::LightVolume mine(got.begin() + std::ptrdiff_t(offset),
                                        got.begin() + std::ptrdiff_t(offset + expected.size()));
            offset += expected.size();
            double largest = 0, worst = 0;
            for (size_t i = 0; i < expected.size(); ++i) {
                largest = std::max(largest, double(std::abs(expected[i])));
                worst = std::max(worst, double(std::abs(mine[i] - expected[i])));
            }
            const double moved = lpv::totalFlux(mine).y / lpv::totalFlux(cas.injected).y;
            std::cout << c.cascades << " cascades, " << c.iterations << " steps, weight " << c.weight << ", cascade "
                      << k << ": largest coefficient " << largest << ", worst |GPU - CPU| / largest "
                      << worst / largest << ", flux accumulated / injected " << moved << "\n";
            ASSERT_GT(largest, 0.0);
            EXPECT_LT(worst / largest, 1e-5);
            // Lavapipe takes the same operations in the same order as the CPU; a GPU may fuse them.
            if (cpuDevice) {
                EXPECT_EQ(mine, expected);
            }
            // The steps moved light (or, with none, it is the injected light).
            if (c.iterations > 0) {
                EXPECT_GT(moved, 1.2);
            } else {
                EXPECT_EQ(mine, cas.injected);
            }
        }
        EXPECT_EQ(offset, got.size());

        // The frame that ran the pass draws what the CPU's volumes draw.
        r.setLpv(cpuVolumes, job->key);
        const RenderedImage reference = r.render(q);
        ASSERT_EQ(first.rgba.size(), reference.rgba.size());
        if (cpuDevice) {
            EXPECT_EQ(first.rgba, reference.rgba);
        } else {
            double worstPixel = 0;
            for (size_t i = 0; i < first.rgba.size(); ++i)
                worstPixel = std::max(worstPixel, double(std::abs(first.rgba[i] - reference.rgba[i])));
            EXPECT_LT(worstPixel, 1e-3);
        }
    }
}

namespace {

double lumaOf(const RenderedImage& img, size_t x, size_t y) {
    const float* p = &img.rgba[(y * img.width + x) * 4];
    return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

// `img` (k·w x k·h) averaged over k x k blocks: the supersampled reference of a w x h frame.
RenderedImage boxDown(const RenderedImage& img, uint32_t k) {
    RenderedImage out;
    out.width = img.width / k;
    out.height = img.height / k;
    out.rgba.assign(size_t(out.width) * out.height * 4, 0.0f);
    for (uint32_t y = 0; y < out.height; ++y)
        for (uint32_t x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                double sum = 0.0;
                for (uint32_t j = 0; j < k; ++j)
                    for (uint32_t i = 0; i < k; ++i)
                        sum += img.rgba[((size_t(y) * k + j) * img.width + size_t(x) * k + i) * 4 + size_t(c)];
                out.rgba[(size_t(y) * out.width + x) * 4 + size_t(c)] = float(sum / double(k * k));
            }
    return out;
}

// The edge pixels of `reference`: a luminance range over their 3 x 3 neighbourhood of at least
// `contrast`.
std::vector<size_t> edgePixels(const RenderedImage& reference, double contrast) {
    std::vector<size_t> edges;
    for (uint32_t y = 1; y + 1 < reference.height; ++y)
        for (uint32_t x = 1; x + 1 < reference.width; ++x) {
            double lo = 1e9, hi = -1e9;
            for (int j = -1; j <= 1; ++j)
                for (int i = -1; i <= 1; ++i) {
                    const double l = lumaOf(reference, size_t(int(x) + i), size_t(int(y) + j));
                    lo = std::min(lo, l);
                    hi = std::max(hi, l);
                }
            if (hi - lo >= contrast) edges.push_back(size_t(y) * reference.width + x);
        }
    return edges;
}

// msaa's mean edge error against the supersampled frame, as a share of off's at most: it
// smooths geometric edges (silhouettes, shores) but not shading edges inside a triangle (shadow
// boundaries), which only ssaa and fxaa see. Measured (480 x 270, lavapipe's msaa4): 0.72-0.82 x
// on the sample, whose edges are mostly shading, 0.42-0.51 x on the crop.
constexpr double kMsaaEdgeBound = 0.9, kMsaaEdgeBoundCrop = 0.6;

double meanEdgeError(const RenderedImage& img, const RenderedImage& reference, const std::vector<size_t>& edges) {
    double sum = 0.0;
    for (size_t e : edges)
        for (int c = 0; c < 3; ++c) sum += std::abs(double(img.rgba[e * 4 + size_t(c)]) - reference.rgba[e * 4 + size_t(c)]);
    return sum / (3.0 * double(std::max<size_t>(edges.size(), 1)));
}

}  // namespace

TEST(AntialiasingPlan, AnMsaaCountTheDeviceLacksFallsToTheLargestBelowOrToFxaa) {
    const DebugView beauty = *findDebugView(kViewBeauty), shadow = *findDebugView(kViewShadow);
    const uint32_t all = 1 | 2 | 4 | 8, lavapipe = 1 | 4;
    features::AntialiasingPlan p = features::antialiasingPlan(Antialiasing::Msaa8, beauty, all);
    EXPECT_EQ(p.samples, 8u);
    EXPECT_TRUE(p.resolve);
    EXPECT_FALSE(p.pass);
    EXPECT_EQ(p.scale, 1u);
    p = features::antialiasingPlan(Antialiasing::Msaa8, beauty, lavapipe);
    EXPECT_EQ(p.samples, 4u);
    EXPECT_EQ(p.mode, Antialiasing::Msaa4);
    // Never more samples than asked: msaa2 on a device with 4 alone is fxaa.
    p = features::antialiasingPlan(Antialiasing::Msaa2, beauty, lavapipe);
    EXPECT_EQ(p.mode, Antialiasing::Fxaa);
    EXPECT_EQ(p.samples, 1u);
    EXPECT_TRUE(p.pass);
    EXPECT_FALSE(p.resolve);
    // A data view keeps one exact sample.
    p = features::antialiasingPlan(Antialiasing::Msaa4, shadow, lavapipe);
    EXPECT_EQ(p.samples, 1u);
    EXPECT_FALSE(p.pass || p.resolve);
}

TEST_F(RenderTest, AntialiasingLowersTheEdgeErrorAgainstASupersampledFrame) {
    // A low sun on the sample and on a mountain crop, far (the default camera) and near (a third
    // of its distance): ridge silhouettes against the sky and long shadow edges. The reference is
    // the same frame drawn with one sample a pixel at 4 x 4 the pixels and averaged (16 samples a
    // pixel); the edges are its pixels whose 3 x 3 luminance range is at least 0.2.
    // Measured (480 x 270, lavapipe): fxaa 0.63-0.65 x the error of off on the crop, 0.88-1.02 x
    // on the sample, whose error is mostly sub-pixel shading that no edge filter sees; ssaa
    // 0.29-0.32 x everywhere; msaa4 0.42-0.51 x on the crop, 0.72-0.82 x on the sample.
    const fs::path dems = fs::path(TERRALUX_SOURCE_DIR) / "tests" / "data" / "dem";
    for (const std::string& dem : {std::string(), (dems / "rainier_crop.tif").string()})
        for (bool near : {false, true}) {
            Project p = loadEffectiveProject("", {"probe_volumes[0].enabled=false", "sun.mode=\"manual\"",
                                                  "sun.azimuth_deg=135", "sun.elevation_deg=12", "camera.elevation_deg=12"},
                                             dem, nullptr);
            p.scene.exportSettings.outDir = (kOut / "bake_antialiasing").string();
            ProjectRenderer r(*ctx_, p);
            if (near) {
                p.scene.camera.radius = double(r.defaultCamera().radius) / 3.0;
                r.setProject(p);
            }
            auto frame = [&](Antialiasing mode, uint32_t scale, int view = kViewBeauty, bool linear = false) {
                p.scene.camera.antialiasing = mode;
                r.setProject(p);
                return draw(r, view, false, linear, 480 * scale, 270 * scale);
            };
            const RenderedImage reference = boxDown(frame(Antialiasing::Off, 4), 4);
            const std::vector<size_t> edges = edgePixels(reference, 0.2);
            const RenderedImage off = frame(Antialiasing::Off, 1), ssaa = frame(Antialiasing::Ssaa, 1),
                                fxaa = frame(Antialiasing::Fxaa, 1);
            // The pass is in the frame and timed like the others.
            const std::vector<std::string> names = passNames(r.renderer().lastFramePasses());
            EXPECT_NE(std::find(names.begin(), names.end(), "antialias"), names.end());
            // msaa at the largest count the device has up to 8 (lavapipe: 4), resolved by a pass of its own.
            const RenderedImage msaa = frame(Antialiasing::Msaa8, 1);
            const uint32_t counts = ctx_->framebufferSampleCounts();
            const Antialiasing drawn = r.renderer().drawnAntialiasing();
            EXPECT_EQ(drawn, (counts & 8u) ? Antialiasing::Msaa8 : (counts & 4u) ? Antialiasing::Msaa4
                             : (counts & 2u) ? Antialiasing::Msaa2 : Antialiasing::Fxaa);
            const std::vector<std::string> msaaNames = passNames(r.renderer().lastFramePasses());
            if (msaaSamples(drawn) > 1) {
                EXPECT_NE(std::find(msaaNames.begin(), msaaNames.end(), "resolve"), msaaNames.end());
            }
            const double eOff = meanEdgeError(off, reference, edges), eFxaa = meanEdgeError(fxaa, reference, edges),
                         eSsaa = meanEdgeError(ssaa, reference, edges), eMsaa = meanEdgeError(msaa, reference, edges);
            const std::string what = (dem.empty() ? std::string("sample") : fs::path(dem).filename().string()) +
                                     (near ? " near: " : " far: ") + std::to_string(edges.size()) +
                                     " edge pixels, mean |error| off " + std::to_string(eOff) + ", fxaa " +
                                     std::to_string(eFxaa) + ", ssaa " + std::to_string(eSsaa) + ", " +
                                     antialiasingName(drawn) + " " + std::to_string(eMsaa);
            std::cout << what << "\n";
            EXPECT_GT(edges.size(), size_t(480 * 270 / 200)) << what;
            EXPECT_LT(eFxaa, (dem.empty() ? 1.02 : 0.75) * eOff) << what;
            EXPECT_LT(eSsaa, 0.5 * eOff) << what;
            if (msaaSamples(drawn) > 1) {
                EXPECT_LT(eMsaa, (dem.empty() ? kMsaaEdgeBound : kMsaaEdgeBoundCrop) * eOff) << what;
            }
            if (near) continue;

            // The data views keep one exact sample a pixel whatever the mode: the same image, no pass.
            const RenderedImage shadowOff = frame(Antialiasing::Off, 1, kViewShadow);
            const RenderedImage shadowSsaa = frame(Antialiasing::Ssaa, 1, kViewShadow);
            EXPECT_EQ(shadowOff.rgba, shadowSsaa.rgba) << what;
            EXPECT_EQ(shadowOff.rgba, frame(Antialiasing::Msaa4, 1, kViewShadow).rgba) << what;
            const std::vector<std::string> dataPasses = passNames(r.renderer().lastFramePasses());
            EXPECT_EQ(std::find(dataPasses.begin(), dataPasses.end(), "antialias"), dataPasses.end()) << what;
            // The scene-linear picture (EXR) is smoothed too, in its own values.
            const RenderedImage linearOff = frame(Antialiasing::Off, 1, kViewLinear, true);
            const RenderedImage linearFxaa = frame(Antialiasing::Fxaa, 1, kViewLinear, true);
            EXPECT_NE(linearOff.rgba, linearFxaa.rgba) << what;
            for (float v : linearFxaa.rgba) ASSERT_TRUE(std::isfinite(v)) << what;
        }
}

TEST_F(RenderTest, TheSkyMeetsTheFoggedGroundAtTheHorizonWithoutAStep) {
    // A low camera over the sample, looking past the terrain at the level ground beyond it. The
    // sky used to be fogged to the far plane only while the ground just below the horizon took the
    // fog's full colour: a step of 0.21 in luminance between two rows at 480 x 270; with the sky
    // fogged along the whole rising ray the largest step is 0.058, the haze's own gradient.
    Project p = sampleProject("horizon", 2, 2);
    p.scene.camera.elevationDeg = 8.0;
    p.scene.camera.antialiasing = Antialiasing::Off;
    ProjectRenderer r(*ctx_, p);
    const uint32_t w = 480, h = 270;
    const RenderedImage img = draw(r, kViewBeauty, false, false, w, h);
    // The level ground's horizon: view rays with d_y = 0, tan(8°) / tan(22.5°) of the half height
    // above the centre.
    const double horizon = 0.5 * h - std::tan(8.0 * M_PI / 180.0) / std::tan(22.5 * M_PI / 180.0) * 0.5 * h;
    double worst = 0.0;
    for (uint32_t x : {10u, w - 10}) {
        for (int y = int(horizon) - 15; y < int(horizon) + 15; ++y)
            worst = std::max(worst, std::abs(lumaOf(img, x, size_t(y + 1)) - lumaOf(img, x, size_t(y))));
    }
    std::cout << "largest step between rows within 15 of the horizon (row " << horizon << "): " << worst << "\n";
    EXPECT_LT(worst, 0.08);
    // And it is a horizon: the haze there is brighter than the sky well above it.
    EXPECT_GT(lumaOf(img, 10, size_t(horizon)), lumaOf(img, 10, size_t(horizon) - 40) + 0.02);
}

TEST_F(RenderTest, TheViewportsThreeSizesKeepTheirTargets) {
    // The viewport draws one view at three sizes: the meter's 128 pixels (histogram metering
    // draws it before each frame whose camera changed), a dynamic-resolution step while the camera
    // moves and the full frame when it stops. Each keeps its targets (the frame's and the water's)
    // once drawn; cycling through them allocates nothing, waits for nothing, and the full frame
    // drawn last matches a renderer that drew it alone.
    Project p = sampleProject("three_sizes", 4, 4);
    p.scene.camera.exposureMode = ExposureMode::Histogram;
    ProjectRenderer r(*ctx_, p);
    addLake(p, r);
    RenderRequest full = unprobed(kViewBeauty, false);
    full.width = 2 * kW;  // the step, half of it, still wider than the meter
    full.height = 2 * kH;
    RenderRequest step = full;
    step.width = kW;
    step.height = kH;
    const RenderedImage first = r.render(full);
    EXPECT_EQ(r.renderer().targetAllocations(), 2u) << "the meter's targets and the frame's";
    r.render(step);
    const size_t allocations = r.renderer().targetAllocations();
    EXPECT_EQ(allocations, 3u) << "the meter's targets, the step's and the full frame's";
    RenderedImage last;
    for (int i = 0; i < 3; ++i) {
        p.scene.camera.azimuthDeg += 20.0;
        r.setProject(p);
        r.render(step);         // meters, then draws the step
        last = r.render(full);  // the same camera: the step's exposure, no meter
    }
    EXPECT_EQ(r.renderer().targetAllocations(), allocations) << "stepping between sizes allocated targets again";
    ProjectRenderer fresh(*ctx_, p);
    fresh.render(step);
    const RenderedImage reference = fresh.render(full);
    ASSERT_EQ(last.rgba.size(), reference.rgba.size());
    size_t differing = 0;
    for (size_t i = 0; i < last.rgba.size(); ++i) differing += last.rgba[i] != reference.rgba[i];
    EXPECT_EQ(differing, 0u) << "of " << last.rgba.size() << " values";
    EXPECT_NE(first.rgba, last.rgba) << "the camera moved";
}

TEST_F(RenderTest, TheMeteredExposurePutsTheTerrainNearMiddleGrey) {
    // Histogram metering on three terrains and three suns under the default sky: the terrain's
    // mean log luminance on the display (sRGB decoded) within a stop of middle grey (0.18), and
    // the sky not clipped. Manual exposure at the default EV100 spans 0.1 to 0.5 there; snow on
    // the Rainier crop at a high sun is the brightest.
    const fs::path dems = fs::path(TERRALUX_SOURCE_DIR) / "tests" / "data" / "dem";
    const uint32_t w = 320, h = 180;
    for (const std::string& dem : {std::string(), (dems / "rainier_crop.tif").string(),
                                   (dems / "bigtujunga_utm11_crop.tif").string()})
        for (const char* elevation : {"12", "35", "60"}) {
            Project p = loadEffectiveProject("", {"probe_volumes[0].enabled=false", "sun.mode=\"manual\"",
                                                  std::string("sun.elevation_deg=") + elevation,
                                                  "camera.exposure_mode=\"histogram\""},
                                             dem, nullptr);
            p.scene.exportSettings.outDir = (kOut / "bake_exposure").string();
            ProjectRenderer r(*ctx_, p);
            const RenderedImage terrain = draw(r, kViewSunVisibility, false, true, w, h);
            // The terrain's geometric mean display luminance, its pixel count, the sky's pixels and
            // how many of those are clipped.
            struct Reading {
                double mean = 0.0;
                size_t terrain = 0, sky = 0, clipped = 0;
            };
            const auto read = [&](const RenderedImage& img) {
                Reading m;
                double logSum = 0.0;
                for (size_t i = 0; i < size_t(w) * h; ++i) {
                    double y = 0.0;
                    for (int c = 0; c < 3; ++c) {
                        const double e = img.rgba[i * 4 + size_t(c)];
                        const double linear = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
                        y += (c == 0 ? 0.2126 : c == 1 ? 0.7152 : 0.0722) * linear;
                    }
                    if (terrain.rgba[i * 4 + 1] > 0.5f) {
                        logSum += std::log2(std::max(y, 1e-4));
                        ++m.terrain;
                    } else {
                        ++m.sky;
                        if (y > 0.95) ++m.clipped;
                    }
                }
                m.mean = std::exp2(logSum / double(std::max<size_t>(m.terrain, 1)));
                return m;
            };
            const RenderedImage img = draw(r, kViewBeauty, false, false, w, h);
            const double ev = r.meteredEv100();
            const Reading metered = read(img);
            p.scene.camera.exposureMode = ExposureMode::Manual;
            r.setProject(p);
            const Reading manual = read(draw(r, kViewBeauty, false, false, w, h));
            p.scene.camera.exposureMode = ExposureMode::Histogram;
            r.setProject(p);
            const size_t n = metered.terrain, sky = metered.sky, clipped = metered.clipped;
            const double mean = metered.mean;
            const std::string what = (dem.empty() ? std::string("sample") : fs::path(dem).filename().string()) +
                                     " sun " + elevation + ": EV100 " + std::to_string(ev) + ", terrain " +
                                     std::to_string(n) + " px at " + std::to_string(mean) + " (manual " +
                                     std::to_string(manual.mean) + "), sky clipped " + std::to_string(clipped) +
                                     " of " + std::to_string(sky) + " (manual " + std::to_string(manual.clipped) + ")";
            std::cout << what << "\n";
            ASSERT_GT(n, size_t(w) * h / 8) << what;
            EXPECT_GT(mean, 0.18 / 2.0) << what;
            EXPECT_LT(mean, 0.18 * 2.0) << what;
            EXPECT_LE(double(clipped), 0.01 * double(sky)) << what;
            EXPECT_TRUE(std::isfinite(ev) && std::abs(ev - r.shownEv100()) < 1e-12) << what;
            // The meter's frame, 128 pixels wide, reads what the whole frame reads.
            const RenderedImage whole = draw(r, kViewBeauty, false, true, w, h);
            EXPECT_NEAR(meterEv100(whole.rgba, w, h, ExposureMode::Histogram), ev, 0.05) << what;

            // The meter follows the light: all of it twice as bright reads one stop more and shows
            // the same picture.
            if (std::string(elevation) != "35") continue;
            p.scene.sun.illuminance *= 2.0;
            p.scene.sky.intensity *= 2.0;
            r.setProject(p);
            const RenderedImage brighter = draw(r, kViewBeauty, false, false, w, h);
            EXPECT_NEAR(r.meteredEv100() - ev, 1.0, 0.01) << what;
            double diff = 0.0;
            for (size_t i = 0; i < img.rgba.size(); ++i) diff = std::max(diff, double(std::abs(img.rgba[i] - brighter.rgba[i])));
            EXPECT_LT(diff, 3.0 / 255.0) << what;
        }
}

TEST_F(RenderTest, BetweenTwoScenariosTheBackgroundIsBothSkiesMixed) {
    // The physical sky and a dim uniform one, the same sun behind the camera: halfway between the
    // scenarios each sky pixel is the mean of the two ends' (the nearer end's image alone would be
    // off by some 70 %). Scene-linear, fog off.
    Project p = loadEffectiveProject("", {"probe_volumes[0].enabled=false", "sky.mode=\"physical\"", "fog.enabled=false",
                                          "sun.mode=\"manual\"", "sun.azimuth_deg=135", "sun.elevation_deg=30",
                                          "camera.azimuth_deg=135", "camera.elevation_deg=4",
                                          "camera.antialiasing=\"off\""},
                                     "", nullptr);
    p.scene.exportSettings.outDir = (kOut / "bake_scenario_background").string();
    LightingScenario grey;
    grey.name = "grey";
    grey.sun = p.scene.sun;
    grey.sky.mode = SkyMode::Uniform;
    grey.sky.color = glm::vec3(0.8f, 0.8f, 1.0f);
    grey.sky.luminance = 0.025 / kSceneUnitsPerLux;
    p.scene.scenarios = {grey};
    ProjectRenderer r(*ctx_, p);
    const uint32_t w = 320, h = 180;
    auto frame = [&](float t, int view) {
        r.setScenarioView({"default", "grey", t});
        return draw(r, view, false, true, w, h);
    };
    const RenderedImage mask = frame(0.0f, kViewShadow);  // green 1 on the terrain
    const RenderedImage a = frame(0.0f, kViewBeauty), b = frame(1.0f, kViewBeauty), half = frame(0.5f, kViewBeauty);
    double error = 0.0, apart = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        if (mask.rgba[i * 4 + 1] > 0.5f) continue;
        for (int c = 0; c < 3; ++c) {
            const double mean = 0.5 * (a.rgba[i * 4 + c] + b.rgba[i * 4 + c]);
            if (!(mean > 1e-4)) continue;
            error += std::abs(half.rgba[i * 4 + c] - mean) / mean;
            apart += std::abs(a.rgba[i * 4 + c] - b.rgba[i * 4 + c]) / mean;
            ++n;
        }
    }
    ASSERT_GT(n, size_t(w) * h / 4);
    std::cout << n / 3 << " sky pixels: halfway off the mean by " << 100.0 * error / double(n) << " %, the ends "
              << 100.0 * apart / double(n) << " % apart\n";
    EXPECT_GT(apart / double(n), 0.5);
    EXPECT_LT(error / double(n), 0.02);
    // Back at an end the end's own image is drawn again.
    EXPECT_EQ(test::compareImages(frame(0.0f, kViewBeauty).rgba, a.rgba, w, h).maxAbs, 0.0);
    EXPECT_EQ(test::compareImages(frame(1.0f, kViewBeauty).rgba, b.rgba, w, h).maxAbs, 0.0);
}

TEST_F(RenderTest, AnHdrSkyIsDrawnBehindTheTerrainAtItsOwnResolution) {
    // A checkered HDR of 16 x 8 cells (radiance 0.1 and 1.0), rotated: the sky pass must draw its
    // texels through the bake's own mapping (Sky::radiance), not the SH's blur of them. Compared
    // scene-linear on the sky pixels above the horizon, away from the sun.
    const int iw = 256, ih = 128;
    std::vector<float> rgba;
    for (int y = 0; y < ih; ++y)
        for (int x = 0; x < iw; ++x) {
            const float v = ((x / 16) + (y / 16)) % 2 ? 1.0f : 0.1f;
            rgba.insert(rgba.end(), {v, 0.5f * v, 0.25f + v, 1.0f});
        }
    const fs::path hdr = kOut / "checker_sky.exr";
    writeImage(hdr, iw, ih, rgba);
    Project p = loadEffectiveProject("", {"probe_volumes[0].enabled=false", "sky.hdr=\"" + hdr.string() + "\"",
                                          "sky.mode=\"hdr\"", "sky.rotation_deg=30",
                                          "sky.intensity=2", "fog.enabled=false", "sun.mode=\"manual\"",
                                          "sun.azimuth_deg=30", "sun.elevation_deg=40", "camera.azimuth_deg=30",
                                          "camera.elevation_deg=4", "camera.antialiasing=\"off\""},
                                     "", nullptr);
    p.scene.exportSettings.outDir = (kOut / "bake_hdr_background").string();
    ProjectRenderer r(*ctx_, p);
    const uint32_t w = 320, h = 180;
    const RenderedImage img = draw(r, kViewBeauty, false, true, w, h);
    const BakeLighting lighting = lightingOf(p, r.heightfield());
    const OrbitCamera cam = r.defaultCamera();
    const glm::mat4 inv = glm::inverse(cam.viewProjection(float(w) / float(h), 1000.0f));
    double sumImage = 0.0, sumSh = 0.0, sumRef = 0.0;
    size_t n = 0;
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const glm::vec4 far = inv * glm::vec4((x + 0.5f) / w * 2.0f - 1.0f, (y + 0.5f) / h * 2.0f - 1.0f, 0.0f, 1.0f);
            const glm::vec3 dir = glm::normalize(glm::vec3(far) / far.w - cam.position());
            if (dir.y < 0.05f || glm::dot(dir, lighting.sun.direction) > 0.99f) continue;
            const glm::vec3 ref = lighting.sky.radiance(dir);
            const glm::vec3 sh = glm::max(sh::evalRadiance(lighting.sky.sh(), dir), glm::vec3(0.0f));
            const size_t i = (size_t(y) * w + x) * 4;
            for (int c = 0; c < 3; ++c) {
                sumImage += std::abs(double(img.rgba[i + size_t(c)]) - ref[c]);
                sumSh += std::abs(double(sh[c]) - ref[c]);
                sumRef += ref[c];
            }
            ++n;
        }
    const double image = sumImage / sumRef, shError = sumSh / sumRef;
    std::cout << n << " sky pixels: mean |drawn - Sky::radiance| " << image << " of the radiance; the SH would be "
              << shError << "\n";
    ASSERT_GT(n, size_t(w) * h / 4);
    EXPECT_LT(image, 0.02);
    EXPECT_GT(shError, 0.2);

    // A uniform sky keeps the SH (exact for it), and the image leaves with it.
    p.scene.sky.mode = SkyMode::Uniform;
    r.setProject(p);
    const RenderedImage uniform = draw(r, kViewBeauty, false, true, w, h);
    const glm::vec3 sky = p.scene.sky.uniformRadiance();
    EXPECT_NEAR(uniform.rgba[(size_t(2) * w + w / 2) * 4], sky.x, 1e-3 * sky.x + 1e-5);
}

TEST_F(RenderTest, CascadeBlendingHandsOverWithinTheBandAndKeepsTheAgreement) {
    // A low sun over the Rainier crop from a third of the default distance, 512-texel maps: the
    // cascades cross the view. Blending (shadows.cascade_blend 0.25 against 0) changes the shadow
    // only in the bands view 34 shows mixed (or on its hand-over line), changes it there, and costs
    // no agreement with the traced sun visibility. Measured (480 x 270, lavapipe): 48 of 13 004
    // band pixels move by more than 0.03 (27 at 2048 texels): neighbouring cascades mostly agree
    // here, and the error's step across a hand-over stays 2.8x its step within a cascade with or
    // without the blend, the terrain's own contrast along those rows.
    const fs::path dem = fs::path(TERRALUX_SOURCE_DIR) / "tests" / "data" / "dem" / "rainier_crop.tif";
    Project p = loadEffectiveProject("", {"probe_volumes[0].enabled=false", "sun.mode=\"manual\"", "sun.azimuth_deg=135",
                                          "sun.elevation_deg=12", "camera.elevation_deg=25",
                                          "camera.antialiasing=\"off\"", "shadows.map_resolution=512"},
                                     dem.string(), nullptr);
    p.scene.exportSettings.outDir = (kOut / "bake_cascade_blend").string();
    ProjectRenderer r(*ctx_, p);
    p.scene.camera.radius = double(r.defaultCamera().radius) / 3.0;
    const uint32_t w = 480, h = 270;
    auto frame = [&](int view, double blend) {
        p.scene.shadows.cascadeBlend = blend;
        r.setProject(p);
        return draw(r, view, false, true, w, h);
    };
    const RenderedImage hard = frame(kViewShadow, 0.0), blended = frame(kViewShadow, 0.25);
    const RenderedImage bands = frame(kViewCascades, 0.25);
    size_t changed = 0, outside = 0, bandPixels = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        if (hard.rgba[i * 4 + 1] < 0.5f) continue;  // off the terrain
        const glm::vec3 c(bands.rgba[i * 4], bands.rgba[i * 4 + 1], bands.rgba[i * 4 + 2]);
        float best = 0.0f;
        for (const glm::vec3& k : kCascadeColours) best = std::max(best, glm::dot(glm::normalize(c), glm::normalize(k)));
        const bool band = glm::length(c) < 0.05f || best < 0.9995f;
        bandPixels += band;
        // A band's first hundredths mix colours a dot product cannot tell from pure: the shadow
        // moves there by at most the same few hundredths.
        if (std::abs(hard.rgba[i * 4] - blended.rgba[i * 4]) > 0.03f) {
            ++changed;
            outside += !band;
        }
    }
    std::cout << bandPixels << " band pixels, " << changed << " changed by the blend, " << outside << " of them outside\n";
    EXPECT_GT(bandPixels, size_t(w) * h / 50);
    EXPECT_GT(changed, size_t(20));
    EXPECT_EQ(outside, 0u);
    p.scene.shadows.cascadeBlend = 0.0;
    r.setProject(p);
    const ShadowAgreement a0 = measureShadowAgreement(r, w, h);
    p.scene.shadows.cascadeBlend = 0.25;
    r.setProject(p);
    const ShadowAgreement a1 = measureShadowAgreement(r, w, h);
    std::cout << "agreement " << 1.0 - a0.disagreeing << " -> " << 1.0 - a1.disagreeing << ", acne " << a0.acne << " -> "
              << a1.acne << ", mean |difference| " << a0.meanAbsDifference << " -> " << a1.meanAbsDifference << "\n";
    EXPECT_LE(a1.disagreeing, a0.disagreeing + 0.002);
    EXPECT_LE(a1.acne, a0.acne + 0.001);
}

TEST_F(RenderTest, TheLastCascadeFadesIntoTheUnshadowedSunAtAShortShadowDistance) {
    // The Rainier crop at a 12-degree sun with the shadow distance short of the orbit radius, so
    // terrain lies beyond it; one cascade, so no hand-over between cascades moves a pixel. Over
    // the cascade's far shadows.cascade_blend the shadow fades into the unshadowed sun: there each
    // pixel's lit fraction is the hard cut's moved toward 1 by the weight view 34 shows as the
    // cascade's colour mixed with grey; elsewhere nothing changes. Measured (480 x 270, lavapipe):
    // 6 644 pixels fading, none off the rule. Without terrain beyond (the default distance) the
    // cascade does not fade.
    const fs::path dem = fs::path(TERRALUX_SOURCE_DIR) / "tests" / "data" / "dem" / "rainier_crop.tif";
    Project p = loadEffectiveProject("", {"probe_volumes[0].enabled=false", "sun.mode=\"manual\"", "sun.azimuth_deg=135",
                                          "sun.elevation_deg=12", "camera.elevation_deg=25",
                                          "camera.antialiasing=\"off\"", "shadows.map_resolution=1024",
                                          "shadows.cascades=1"},
                                     dem.string(), nullptr);
    p.scene.exportSettings.outDir = (kOut / "bake_shadow_fade").string();
    ProjectRenderer r(*ctx_, p);
    p.scene.shadows.maxDistance = 0.85 * double(r.defaultCamera().radius);
    const uint32_t w = 480, h = 270;
    auto frame = [&](int view, double blend) {
        p.scene.shadows.cascadeBlend = blend;
        r.setProject(p);
        return draw(r, view, false, true, w, h);
    };
    const RenderedImage hard = frame(kViewShadow, 0.0), faded = frame(kViewShadow, 0.25);
    const RenderedImage bands = frame(kViewCascades, 0.25);
    const int last = p.scene.shadows.cascades - 1;
    const glm::vec3 lastColour = kCascadeColours[last], grey(0.45f);
    size_t fading = 0, beyond = 0, moved = 0, wrong = 0, changedElsewhere = 0;
    double lifted = 0.0;
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        if (hard.rgba[i * 4 + 1] < 0.5f) continue;  // off the terrain
        const glm::vec3 c(bands.rgba[i * 4], bands.rgba[i * 4 + 1], bands.rgba[i * 4 + 2]);
        if (glm::length(c) < 0.05f) continue;  // the dark line at a split
        // c = shade·(lastColour + t·(grey − lastColour)): least squares for shade and shade·t.
        const glm::vec3 d = grey - lastColour;
        const float aa = glm::dot(lastColour, lastColour), ad = glm::dot(lastColour, d), dd = glm::dot(d, d);
        const float ac = glm::dot(lastColour, c), dc = glm::dot(d, c), det = aa * dd - ad * ad;
        const float shade = (ac * dd - ad * dc) / det, shadeT = (aa * dc - ad * ac) / det;
        const glm::vec3 fit = shade * lastColour + shadeT * d;
        const float hardLit = hard.rgba[i * 4], fadedLit = faded.rgba[i * 4];
        if (glm::length(fit - c) > 0.01f * glm::length(c) || !(shade > 1e-3f)) {
            ++changedElsewhere;  // one cascade: every terrain pixel is its colour, grey or between
            continue;
        }
        const float t = std::clamp(shadeT / shade, 0.0f, 1.0f);
        // Shaded 0.45 + 0.55·N·L: at 0.45 the sun is behind the surface, unlit either way.
        if (shade < 0.452f) continue;
        if (t >= 0.999f) {
            ++beyond;
            if (std::abs(fadedLit - hardLit) > 1e-4f) ++changedElsewhere;
            continue;
        }
        if (t <= 0.001f) {
            if (std::abs(fadedLit - hardLit) > 0.03f) ++changedElsewhere;
            continue;
        }
        ++fading;
        const float expected = hardLit + t * (1.0f - hardLit);
        if (std::abs(fadedLit - expected) > 0.03f) ++wrong;
        if (fadedLit - hardLit > 0.03f) ++moved;
        lifted += fadedLit - hardLit;
    }
    std::cout << fading << " pixels fading, " << beyond << " beyond the distance, " << moved << " lifted by more than 0.03 (mean "
              << (fading ? lifted / double(fading) : 0.0) << "), " << wrong << " off the blend, " << changedElsewhere
              << " changed elsewhere\n";
    EXPECT_GT(fading, size_t(w) * h / 100);
    EXPECT_GT(beyond, size_t(w) * h / 100);
    EXPECT_GT(moved, size_t(20));
    EXPECT_LE(wrong, fading / 200);
    EXPECT_EQ(changedElsewhere, 0u);
    // At the default distance no terrain lies beyond: the last cascade keeps its own shadow.
    p.scene.shadows.maxDistance.reset();
    const RenderedImage fullHard = frame(kViewShadow, 0.0), fullBlend = frame(kViewCascades, 0.25);
    size_t greyish = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i) {
        if (fullHard.rgba[i * 4 + 1] < 0.5f) continue;
        const glm::vec3 c(fullBlend.rgba[i * 4], fullBlend.rgba[i * 4 + 1], fullBlend.rgba[i * 4 + 2]);
        if (glm::length(c) < 0.05f) continue;
        const glm::vec3 u = glm::normalize(c);
        greyish += std::abs(u.x - u.y) < 0.02f && std::abs(u.y - u.z) < 0.02f;
    }
    EXPECT_EQ(greyish, 0u);
}

// A frame drawn offscreen without waiting (the viewport's exposure meter) is the frame render()
// draws, pixel for pixel, taken once the device has drawn it; one is in flight at a time, and a
// synchronous render meanwhile neither waits for it in vain nor overwrites its read-back.
TEST_F(RenderTest, AnOffscreenFrameIsTheRenderedFrameTakenWithoutWaiting) {
    Project p = sampleProject("offscreen", 4, 4);
    ProjectRenderer r(*ctx_, p);
    TerrainRenderer& t = r.renderer();
    const OrbitCamera camera = OrbitCamera::fromSettings(p.scene.camera, r.heightfield());
    RenderRequest q = unprobed(kViewBeauty, true);
    q.width = 128;
    q.height = 96;
    const RenderSettings s = r.settingsOf(q, camera);
    const RenderedImage waited = t.render(s);
    auto take = [&] {
        std::optional<RenderedImage> img;
        for (int i = 0; i < 6000 && !img; ++i) {
            img = t.takeOffscreen();
            if (!img) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        return img;
    };
    // Nothing on the way waits for the device: beginning submits, taking polls the fence.
    const size_t waits = ctx_->hostWaits();
    ASSERT_TRUE(t.beginOffscreen(s));
    EXPECT_TRUE(t.offscreenPending());
    EXPECT_FALSE(t.beginOffscreen(s));  // one at a time
    std::optional<RenderedImage> taken = take();
    EXPECT_EQ(ctx_->hostWaits(), waits);
    ASSERT_TRUE(taken);
    EXPECT_FALSE(t.offscreenPending());
    EXPECT_FALSE(t.takeOffscreen());  // taken once
    ASSERT_EQ(taken->width, waited.width);
    ASSERT_EQ(taken->height, waited.height);
    EXPECT_EQ(taken->rgba, waited.rgba);

    // Another frame of the same size drawn synchronously while it is in flight draws into the
    // same target: the offscreen frame's pixels are read first.
    ASSERT_TRUE(t.beginOffscreen(s));
    RenderSettings other = s;
    other.debugView = kViewNormal;
    const RenderedImage normals = t.render(other);
    EXPECT_NE(normals.rgba, waited.rgba);
    taken = take();
    ASSERT_TRUE(taken);
    EXPECT_EQ(taken->rgba, waited.rgba);
}

// The mesh's level of detail (terrain/MeshLod.h): each patch draws the coarsest level whose error
// against the DEM covers at most a pixel from the camera, and the frame is the frame of the whole
// mesh up to that pixel; close to the ground the patches there draw every vertex.
// The viewport's frames below full resolution (dynamic resolution) keep the full frame's levels
// while its cascades stand, so an edit of the exposure, fog or water draws no shadow maps (on
// lavapipe they were 60 ms of a 100 ms frame at a quarter of the side); once the cascades move
// (a sun edit) the maps are drawn again anyway, and the small frame takes its own coarser levels.
TEST_F(RenderTest, AFrameBelowFullResolutionKeepsTheShadowMapsUntilTheCascadesMove) {
    Project p = sampleProject("lod_rows", 4, 4);
    p.scene.camera.exposureMode = ExposureMode::Manual;  // each render one frame: no meter's frame before it
    ProjectRenderer r(*ctx_, p);
    TerrainRenderer& t = r.renderer();
    auto hasShadowPass = [&] {
        const std::vector<std::string> names = passNames(t.lastFramePasses());
        return std::find(names.begin(), names.end(), "shadow") != names.end();
    };
    const uint32_t w = 480, h = 320;
    RenderRequest full = unprobed(kViewBeauty, false);
    full.width = w;
    full.height = h;
    r.render(full);
    ASSERT_TRUE(hasShadowPass());
    const TerrainRenderer::LodChoice fullLevels = t.lastLod();
    RenderRequest small = full;
    small.width = w / 4;
    small.height = h / 4;
    small.levelOfDetailRows = h;
    // The exposure changed: same cascades, the full frame's levels, no shadow pass.
    p.scene.camera.exposureEv += 1.0;
    r.setProject(p);
    r.render(small);
    EXPECT_FALSE(hasShadowPass());
    EXPECT_EQ(t.lastLod().levels, fullLevels.levels);
    // A frame of its own rows would have chosen coarser levels and drawn the maps for them.
    RenderRequest own = small;
    own.levelOfDetailRows = 0;
    r.render(own);
    EXPECT_TRUE(hasShadowPass());
    EXPECT_LT(t.lastLod().triangles, fullLevels.triangles);
    r.render(full);  // back to the full frame's levels and maps
    ASSERT_TRUE(hasShadowPass());
    // The sun moved: the maps are drawn again, at the small frame's own levels, which the frames
    // after it keep while the sun stands; the full frame then takes its own again.
    p.scene.sun.elevationDeg += 5.0;
    r.setProject(p);
    const RenderedImage moved = r.render(small);
    EXPECT_TRUE(hasShadowPass());
    const TerrainRenderer::LodChoice smallLevels = t.lastLod();
    EXPECT_LT(smallLevels.triangles, fullLevels.triangles);
    const RenderedImage kept = r.render(small);
    EXPECT_FALSE(hasShadowPass());
    EXPECT_EQ(t.lastLod().levels, smallLevels.levels);
    EXPECT_EQ(test::compareImages(kept.rgba, moved.rgba, w / 4, h / 4).maxAbs, 0.0);
    // The same picture as a frame of its own rows.
    EXPECT_EQ(test::compareImages(kept.rgba, r.render(own).rgba, w / 4, h / 4).maxAbs, 0.0);
    EXPECT_EQ(t.lastLod().levels, smallLevels.levels);
    r.render(full);
    EXPECT_TRUE(hasShadowPass());
    EXPECT_GT(t.lastLod().triangles, smallLevels.triangles);
    // A change of what the levels are chosen by (the pixel asked for; the water's level, whose
    // shore draws every vertex) is no frame to keep levels through: the small frame takes levels
    // of its own and draws the maps for them.
    const TerrainRenderer::LodChoice fullAgain = t.lastLod();
    t.setLodPixelError(4.0);
    r.render(small);
    EXPECT_TRUE(hasShadowPass());
    EXPECT_LT(t.lastLod().triangles, fullAgain.triangles);
    t.setLodPixelError(1.0);
    r.render(full);
    p = withWater(p, r, 20.0);
    r.setProject(p);
    r.render(full);
    const TerrainRenderer::LodChoice wet = t.lastLod();
    p.scene.water.level = 0.5 * (double(r.heightfield().minHeight()) + double(r.heightfield().maxHeight()));
    r.setProject(p);
    r.render(small);
    EXPECT_TRUE(hasShadowPass());
    EXPECT_NE(t.lastLod().levels, wet.levels);
    p.scene.water.enabled = false;
    r.setProject(p);

    // The viewport names its own height for a full-resolution frame too: with supersampling (the
    // target twice the rows) that frame still takes the levels of its output, not a small frame's.
    p.scene.camera.antialiasing = Antialiasing::Ssaa;
    p.scene.sun.elevationDeg += 5.0;
    r.setProject(p);
    RenderRequest viewportFull = full;
    viewportFull.levelOfDetailRows = h;
    r.render(full);
    const TerrainRenderer::LodChoice supersampled = t.lastLod();
    p.scene.sun.elevationDeg += 5.0;
    r.setProject(p);
    r.render(small);
    EXPECT_LT(t.lastLod().triangles, supersampled.triangles);
    p.scene.sun.elevationDeg -= 5.0;
    r.setProject(p);
    r.render(viewportFull);
    EXPECT_EQ(t.lastLod().levels, supersampled.levels);
}

// Source resolution (TerrainRenderer::kDetailVertexBudget): a DEM past the mesh's vertex budget
// is drawn from every k-th vertex, and where that leaves more than the pixel out, near the camera,
// patches are drawn from the DEM's own vertices, lit by the probes at those vertices and casting
// shadows as drawn. The sample with a budget that halves it, seen close to the ground: the frame is
// the undecimated mesh's up to the pixel (no cracks: the sky would show through), and without
// the detail patches it is not.
// The vertices of the project's DEM as imported.
size_t demVertices(const Project& p) {
    const DemImportResult t = loadProjectTerrain(p);
    return size_t(t.heightfield.width()) * size_t(t.heightfield.depth());
}

TEST_F(RenderTest, CloseToTheGroundADecimatedDemIsDrawnAtItsSourceResolution) {
    Project p = sampleProject("detail", 4, 4);
    p.scene.camera.exposureMode = ExposureMode::Manual;
    const size_t vertices = demVertices(p);
    ProjectRenderer whole(*ctx_, p, loadProjectTerrain(p));
    ProjectRenderer decimated(*ctx_, p, loadProjectTerrain(p), true, vertices / 3);
    ASSERT_EQ(whole.renderer().meshStride(), 1);
    ASSERT_EQ(decimated.renderer().meshStride(), 2);
    ASSERT_EQ(whole.loadProbes(true), 1u);
    ASSERT_EQ(decimated.loadProbes(true), 1u);
    ASSERT_TRUE(whole.renderer().hasProbeResources());
    OrbitCamera close = OrbitCamera::fromSettings(p.scene.camera, whole.heightfield());
    close.radius = 150.0f;
    close.elevationDeg = 10.0f;
    RenderRequest q = unprobed(kViewBeauty, false);
    q.probes = true;
    const RenderedImage reference = whole.render(q, close);
    const RenderedImage detailed = decimated.render(q, close);
    const TerrainRenderer::LodChoice chosen = decimated.renderer().lastLod();
    const size_t detailPatches = size_t(std::count_if(chosen.detail.begin(), chosen.detail.end(), [](int8_t d) { return d >= 0; }));
    decimated.renderer().setSourceDetail(false);
    const RenderedImage coarse = decimated.render(q, close);
    const double coarsePixels = decimated.renderer().lastLod().screenErrorPixels;
    const test::ImageDiff d = test::compareImages(detailed.rgba, reference.rgba, kW, kH);
    const test::ImageDiff c = test::compareImages(coarse.rgba, reference.rgba, kW, kH);
    std::printf("detail patches %zu (%zu vertices), %.3f px (without: %.3f px); against the whole mesh: "
                "mean %.5f max %.4f ssim %.5f, without %.5f %.4f %.5f\n",
                detailPatches, chosen.detailVertices, chosen.screenErrorPixels, coarsePixels, d.meanAbs, d.maxAbs, d.ssim,
                c.meanAbs, c.maxAbs, c.ssim);
    EXPECT_GE(detailPatches, 1u);
    EXPECT_LE(chosen.screenErrorPixels, 1.0);
    EXPECT_GT(coarsePixels, 1.0);
    // Near the camera both draw every DEM sample; further out, the same levels' vertices.
    EXPECT_LT(d.meanAbs, 2e-4);
    EXPECT_LT(d.maxAbs, 0.05);
    EXPECT_GT(c.meanAbs, 5e-4);
    EXPECT_LT(d.meanAbs, 0.1 * c.meanAbs);
    EXPECT_GT(d.ssim, c.ssim);
    // The frames are lit by the probes (the probe pass's light at the detail patches' vertices
    // among them): without them the same frame differs.
    decimated.renderer().setSourceDetail(true);
    RenderRequest unlit = q;
    unlit.probes = false;
    EXPECT_GT(test::compareImages(decimated.render(unlit, close).rgba, detailed.rgba, kW, kH).meanAbs, 5e-4);
}

// The viewport's frames (waitForLevelOfDetail off) choose a new camera's levels on a worker: the
// frame that asks draws the set held, the first frame after the worker has finished draws the new
// one, and that frame is the one a frame that waits draws.
TEST_F(RenderTest, AViewportFrameChoosesItsLevelsOnAWorkerAndDrawsTheHeldSetMeanwhile) {
    Project p = sampleProject("lod_worker", 4, 4);
    p.scene.camera.exposureMode = ExposureMode::Manual;
    const size_t vertices = demVertices(p);
    ProjectRenderer waits(*ctx_, p, loadProjectTerrain(p), true, vertices / 3);
    ProjectRenderer viewport(*ctx_, p, loadProjectTerrain(p), true, vertices / 3);
    const OrbitCamera far = OrbitCamera::fromSettings(p.scene.camera, waits.heightfield());
    OrbitCamera close = far;
    close.radius = 150.0f;
    close.elevationDeg = 10.0f;
    RenderRequest q = unprobed(kViewBeauty, false);
    q.waitForLevelOfDetail = false;
    TerrainRenderer& t = viewport.renderer();
    // The first frame holds no set: it chooses its own.
    viewport.render(q, far);
    const uint64_t first = t.levelOfDetailSerial();
    const TerrainRenderer::LodChoice farLevels = t.lastLod();
    EXPECT_GT(first, 0u);
    EXPECT_FALSE(t.levelOfDetailBuilding());
    // The same camera again asks for nothing.
    viewport.render(q, far);
    EXPECT_FALSE(t.levelOfDetailBuilding());
    EXPECT_EQ(t.levelOfDetailSerial(), first);
    // The close camera: this frame draws the far set while the worker chooses.
    const RenderedImage held = viewport.render(q, close);
    EXPECT_TRUE(t.levelOfDetailBuilding());
    EXPECT_EQ(t.levelOfDetailSerial(), first);
    EXPECT_EQ(t.lastLod().levels, farLevels.levels);
    const auto start = std::chrono::steady_clock::now();
    while (!t.levelOfDetailBuilt() && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ASSERT_TRUE(t.levelOfDetailBuilt());
    const RenderedImage landed = viewport.render(q, close);
    EXPECT_GT(t.levelOfDetailSerial(), first);
    EXPECT_FALSE(t.levelOfDetailBuilding()) << "the same camera again started another choice";

    const RenderedImage reference = waits.render(unprobed(kViewBeauty, false), close);
    const TerrainRenderer::LodChoice& chosen = waits.renderer().lastLod();
    EXPECT_GE(std::count_if(chosen.detail.begin(), chosen.detail.end(), [](int8_t d) { return d >= 0; }), 1);
    EXPECT_EQ(t.lastLod().levels, chosen.levels);
    EXPECT_EQ(t.lastLod().detail, chosen.detail);
    EXPECT_EQ(t.lastLod().triangles, chosen.triangles);
    const test::ImageDiff same = test::compareImages(landed.rgba, reference.rgba, kW, kH);
    const test::ImageDiff before = test::compareImages(held.rgba, reference.rgba, kW, kH);
    std::printf("held set against the close camera's own: mean %.5f; landed: mean %.6f max %.6f\n", before.meanAbs,
                same.meanAbs, same.maxAbs);
    EXPECT_LE(same.maxAbs, 1e-6);
    EXPECT_GT(before.meanAbs, 5e-4);
}

// A viewport's first picture of a terrain (waitForLevelOfDetail off) finds no set held: its levels
// are chosen on a worker (levelOfDetailReady) and the frame is put off, nothing chosen where it asked;
// once they have landed it draws them without choosing again, and they are the set, and the frame,
// of a renderer that chose where it recorded. A view the worker does not choose for is ready at once.
TEST_F(RenderTest, AViewportsFirstLevelsAreChosenOnAWorker) {
    Project p = sampleProject("lod_first", 4, 4);
    p.scene.camera.exposureMode = ExposureMode::Manual;
    const size_t vertices = demVertices(p);
    ProjectRenderer waits(*ctx_, p, loadProjectTerrain(p), true, vertices / 3);
    ProjectRenderer viewport(*ctx_, p, loadProjectTerrain(p), true, vertices / 3);
    OrbitCamera camera = OrbitCamera::fromSettings(p.scene.camera, waits.heightfield());
    camera.radius = 150.0f;
    camera.elevationDeg = 10.0f;
    RenderRequest q = unprobed(kViewBeauty, false);
    q.waitForLevelOfDetail = false;
    TerrainRenderer& t = viewport.renderer();
    const RenderSettings s = viewport.settingsOf(q, camera);
    EXPECT_FALSE(t.levelOfDetailReady(s));
    EXPECT_TRUE(t.levelOfDetailBuilding());
    EXPECT_EQ(t.levelOfDetailSerial(), 0u);
    const auto start = std::chrono::steady_clock::now();
    while (!t.levelOfDetailBuilt() && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    EXPECT_FALSE(t.levelOfDetailAwaited());
    EXPECT_TRUE(t.levelOfDetailReady(s));
    EXPECT_EQ(t.levelOfDetailSerial(), 0u) << "a set was published before a frame took it";
    const RenderedImage drawn = viewport.render(q, camera);
    EXPECT_EQ(t.levelOfDetailSerial(), 1u);
    EXPECT_FALSE(t.levelOfDetailBuilding()) << "the frame asked for another set than the one chosen for it";

    const RenderedImage reference = waits.render(unprobed(kViewBeauty, false), camera);
    const TerrainRenderer::LodChoice& chosen = waits.renderer().lastLod();
    EXPECT_GE(std::count_if(chosen.detail.begin(), chosen.detail.end(), [](int8_t d) { return d >= 0; }), 1);
    EXPECT_EQ(t.lastLod().levels, chosen.levels);
    EXPECT_EQ(t.lastLod().detail, chosen.detail);
    EXPECT_EQ(t.lastLod().triangles, chosen.triangles);
    EXPECT_LE(test::compareImages(drawn.rgba, reference.rgba, kW, kH).maxAbs, 1e-6);
    // The traced sun's view chooses its own levels where it records (its per-vertex visibility
    // draws no detail patches).
    ProjectRenderer traced(*ctx_, p, loadProjectTerrain(p), true, vertices / 3);
    RenderRequest sunView = unprobed(kViewSunVisibility, false);
    sunView.waitForLevelOfDetail = false;
    EXPECT_TRUE(traced.renderer().levelOfDetailReady(traced.settingsOf(sunView, camera)));
    EXPECT_FALSE(traced.renderer().levelOfDetailBuilding());
}

// A viewport's frame (waitUntilDrawable off) whose pipelines are not built has them built on a
// worker and is not drawn meanwhile (lavapipe compiles the terrain's in 120-170 ms): the terrain's
// and the sky's at the frame's samples and at the water reflection's one, and the water's. Once they have
// landed the frame records without building any, and it is the frame a renderer that built them
// where it recorded draws. A feature turned on asks for its variant the same way.
TEST_F(RenderTest, PipelinesAFrameLacksAreBuiltOnAWorkerAndDrawTheSameFrame) {
    Project p = sampleProject("pipelines_worker", 4, 4);
    p.scene.camera.exposureMode = ExposureMode::Manual;
    p.scene.fog.enabled = false;
    ProjectRenderer here(*ctx_, p, loadProjectTerrain(p), true);
    addLake(p, here);
    p.scene.water.reflection = WaterReflection::Planar;
    const bool msaa = (ctx_->framebufferSampleCounts() & 4u) != 0;
    if (msaa) p.scene.camera.antialiasing = Antialiasing::Msaa4;
    here.setProject(p);
    ProjectRenderer worker(*ctx_, p, loadProjectTerrain(p), true);
    const OrbitCamera camera = OrbitCamera::fromSettings(p.scene.camera, worker.heightfield());
    RenderRequest q = unprobed(kViewBeauty, false);
    TerrainRenderer& t = worker.renderer();
    auto landed = [&] {
        const auto start = std::chrono::steady_clock::now();
        while (t.pipelinesBuilding() && std::chrono::steady_clock::now() - start < std::chrono::seconds(60))
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        return !t.pipelinesBuilding();
    };
    const RenderSettings s = worker.settingsOf(q, camera);
    EXPECT_FALSE(t.pipelinesReady(s));
    EXPECT_TRUE(t.pipelinesBuilding());
    EXPECT_FALSE(t.pipelinesReady(s)) << "asked again while building";
    ASSERT_TRUE(landed());
    EXPECT_TRUE(t.pipelinesReady(s));
    // The terrain and the sky at the frame's samples and, with 4, at the reflection's 1; the water's.
    EXPECT_EQ(t.pipelinesBuiltOnWorkers(), msaa ? 5u : 3u);
    const RenderedImage drawn = worker.render(q, camera);
    EXPECT_EQ(t.pipelinesBuiltInline(), 0u) << "the frame built a pipeline where it recorded";
    const std::vector<std::string> names = passNames(t.lastFramePasses());
    for (const char* pass : {"terrain", "water-reflection", "water"})
        EXPECT_NE(std::find(names.begin(), names.end(), pass), names.end()) << pass;
    const RenderedImage reference = here.render(q, camera);
    EXPECT_GT(here.renderer().pipelinesBuiltInline(), 0u);
    EXPECT_EQ(here.renderer().pipelinesBuiltOnWorkers(), 0u);
    EXPECT_EQ(drawn.rgba, reference.rgba);

    // Fog on: a new variant of each, built on a worker again.
    p.scene.fog.enabled = true;
    worker.setProject(p);
    const RenderSettings fogged = worker.settingsOf(q, camera);
    EXPECT_FALSE(t.pipelinesReady(fogged));
    ASSERT_TRUE(landed());
    EXPECT_TRUE(t.pipelinesReady(fogged));
    worker.render(q, camera);
    EXPECT_EQ(t.pipelinesBuiltInline(), 0u);
    EXPECT_EQ(t.pipelinesBuiltOnWorkers(), msaa ? 10u : 6u);
    // Back to no fog: the first variants are still there.
    p.scene.fog.enabled = false;
    worker.setProject(p);
    EXPECT_TRUE(t.pipelinesReady(worker.settingsOf(q, camera)));
    // Probes on: the terrain's probe-light variant and the probe pass's compute pipeline (40-50 ms
    // on lavapipe) are built on workers too, and the frame that evaluates the probes builds none.
    ASSERT_EQ(worker.loadProbes(true), 1u);
    RenderRequest probed = q;
    probed.probes = true;
    const RenderSettings withProbes = worker.settingsOf(probed, camera);
    const size_t before = t.pipelinesBuiltOnWorkers();
    EXPECT_FALSE(t.pipelinesReady(withProbes));
    ASSERT_TRUE(landed());
    EXPECT_TRUE(t.pipelinesReady(withProbes));
    // The terrain's at the frame's samples (and the reflection's 1), and the probe pass's.
    EXPECT_EQ(t.pipelinesBuiltOnWorkers(), before + (msaa ? 3u : 2u));
    worker.render(probed, camera);
    const std::vector<std::string> probedPasses = passNames(t.lastFramePasses());
    EXPECT_NE(std::find(probedPasses.begin(), probedPasses.end(), "probe-vertices"), probedPasses.end());
    EXPECT_EQ(t.pipelinesBuiltInline(), 0u) << "the probed frame built a pipeline where it recorded";
}

TEST_F(RenderTest, DetailPatchesMeetTheirPixelWhereverTheCameraIsAndKeepToTheirBudget) {
    Project p = sampleProject("detail_budget", 4, 4);
    // The sample at four times its resolution (bilinear, with a metre of deterministic roughness),
    // drawn at stride 4: 64 patches with two detail levels each.
    DemImportResult fine = loadProjectTerrain(p);
    {
        const Heightfield& h = fine.heightfield;
        const int w = (h.width() - 1) * 4 + 1, d = (h.depth() - 1) * 4 + 1;
        std::vector<float> heights(size_t(w) * size_t(d));
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < w; ++c) {
                const int c0 = std::min(c / 4, h.width() - 2), r0 = std::min(r / 4, h.depth() - 2);
                const float u = float(c - 4 * c0) / 4.0f, v = float(r - 4 * r0) / 4.0f;
                const float z = (1 - v) * ((1 - u) * h.at(c0, r0) + u * h.at(c0 + 1, r0)) +
                                v * ((1 - u) * h.at(c0, r0 + 1) + u * h.at(c0 + 1, r0 + 1));
                const uint32_t hash = (uint32_t(c) * 73856093u) ^ (uint32_t(r) * 19349663u);
                heights[size_t(r) * size_t(w) + size_t(c)] = z + float(hash % 1000u) / 1000.0f;
            }
        fine.heightfield = Heightfield(w, d, h.cellSizeX() / 4.0, h.cellSizeZ() / 4.0, std::move(heights));
    }
    const size_t vertices = size_t(fine.heightfield.width()) * size_t(fine.heightfield.depth());
    ProjectRenderer r(*ctx_, p, std::move(fine), true, vertices / 12);
    TerrainRenderer& t = r.renderer();
    ASSERT_GE(t.meshStride(), 4);
    ASSERT_GE(t.detailLevels(), 2);
    const RenderRequest q = unprobed(kViewBeauty, false);
    auto detailPatches = [](const TerrainRenderer::LodChoice& c) {
        return size_t(std::count_if(c.detail.begin(), c.detail.end(), [](int8_t d) { return d >= 0; }));
    };
    // Near the ground and further out, low and higher: a detail patch's ring zipped to a drawn
    // neighbour leaves what that neighbour's grid leaves out, seen nearer; the neighbour is drawn
    // from the DEM too, so every patch keeps to the pixel.
    OrbitCamera close = OrbitCamera::fromSettings(p.scene.camera, r.heightfield());
    for (const float radius : {150.0f, 600.0f, 1500.0f})
        for (const float elevation : {10.0f, 25.0f}) {
            close.radius = radius;
            close.elevationDeg = elevation;
            r.render(q, close);
            std::printf("%.0f m at %.0f deg: %zu detail patches, %.3f px\n", radius, elevation,
                        detailPatches(t.lastLod()), t.lastLod().screenErrorPixels);
            EXPECT_GE(detailPatches(t.lastLod()), 1u);
            EXPECT_LE(t.lastLod().screenErrorPixels, 1.0) << radius << " m at " << elevation << " deg";
        }
    close.radius = 600.0f;
    close.elevationDeg = 25.0f;
    r.render(q, close);
    const TerrainRenderer::LodChoice free = t.lastLod();
    t.setSourceDetail(false);
    r.render(q, close);
    const double drawnPixels = t.lastLod().screenErrorPixels;
    t.setSourceDetail(true);
    t.setDetailVertexBudget(free.detailVertices / 3);
    r.render(q, close);
    const TerrainRenderer::LodChoice bound = t.lastLod();
    std::printf("free: %zu patches, %zu vertices, %.3f px; a third of the budget: %zu patches, %zu vertices, "
                "%.3f px; without detail %.3f px\n",
                detailPatches(free), free.detailVertices, free.screenErrorPixels, detailPatches(bound),
                bound.detailVertices, bound.screenErrorPixels, drawnPixels);
    EXPECT_LE(free.screenErrorPixels, 1.0);
    EXPECT_LE(bound.detailVertices, free.detailVertices / 3);
    EXPECT_GT(bound.screenErrorPixels, 1.0);  // the budget binds
    EXPECT_LT(bound.screenErrorPixels, 0.5 * drawnPixels);
    // A frame of more pixels than kDetailBudgetPixels gets the budget in proportion (1920 x 1080:
    // 2.25 times), so its pixel costs no more of the DEM than a 1280 x 720 frame's does.
    const size_t budget = free.detailVertices / 3;
    EXPECT_NEAR(double(TerrainRenderer::detailBudgetFor(budget, 720.0, 16.0 / 9.0)), double(budget), 1.0);
    const size_t scaled = TerrainRenderer::detailBudgetFor(budget, 1080.0, 16.0 / 9.0);
    EXPECT_NEAR(double(scaled), 2.25 * double(budget), 1.0);
    EXPECT_NEAR(double(TerrainRenderer::detailBudgetFor(budget, 4320.0, 16.0 / 9.0)),
                TerrainRenderer::kDetailBudgetMaxScale * double(budget), 1.0);
    RenderRequest large = q;
    large.width = 1920;
    large.height = 1080;
    r.render(large, close);
    std::printf("1920 x 1080 at a third of the budget: %zu vertices (budget %zu), %.3f px\n",
                t.lastLod().detailVertices, scaled, t.lastLod().screenErrorPixels);
    EXPECT_GT(t.lastLod().detailVertices, budget);
    EXPECT_LE(t.lastLod().detailVertices, scaled);
}

TEST_F(RenderTest, TheLevelOfDetailDrawnStraysAtMostAPixelFromTheWholeMesh) {
    Project p = sampleProject("lod", 4, 4);
    ProjectRenderer r(*ctx_, p);
    TerrainRenderer& t = r.renderer();
    const lod::Patches& patches = t.lodPatches();
    ASSERT_GE(patches.count(), 16u);
    EXPECT_EQ(t.decimationError(), 0.0);  // the sample is drawn whole
    const size_t whole = t.triangleCount();
    for (const auto& [w, h] : {std::pair<uint32_t, uint32_t>{kW, kH}, {480, 320}}) {
        t.setLodPixelError(1.0);
        const RenderedImage lod = draw(r, kViewBeauty, false, false, w, h);
        const TerrainRenderer::LodChoice chosen = t.lastLod();
        t.setLodPixelError(0.0);
        const RenderedImage all = draw(r, kViewBeauty, false, false, w, h);
        std::printf("%ux%u: %zu of %zu triangles, %.3f px\n", w, h, chosen.triangles, t.lastLod().triangles,
                    chosen.screenErrorPixels);
        EXPECT_LE(chosen.screenErrorPixels, 1.0);
        EXPECT_EQ(t.lastLod().screenErrorPixels, 0.0);
        EXPECT_LT(chosen.triangles, whole / 2) << w << "x" << h;
        const test::ImageDiff d = test::compareImages(lod.rgba, all.rgba, w, h);
        std::printf("  mean %.5f max %.4f ssim %.5f\n", d.meanAbs, d.maxAbs, d.ssim);
        EXPECT_LT(d.meanAbs, 0.004) << w << "x" << h;
        EXPECT_GT(d.ssim, 0.98) << w << "x" << h;
    }
    // Standing near the ground: the patches around the camera draw every vertex.
    t.setLodPixelError(1.0);
    OrbitCamera close = OrbitCamera::fromSettings(p.scene.camera, r.heightfield());
    close.radius = 150.0f;
    close.elevationDeg = 10.0f;
    RenderRequest q = unprobed(kViewBeauty, false);
    r.render(q, close);
    const std::vector<uint8_t>& levels = t.lastLod().levels;
    ASSERT_EQ(levels.size(), patches.count());
    size_t wholePatches = 0;
    for (size_t k = 0; k < levels.size(); ++k)
        if (levels[k] == 0 && lod::distanceToBox(close.position(), patches.lo[k], patches.hi[k]) < 100.0) ++wholePatches;
    EXPECT_GE(wholePatches, 1u);
    EXPECT_GT(*std::max_element(levels.begin(), levels.end()), 0);
    EXPECT_LE(t.lastLod().screenErrorPixels, 1.0);
}
