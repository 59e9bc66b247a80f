#pragma once
// The rules C++ and GLSL share, each written once in the common subset of the two languages:
// height-fog optics (fog_math.glsl), the display encoding (display_math.glsl), the SH basis
// (sh_basis.glsl), the equirectangular sky (sky_math.glsl), the shadow hand-over
// (shadow_math.glsl), and the Gerstner waves
// (water_math.glsl). C++ sees them here as inline float
// functions in terralux::glsl (the waves in double, in terralux::glsl::dbl), with the GLSL
// built-ins they call; tests/render/test_shader_math.cpp holds each against the shaders' own
// evaluation on the device.

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace terralux::glsl {

using std::abs;
using std::acos;
using std::exp;
using std::floor;
using std::pow;
using std::sqrt;
inline float max(float a, float b) { return std::max(a, b); }
inline float min(float a, float b) { return std::min(a, b); }
inline float clamp(float x, float lo, float hi) { return std::min(std::max(x, lo), hi); }  // GLSL's definition
inline float atan(float y, float x) { return std::atan2(y, x); }  // GLSL's two-argument atan

#define TLX_SHARED inline
#include "fog_math.glsl"
#include "display_math.glsl"
#include "sh_basis.glsl"
#include "sky_math.glsl"
#include "shadow_math.glsl"
#undef TLX_SHARED

// C++ only: the same luminance of a colour, as the bake's and the meter's code holds it.
inline float rec709Luminance(const glm::vec3& c) { return rec709Luminance(c.x, c.y, c.z); }

}  // namespace terralux::glsl

namespace terralux::glsl::dbl {

using glm::clamp;
using glm::cross;
using glm::dot;
using glm::max;
using glm::normalize;
using std::cos;
using std::sin;
using std::sqrt;
using std::tanh;

#define TLX_SHARED inline
#define TLX_REAL double
#define TLX_RVEC2 glm::dvec2
#define TLX_RVEC3 glm::dvec3
#define TLX_INOUT(T) T&
#include "water_math.glsl"
#undef TLX_SHARED
#undef TLX_REAL
#undef TLX_RVEC2
#undef TLX_RVEC3
#undef TLX_INOUT

}  // namespace terralux::glsl::dbl
