#pragma once
// An analytic clear sky and the sun seen through it: Preetham, Shirley, Smits, "A Practical
// Analytic Model for Daylight", SIGGRAPH 1999 (the Perez distribution of luminance Y and
// chromaticity x, y scaled by the zenith values of the paper's appendix), converted from xyY to
// linear Rec.709 RGB. Radiance and illuminance are in scene units: photometric values times
// kSceneUnitsPerLux.

#include <glm/vec3.hpp>

namespace terralux {

// Scene units per lux, and per cd/m² of sky luminance: the default sun.illuminance, a clear day's
// 100 klx, lights with 3. The sun and the sky share it, so their ratio is the model's.
inline constexpr double kSceneUnitsPerLux = 3.0e-5;

// An illuminance authored in lux (sun.illuminance) in the scene units the bake and the renderer
// light with.
inline float sceneUnitsOfLux(double lux) { return float(lux * kSceneUnitsPerLux); }

// The turbidities the paper fits; the model is clamped to them.
inline constexpr double kMinTurbidity = 1.7;
inline constexpr double kMaxTurbidity = 10.0;

class PhysicalSky {
public:
    // sunDir: unit, toward the sun (sunDirection()). The sky of a sun below the horizon is the
    // sky of the sun on the horizon at the same azimuth, dimmed tenfold every 3° below it.
    PhysicalSky(const glm::vec3& sunDir, double turbidity);

    // Sky luminance toward the unit `dir`, cd/m². Directions below the horizon take the
    // horizon's value at their azimuth (the model has no ground).
    double luminance(const glm::vec3& dir) const;
    // Sky radiance toward `dir`, linear RGB in scene units, each channel >= 0.
    glm::vec3 radiance(const glm::vec3& dir) const;
    // The direct sun on a surface facing it, colour × illuminance in scene units; 0 below the
    // horizon. Its luminance is sunIlluminanceLux() × kSceneUnitsPerLux.
    glm::vec3 sunIlluminance() const { return sunRgb_; }
    double sunIlluminanceLux() const { return sunLux_; }

    const glm::vec3& sunDirection() const { return sun_; }
    double turbidity() const { return turbidity_; }

private:
    struct Perez {
        double A = 0, B = 0, C = 0, D = 0, E = 0;
    };
    // xyY toward `dir`, before the twilight fade.
    void xyY(const glm::vec3& dir, double& x, double& y, double& Y) const;

    glm::vec3 sun_{0.0f, 1.0f, 0.0f};
    glm::vec3 modelSun_{0.0f, 1.0f, 0.0f};  // the sun the sky formulas see, at or above the horizon
    double turbidity_ = 3.0;
    Perez perezY_, perezX_, perezYc_;  // luminance Y, chromaticity x and y
    double zenithY_ = 0, zenithX_ = 0, zenithYc_ = 0;  // Y (cd/m²), x, y at the zenith
    double normY_ = 1, normX_ = 1, normYc_ = 1;        // F(0, θs) of each
    double fade_ = 1.0;
    glm::vec3 sunRgb_{0.0f};
    double sunLux_ = 0.0;
};

// Relative optical air mass toward a zenith angle in degrees (Kasten & Young 1989, "Revised
// optical air mass tables and approximation formula"): 1 at the zenith, about 38 at the horizon.
double relativeAirMass(double zenithDeg);

}  // namespace terralux
