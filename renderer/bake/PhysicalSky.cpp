#include "bake/PhysicalSky.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace terralux {

namespace {

constexpr double kPi = std::numbers::pi;

// Illuminance of the sun outside the atmosphere at the mean Earth-Sun distance (the "solar
// illuminance constant" of lighting handbooks; published values run from 127.5 to 133.8 klx).
constexpr double kSolarIlluminanceLux = 128000.0;
// Twilight: the sky of a sun below the horizon dims tenfold every this many degrees, about how
// fast measured clear-sky illuminance falls between sunset and the end of civil twilight (-6°).
constexpr double kTwilightDegreesPerDecade = 3.0;

// CIE XYZ to linear Rec.709 / sRGB primaries, D65 white.
glm::dvec3 xyzToRgb(const glm::dvec3& c) {
    return {3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z,
            -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
            0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z};
}

glm::vec3 toScene(const glm::dvec3& rgb) {
    return glm::vec3(glm::max(rgb, glm::dvec3(0.0)) * double(kSceneUnitsPerLux));
}

// CIE 1931 colour matching functions, the multi-lobe fit of Wyman, Sloan, Shirley, "Simple
// Analytic Approximations to the CIE XYZ Color Matching Functions", JCGT 2013.
double lobe(double nm, double mu, double below, double above) {
    const double t = (nm - mu) / (nm < mu ? below : above);
    return std::exp(-0.5 * t * t);
}
glm::dvec3 cie1931(double nm) {
    return {1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) -
                0.065 * lobe(nm, 501.1, 20.4, 26.2),
            0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1),
            1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8)};
}

// Spectral shape of the sun outside the atmosphere: a black body at the sun's effective
// temperature (5778 K), in arbitrary units.
double solarSpectrum(double nm) {
    const double m = nm * 1e-9;
    return 1.0 / (m * m * m * m * m * std::expm1(1.438776877e-2 / (m * 5778.0)));
}

// The sun through the atmosphere, CIE XYZ in lux on a surface facing it. Transmittance per
// wavelength from Preetham et al. 1999, appendix A.2: Rayleigh scattering
// exp(-0.008735 λ^-4.08 m) and Ångström's aerosol term exp(-β λ^-1.3 m) with
// β = 0.04608 T - 0.04586 (λ in µm, m the air mass). Ozone, water vapour and the mixed gases
// are left out: in the visible they take a few percent at most.
glm::dvec3 sunXyz(double elevationDeg, double turbidity) {
    if (elevationDeg <= 0.0) return glm::dvec3(0.0);
    const double m = relativeAirMass(90.0 - elevationDeg);
    const double beta = 0.04608365822050 * turbidity - 0.04586025928522;
    glm::dvec3 xyz(0.0);
    double outside = 0.0;  // luminance outside the atmosphere, same units
    for (double nm = 380.0; nm <= 780.0; nm += 5.0) {
        const double um = nm * 1e-3;
        const double tau = std::exp(-m * (0.008735 * std::pow(um, -4.08) + beta * std::pow(um, -1.3)));
        const glm::dvec3 cmf = cie1931(nm);
        const double s = solarSpectrum(nm);
        xyz += s * tau * cmf;
        outside += s * cmf.y;
    }
    return xyz * (kSolarIlluminanceLux / outside);
}

// Zenith luminance, kcd/m², and chromaticity of Preetham et al. 1999, appendix A.2; θs the
// sun's zenith angle in radians.
double zenithLuminance(double T, double thetaS) {
    const double chi = (4.0 / 9.0 - T / 120.0) * (kPi - 2.0 * thetaS);
    return (4.0453 * T - 4.9710) * std::tan(chi) - 0.2155 * T + 2.4192;
}
double zenithChromaticity(double T, double thetaS, const double (&m)[3][4]) {
    const double t[4] = {thetaS * thetaS * thetaS, thetaS * thetaS, thetaS, 1.0};
    const double tt[3] = {T * T, T, 1.0};
    double sum = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j) sum += tt[i] * m[i][j] * t[j];
    return sum;
}
constexpr double kZenithX[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                                   {-0.02903, 0.06377, -0.03202, 0.00394},
                                   {0.11693, -0.21196, 0.06052, 0.25886}};
constexpr double kZenithY[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                                   {-0.04214, 0.08970, -0.04153, 0.00516},
                                   {0.15346, -0.26756, 0.06670, 0.26688}};

}  // namespace

double relativeAirMass(double zenithDeg) {
    const double z = std::clamp(zenithDeg, 0.0, 90.0);
    return 1.0 / (std::cos(z * kPi / 180.0) + 0.50572 * std::pow(96.07995 - z, -1.6364));
}

PhysicalSky::PhysicalSky(const glm::vec3& sunDir, double turbidity) {
    const double T = std::clamp(turbidity, kMinTurbidity, kMaxTurbidity);
    turbidity_ = T;
    sun_ = glm::normalize(sunDir);
    const double elevationDeg = std::asin(std::clamp(double(sun_.y), -1.0, 1.0)) * 180.0 / kPi;

    // The formulas are fitted for a sun at or above the horizon: a lower sun is seen on the
    // horizon at its azimuth, and the sky it lights fades (continuous at 0°).
    modelSun_ = sun_;
    if (sun_.y < 0.0f) {
        const float len = std::sqrt(sun_.x * sun_.x + sun_.z * sun_.z);
        modelSun_ = len > 1e-6f ? glm::vec3(sun_.x / len, 0.0f, sun_.z / len) : glm::vec3(0.0f, 0.0f, -1.0f);
        fade_ = std::pow(10.0, elevationDeg / kTwilightDegreesPerDecade);
    }
    const double thetaS = std::acos(std::clamp(double(modelSun_.y), 0.0, 1.0));

    // Perez coefficients as linear functions of turbidity (appendix A.2).
    perezY_ = {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251,
               0.1206 * T - 2.5771, -0.0670 * T + 0.3703};
    perezX_ = {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125,
               -0.0641 * T - 0.8989, -0.0033 * T + 0.0452};
    perezYc_ = {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102,
                -0.0441 * T - 1.6537, -0.0109 * T + 0.0529};
    zenithY_ = 1000.0 * zenithLuminance(T, thetaS);
    zenithX_ = zenithChromaticity(T, thetaS, kZenithX);
    zenithYc_ = zenithChromaticity(T, thetaS, kZenithY);

    auto perez = [](const Perez& p, double cosTheta, double gamma) {
        const double c = std::cos(gamma);
        return (1.0 + p.A * std::exp(p.B / cosTheta)) * (1.0 + p.C * std::exp(p.D * gamma) + p.E * c * c);
    };
    normY_ = perez(perezY_, 1.0, thetaS);
    normX_ = perez(perezX_, 1.0, thetaS);
    normYc_ = perez(perezYc_, 1.0, thetaS);

    const glm::dvec3 sun = sunXyz(elevationDeg, T);
    sunLux_ = sun.y;
    sunRgb_ = toScene(xyzToRgb(sun));
}

void PhysicalSky::xyY(const glm::vec3& dir, double& x, double& y, double& Y) const {
    // Below the horizon: the horizon at the same azimuth (straight down has none; any will do).
    glm::vec3 d = dir;
    if (d.y < 0.0f) {
        const float len = std::sqrt(d.x * d.x + d.z * d.z);
        d = len > 1e-6f ? glm::vec3(d.x / len, 0.0f, d.z / len) : glm::vec3(0.0f, 0.0f, -1.0f);
    }
    // B < 0 for every turbidity in range, so exp(B / cos θ) -> 0 toward the horizon; the floor
    // on cos θ only keeps the division finite there.
    const double cosTheta = std::max(double(d.y), 1e-4);
    const double cosGamma = std::clamp(double(glm::dot(d, modelSun_)), -1.0, 1.0);
    const double gamma = std::acos(cosGamma);
    auto perez = [&](const Perez& p) {
        return (1.0 + p.A * std::exp(p.B / cosTheta)) *
               (1.0 + p.C * std::exp(p.D * gamma) + p.E * cosGamma * cosGamma);
    };
    Y = std::max(0.0, zenithY_ * perez(perezY_) / normY_);
    x = zenithX_ * perez(perezX_) / normX_;
    y = zenithYc_ * perez(perezYc_) / normYc_;
}

double PhysicalSky::luminance(const glm::vec3& dir) const {
    double x, y, Y;
    xyY(dir, x, y, Y);
    return Y * fade_;
}

glm::vec3 PhysicalSky::radiance(const glm::vec3& dir) const {
    double x, y, Y;
    xyY(dir, x, y, Y);
    if (!(y > 1e-6) || !(Y > 0.0)) return glm::vec3(0.0f);
    Y *= fade_;
    return toScene(xyzToRgb(glm::dvec3(x / y * Y, Y, (1.0 - x - y) / y * Y)));
}

}  // namespace terralux
