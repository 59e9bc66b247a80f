#pragma once
// Dynamic resolution for the live viewport (docs/ARCHITECTURE.md, "Dynamic resolution"): while the
// view changes, frames are drawn at a fraction of the window's pixels chosen to hold a frame
// budget, and blitted up to the window; when the changes stop the viewport draws one frame at
// full resolution. Plain arithmetic, no Vulkan or Qt, so the rule has its own tests.

#include <array>
#include <cstdint>

namespace terralux {

class DynamicResolution {
public:
    // The scales a frame may be drawn at, each half the pixels of the one before: few steps, so
    // the offscreen targets are rarely reallocated, and 1/16 of the pixels at the least.
    static constexpr std::array<double, 5> kScales = {1.0, 0.70710678118654752, 0.5, 0.35355339059327376, 0.25};
    // Smoothing of the time measured at one scale: the weight of each new frame.
    static constexpr double kSmoothing = 0.5;

    // `budgetMilliseconds` > 0: the frame time interactive frames aim at.
    explicit DynamicResolution(double budgetMilliseconds);

    double budgetMilliseconds() const { return budget_; }
    void setBudgetMilliseconds(double ms);

    // A finished frame: its time and the scale it was drawn at (its pixels over the window's,
    // square-rooted), counted at the nearest of kScales.
    void frameFinished(double milliseconds, double scale);

    // The predicted time of a frame at `scale`: t = a + b·scale², a the part that does not
    // depend on the pixels (the shadow maps, the probe pass) and b the full frame's pixel work,
    // fitted through the last two scales measured. With one scale measured (or a fit that does
    // not hold: a or b negative) all of the last frame's time is taken as per-pixel, which
    // overestimates the smaller scales, so the rule errs toward the budget. 0 before any frame.
    double predictedMilliseconds(double scale) const;

    // The scale for a frame while the view changes: the largest of kScales whose predicted time
    // is within the budget, or the smallest. 1 until a frame was measured.
    double interactiveScale() const;

private:
    struct Measured {
        double milliseconds = 0.0;
        uint64_t order = 0;  // 0: never; else when it was last measured (larger is later)
    };
    double budget_;
    std::array<Measured, kScales.size()> measured_{};
    uint64_t frames_ = 0;
};

// The size drawn at `scale` of a `width` x `height` window: each side scaled and rounded, at
// least 1 pixel.
struct ScaledSize {
    uint32_t width = 1, height = 1;
};
ScaledSize scaledSize(uint32_t width, uint32_t height, double scale);

}  // namespace terralux
