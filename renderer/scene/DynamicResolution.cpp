#include "scene/DynamicResolution.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace terralux {

DynamicResolution::DynamicResolution(double budgetMilliseconds) : budget_(0.0) {
    setBudgetMilliseconds(budgetMilliseconds);
}

void DynamicResolution::setBudgetMilliseconds(double ms) {
    if (!(ms > 0.0) || !std::isfinite(ms))
        throw std::invalid_argument("frame budget " + std::to_string(ms) + " ms: must be a positive number");
    budget_ = ms;
}

void DynamicResolution::frameFinished(double milliseconds, double scale) {
    if (!(milliseconds >= 0.0) || !std::isfinite(milliseconds) || !(scale > 0.0) || scale > 1.0) return;
    // The nearest step by pixel count (rounded window sides land between steps).
    size_t step = 0;
    for (size_t i = 1; i < kScales.size(); ++i)
        if (std::abs(std::log(scale / kScales[i])) < std::abs(std::log(scale / kScales[step]))) step = i;
    Measured& m = measured_[step];
    m.milliseconds = m.order ? (1.0 - kSmoothing) * m.milliseconds + kSmoothing * milliseconds : milliseconds;
    m.order = ++frames_;
}

double DynamicResolution::predictedMilliseconds(double scale) const {
    // The last two steps measured.
    int last = -1, before = -1;
    for (int i = 0; i < int(kScales.size()); ++i) {
        if (!measured_[size_t(i)].order) continue;
        if (last < 0 || measured_[size_t(i)].order > measured_[size_t(last)].order) {
            before = last;
            last = i;
        } else if (before < 0 || measured_[size_t(i)].order > measured_[size_t(before)].order) {
            before = i;
        }
    }
    if (last < 0) return 0.0;
    const double s2 = scale * scale;
    const double t1 = measured_[size_t(last)].milliseconds, q1 = kScales[size_t(last)] * kScales[size_t(last)];
    if (before >= 0) {
        const double t2 = measured_[size_t(before)].milliseconds, q2 = kScales[size_t(before)] * kScales[size_t(before)];
        const double b = (t1 - t2) / (q1 - q2), a = t1 - b * q1;
        if (b >= 0.0 && a >= 0.0) return a + b * s2;
    }
    return t1 / q1 * s2;
}

double DynamicResolution::interactiveScale() const {
    if (predictedMilliseconds(1.0) <= 0.0) return 1.0;
    for (double s : kScales)
        if (predictedMilliseconds(s) <= budget_) return s;
    return kScales.back();
}

ScaledSize scaledSize(uint32_t width, uint32_t height, double scale) {
    auto side = [&](uint32_t n) {
        return uint32_t(std::max(1.0, std::round(double(n) * std::clamp(scale, 0.0, 1.0))));
    };
    return {side(width), side(height)};
}

}  // namespace terralux
