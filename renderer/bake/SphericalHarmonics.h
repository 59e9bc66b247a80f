#pragma once
// Order-2 (9-coefficient) real spherical harmonics for RGB radiance and irradiance.
//
// Convention (byte contract with .shprobe files and the shaders): bands l = 0..2, coefficient
// index k = l(l + 1) + m, evaluated directly on the engine-space unit direction (x, y, z), Y up.
// Positive constants, no Condon-Shortley phase:
//   k=0: 1/(2 sqrt(pi))                     k=4: (1/2) sqrt(15/pi) * x*y
//   k=1: sqrt(3/(4 pi)) * y                 k=5: (1/2) sqrt(15/pi) * y*z
//   k=2: sqrt(3/(4 pi)) * z                 k=6: (1/4) sqrt(5/pi)  * (3z^2 - 1)
//   k=3: sqrt(3/(4 pi)) * x                 k=7: (1/2) sqrt(15/pi) * x*z
//                                           k=8: (1/4) sqrt(15/pi) * (x^2 - y^2)
// Stored coefficients are radiance projections L_k = integral of L(w) Y_k(w) dw. Irradiance for a
// unit normal n is E(n) = sum_k A_l L_k Y_k(n) with the clamped-cosine lobe A_l = {pi, 2pi/3,
// pi/4} (Ramamoorthi & Hanrahan 2001, "An Efficient Representation for Irradiance Environment
// Maps"). A constant sky of radiance 1 gives L_0 = 2 sqrt(pi) and E = pi for every n.

#include <array>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <glm/vec3.hpp>

namespace terralux::sh {

inline constexpr int kCoeffCount = 9;
inline constexpr int kBandCount = 3;

// RGB coefficients, c[k] = (R, G, B) of coefficient k.
struct ShRgb {
    std::array<glm::vec3, kCoeffCount> c{};  // zero-initialised

    ShRgb& operator+=(const ShRgb& other);
    ShRgb& operator*=(float s);
};

// Real SH basis at a unit direction (not normalised here: the caller guarantees |dir| = 1).
void evalBasis(const glm::vec3& dir, float out[kCoeffCount]);
std::array<float, kCoeffCount> evalBasis(const glm::vec3& dir);

// Clamped-cosine convolution factors A_l per band (Ramamoorthi & Hanrahan 2001).
inline constexpr std::array<float, kBandCount> kCosineLobe = {
    static_cast<float>(std::numbers::pi), static_cast<float>(2.0 * std::numbers::pi / 3.0),
    static_cast<float>(std::numbers::pi / 4.0)};

// Band l of coefficient k: 0, 1, 1, 1, 2, 2, 2, 2, 2.
constexpr int bandOf(int k) {
    return k < 1 ? 0 : (k < 4 ? 1 : 2);
}

// sum_k L_k Y_k(dir): the band-limited radiance.
glm::vec3 evalRadiance(const ShRgb& sh, const glm::vec3& dir);
// sum_k A_l L_k Y_k(n): irradiance on a surface with unit normal n.
glm::vec3 evalIrradiance(const ShRgb& sh, const glm::vec3& n);

// Analytic projections.
// Uniform sphere of the given radiance: L_0 = radiance * 2 sqrt(pi), all others zero.
ShRgb projectConstant(const glm::vec3& radiance);
// Delta light from unit direction dir whose radiance integrates to `integral`:
// L_k = integral * Y_k(dir).
ShRgb projectDirectional(const glm::vec3& dir, const glm::vec3& integral);
// f(w) = scale * max(0, n . w) about unit n. Its zonal coefficients are
// integral of max(0, cos) Y_l0 = {sqrt(pi)/2, sqrt(pi/3), sqrt(5 pi)/8}, rotated to n by
// sqrt(4 pi/(2l + 1)) Y_k(n) (Funk-Hecke), which gives L_k = scale * A_l * Y_k(n).
ShRgb projectClampedCosine(const glm::vec3& n, const glm::vec3& scale);

// Monte Carlo / quadrature accumulation of one sample: acc.c[k] += weight * radiance * Y_k(dir).
void accumulate(ShRgb& acc, const glm::vec3& dir, const glm::vec3& radiance, float weight);

// Lanczos sigma window (Sloan 2008, "Stupid Spherical Harmonics (SH) Tricks", windowing):
// w_l(W) = sinc(l / W) = sin(pi l / W) / (pi l / W), w_0 = 1. Ordinary widths are W > 2. Bands
// with l >= W get 0 (sinc reaches its first zero at l = W, so the weights stay continuous in W):
// 1 < W <= 2 keeps a damped band 1 only, W <= 1 keeps DC only. W = +inf (or NaN) means no window.
float windowWeight(int band, float width);
// Multiplies band l of every channel by windowWeight(l, width).
void applyWindow(ShRgb& sh, float width);

// Exact minimum over the unit sphere of the irradiance E(n) (as evalIrradiance computes it) of
// one channel (0 = R, 1 = G, 2 = B). Optionally returns the minimising unit normal.
float minIrradiance(const ShRgb& sh, int channel, glm::vec3* argmin = nullptr);

struct DeringResult {
    bool windowed = false;
    // Window width applied: +inf when untouched, 0 when reduced to DC only.
    float width = std::numeric_limits<float>::infinity();
    float minBefore = 0.0f;  // min over channels and normals of the irradiance, before
    float minAfter = 0.0f;   // ... and after
};

// Makes the irradiance non-negative for every normal and channel. A set that already is
// non-negative is left bit-identical (windowed = false). Otherwise the weakest Lanczos window
// (largest W) found by a coarse scan plus bisection on 1/W that gives non-negative minimum
// irradiance in all three channels is applied. If only DC remains feasible the result is DC only
// (width = 0); a negative L_0 is then clamped to 0, the only non-negative option left.
DeringResult deringIrradiance(ShRgb& sh);
// deringIrradiance on every probe `valid` marks (size of `sh`): how many were windowed and the
// narrowest window applied (infinity when none was).
struct DeringSummary {
    int windowed = 0;
    float strongest = std::numeric_limits<float>::infinity();
};
DeringSummary deringProbes(std::vector<ShRgb>& sh, const std::vector<uint8_t>& valid);

}  // namespace terralux::sh
