#pragma once
// The camera's exposure in EV100 and the metering of a frame (docs/lighting.md, "Exposure").
// Lagarde and de Rousiers, "Moving Frostbite to Physically Based Rendering" (SIGGRAPH 2014
// course notes, section 5.1): a reflected-light meter of calibration K = 12.5 at ISO 100 reads
// EV100 = log2(L_avg * 100 / 12.5) for an average scene luminance L_avg in cd/m², and a camera at
// EV100 saturates at the luminance 1.2 * 2^EV100 (ISO 12232's saturation-based speed).

#include <cstdint>
#include <vector>

#include "scene/SceneDescription.h"

namespace terralux {

// The factor the display applies to scene-linear light before the tone curve: 2^compensation /
// (1.2 * 2^ev100 * kSceneUnitsPerLux), so that a luminance of 1.2 * 2^ev100 cd/m² shows as 1.
double exposureScale(double ev100, double compensationEv);

// The display scale of `camera`: at camera.ev100 in mode manual; in a metered mode at
// `shownEv100`, what the viewport shows now (camera.ev100 while that is not yet known, NaN).
double cameraExposureScale(const CameraSettings& camera, double shownEv100);

// The EV100 a meter in `mode` reads from a scene-linear RGBA frame (row-major, 4 floats a pixel,
// radiance in scene units): average, the log of the geometric mean luminance of every pixel;
// histogram, the mean log luminance of the pixels between the 10th and 90th percentiles (the
// darkest and brightest tenth, deep shadow and the sun's glint, do not move it). Luminances are
// clamped to [2^-10, 2^24] cd/m², so a black frame reads -7. Mode manual meters nothing: NaN.
double meterEv100(const std::vector<float>& rgba, uint32_t width, uint32_t height, ExposureMode mode);

// The shown exposure after `seconds` of adapting from `shownEv100` toward `targetEv100` with the
// time constant `tauSeconds` (exponential, as the eye and auto-exposure cameras adapt); 0 s of
// time constant, or a first frame (shown NaN), jumps to the target.
double adaptEv100(double shownEv100, double targetEv100, double seconds, double tauSeconds);

}  // namespace terralux
