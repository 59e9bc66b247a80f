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
    // Exact projection of the whole sky onto SH L2 (texel solid angles, no sampling).
    const sh::ShRgb& sh() const { return sh_; }
    // Irradiance on an unoccluded level surface (normal +Y), integrated exactly over the texels.
    glm::vec3 openIrradianceUp() const { return openUp_; }

private:
    struct Level {
        int width = 0, height = 0;
        std::vector<glm::vec3> texels;
    };
    glm::vec3 sample(const Level& level, float u, float v) const;
    void computeSh();

    glm::vec3 uniform_{0.0f};
    // Immutable once built and shared between copies: a Sky is cheap to copy into every bake.
    std::shared_ptr<const std::vector<Level>> levels_;
    float rotation_ = 0.0f;  // in u units [0, 1)
    glm::vec3 scale_{1.0f};  // applied to the shared levels on lookup
    sh::ShRgb sh_;
    glm::vec3 openUp_{0.0f};
};

// The equirectangular image (rotation 0, row 0 at the zenith, scale 1) of two skies mixed,
// (1 − t)·a + t·b toward each texel centre: what a blend between two lighting scenarios shows
// behind the terrain, whatever the two skies' kinds, resolutions and rotations.
std::vector<glm::vec3> blendedEquirect(const Sky& a, const Sky& b, float t, int width, int height);

}  // namespace terralux
