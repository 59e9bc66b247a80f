#pragma once
// Deterministic, stratified direction sets. Seeds come from probe / point indices so a bake gives
// the same bytes whatever the thread count.

#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace terralux {

// SplitMix64 (Steele, Lea, Flood 2014): a counter-based hash, so any index maps to a
// well-mixed stream without shared state.
inline uint64_t splitmix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}
inline float hashToUnit(uint64_t h) { return float(h >> 40) * (1.0f / 16777216.0f); }

class Rng {
public:
    explicit Rng(uint64_t seed) : state_(splitmix64(seed)) {}
    float next() { return hashToUnit(splitmix64(state_++)); }

private:
    uint64_t state_;
};

// Point i of n on the spherical Fibonacci lattice (Marques et al. 2013, "Spherical Fibonacci
// Point Sets for Illumination Integrals"), with its pole on +Y: y = 1 − (2i + 1)/n puts an equal
// number of points above and below the horizon, which is where terrain radiance jumps.
// `azimuthOffset` in [0, 1) turns the set about +Y.
inline glm::vec3 fibonacciSphere(uint32_t i, uint32_t n, float azimuthOffset) {
    constexpr double kInvGolden = 0.6180339887498949;  // 1/φ
    const double y = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    double t = i * kInvGolden + azimuthOffset;
    t -= std::floor(t);
    const double phi = 2.0 * std::numbers::pi * t;
    return glm::vec3(float(r * std::sin(phi)), float(y), float(-r * std::cos(phi)));
}

// Orthonormal basis around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited").
inline void basisAround(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float c = n.x * n.y * a;
    t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

// Cosine-weighted hemisphere direction i of n about `normal`: a Fibonacci spiral on the unit
// disk lifted to the hemisphere (Malley's method), turned by `azimuthOffset`.
inline glm::vec3 cosineHemisphere(uint32_t i, uint32_t n, float azimuthOffset,
                                  const glm::vec3& normal) {
    constexpr double kInvGolden = 0.6180339887498949;
    const double r2 = (i + 0.5) / n;
    double t = i * kInvGolden + azimuthOffset;
    t -= std::floor(t);
    const double phi = 2.0 * std::numbers::pi * t;
    const double r = std::sqrt(r2);
    const float x = float(r * std::cos(phi)), z = float(r * std::sin(phi));
    const float y = float(std::sqrt(std::max(0.0, 1.0 - r2)));
    glm::vec3 tangent, bitangent;
    basisAround(normal, tangent, bitangent);
    return glm::normalize(x * tangent + y * normal + z * bitangent);
}

// A direction uniformly inside the cone of half-angle `radius` about `axis`.
inline glm::vec3 sampleCone(const glm::vec3& axis, float radius, float u1, float u2) {
    if (radius <= 0.0f) return axis;
    const float cosMax = std::cos(radius);
    const float cosT = 1.0f - u1 * (1.0f - cosMax);
    const float sinT = std::sqrt(std::max(0.0f, 1.0f - cosT * cosT));
    const float phi = 2.0f * std::numbers::pi_v<float> * u2;
    glm::vec3 t, b;
    basisAround(axis, t, b);
    return glm::normalize(cosT * axis + sinT * (std::cos(phi) * t + std::sin(phi) * b));
}

}  // namespace terralux
