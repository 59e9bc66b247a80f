// Render tests on the real Vulkan path (Mesa lavapipe in CI): golden images of every debug view
// and behaviour checks. They skip, saying why, when no Vulkan device exists, and fail on any
// validation-layer message.
#include <cstdlib>
#include <filesystem>
#include <memory>

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include "ImageCompare.h"
#include "ImageFile.h"
#include "RenderJob.h"
#include "TerrainLoading.h"
#include "render/DebugViews.h"

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

RenderedImage draw(ProjectRenderer& r, int view, bool probes = true) {
    RenderRequest q;
    q.width = kW;
    q.height = kH;
    q.debugView = view;
    q.probes = probes;
    return r.render(q);
}

double meanAbsDiff(const RenderedImage& a, const RenderedImage& b) {
    return test::compareImages(a.rgba, b.rgba, a.width, a.height).meanAbs;
}

}  // namespace

TEST_F(RenderTest, GoldenImagesOfEveryView) {
    ProjectRenderer r(*ctx_, sampleProject("golden", 8, 8));
    ASSERT_EQ(r.loadProbes(true), 1u);
    const bool update = std::getenv("TERRALUX_UPDATE_GOLDENS") != nullptr;
    for (const auto& v : debugViews()) {
        const RenderedImage img = draw(r, v.number);
        const fs::path golden = kGolden / (std::to_string(v.number) + "-" + v.name + ".png");
        const fs::path actual = kOut / (std::to_string(v.number) + "-" + v.name + ".png");
        writeImage(actual, img.width, img.height, img.rgba);
        if (update) {
            writeImage(golden, img.width, img.height, img.rgba);
            continue;
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
            const fs::path diff = kOut / (std::to_string(v.number) + "-" + v.name + ".diff.png");
            writeImage(diff, kW, kH, d.diff);
            ADD_FAILURE() << "view " << v.number << " " << v.name << ": mean |diff| "
                          << d.meanAbs * 255.0 << "/255, SSIM " << d.ssim << ", max "
                          << d.maxAbs * 255.0 << "/255 at (" << d.maxX << ", " << d.maxY
                          << "); diff image " << diff;
        }
    }
}

TEST_F(RenderTest, ProbesDisabledEqualsTheUnprobedImage) {
    ProjectRenderer withProbes(*ctx_, sampleProject("disabled", 8, 8));
    ASSERT_EQ(withProbes.loadProbes(true), 1u);
    ProjectRenderer without(*ctx_, sampleProject("none", 8, 8));  // no probes loaded at all
    const RenderedImage off = draw(withProbes, 0, false);
    const RenderedImage none = draw(without, 0, true);
    const RenderedImage on = draw(withProbes, 0, true);
    const auto d = test::compareImages(off.rgba, none.rgba, kW, kH);
    EXPECT_LE(d.maxAbs, 1.0 / 255.0);
    EXPECT_GT(meanAbsDiff(on, off), 0.5 / 255.0) << "probe lighting changes the image";
}

TEST_F(RenderTest, OneByOneGridWeighsOneEverywhere) {
    ProjectRenderer r(*ctx_, sampleProject("one", 1, 1));
    ASSERT_EQ(r.loadProbes(true), 1u);
    const RenderedImage w = draw(r, 51);
    const RenderedImage albedo = draw(r, 1);
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
    q.debugView = 50;
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
    auto linear50 = [&](ProjectRenderer& r) {
        RenderRequest q;
        q.width = kW;
        q.height = kH;
        q.debugView = 50;
        q.linearOutput = true;
        return r.render(q);
    };
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
    ProjectRenderer rb(*ctx_, b);
    ASSERT_EQ(rb.loadProbes(true), 1u);
    ProjectRenderer rc(*ctx_, sampleProject("gridC", 2, 2));
    ASSERT_EQ(rc.loadProbes(true), 1u);
    const RenderedImage ia = linear50(ra), ib = linear50(rb), ic = linear50(rc);
    EXPECT_GT(relDiff(ia, ib), 0.2) << "sky colour";
    EXPECT_GT(relDiff(ia, ic), 0.01) << "probe grid";
}

TEST_F(RenderTest, EveryViewDiffersFromBeauty) {
    ProjectRenderer r(*ctx_, sampleProject("views", 8, 8));
    ASSERT_EQ(r.loadProbes(true), 1u);
    const RenderedImage beauty = draw(r, 0);
    for (const auto& v : debugViews()) {
        if (v.number == 0) continue;
        EXPECT_GT(meanAbsDiff(draw(r, v.number), beauty), 2.0 / 255.0) << v.number << " " << v.name;
    }
}
