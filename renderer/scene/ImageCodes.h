#pragma once
// The 8-bit code of a display-encoded sample, as every 8-bit image Terralux writes holds it: the
// sample clamped to [0, 1] and rounded to the nearest of 256 codes, a non-finite sample as 0. The
// PNG writer (io/ImageFile.cpp) and the read-back's 8-bit path (vk::Readback::bytes) share it,
// so a frame read back as bytes is the same file as one read back as floats.

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace terralux {

inline uint8_t unitToByte(float v) {
    return uint8_t(std::lround(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f) * 255.0f));
}

}  // namespace terralux
