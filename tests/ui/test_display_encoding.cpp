// The docks' display encoding by lookup (ui/DisplayEncoding.h) against the curves it tabulates.
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "DisplayEncoding.h"

using namespace terralux;

// Every 101st float from 0 to 10^6 (12 million lights, every code among them): the lookup gives
// the formula's code but where the formula's float rounding steps it back by one code within a
// few ulps of a step (147 floats of the 1.2 billion, found by an exhaustive sweep).
TEST(DisplayEncoding, TheLookupGivesTheFormulasCode) {
    const uint32_t top = std::bit_cast<uint32_t>(1.0e6f);
    size_t differ = 0, checked = 0;
    int seen = 0;
    for (uint32_t b = 0; b <= top; b += 101) {
        const float light = std::bit_cast<float>(b);
        const int looked = displayByte(light), formula = displayByteFormula(light);
        ASSERT_LE(std::abs(looked - formula), 1) << light;
        differ += looked != formula;
        seen = std::max(seen, looked);
        ++checked;
    }
    EXPECT_EQ(seen, 255);
    EXPECT_LE(double(differ), 1e-6 * double(checked)) << differ << " of " << checked;
}

// Each step is where the formula reaches its code, and the float below it still is below.
TEST(DisplayEncoding, EachStepIsWhereTheFormulasCodeBegins) {
    const auto steps = displayByteSteps();
    for (int code = 1; code <= 255; ++code) {
        const float step = steps[size_t(code - 1)];
        EXPECT_EQ(displayByte(step), code);
        EXPECT_GE(displayByteFormula(step), code);
        EXPECT_LT(displayByteFormula(std::nextafter(step, 0.0f)), code) << code;
        if (code > 1) {
            EXPECT_GT(step, steps[size_t(code - 2)]);
        }
    }
}

TEST(DisplayEncoding, LightsOutsideTheCurveAreBlackOrWhite) {
    EXPECT_EQ(displayByte(-1.0f), 0);
    EXPECT_EQ(displayByte(-0.0f), 0);
    EXPECT_EQ(displayByte(0.0f), 0);
    EXPECT_EQ(displayByte(std::numeric_limits<float>::quiet_NaN()), 0);
    EXPECT_EQ(displayByte(1.0e7f), 255);
    // Past about 10^19 the formula's ratio is inf/inf; the lookup stays white.
    EXPECT_EQ(displayByte(1.0e20f), 255);
    EXPECT_EQ(displayByte(std::numeric_limits<float>::infinity()), 255);
}
