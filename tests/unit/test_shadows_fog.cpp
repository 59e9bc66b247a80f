// Cascade splits and height-fog optics against their formulas, and the shadows and fog sections
// of the project file.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "ParameterTable.h"
#include "Project.h"
#include "ProjectErrors.h"
#include "ShaderMath.h"
#include "scene/ShadowCascades.h"

namespace fogmath = terralux::glsl;

using namespace terralux;
using nlohmann::json;

TEST(ShadowSplits, PracticalSplitsAreUniformMeanAndLogarithmic) {
    const double n = 10.0, f = 10000.0;
    const int N = 4;
    const auto uni = practicalSplits(n, f, N, 0.0);
    const auto log = practicalSplits(n, f, N, 1.0);
    const auto half = practicalSplits(n, f, N, 0.5);
    ASSERT_EQ(uni.size(), 4u);
    for (int i = 1; i <= N; ++i) {
        const double s = double(i) / N;
        const double cUni = n + (f - n) * s, cLog = n * std::pow(f / n, s);
        EXPECT_NEAR(uni[size_t(i - 1)], cUni, 1e-9 * f) << i;
        EXPECT_NEAR(log[size_t(i - 1)], cLog, 1e-9 * f) << i;
        EXPECT_NEAR(half[size_t(i - 1)], 0.5 * (cUni + cLog), 1e-9 * f) << i;
    }
    // λ = 1 splits at the geometric mean: the second of four logarithmic splits is √(n·f).
    EXPECT_NEAR(log[1], std::sqrt(n * f), 1e-9 * f);
    EXPECT_EQ(practicalSplits(n, f, 1, 0.7), std::vector<double>{f});
}

TEST(ShadowSplits, RangeCoversTheTerrainAndManualSplitsAreUsed) {
    OrbitCamera cam;
    cam.target = glm::vec3(0.0f);
    cam.radius = 5000.0f;
    cam.elevationDeg = 30.0f;
    const glm::vec3 lo(-2000.0f, 0.0f, -2000.0f), hi(2000.0f, 500.0f, 2000.0f);
    ShadowSettings s;
    CascadeRange r = cascadeRange(s, cam, 16.0f / 9.0f, lo, hi);
    ASSERT_EQ(r.ends.size(), 4u);
    EXPECT_GT(r.nearDistance, 1000.0);  // the camera stands outside the box
    EXPECT_NEAR(r.farDistance, r.ends.back(), 1e-9);
    EXPECT_GT(r.farDistance, 5000.0);
    for (size_t i = 1; i < r.ends.size(); ++i) EXPECT_GT(r.ends[i], r.ends[i - 1]);
    EXPECT_FALSE(r.fadesOut);  // the last cascade reaches the farthest corner
    s.maxDistance = 4000.0;
    EXPECT_NEAR(cascadeRange(s, cam, 1.0f, lo, hi).farDistance, 4000.0, 1e-9);
    EXPECT_TRUE(cascadeRange(s, cam, 1.0f, lo, hi).fadesOut);  // terrain lies beyond 4 km
    s.maxDistance = 1.0e6;
    EXPECT_FALSE(cascadeRange(s, cam, 1.0f, lo, hi).fadesOut);  // a distance past the terrain
    s.maxDistance = 4000.0;
    s.splitMode = SplitMode::Manual;
    s.cascades = 3;
    s.splits = std::vector<double>{3000.0, 3500.0};
    r = cascadeRange(s, cam, 1.0f, lo, hi);
    EXPECT_EQ(r.ends, (std::vector<double>{3000.0, 3500.0, 4000.0}));
}

TEST(ShadowSplits, ManualSplitsAreFittedToTheCascadeCount) {
    CascadeRange practical;
    practical.nearDistance = 100.0;
    practical.farDistance = 10000.0;
    practical.ends = {1234.4, 3456.6, 6789.2, 10000.0};
    // None authored: the practical inner ends, in whole metres.
    EXPECT_EQ(fitManualSplits({}, 4, practical, std::nullopt), (std::vector<double>{1234.0, 3457.0, 6789.0}));
    // Fewer cascades keep the leading authored splits; the authored values stay as they are.
    EXPECT_EQ(fitManualSplits({500.5, 2000.0, 3000.0}, 2, practical, std::nullopt), std::vector<double>{500.5});
    // More cascades keep the authored ones and fill from the practical ends beyond them.
    EXPECT_EQ(fitManualSplits({2000.0}, 4, practical, std::nullopt), (std::vector<double>{2000.0, 3457.0, 6789.0}));
    // Authored splits beyond every practical one: even steps to the far end.
    EXPECT_EQ(fitManualSplits({8000.0}, 3, practical, std::nullopt), (std::vector<double>{8000.0, 9000.0}));
    // A shadow distance below the last split drops it and what follows.
    const auto below = fitManualSplits({1000.0, 5000.0, 9000.0}, 4, practical, 6000.0);
    ASSERT_EQ(below.size(), 3u);
    EXPECT_EQ(below[0], 1000.0);
    EXPECT_EQ(below[1], 5000.0);
    EXPECT_GT(below[2], 5000.0);
    EXPECT_LT(below[2], 6000.0);
    // Out of order or not positive: kept only up to the first that breaks the rule.
    EXPECT_EQ(fitManualSplits({3000.0, 2000.0, 9000.0}, 4, practical, std::nullopt),
              (std::vector<double>{3000.0, 3457.0, 6789.0}));
    EXPECT_EQ(fitManualSplits({0.0}, 2, practical, std::nullopt), std::vector<double>{1234.0});
    EXPECT_TRUE(fitManualSplits({1000.0}, 1, practical, std::nullopt).empty());
    // A short range keeps fractions where whole metres would reorder the splits.
    CascadeRange tiny;
    tiny.nearDistance = 0.1;
    tiny.farDistance = 1.0;
    tiny.ends = {0.3, 0.6, 1.0};
    EXPECT_EQ(fitManualSplits({}, 3, tiny, std::nullopt), (std::vector<double>{0.3, 0.6}));
    // The fitted splits pass the project's rules.
    const auto fitted = fitManualSplits({2000.0}, 4, practical, 9000.0);
    json doc = projectToJson(Project{});
    doc["shadows"]["split_mode"] = "manual";
    doc["shadows"]["max_distance"] = 9000.0;
    doc["shadows"]["splits"] = fitted;
    EXPECT_NO_THROW(sceneFromJson(doc, "project", nullptr));
}

TEST(ShadowSplits, CascadesAreStableAsTheCameraTurns) {
    // The same slice seen from two camera azimuths: the same radius, and light-space centres on
    // the same texel grid (the map moves by whole texels only).
    const glm::vec3 lo(-2000.0f, 0.0f, -2000.0f), hi(2000.0f, 500.0f, 2000.0f);
    const glm::vec3 sun = glm::normalize(glm::vec3(0.3f, 0.4f, -0.5f));
    ShadowSettings s;
    OrbitCamera a;
    a.radius = 4000.0f;
    OrbitCamera b = a;
    b.azimuthDeg += 7.3f;
    const CascadeRange r = cascadeRange(s, a, 1.5f, lo, hi);
    const auto ca = fitCascades(r, a, 1.5f, sun, 2048, lo, hi);
    const auto cb = fitCascades(r, b, 1.5f, sun, 2048, lo, hi);
    ASSERT_EQ(ca.size(), 4u);
    for (size_t i = 0; i < ca.size(); ++i) {
        EXPECT_EQ(ca[i].radius, cb[i].radius);
        // The world origin's position in each map, in texels: an integer offset between the two.
        const glm::vec4 pa = ca[i].lightViewProj * glm::vec4(0, 0, 0, 1), pb = cb[i].lightViewProj * glm::vec4(0, 0, 0, 1);
        const double dx = (pa.x - pb.x) * 0.5 * 2048.0, dy = (pa.y - pb.y) * 0.5 * 2048.0;
        EXPECT_NEAR(dx, std::round(dx), 1e-2) << i;
        EXPECT_NEAR(dy, std::round(dy), 1e-2) << i;
        // Every corner of the slice lands inside the map.
        EXPECT_GT(ca[i].texelSize, 0.0f);
    }
}

namespace {

// Midpoint-rule optical depth of the fog along a ray, in double.
double numericDepth(double density, double falloff, double h0, double dirY, double distance) {
    const int n = 200000;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        const double t = (i + 0.5) * distance / n;
        sum += density * std::exp(-falloff * (h0 + dirY * t));
    }
    return sum * distance / n;
}

}  // namespace

TEST(HeightFog, OpticalDepthMatchesTheIntegralUpDownAndHorizontal) {
    const float density = 2e-4f, falloff = 1.0f / 800.0f;
    struct Ray {
        float h0, dirY, distance;
    };
    for (const Ray& r : {Ray{100.0f, 0.5f, 5000.0f}, Ray{1500.0f, -0.3f, 4000.0f}, Ray{300.0f, 0.0f, 20000.0f},
                         Ray{300.0f, 1e-7f, 20000.0f}, Ray{300.0f, -1e-6f, 20000.0f}, Ray{-200.0f, 0.02f, 30000.0f},
                         Ray{0.0f, -1.0f, 10.0f}}) {
        const double exact = numericDepth(density, falloff, r.h0, r.dirY, r.distance);
        const double closed = fogmath::fogOpticalDepth(density, falloff, r.h0, r.dirY, r.distance);
        EXPECT_NEAR(closed / exact, 1.0, 1e-4) << r.h0 << " " << r.dirY << " " << r.distance;
    }
    // No falloff: uniform fog, depth = density × distance.
    EXPECT_NEAR(fogmath::fogOpticalDepth(1e-3f, 0.0f, 50.0f, 0.7f, 1000.0f), 1.0f, 1e-6f);
}

TEST(HeightFog, PhaseFunctionIsNormalisedAndForwardPeaked) {
    for (float g : {0.0f, 0.6f, -0.4f, 0.9f}) {
        double sum = 0.0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            const double mu = -1.0 + (i + 0.5) * 2.0 / n;
            sum += fogmath::henyeyGreenstein(g, float(mu)) * 2.0 * M_PI * (2.0 / n);
        }
        EXPECT_NEAR(sum, 1.0, 2e-3) << g;
    }
    EXPECT_GT(fogmath::henyeyGreenstein(0.6f, 1.0f), fogmath::henyeyGreenstein(0.6f, -1.0f));
}

TEST(ShadowSettingsFile, ManualSplitsAreValidated) {
    json manual = defaultProjectJson();
    manual["shadows"]["split_mode"] = "manual";
    manual["shadows"]["cascades"] = 3;
    EXPECT_NE(test::projectErrorFor("shadows.splits", nullptr, manual).find("must list 2 distances"), std::string::npos)
        << test::projectErrorFor("shadows.splits", nullptr, manual);
    EXPECT_EQ(test::projectErrorFor("shadows.splits", json{500, 2000}, manual), "");
    const std::string decreasing = test::projectErrorFor("shadows.splits", json{2000, 500}, manual);
    EXPECT_NE(decreasing.find("shadows.splits[1]"), std::string::npos) << decreasing;
    EXPECT_NE(decreasing.find("strictly increasing"), std::string::npos) << decreasing;
    const std::string count = test::projectErrorFor("shadows.splits", json{500, 1000, 2000}, manual);
    EXPECT_NE(count.find("2"), std::string::npos) << count;
    manual["shadows"]["max_distance"] = 1500;
    const std::string beyond = test::projectErrorFor("shadows.splits", json{500, 2000}, manual);
    EXPECT_NE(beyond.find("max_distance"), std::string::npos) << beyond;
    EXPECT_NE(test::projectErrorFor("shadows.map_resolution", 256).find("[512, 4096]"), std::string::npos);
    EXPECT_NE(test::projectErrorFor("shadows.filter", "soft").find("pcss"), std::string::npos);
    EXPECT_NE(test::projectErrorFor("fog.anisotropy", 1.0).find("fog.anisotropy"), std::string::npos);
}

TEST(ShadowSettingsFile, SectionsRoundTrip) {
    json doc = defaultProjectJson();
    doc["shadows"] = {{"cascades", 2}, {"split_mode", "manual"}, {"splits", {750.5}}, {"filter", "pcf"},
                      {"map_resolution", 1024}};
    doc["fog"] = {{"enabled", true}, {"density", 1e-4}, {"base_height", 120.0}, {"color", {0.5, 0.6, 0.7}}};
    doc["camera"]["exposure_ev"] = -1.5;
    const SceneDescription scene = sceneFromJson(doc, "p.json", nullptr);
    EXPECT_EQ(scene.shadows.cascades, 2);
    EXPECT_EQ(scene.shadows.filter, ShadowFilter::Pcf);
    ASSERT_TRUE(scene.shadows.splits);
    EXPECT_EQ(*scene.shadows.splits, std::vector<double>{750.5});
    EXPECT_TRUE(scene.fog.enabled);
    ASSERT_TRUE(scene.fog.baseHeight);
    EXPECT_EQ(*scene.fog.baseHeight, 120.0);
    EXPECT_EQ(scene.camera.exposureEv, -1.5);
    const json back = sceneToJson(scene);
    EXPECT_EQ(back["shadows"]["splits"], json({750.5}));
    EXPECT_EQ(back["fog"]["color"], json({0.5, 0.6, 0.7}));
    EXPECT_EQ(sceneFromJson(back, "p.json", nullptr).shadows.mapResolution, 1024);
}

TEST(HeightFog, TheSkysDepthIsTheWholeRisingRayAndMeetsTheGroundsAtTheHorizon) {
    const float density = 2e-5f, falloff = 1.0f / 1200.0f, h0 = 900.0f;
    // Rising: the limit of the depth over ever longer distances.
    for (float dirY : {0.5f, 0.05f, 0.005f}) {
        const double whole = fogmath::fogSkyOpticalDepth(density, falloff, h0, dirY, 1.0e4f);
        const double far = numericDepth(density, falloff, h0, dirY, 60.0f / (falloff * dirY));
        EXPECT_NEAR(whole / far, 1.0, 1e-4) << dirY;
        EXPECT_GT(whole, fogmath::fogOpticalDepth(density, falloff, h0, dirY, 1.0e4f)) << dirY;
    }
    // Toward the horizon it grows without bound, as the depth to level ground below it does: the
    // two meet in the fog's own colour.
    EXPECT_GT(fogmath::fogSkyOpticalDepth(density, falloff, h0, 1e-6f, 1.0e4f), 50.0f);
    EXPECT_GT(fogmath::fogOpticalDepth(density, falloff, h0, -1e-6f, h0 / 1e-6f), 50.0f);
    // Uniform fog has no top, and a falling ray meets the far plane: the depth over that distance.
    EXPECT_FLOAT_EQ(fogmath::fogSkyOpticalDepth(1e-3f, 0.0f, 50.0f, 0.7f, 1000.0f), 1.0f);
    EXPECT_FLOAT_EQ(fogmath::fogSkyOpticalDepth(density, falloff, h0, -0.2f, 5000.0f),
                    fogmath::fogOpticalDepth(density, falloff, h0, -0.2f, 5000.0f));
}
