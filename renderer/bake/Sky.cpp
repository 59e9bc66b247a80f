#include "bake/Sky.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <glm/common.hpp>
#include <tbb/parallel_for.h>

#include "ShaderMath.h"
#include "bake/PhysicalSky.h"

namespace terralux {

namespace {
constexpr float kPi = std::numbers::pi_v<float>;
// The direction of texel (x, y)'s centre in a width x height image turned by `rotation` (u units):
// the middle of its rows' polar angles and of its column, where the glow's projection and its
// samples' projection take the texel.
glm::vec3 texelCentre(int x, int y, int width, int height, float rotation) {
    const float theta = float(std::numbers::pi * (y + 0.5) / height);
    const float phi = ((x + 0.5f) / float(width) - 0.5f + rotation) * 2.0f * kPi;
    return glm::vec3(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
}
}

glm::vec3 sunDirection(double azimuthDeg, double elevationDeg) {
    const double az = azimuthDeg * std::numbers::pi / 180.0;
    const double el = elevationDeg * std::numbers::pi / 180.0;
    return glm::vec3(float(std::sin(az) * std::cos(el)), float(std::sin(el)),
                     float(-std::cos(az) * std::cos(el)));
}

Sky Sky::uniform(const glm::vec3& radiance) {
    Sky s;
    s.uniform_ = radiance;
    s.sh_ = sh::projectConstant(radiance);
    s.smoothSh_ = s.sh_;
    s.openUp_ = std::numbers::pi_v<float> * radiance;
    s.smoothOpenUp_ = s.openUp_;
    return s;
}

Sky Sky::equirect(std::vector<float> rgb, int width, int height, float intensity,
                  float rotationDeg) {
    if (width < 1 || height < 1 || rgb.size() != size_t(width) * size_t(height) * 3)
        throw std::invalid_argument("sky image: " + std::to_string(width) + "x" +
                                    std::to_string(height) + " does not match its data");
    if (!(intensity >= 0.0f) || !std::isfinite(intensity))
        throw std::invalid_argument("sky intensity must be finite and >= 0");
    Sky s;
    std::vector<Level> levels;
    Level base{width, height, std::vector<glm::vec3>(size_t(width) * height)};
    for (size_t i = 0; i < base.texels.size(); ++i) {
        const glm::vec3 t(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
        if (!std::isfinite(t.x) || !std::isfinite(t.y) || !std::isfinite(t.z) || t.x < 0 ||
            t.y < 0 || t.z < 0)
            throw std::invalid_argument("sky image: texel " + std::to_string(i % width) + "," +
                                        std::to_string(i / width) +
                                        " is negative or not finite");
        base.texels[i] = t * intensity;
    }
    levels.push_back(std::move(base));
    buildPyramid(levels);
    s.levels_ = std::make_shared<const std::vector<Level>>(std::move(levels));
    s.rotation_ = float(rotationDeg / 360.0 - std::floor(rotationDeg / 360.0));
    s.computeSh();
    s.splitGlow();
    return s;
}

void Sky::buildPyramid(std::vector<Level>& levels) {
    // Box-filtered pyramid, each texel weighted by its solid angle (∝ sin θ) so the poles do not
    // dominate the average.
    while (levels.back().width > 1 || levels.back().height > 1) {
        const Level& f = levels.back();
        Level c{std::max(1, f.width / 2), std::max(1, f.height / 2), {}};
        c.texels.assign(size_t(c.width) * c.height, glm::vec3(0.0f));
        for (int y = 0; y < c.height; ++y)
            for (int x = 0; x < c.width; ++x) {
                glm::vec3 sum(0.0f);
                float wsum = 0.0f;
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                        const int fx = std::min(2 * x + dx, f.width - 1);
                        const int fy = std::min(2 * y + dy, f.height - 1);
                        const float w = std::sin(kPi * (fy + 0.5f) / f.height);
                        sum += w * f.texels[size_t(fy) * f.width + fx];
                        wsum += w;
                    }
                c.texels[size_t(y) * c.width + x] = wsum > 0 ? sum / wsum : glm::vec3(0.0f);
            }
        levels.push_back(std::move(c));
    }
}

void Sky::splitGlow() {
    const Level& l = levels_->front();
    smoothSh_ = sh_;
    smoothOpenUp_ = openUp_;
    smooth_ = levels_;
    glow_ = nullptr;
    const double dphi = 2.0 * std::numbers::pi / l.width;
    std::vector<double> solidAngle(size_t(l.height));
    double skyFlux = 0.0;
    for (int y = 0; y < l.height; ++y) {
        solidAngle[size_t(y)] =
            dphi * (std::cos(std::numbers::pi * y / l.height) - std::cos(std::numbers::pi * (y + 1) / l.height));
        for (int x = 0; x < l.width; ++x) skyFlux += glsl::rec709Luminance(l.texels[size_t(y) * l.width + x]) * solidAngle[size_t(y)];
    }
    // The threshold is kGlowThreshold times the mean of the smooth part it leaves, not of the
    // whole sky: a sun holding most of the light would otherwise set it so high that the smooth
    // part kept a disc many times brighter than the rest. T <- k mean(min(Y, T)) from
    // T = k mean(Y) falls toward the largest fixed point; it stops once a step moves it by under
    // 1 % (one to three steps on the shared HDRs).
    double threshold = double(kGlowThreshold) * skyFlux / (4.0 * std::numbers::pi);
    for (int step = 0; step < 32 && threshold > 0.0; ++step) {
        double clamped = 0.0;
        for (int y = 0; y < l.height; ++y)
            for (int x = 0; x < l.width; ++x)
                clamped += std::min(double(glsl::rec709Luminance(l.texels[size_t(y) * l.width + x])), threshold) * solidAngle[size_t(y)];
        const double next = double(kGlowThreshold) * clamped / (4.0 * std::numbers::pi);
        const bool settled = next > 0.99 * threshold;
        threshold = next;
        if (settled) break;
    }
    // A glow is a bright spot: never more than kMaxGlowSolidAngle of the sphere. An image mostly
    // black has no positive fixed point (the threshold would fall until nearly all of it glowed),
    // so the threshold is at least the luminance above which that much of the sphere lies.
    {
        std::vector<std::pair<double, double>> byLuminance;  // (Y, solid angle)
        byLuminance.reserve(l.texels.size());
        for (int y = 0; y < l.height; ++y)
            for (int x = 0; x < l.width; ++x)
                byLuminance.emplace_back(glsl::rec709Luminance(l.texels[size_t(y) * l.width + x]), solidAngle[size_t(y)]);
        std::sort(byLuminance.begin(), byLuminance.end(), std::greater<>());
        double covered = 0.0;
        for (const auto& [y, omega] : byLuminance) {
            covered += omega;
            if (covered > kMaxGlowSolidAngle) {
                threshold = std::max(threshold, y);
                break;
            }
        }
    }
    if (!(threshold > 0.0)) return;
    bool any = false;
    for (const glm::vec3& t : l.texels) any |= glsl::rec709Luminance(t) > threshold;
    if (!any) return;

    auto glow = std::make_shared<Glow>();
    glow->width = l.width;
    glow->height = l.height;
    glow->skyFlux = skyFlux;
    Level smooth{l.width, l.height, l.texels};
    // Both parts' projections in double: the bake's probes take the smooth part's as their base,
    // and a sun many thousand times the rest would leave float's rounding of the whole sky's sum
    // as a bias of a percent or more on probes that do not see it.
    std::array<glm::dvec3, sh::kCoeffCount> smoothSh{}, glowSh{};
    glm::dvec3 smoothUp(0.0), glowMean(0.0);
    for (int y = 0; y < l.height; ++y) {
        for (int x = 0; x < l.width; ++x) {
            const size_t i = size_t(y) * l.width + x;
            const glm::vec3 dir = texelCentre(x, y, l.width, l.height, rotation_);
            const double y0 = glsl::rec709Luminance(l.texels[i]);
            glm::vec3 g(0.0f);
            if (y0 > threshold) {
                smooth.texels[i] = l.texels[i] * float(threshold / y0);
                g = l.texels[i] - smooth.texels[i];
            }
            float basis[sh::kCoeffCount];
            sh::evalBasis(dir, basis);
            for (int k = 0; k < sh::kCoeffCount; ++k) {
                smoothSh[size_t(k)] += glm::dvec3(smooth.texels[i]) * (double(basis[k]) * solidAngle[size_t(y)]);
                glowSh[size_t(k)] += glm::dvec3(g) * (double(basis[k]) * solidAngle[size_t(y)]);
            }
            if (dir.y > 0.0f) smoothUp += glm::dvec3(smooth.texels[i]) * (double(dir.y) * solidAngle[size_t(y)]);
            const double gy = glsl::rec709Luminance(g);
            if (!(gy > 0.0)) continue;
            glow->texel.push_back(uint32_t(i));
            glow->colour.push_back(g / float(gy));
            glow->flux += gy * solidAngle[size_t(y)];
            glowMean += glm::dvec3(dir) * (gy * solidAngle[size_t(y)]);
            glow->cdf.push_back(glow->flux);
        }
    }
    if (glow->texel.empty()) return;
    // The glow as a sun: its spread about its mean direction, in a second pass over its texels.
    const glm::dvec3 toSun = glm::length(glowMean) > 0.0 ? glm::normalize(glowMean) : glm::dvec3(0.0, 1.0, 0.0);
    glm::dvec3 illuminance(0.0);
    double spread = 0.0;
    for (size_t k = 0; k < glow->texel.size(); ++k) {
        const int x = int(glow->texel[k] % uint32_t(l.width)), y = int(glow->texel[k] / uint32_t(l.width));
        const glm::dvec3 dir(texelCentre(x, y, l.width, l.height, rotation_));
        const double omega = solidAngle[size_t(y)];
        const double flux = (glow->cdf[k] - (k ? glow->cdf[k - 1] : 0.0));  // Y·ω of this texel
        const double angle = std::acos(std::clamp(glm::dot(dir, toSun), -1.0, 1.0));
        spread += flux * (angle * angle + omega / 6.0);
        illuminance += glm::dvec3(glow->colour[k]) * (flux * std::max(0.0, glm::dot(dir, toSun)));
    }
    glow->sun.direction = glm::vec3(toSun);
    glow->sun.illuminance = glm::vec3(illuminance);
    glow->sun.angularRadius = float(std::sqrt(2.0 * spread / glow->flux));
    smoothOpenUp_ = glm::vec3(smoothUp);
    for (double& c : glow->cdf) c /= glow->flux;
    for (int k = 0; k < sh::kCoeffCount; ++k) {
        smoothSh_.c[size_t(k)] = glm::vec3(smoothSh[size_t(k)]);
        glow->sh.c[size_t(k)] = glm::vec3(glowSh[size_t(k)]);
    }
    std::vector<Level> levels;
    levels.push_back(std::move(smooth));
    buildPyramid(levels);
    smooth_ = std::make_shared<const std::vector<Level>>(std::move(levels));
    glow_ = std::move(glow);
}

glm::vec3 Sky::sampleGlow(float u0, float u1, float u2, glm::vec3& dir, glm::vec3* centre) const {
    if (!glow_) return glm::vec3(0.0f);
    const Glow& g = *glow_;
    const size_t k = std::min(size_t(std::upper_bound(g.cdf.begin(), g.cdf.end(), double(u0)) - g.cdf.begin()),
                              g.texel.size() - 1);
    const int x = int(g.texel[k] % uint32_t(g.width)), y = int(g.texel[k] / uint32_t(g.width));
    // Uniform over the texel's solid angle: its azimuths, and cos θ between its rows' edges.
    const double c0 = std::cos(std::numbers::pi * y / g.height), c1 = std::cos(std::numbers::pi * (y + 1) / g.height);
    const double ct = c0 + (c1 - c0) * double(u2), st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
    const double phi = ((x + double(u1)) / g.width - 0.5 + double(rotation_)) * 2.0 * std::numbers::pi;
    dir = glm::vec3(float(st * std::sin(phi)), float(ct), float(-st * std::cos(phi)));
    if (centre) *centre = texelCentre(x, y, g.width, g.height, rotation_);
    return scale_ * g.colour[k] * float(g.flux);
}

SunLight Sky::glowSun() const {
    if (!glow_) return SunLight{};
    SunLight sun = glow_->sun;
    sun.illuminance *= scale_;
    return sun;
}

bool Sky::glowIsSun() const {
    return glow_ && double(glow_->sun.angularRadius) <= kMaxSunRadiusDeg * std::numbers::pi / 180.0;
}

Sky Sky::withoutGlow() const {
    if (!glow_) return *this;
    Sky s = *this;
    s.levels_ = smooth_;
    s.glow_ = nullptr;
    s.sh_ = smoothSh_;
    s.openUp_ = s.smoothOpenUp_ = smoothOpenUp_;
    s.takenGlowShare_ = glowShare();
    return s;
}

float Sky::glowShare() const { return glow_ ? float(glow_->flux / glow_->skyFlux) : 0.0f; }

sh::ShRgb Sky::glowSh() const {
    if (!glow_) return {};
    sh::ShRgb s = glow_->sh;
    for (auto& c : s.c) c *= scale_;
    return s;
}

namespace {

// The unit direction through the centre of texel (x, y) of a width x height equirectangular image
// at rotation 0 (the inverse of equirectU and equirectV): the texel centres computeSh() integrates
// over.
glm::vec3 texelDirection(int x, int y, int width, int height) {
    const double theta = std::numbers::pi * (y + 0.5) / height;
    const float st = float(std::sin(theta)), ct = float(std::cos(theta));
    const float phi = ((x + 0.5f) / width - 0.5f) * 2.0f * kPi;
    return glm::vec3(st * std::sin(phi), ct, -st * std::cos(phi));
}

}  // namespace

Sky Sky::physical(const PhysicalSky& model, int width, int height) {
    if (width < 1 || height < 1)
        throw std::invalid_argument("physical sky: " + std::to_string(width) + "x" +
                                    std::to_string(height) + " is not an image size");
    std::vector<float> rgb(size_t(width) * size_t(height) * 3);
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const glm::vec3 r = model.radiance(texelDirection(x, y, width, height));
            float* out = &rgb[3 * (size_t(y) * width + x)];
            out[0] = r.x;
            out[1] = r.y;
            out[2] = r.z;
        }
    });
    return equirect(std::move(rgb), width, height, 1.0f, 0.0f);
}

const std::vector<glm::vec3>* Sky::image(int* width, int* height) const {
    if (!levels_) return nullptr;
    *width = levels_->front().width;
    *height = levels_->front().height;
    return &levels_->front().texels;
}

Sky Sky::scaled(const glm::vec3& factor) const {
    if (!levels_) return uniform(uniform_ * factor);
    Sky s = *this;
    s.scale_ *= factor;
    for (auto& c : s.sh_.c) c *= factor;
    for (auto& c : s.smoothSh_.c) c *= factor;
    s.openUp_ *= factor;
    s.smoothOpenUp_ *= factor;
    return s;
}

void Sky::computeSh() {
    const Level& l = levels_->front();
    sh_ = sh::ShRgb{};
    openUp_ = glm::vec3(0.0f);
    const double dphi = 2.0 * std::numbers::pi / l.width;
    for (int y = 0; y < l.height; ++y) {
        const double t0 = std::numbers::pi * y / l.height, t1 = std::numbers::pi * (y + 1) / l.height;
        const float solidAngle = float(dphi * (std::cos(t0) - std::cos(t1)));
        const float theta = float(0.5 * (t0 + t1));
        for (int x = 0; x < l.width; ++x) {
            const float u = (x + 0.5f) / l.width;
            const float phi = (u - 0.5f + rotation_) * 2.0f * kPi;
            const glm::vec3 dir(std::sin(theta) * std::sin(phi), std::cos(theta),
                                -std::sin(theta) * std::cos(phi));
            const glm::vec3& texel = l.texels[size_t(y) * l.width + x];
            sh::accumulate(sh_, dir, texel, solidAngle);
            if (dir.y > 0.0f) openUp_ += texel * (dir.y * solidAngle);
        }
    }
}

glm::vec3 Sky::sample(const Level& level, float u, float v) const {
    // Bilinear, wrapping in u and clamping in v.
    const float fx = u * level.width - 0.5f, fy = std::clamp(v * level.height - 0.5f, 0.0f,
                                                              float(level.height - 1));
    const int x0 = int(std::floor(fx)), y0 = int(fy);
    const float tx = fx - std::floor(fx), ty = fy - y0;
    const int y1 = std::min(y0 + 1, level.height - 1);
    auto at = [&](int x, int y) {
        x = ((x % level.width) + level.width) % level.width;
        return level.texels[size_t(y) * level.width + x];
    };
    return (1 - ty) * ((1 - tx) * at(x0, y0) + tx * at(x0 + 1, y0)) +
           ty * ((1 - tx) * at(x0, y1) + tx * at(x0 + 1, y1));
}

glm::vec3 Sky::radiance(const glm::vec3& dir, float solidAngle) const {
    if (!levels_) return uniform_;
    return lookup(*levels_, dir, solidAngle);
}

glm::vec3 Sky::smoothRadiance(const glm::vec3& dir, float solidAngle) const {
    if (!levels_) return uniform_;
    return lookup(*smooth_, dir, solidAngle);
}

glm::vec3 Sky::lookup(const std::vector<Level>& levels, const glm::vec3& dir, float solidAngle) const {
    solidAngle = std::min(solidAngle, kMaxFilterSolidAngle);
    const float u = glsl::equirectU(dir.x, dir.z, rotation_), v = glsl::equirectV(dir.y);
    const Level& base = levels.front();
    // Level whose texel (at the equator) covers about `solidAngle`; blend the two nearest.
    const float texel0 = 2.0f * kPi * kPi / float(base.width * base.height);
    float lod = solidAngle > texel0 ? 0.5f * std::log2(solidAngle / texel0) : 0.0f;
    lod = std::min(lod, float(levels.size() - 1));
    const int l0 = int(lod);
    const int l1 = std::min(l0 + 1, int(levels.size()) - 1);
    const float t = lod - l0;
    const glm::vec3 a = sample(levels[size_t(l0)], u, v);
    if (t <= 0.0f || l1 == l0) return scale_ * a;
    return scale_ * glm::mix(a, sample(levels[size_t(l1)], u, v), t);
}

std::vector<glm::vec3> blendedEquirect(const Sky& a, const Sky& b, float t, int width, int height) {
    if (width < 1 || height < 1)
        throw std::invalid_argument("blended sky: " + std::to_string(width) + "x" + std::to_string(height) +
                                    " is not an image size");
    std::vector<glm::vec3> out(size_t(width) * size_t(height));
    tbb::parallel_for(0, height, [&](int y) {
        for (int x = 0; x < width; ++x) {
            const glm::vec3 d = texelDirection(x, y, width, height);
            out[size_t(y) * width + x] = glm::mix(a.radiance(d), b.radiance(d), t);
        }
    });
    return out;
}

}  // namespace terralux
