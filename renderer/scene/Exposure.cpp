#include "scene/Exposure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "ShaderMath.h"
#include "bake/PhysicalSky.h"

namespace terralux {

namespace {
constexpr double kMinLog2 = -10.0, kMaxLog2 = 24.0;
// log2(S / K) for ISO 100 and the meter calibration K = 12.5.
constexpr double kLog2IsoOverK = 3.0;
}  // namespace

double exposureScale(double ev100, double compensationEv) {
    return std::exp2(compensationEv - ev100) / (1.2 * double(kSceneUnitsPerLux));
}

double cameraExposureScale(const CameraSettings& camera, double shownEv100) {
    const bool metered = camera.exposureMode != ExposureMode::Manual && std::isfinite(shownEv100);
    return exposureScale(metered ? shownEv100 : camera.ev100, camera.exposureEv);
}

double meterEv100(const std::vector<float>& rgba, uint32_t width, uint32_t height, ExposureMode mode) {
    if (mode == ExposureMode::Manual) return std::numeric_limits<double>::quiet_NaN();
    const size_t n = std::min(size_t(width) * height, rgba.size() / 4);
    if (n == 0) return kMinLog2 + kLog2IsoOverK;
    std::vector<double> logs(n);
    for (size_t i = 0; i < n; ++i) {
        const float* p = &rgba[i * 4];
        const double y = glsl::rec709Luminance(p[0], p[1], p[2]);
        const double cd = y / double(kSceneUnitsPerLux);
        logs[i] = std::isfinite(cd) && cd > 0.0 ? std::clamp(std::log2(cd), kMinLog2, kMaxLog2) : kMinLog2;
    }
    size_t first = 0, last = n;
    if (mode == ExposureMode::Histogram) {
        std::sort(logs.begin(), logs.end());
        first = n / 10;
        last = std::max(first + 1, n - n / 10);
    }
    double sum = 0.0;
    for (size_t i = first; i < last; ++i) sum += logs[i];
    return sum / double(last - first) + kLog2IsoOverK;
}

double adaptEv100(double shownEv100, double targetEv100, double seconds, double tauSeconds) {
    if (!std::isfinite(shownEv100) || !(tauSeconds > 0.0)) return targetEv100;
    return targetEv100 + (shownEv100 - targetEv100) * std::exp(-std::max(0.0, seconds) / tauSeconds);
}

}  // namespace terralux
