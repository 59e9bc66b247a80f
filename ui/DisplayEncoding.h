#pragma once
// The viewport's display encoding for the docks' own pictures (shaders/display_math.glsl): the
// ACES fit, then sRGB, as an 8-bit code.

#include <algorithm>
#include <cmath>

#include "ShaderMath.h"

namespace terralux {

inline int displayByte(float linear) {
    const float c = glsl::srgbEncode(glsl::acesFit(std::max(linear, 0.0f)));
    return std::clamp(int(std::lround(255.0f * c)), 0, 255);
}

}  // namespace terralux
