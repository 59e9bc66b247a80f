// The viewport's dynamic resolution (renderer/scene/DynamicResolution.h): the scale that holds a
// frame budget from measured frames, its steps, and the sizes drawn.

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "scene/DynamicResolution.h"

using namespace terralux;

TEST(DynamicResolution, FullResolutionUntilAFrameIsMeasuredAndWhileItFits) {
    DynamicResolution r(100.0);
    EXPECT_EQ(r.interactiveScale(), 1.0);
    EXPECT_EQ(r.predictedMilliseconds(1.0), 0.0);
    r.frameFinished(80.0, 1.0);
    EXPECT_EQ(r.interactiveScale(), 1.0);
    EXPECT_DOUBLE_EQ(r.predictedMilliseconds(1.0), 80.0);
    // Each step halves the pixels.
    for (size_t i = 1; i < DynamicResolution::kScales.size(); ++i)
        EXPECT_NEAR(std::pow(DynamicResolution::kScales[i] / DynamicResolution::kScales[i - 1], 2.0), 0.5, 1e-12);
}

TEST(DynamicResolution, OneScaleMeasuredTakesAllTheTimeAsPixels) {
    // 300 ms at full resolution: half the pixels 150 ms, over 100; a quarter 75 ms.
    DynamicResolution r(100.0);
    r.frameFinished(300.0, 1.0);
    EXPECT_DOUBLE_EQ(r.interactiveScale(), 0.5);
    EXPECT_DOUBLE_EQ(r.predictedMilliseconds(0.5), 75.0);
    // 2 s: even 1/16 of the pixels is 125 ms, so the smallest step.
    DynamicResolution slow(100.0);
    slow.frameFinished(2000.0, 1.0);
    EXPECT_EQ(slow.interactiveScale(), 0.25);
    // A frame measured at half the side is a quarter of the full one.
    DynamicResolution half(100.0);
    half.frameFinished(75.0, 0.5);
    EXPECT_DOUBLE_EQ(half.predictedMilliseconds(1.0), 300.0);
    // A rounded size counts at the nearest step.
    DynamicResolution near(100.0);
    near.frameFinished(75.0, 0.502);
    EXPECT_DOUBLE_EQ(near.predictedMilliseconds(1.0), 300.0);
}

TEST(DynamicResolution, TwoScalesSeparateTheFixedCostFromThePixels) {
    // Measured on lavapipe (bench_render BM_DynamicResolution, N42E001 at 1350 x 990): 780 ms at
    // full resolution and 136 ms at a quarter of the side, so about 95 ms that no scale removes.
    DynamicResolution r(200.0);
    r.frameFinished(780.0, 1.0);
    r.frameFinished(136.0, 0.25);
    const double b = (780.0 - 136.0) / (1.0 - 0.0625), a = 780.0 - b;
    EXPECT_NEAR(r.predictedMilliseconds(0.5), a + 0.25 * b, 1e-9);
    // 1/(2√2) of the side is predicted at 181 ms, within 200: taking all 136 ms as pixels would
    // have predicted 272 and drawn at a quarter.
    EXPECT_NEAR(r.interactiveScale(), DynamicResolution::kScales[3], 1e-12);
    // No step holds 100 ms: the smallest.
    r.setBudgetMilliseconds(100.0);
    EXPECT_EQ(r.interactiveScale(), 0.25);
    // A fit that does not hold (dearer at fewer pixels: the view changed between the frames)
    // falls back to the last frame, all pixels.
    DynamicResolution odd(100.0);
    odd.frameFinished(50.0, 1.0);
    odd.frameFinished(60.0, 0.5);
    EXPECT_DOUBLE_EQ(odd.predictedMilliseconds(1.0), 240.0);
    // Mostly fixed cost: fewer pixels barely help, and the fit says so.
    DynamicResolution fixed(100.0);
    fixed.frameFinished(50.0, 1.0);
    fixed.frameFinished(40.0, 0.5);
    EXPECT_NEAR(fixed.predictedMilliseconds(0.25), 40.0 - (10.0 / 0.75) * (0.25 - 0.0625), 1e-9);
}

TEST(DynamicResolution, EachScaleIsSmoothedAndNonsenseIsIgnored) {
    DynamicResolution r(100.0);
    r.frameFinished(400.0, 1.0);
    r.frameFinished(200.0, 1.0);
    EXPECT_DOUBLE_EQ(r.predictedMilliseconds(1.0), 300.0);
    r.frameFinished(-1.0, 1.0);
    r.frameFinished(NAN, 1.0);
    r.frameFinished(10.0, 0.0);
    r.frameFinished(10.0, 2.0);
    EXPECT_DOUBLE_EQ(r.predictedMilliseconds(1.0), 300.0);
}

TEST(DynamicResolution, TheBudgetIsAPositiveNumber) {
    EXPECT_THROW(DynamicResolution{0.0}, std::invalid_argument);
    EXPECT_THROW(DynamicResolution{-5.0}, std::invalid_argument);
    EXPECT_THROW(DynamicResolution{INFINITY}, std::invalid_argument);
    DynamicResolution r(100.0);
    r.frameFinished(300.0, 1.0);
    r.setBudgetMilliseconds(1000.0);
    EXPECT_EQ(r.interactiveScale(), 1.0);
    r.setBudgetMilliseconds(10.0);
    EXPECT_EQ(r.interactiveScale(), 0.25);
}

TEST(DynamicResolution, ScaledSizesRoundAndKeepAPixel) {
    const ScaledSize half = scaledSize(1351, 990, 0.5);
    EXPECT_EQ(half.width, 676u);
    EXPECT_EQ(half.height, 495u);
    const ScaledSize tiny = scaledSize(3, 2, 0.25);
    EXPECT_EQ(tiny.width, 1u);
    EXPECT_EQ(tiny.height, 1u);
    const ScaledSize full = scaledSize(640, 480, 1.0);
    EXPECT_EQ(full.width, 640u);
    EXPECT_EQ(full.height, 480u);
}
