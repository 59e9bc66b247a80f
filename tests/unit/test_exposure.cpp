// The camera's exposure: EV100 against scene units, the two meters and the adaptation
// (renderer/scene/Exposure.h).

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "ParameterTable.h"
#include "Project.h"
#include "bake/PhysicalSky.h"
#include "scene/Exposure.h"

using namespace terralux;

namespace {

// A frame of `n` pixels of grey scene-linear radiance `value`, then `m` pixels of `other`.
std::vector<float> frame(size_t n, float value, size_t m = 0, float other = 0.0f) {
    std::vector<float> rgba;
    for (size_t i = 0; i < n + m; ++i) {
        const float v = i < n ? value : other;
        rgba.insert(rgba.end(), {v, v, v, 1.0f});
    }
    return rgba;
}

}  // namespace

TEST(Exposure, TheDefaultEv100IsTheExposureTheDefaultsWereSetFor) {
    // Before EV100 the display multiplied scene light by 2^exposure_ev: the default must keep 1.
    EXPECT_NEAR(exposureScale(kDefaultEv100, 0.0), 1.0, 1e-4);
    EXPECT_NEAR(kDefaultEv100, std::log2(1.0 / (1.2 * double(kSceneUnitsPerLux))), 1e-4);
    // A stop of EV100 halves the displayed light; a stop of compensation doubles it.
    EXPECT_DOUBLE_EQ(exposureScale(13.0, 0.0) / exposureScale(14.0, 0.0), 2.0);
    EXPECT_DOUBLE_EQ(exposureScale(13.0, 1.0) / exposureScale(13.0, 0.0), 2.0);
    // Saturation: 1.2 x 2^EV100 cd/m2 displays as 1.
    const double cd = 1.2 * std::exp2(15.0);
    EXPECT_NEAR(cd * double(kSceneUnitsPerLux) * exposureScale(15.0, 0.0), 1.0, 1e-9);
}

TEST(Exposure, TheMeterReadsTheReflectedLightCalibration) {
    // A uniform frame of L cd/m2 reads log2(L x 100 / 12.5) in both modes.
    const double cd = 4000.0;
    const std::vector<float> grey = frame(1000, float(cd * kSceneUnitsPerLux));
    const double expected = std::log2(cd * 100.0 / 12.5);
    EXPECT_NEAR(meterEv100(grey, 100, 10, ExposureMode::Average), expected, 1e-4);
    EXPECT_NEAR(meterEv100(grey, 100, 10, ExposureMode::Histogram), expected, 1e-4);
    // Twice the light reads one stop more: the exposure follows the light, and the image holds.
    const std::vector<float> twice = frame(1000, float(2.0 * cd * kSceneUnitsPerLux));
    EXPECT_NEAR(meterEv100(twice, 100, 10, ExposureMode::Histogram) - expected, 1.0, 1e-4);
    EXPECT_TRUE(std::isnan(meterEv100(grey, 100, 10, ExposureMode::Manual)));
    // A black frame reads the floor, not minus infinity.
    EXPECT_NEAR(meterEv100(frame(100, 0.0f), 10, 10, ExposureMode::Average), -7.0, 1e-9);
}

TEST(Exposure, TheHistogramIgnoresTheDarkestAndBrightestTenth) {
    // 92 % of the frame at L, 4 % black and 4 % a glint 2^12 brighter: the histogram reads L
    // exactly; the average is pulled by both tails.
    const double cd = 2000.0;
    const float v = float(cd * kSceneUnitsPerLux);
    std::vector<float> rgba = frame(920, v, 40, 0.0f);
    const std::vector<float> glints = frame(40, v * 4096.0f);
    rgba.insert(rgba.end(), glints.begin(), glints.end());
    const double expected = std::log2(cd * 8.0);
    EXPECT_NEAR(meterEv100(rgba, 1000, 1, ExposureMode::Histogram), expected, 1e-4);
    EXPECT_GT(std::abs(meterEv100(rgba, 1000, 1, ExposureMode::Average) - expected), 0.3);
}

TEST(Exposure, AdaptationFollowsTheMeterExponentially) {
    // After one time constant 1 - 1/e of the way, after five within 1 %; 0 s jumps; a first frame
    // (nothing shown yet) starts at the meter.
    EXPECT_NEAR(adaptEv100(10.0, 14.0, 1.0, 1.0), 14.0 - 4.0 * std::exp(-1.0), 1e-12);
    EXPECT_NEAR(adaptEv100(10.0, 14.0, 5.0, 1.0), 14.0, 0.04 * 1.0 + 1e-9);
    EXPECT_DOUBLE_EQ(adaptEv100(10.0, 14.0, 0.1, 0.0), 14.0);
    EXPECT_DOUBLE_EQ(adaptEv100(std::nan(""), 14.0, 0.1, 1.0), 14.0);
    EXPECT_DOUBLE_EQ(adaptEv100(10.0, 14.0, 0.0, 1.0), 10.0);
}

TEST(Exposure, TheCameraScaleIsManualOrWhatTheViewportShows) {
    CameraSettings c;
    c.exposureMode = ExposureMode::Manual;
    c.ev100 = 12.0;
    c.exposureEv = 0.5;
    EXPECT_DOUBLE_EQ(cameraExposureScale(c, 15.0), exposureScale(12.0, 0.5));
    c.exposureMode = ExposureMode::Histogram;
    EXPECT_DOUBLE_EQ(cameraExposureScale(c, 15.0), exposureScale(15.0, 0.5));
    EXPECT_DOUBLE_EQ(cameraExposureScale(c, std::nan("")), exposureScale(12.0, 0.5));
}

TEST(Exposure, TheSettingsAreParametersWithTheirRules) {
    nlohmann::json doc = defaultProjectJson();
    EXPECT_EQ(doc["camera"]["exposure_mode"], "histogram");
    EXPECT_NEAR(doc["camera"]["ev100"].get<double>(), kDefaultEv100, 1e-9);
    applyOverride(doc, "camera.exposure_mode=\"average\"");
    applyOverride(doc, "camera.adaptation_s=0");
    const SceneDescription s = sceneFromJson(doc, "--set", nullptr);
    EXPECT_EQ(s.camera.exposureMode, ExposureMode::Average);
    EXPECT_EQ(s.camera.adaptationSeconds, 0.0);
    // An unknown mode and an EV100 out of range are refused, naming the value and the rule.
    for (const auto& [edit, words] : std::vector<std::pair<std::string, std::string>>{
             {"camera.exposure_mode=\"spot\"", "histogram"}, {"camera.ev100=40", "24"}}) {
        nlohmann::json bad = defaultProjectJson();
        applyOverride(bad, edit);
        try {
            sceneFromJson(bad, "--set", nullptr);
            ADD_FAILURE() << edit << " was accepted";
        } catch (const std::exception& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    }
}
