#pragma once
// The rules C++ and GLSL share, each written once in the common subset of the two languages:
// height-fog optics (fog_math.glsl), the display encoding (display_math.glsl) and the SH basis
// (sh_basis.glsl). C++ sees them here as inline float functions in terralux::glsl, with the GLSL
// built-ins they call; tests/render/test_shader_math.cpp holds each against the shaders' own
// evaluation on the device.

#include <algorithm>
#include <cmath>

namespace terralux::glsl {

using std::abs;
using std::exp;
using std::pow;
using std::sqrt;
inline float max(float a, float b) { return std::max(a, b); }
inline float min(float a, float b) { return std::min(a, b); }
inline float clamp(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }  // GLSL's definition

#define TLX_SHARED inline
#include "fog_math.glsl"
#include "display_math.glsl"
#include "sh_basis.glsl"
#undef TLX_SHARED

}  // namespace terralux::glsl
