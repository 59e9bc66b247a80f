#pragma once
// The sky a bake sees: a uniform radiance, an equirectangular HDR (× intensity, turned about +Y),
// or the analytic clear sky (PhysicalSky) sampled into one, plus the sun as a separate
// directional light with an angular radius.
//
// Equirectangular mapping: v = acos(y) / π (v = 0 at the zenith); u = 0.5 + φ / 2π − rotation,
// with φ = atan2(x, −z) the azimuth clockwise from north (−Z) toward east (+X). At rotation 0 the
// image centre column faces north.

#include <memory>
#include <numbers>
#include <vector>

#include <glm/vec3.hpp>

#include "bake/SphericalHarmonics.h"

namespace terralux {

struct SunLight {
    glm::vec3 direction{0.0f, 1.0f, 0.0f};  // unit, toward the sun
    glm::vec3 illuminance{0.0f};            // E_sun × colour on a surface facing the sun
    float angularRadius = 0.0f;             // radians
};

// Direction toward the sun from azimuth (clockwise from north) and elevation, in degrees.
glm::vec3 sunDirection(double azimuthDeg, double elevationDeg);

class PhysicalSky;

class Sky {
public:
    static Sky uniform(const glm::vec3& radiance);
    // rgb: width × height × 3 floats, row 0 at the zenith. Throws std::invalid_argument on bad
    // sizes or non-finite / negative texels.
    static Sky equirect(std::vector<float> rgb, int width, int height, float intensity,
                        float rotationDeg);
    // The physical sky's radiance at each texel centre of a width × height equirectangular image
    // (rotation 0), then as equirect(). The image holds the sky only: the sun is the separate
    // directional light, and a disc in the image would light the scene twice.
    static Sky physical(const PhysicalSky& model, int width = 512, int height = 256);

    // The same sky with its radiance multiplied per channel (a tint times an intensity), without
    // filtering the image again: the pyramid and the SH projection are linear in the radiance.
    Sky scaled(const glm::vec3& factor) const;

    bool isUniform() const { return !levels_; }
    // The image of an hdr or physical sky at full resolution, row 0 at the zenith, before scale()
    // and rotationTurns(): what the sky pass draws behind the terrain. Null for a uniform sky;
    // copies of a sky share it.
    const std::vector<glm::vec3>* image(int* width, int* height) const;
    glm::vec3 scale() const { return scale_; }
    float rotationTurns() const { return rotation_; }
    // Radiance toward `dir`, averaged over about `solidAngle` steradians around it (the share of
    // the sphere one sample stands for), at most kMaxFilterSolidAngle. Prefiltering a peaky HDR
    // this way removes most of the variance of a few hundred samples at the cost of blur below
    // the SH's own resolution.
    glm::vec3 radiance(const glm::vec3& dir, float solidAngle = 0.0f) const;
    // The widest prefilter a lookup gets, 4π/1024 sr (docs/lighting.md, "HDR sky"): a filter of
    // Ω steradians takes about Ω/2 off the SH's band 2 (a kernel of variance Ω/6 per axis, whose
    // band-l factor is exp(−l(l+1)·Ω/12)), 0.6 % here. Draft's 96 rays (0.13 sr each) took 6 %
    // off, a bias under the physical sky larger than draft's noise.
    static constexpr float kMaxFilterSolidAngle = 4.0f * std::numbers::pi_v<float> / 1024.0f;
    // The sky split in two where it is peaky (an HDR's sun and its glow; the physical sky has
    // no texel over the threshold): each texel brighter than kGlowThreshold times the smooth part's mean
    // luminance keeps that luminance in the smooth part, in its own colour, and gives the rest to
    // the glow.
    // A probe estimates the terrain's occlusion of the smooth part with its lattice rays and that
    // of the glow with rays drawn from the glow's own luminance (docs/lighting.md, "The sky's
    // glow"). Without texels over the threshold (a uniform sky) the smooth part is the sky.
    static constexpr float kGlowThreshold = 8.0f;
    // The most of the sphere a glow covers, steradians (1/16 of it).
    static constexpr double kMaxGlowSolidAngle = 4.0 * std::numbers::pi / 16.0;
    bool hasGlow() const { return glow_ != nullptr; }
    // radiance() of the smooth part.
    glm::vec3 smoothRadiance(const glm::vec3& dir, float solidAngle = 0.0f) const;
    // A direction `dir` drawn with density p(ω) proportional to the glow's luminance (a texel by
    // u0, then uniformly over its solid angle by u1, u2, each in [0, 1)), and the glow's radiance
    // there over p(ω): its colour times the glow's luminous flux ∫ Y(glow) dω. Zero without glow.
    // `centre`, when given, receives the texel's centre: sh() takes each texel's SH there, so a
    // projection that weighs the ray by the SH at the centre takes nothing of the glow's extent
    // as noise (a sun hidden whole then costs nothing).
    glm::vec3 sampleGlow(float u0, float u1, float u2, glm::vec3& dir, glm::vec3* centre = nullptr) const;
    // The glow's share of the sky's luminous flux over the whole sphere (0 without glow).
    float glowShare() const;
    // The glow's exact SH projection, as sh() projects the sky (zero without glow).
    sh::ShRgb glowSh() const;
    // The glow as a sun (sun.follow_sky under an image sky), so the terrain's shadow of it is drawn
    // sharp rather than left to probes a kilometre apart: the direction is the glow's mean
    // direction weighted by its luminous flux; the illuminance, per channel, what the glow gives a
    // surface facing that way; the angular radius that of a uniform disc with the glow's spread
    // about that direction (a disc of radius r has mean squared angle r²/2; each texel adds its own,
    // a²/6 for a square of side a). Zero illuminance, straight up, without a glow.
    SunLight glowSun() const;
    // The widest sun a glow may be taken for, and sun.angular_radius_deg's upper bound: past it a
    // glow is light from a wide part of the sky (two suns, a bright cloud bank), not a sun.
    static constexpr double kMaxSunRadiusDeg = 45.0;
    // A glow that is a sun: one whose glowSun() radius is at most kMaxSunRadiusDeg.
    bool glowIsSun() const;
    // The sky less its glow: the smooth part alone (image, projection, open irradiance), the sky
    // that lights with glowSun() as the sun. The sky itself when it has no glow.
    Sky withoutGlow() const;
    // The glowShare() of the sky withoutGlow() took the glow from (0 for any other sky).
    float takenGlowShare() const { return takenGlowShare_; }
    // The smooth part's exact SH projection (sh() without glow), summed in double: what a
    // probe's rays take as their control variate.
    const sh::ShRgb& smoothSh() const { return smoothSh_; }
    // Exact projection of the whole sky onto SH L2 (texel solid angles, no sampling).
    const sh::ShRgb& sh() const { return sh_; }
    // Irradiance on an unoccluded level surface (normal +Y), integrated exactly over the texels.
    glm::vec3 openIrradianceUp() const { return openUp_; }

private:
    struct Level {
        int width = 0, height = 0;
        std::vector<glm::vec3> texels;
    };
    struct Glow {
        int width = 0, height = 0;
        std::vector<uint32_t> texel;    // the glow's texels of level 0
        std::vector<double> cdf;        // their luminous flux, accumulated and normalised
        std::vector<glm::vec3> colour;  // their glow radiance over its luminance
        double flux = 0.0;              // ∫ Y(glow) dω over the sphere
        sh::ShRgb sh;                   // its projection, texel centres as computeSh()
        double skyFlux = 0.0;           // ∫ Y(sky) dω
        SunLight sun;                   // glowSun() before scale()
    };
    glm::vec3 sample(const Level& level, float u, float v) const;
    glm::vec3 lookup(const std::vector<Level>& levels, const glm::vec3& dir, float solidAngle) const;
    static void buildPyramid(std::vector<Level>& levels);
    void computeSh();
    void splitGlow();

    glm::vec3 uniform_{0.0f};
    // Immutable once built and shared between copies: a Sky is cheap to copy into every bake.
    std::shared_ptr<const std::vector<Level>> levels_;
    std::shared_ptr<const std::vector<Level>> smooth_;  // levels_ where there is no glow
    std::shared_ptr<const Glow> glow_;
    float rotation_ = 0.0f;  // in u units [0, 1)
    glm::vec3 scale_{1.0f};  // applied to the shared levels on lookup
    sh::ShRgb sh_;
    sh::ShRgb smoothSh_;
    glm::vec3 openUp_{0.0f};
    glm::vec3 smoothOpenUp_{0.0f};  // openIrradianceUp() of the smooth part
    float takenGlowShare_ = 0.0f;
};

// The equirectangular image (rotation 0, row 0 at the zenith, scale 1) of two skies mixed,
// (1 − t)·a + t·b toward each texel centre: what a blend between two lighting scenarios shows
// behind the terrain, whatever the two skies' kinds, resolutions and rotations.
std::vector<glm::vec3> blendedEquirect(const Sky& a, const Sky& b, float t, int width, int height);

}  // namespace terralux
