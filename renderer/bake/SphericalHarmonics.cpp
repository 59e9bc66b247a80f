#include "bake/SphericalHarmonics.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace terralux::sh {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInfD = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();

// Newton square root usable in constant expressions (std::sqrt is not constexpr in C++20), so
// the basis constants are the exact closed forms rounded once and need no static initialiser.
constexpr double constSqrt(double x) {
    double r = x > 1.0 ? x : 1.0;
    for (int i = 0; i < 100; ++i) {
        const double next = 0.5 * (r + x / r);
        if (next == r) {
            break;
        }
        r = next;
    }
    return r;
}

constexpr double kC0 = 0.5 * constSqrt(1.0 / kPi);    // l = 0
constexpr double kC1 = constSqrt(3.0 / (4.0 * kPi));  // l = 1
constexpr double kC2 = 0.5 * constSqrt(15.0 / kPi);   // xy, yz, xz
constexpr double kC3 = 0.25 * constSqrt(5.0 / kPi);   // 3z^2 - 1
constexpr double kC4 = 0.25 * constSqrt(15.0 / kPi);  // x^2 - y^2
constexpr double kLobe[kBandCount] = {kPi, 2.0 * kPi / 3.0, kPi / 4.0};

constexpr float kC0f = static_cast<float>(kC0);
constexpr float kC1f = static_cast<float>(kC1);
constexpr float kC2f = static_cast<float>(kC2);
constexpr float kC3f = static_cast<float>(kC3);
constexpr float kC4f = static_cast<float>(kC4);

using Vec3d = std::array<double, 3>;
using Mat3d = std::array<Vec3d, 3>;

// One channel of E(n) written as the polynomial c + b.n + n^T A n. It equals evalIrradiance on
// the unit sphere term by term; no |n| = 1 substitution is made, so off-sphere values are
// irrelevant and the constant -1 of (3z^2 - 1) stays in c.
struct Quadratic {
    double c = 0.0;
    Vec3d b{};
    Mat3d a{};

    double operator()(const Vec3d& n) const {
        double f = c;
        for (int i = 0; i < 3; ++i) {
            f += b[i] * n[i];
            for (int j = 0; j < 3; ++j) {
                f += n[i] * a[i][j] * n[j];
            }
        }
        return f;
    }
};

Quadratic irradianceQuadratic(const ShRgb& sh, int channel) {
    double l[kCoeffCount];
    for (int k = 0; k < kCoeffCount; ++k) {
        l[k] = kLobe[bandOf(k)] * static_cast<double>(sh.c[k][channel]);
    }
    Quadratic q;
    q.c = kC0 * l[0] - kC3 * l[6];
    q.b = {kC1 * l[3], kC1 * l[1], kC1 * l[2]};  // (x, y, z)
    const double axy = 0.5 * kC2 * l[4];
    const double ayz = 0.5 * kC2 * l[5];
    const double axz = 0.5 * kC2 * l[7];
    q.a = {Vec3d{kC4 * l[8], axy, axz}, Vec3d{axy, -kC4 * l[8], ayz},
           Vec3d{axz, ayz, 3.0 * kC3 * l[6]}};
    return q;
}

// Symmetric 3x3 eigen-decomposition by cyclic Jacobi rotations (Golub & Van Loan, "Matrix
// Computations", 4th ed., sec. 8.5). Values ascending; vectors[i] is the unit eigenvector of
// values[i].
struct SymEigen {
    Vec3d values{};
    Mat3d vectors{};
};

SymEigen jacobiEigen(Mat3d a) {
    Mat3d v{};
    for (int i = 0; i < 3; ++i) {
        v[i][i] = 1.0;
    }
    constexpr int kPairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (int sweep = 0; sweep < 64; ++sweep) {
        const double off = std::abs(a[0][1]) + std::abs(a[0][2]) + std::abs(a[1][2]);
        if (off == 0.0) {
            break;
        }
        for (const auto& pair : kPairs) {
            const int p = pair[0];
            const int q = pair[1];
            const double apq = a[p][q];
            if (apq == 0.0) {
                continue;
            }
            // Negligible against the diagonal: dropping it perturbs the eigenvalues by far less
            // than an ulp.
            if (std::abs(apq) <= 1e-18 * (std::abs(a[p][p]) + std::abs(a[q][q]))) {
                a[p][q] = a[q][p] = 0.0;
                continue;
            }
            // Rotation angle that zeroes a[p][q]; t is the smaller root of t^2 + 2 theta t - 1.
            const double theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            const double t =
                (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::hypot(theta, 1.0));
            const double cs = 1.0 / std::sqrt(t * t + 1.0);
            const double sn = t * cs;
            for (int k = 0; k < 3; ++k) {  // A J
                const double akp = a[k][p];
                const double akq = a[k][q];
                a[k][p] = cs * akp - sn * akq;
                a[k][q] = sn * akp + cs * akq;
            }
            for (int k = 0; k < 3; ++k) {  // J^T (A J)
                const double apk = a[p][k];
                const double aqk = a[q][k];
                a[p][k] = cs * apk - sn * aqk;
                a[q][k] = sn * apk + cs * aqk;
            }
            a[p][q] = a[q][p] = 0.0;
            for (int k = 0; k < 3; ++k) {  // V J
                const double vkp = v[k][p];
                const double vkq = v[k][q];
                v[k][p] = cs * vkp - sn * vkq;
                v[k][q] = sn * vkp + cs * vkq;
            }
        }
    }
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int i, int j) { return a[i][i] < a[j][j]; });
    SymEigen e;
    for (int i = 0; i < 3; ++i) {
        e.values[i] = a[order[i]][order[i]];
        for (int k = 0; k < 3; ++k) {
            e.vectors[i][k] = v[k][order[i]];
        }
    }
    return e;
}

float minAllChannels(const ShRgb& sh) {
    float m = kInfF;
    for (int ch = 0; ch < 3; ++ch) {
        m = std::min(m, minIrradiance(sh, ch));
    }
    return m;
}

ShRgb windowed(const ShRgb& sh, float width) {
    ShRgb w = sh;
    applyWindow(w, width);
    return w;
}

}  // namespace

ShRgb& ShRgb::operator+=(const ShRgb& other) {
    for (int k = 0; k < kCoeffCount; ++k) {
        c[k] += other.c[k];
    }
    return *this;
}

ShRgb& ShRgb::operator*=(float s) {
    for (auto& v : c) {
        v *= s;
    }
    return *this;
}

void evalBasis(const glm::vec3& dir, float out[kCoeffCount]) {
    const float x = dir.x;
    const float y = dir.y;
    const float z = dir.z;
    out[0] = kC0f;
    out[1] = kC1f * y;
    out[2] = kC1f * z;
    out[3] = kC1f * x;
    out[4] = kC2f * x * y;
    out[5] = kC2f * y * z;
    out[6] = kC3f * (3.0f * z * z - 1.0f);
    out[7] = kC2f * x * z;
    out[8] = kC4f * (x * x - y * y);
}

std::array<float, kCoeffCount> evalBasis(const glm::vec3& dir) {
    std::array<float, kCoeffCount> out;
    evalBasis(dir, out.data());
    return out;
}

glm::vec3 evalRadiance(const ShRgb& sh, const glm::vec3& dir) {
    float y[kCoeffCount];
    evalBasis(dir, y);
    glm::vec3 sum(0.0f);
    for (int k = 0; k < kCoeffCount; ++k) {
        sum += sh.c[k] * y[k];
    }
    return sum;
}

glm::vec3 evalIrradiance(const ShRgb& sh, const glm::vec3& n) {
    float y[kCoeffCount];
    evalBasis(n, y);
    glm::vec3 sum(0.0f);
    for (int k = 0; k < kCoeffCount; ++k) {
        sum += sh.c[k] * (kCosineLobe[bandOf(k)] * y[k]);
    }
    return sum;
}

ShRgb projectConstant(const glm::vec3& radiance) {
    // integral of Y_0 over the sphere = 4 pi * 1/(2 sqrt(pi)) = 2 sqrt(pi).
    ShRgb sh;
    sh.c[0] = radiance * static_cast<float>(4.0 * kPi * kC0);
    return sh;
}

ShRgb projectDirectional(const glm::vec3& dir, const glm::vec3& integral) {
    ShRgb sh;
    accumulate(sh, dir, integral, 1.0f);
    return sh;
}

ShRgb projectClampedCosine(const glm::vec3& n, const glm::vec3& scale) {
    float y[kCoeffCount];
    evalBasis(n, y);
    ShRgb sh;
    for (int k = 0; k < kCoeffCount; ++k) {
        sh.c[k] = scale * (kCosineLobe[bandOf(k)] * y[k]);
    }
    return sh;
}

void accumulate(ShRgb& acc, const glm::vec3& dir, const glm::vec3& radiance, float weight) {
    float y[kCoeffCount];
    evalBasis(dir, y);
    const glm::vec3 r = radiance * weight;
    for (int k = 0; k < kCoeffCount; ++k) {
        acc.c[k] += r * y[k];
    }
}

float windowWeight(int band, float width) {
    if (band <= 0 || !(width < kInfF)) {
        return 1.0f;
    }
    const double w = width;
    if (!(w > band)) {
        return 0.0f;
    }
    const double x = kPi * band / w;
    return static_cast<float>(std::sin(x) / x);
}

void applyWindow(ShRgb& sh, float width) {
    if (!(width < kInfF)) {
        return;
    }
    const float w[kBandCount] = {1.0f, windowWeight(1, width), windowWeight(2, width)};
    for (int k = 1; k < kCoeffCount; ++k) {
        sh.c[k] *= w[bandOf(k)];
    }
}

// Minimise f(n) = c + b.n + n^T A n subject to |n| = 1 (a trust-region subproblem on the
// boundary). With A = Q diag(a_i) Q^T, u = Q^T n and beta = Q^T b / 2, the Lagrange condition is
// (a_i - lambda) u_i = -beta_i, and the global minimiser has lambda <= a_0 = lambda_min(A)
// (Gander, Golub & von Matt 1989, "A constrained eigenvalue problem"; More & Sorensen 1983,
// "Computing a trust region step"). Easy case: the unique root of the secular equation
// sum beta_i^2 / (a_i - lambda)^2 = 1 below a_0. Hard case (beta = 0 along the a_0 eigenspace and
// the remaining part p has |p| <= 1): lambda = a_0, u = p + tau * q_0 with |u| = 1. Both are
// generated as candidates, plus eigenvectors, and the lowest f among them wins; every candidate
// is a unit vector, so the value returned is always attained.
float minIrradiance(const ShRgb& sh, int channel, glm::vec3* argmin) {
    assert(channel >= 0 && channel < 3);
    const Quadratic q = irradianceQuadratic(sh, channel);
    const SymEigen eig = jacobiEigen(q.a);

    Vec3d beta{};
    Vec3d gap{};  // a_i - a_0 >= 0; working relative to a_0 avoids cancellation near the pole
    double betaNorm2 = 0.0;
    for (int i = 0; i < 3; ++i) {
        const Vec3d& v = eig.vectors[i];
        beta[i] = 0.5 * (v[0] * q.b[0] + v[1] * q.b[1] + v[2] * q.b[2]);
        gap[i] = std::max(0.0, eig.values[i] - eig.values[0]);
        betaNorm2 += beta[i] * beta[i];
    }
    const double betaNorm = std::sqrt(betaNorm2);

    double best = kInfD;
    Vec3d bestN = {0.0, 1.0, 0.0};
    auto consider = [&](const Vec3d& u) {  // u in eigen coordinates
        Vec3d n{};
        for (int i = 0; i < 3; ++i) {
            for (int k = 0; k < 3; ++k) {
                n[k] += u[i] * eig.vectors[i][k];
            }
        }
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 0.0) || !std::isfinite(len)) {
            return;
        }
        for (double& x : n) {
            x /= len;
        }
        const double f = q(n);
        if (f < best) {
            best = f;
            bestN = n;
        }
    };

    for (int i = 0; i < 3; ++i) {
        Vec3d u{};
        u[i] = 1.0;
        consider(u);
        u[i] = -1.0;
        consider(u);
    }

    if (betaNorm > 0.0) {
        // Secular equation in delta = a_0 - lambda > 0. g(delta) = 1/sqrt(phi) - 1 is concave and
        // increasing (More & Sorensen), so Newton from any point approaches the root from the
        // left; the bracket [lo, hi] with phi(betaNorm) <= 1 guards against round-off.
        double lo = 0.0;
        double hi = betaNorm;
        double delta = betaNorm;
        for (int it = 0; it < 200; ++it) {
            double phi = 0.0;
            double dphi = 0.0;  // -phi'(delta) / 2
            for (int i = 0; i < 3; ++i) {
                if (beta[i] != 0.0) {
                    const double r = 1.0 / (gap[i] + delta);
                    const double t = beta[i] * r;
                    phi += t * t;
                    dphi += t * t * r;
                }
            }
            const double sqrtPhi = std::sqrt(phi);
            const double g = 1.0 / sqrtPhi - 1.0;
            if (g > 0.0) {
                hi = delta;
            } else if (g < 0.0) {
                lo = delta;
            } else {
                break;
            }
            double next = delta - g * phi * sqrtPhi / dphi;
            if (!(next > lo && next < hi)) {
                next = 0.5 * (lo + hi);
            }
            if (next == delta || std::abs(g) < 1e-15) {
                break;
            }
            delta = next;
        }
        Vec3d u{};
        for (int i = 0; i < 3; ++i) {
            u[i] = -beta[i] / (gap[i] + delta);
        }
        consider(u);
        const Vec3d minusB = {-beta[0], -beta[1], -beta[2]};
        consider(minusB);
    }

    // Hard case. Eigenvalues within a relative 1e-10 of a_0 are treated as one eigenspace.
    const double scale = std::max({std::abs(eig.values[0]), std::abs(eig.values[2]), betaNorm});
    const double tol = 1e-10 * scale;
    Vec3d p{};
    double pNorm2 = 0.0;
    Vec3d betaCluster{};
    double betaClusterNorm2 = 0.0;
    bool inCluster[3] = {};
    for (int i = 0; i < 3; ++i) {
        inCluster[i] = gap[i] <= tol;
        if (inCluster[i]) {
            betaCluster[i] = beta[i];
            betaClusterNorm2 += beta[i] * beta[i];
        } else {
            p[i] = -beta[i] / gap[i];
            pNorm2 += p[i] * p[i];
        }
    }
    if (pNorm2 <= 1.0) {
        const double tau = std::sqrt(1.0 - pNorm2);
        if (betaClusterNorm2 > 0.0) {
            // Nearly hard: the residual beta in the eigenspace picks the side.
            const double inv = 1.0 / std::sqrt(betaClusterNorm2);
            Vec3d u = p;
            for (int i = 0; i < 3; ++i) {
                u[i] -= tau * betaCluster[i] * inv;
            }
            consider(u);
        }
        for (int j = 0; j < 3; ++j) {
            if (!inCluster[j]) {
                continue;
            }
            for (const double sign : {1.0, -1.0}) {
                Vec3d u = p;
                u[j] += sign * tau;
                consider(u);
            }
        }
    }

    if (argmin != nullptr) {
        *argmin = glm::vec3(static_cast<float>(bestN[0]), static_cast<float>(bestN[1]),
                            static_cast<float>(bestN[2]));
    }
    return static_cast<float>(best);
}

DeringResult deringIrradiance(ShRgb& sh) {
    DeringResult result;
    result.minBefore = minAllChannels(sh);
    if (result.minBefore >= 0.0f) {
        result.minAfter = result.minBefore;
        return result;
    }
    result.windowed = true;

    // Searched over s = 1/W in (0, 1]: s -> 0 is no window, s = 1 (W = 1) is DC only. The
    // feasible set of s need not be an interval (Lanczos weights of bands 1 and 2 fall at
    // different rates), so a coarse scan finds the first feasible s before bisection refines the
    // boundary. Feasibility is checked on exactly the float width that gets applied.
    auto widthOf = [](double s) { return s >= 1.0 ? 0.0f : static_cast<float>(1.0 / s); };
    auto feasible = [&](double s) { return minAllChannels(windowed(sh, widthOf(s))) >= 0.0f; };

    constexpr int kScanSteps = 64;
    constexpr int kBisectSteps = 30;
    int firstFeasible = 0;
    for (int j = 1; j <= kScanSteps; ++j) {
        if (feasible(static_cast<double>(j) / kScanSteps)) {
            firstFeasible = j;
            break;
        }
    }

    if (firstFeasible == 0) {
        // Even DC only is negative somewhere, i.e. some L_0 < 0: clamp it, as nothing else can
        // make a constant non-negative.
        for (int k = 1; k < kCoeffCount; ++k) {
            sh.c[k] = glm::vec3(0.0f);
        }
        for (int ch = 0; ch < 3; ++ch) {
            sh.c[0][ch] = std::max(0.0f, sh.c[0][ch]);
        }
        result.width = 0.0f;
    } else {
        double lo = static_cast<double>(firstFeasible - 1) / kScanSteps;  // infeasible
        double hi = static_cast<double>(firstFeasible) / kScanSteps;      // feasible
        for (int i = 0; i < kBisectSteps; ++i) {
            const double mid = 0.5 * (lo + hi);
            if (feasible(mid)) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        result.width = widthOf(hi);
        applyWindow(sh, result.width);
    }
    result.minAfter = minAllChannels(sh);
    return result;
}

DeringSummary deringProbes(std::vector<ShRgb>& sh, const std::vector<uint8_t>& valid) {
    DeringSummary out;
    for (size_t i = 0; i < sh.size(); ++i) {
        if (!valid[i]) continue;
        const DeringResult d = deringIrradiance(sh[i]);
        if (d.windowed) {
            ++out.windowed;
            out.strongest = std::min(out.strongest, d.width);
        }
    }
    return out;
}

}  // namespace terralux::sh
