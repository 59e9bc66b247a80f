#pragma once
// The viewport's display encoding for the docks' own pictures (shaders/display_math.glsl): the
// ACES fit, then sRGB, as an 8-bit code.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>

#include "ShaderMath.h"

namespace terralux {

// The code straight from the curves: a power and a rational function per call.
inline int displayByteFormula(float linear) {
    const float c = glsl::srgbEncode(glsl::acesFit(std::max(linear, 0.0f)));
    return std::clamp(int(std::lround(255.0f * c)), 0, 255);
}

// The light at which each code 1..255 begins: a float where the formula's code reaches it and
// the float below does not, found by bisection over the floats' bit patterns (which order
// non-negative floats as their values). The code rises with the light but for the float rounding
// of the curves, which steps it back by one at a few floats near a step.
inline std::array<float, 255> displayByteSteps() {
    std::array<float, 255> steps{};
    const uint32_t top = std::bit_cast<uint32_t>(1.0e6f);  // well past white (code 255)
    for (int code = 1; code <= 255; ++code) {
        uint32_t lo = 0, hi = top;  // formula(lo) < code <= formula(hi)
        while (hi - lo > 1) {
            const uint32_t mid = lo + (hi - lo) / 2;
            (displayByteFormula(std::bit_cast<float>(mid)) >= code ? hi : lo) = mid;
        }
        steps[size_t(code - 1)] = std::bit_cast<float>(hi);
    }
    return steps;
}

// The same code by lookup: the number of steps at or below the light, a binary search instead of
// a power per channel, so a dock's picture of 16 000 pixels costs a fraction of a millisecond
// rather than several on the UI thread. A NaN light is black, as in the formula; above about
// 10^19 the formula's ratio overflows to NaN (black), and the lookup says white.
inline int displayByte(float linear) {
    static const std::array<float, 255> steps = displayByteSteps();
    if (!(linear >= steps[0])) return 0;
    return int(std::upper_bound(steps.begin(), steps.end(), linear) - steps.begin());
}

}  // namespace terralux
