#include "bake/DiffuseBake.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include <glm/common.hpp>
#include <cmath>
#include <numbers>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "ShaderMath.h"
#include "bake/SphereSampling.h"
#include "water/Water.h"

namespace terralux {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
// Standard error (docs/lighting.md "Monte Carlo standard error"), by randomised quasi-Monte Carlo
// (Owen 1997; L'Ecuyer & Lemieux 2002, "Recent advances in randomized quasi-Monte Carlo
// methods"): a probe's N rays are kReplicates spherical Fibonacci lattices of about
// N / kReplicates rays, each turned about the vertical by its own uniform random azimuth. Each
// replicate is then an unbiased estimate of the lattice's height quadrature (one ray at the centre
// of each equal-area height band: exact for flat ground's horizon, which falls on a band edge, and
// off by O(N^-2) where the light varies smoothly with height) and the replicates are independent,
// so the spread of their coefficients over sqrt(kReplicates) estimates the error of their mean
// with no factor to calibrate, whatever the terrain, sky or albedo. (No estimate can be had from
// one lattice: its error is not a sum of independent parts.) The figure is of the metric every
// other error uses, the relative RMS over normals of the irradiance: for orthonormal SH,
// (1/4π)∫ δE(n)² dn = (1/4π) Σ_k A_l² δL_k², so
//   SE = sqrt(Σ_k A_l² Var(L_k) / K) / sqrt(Σ_k A_l² L_k²)
// on the luminance of the coefficients (Ramamoorthi & Hanrahan 2001 for A_l). Two replicates
// suffice: the estimate pools nine coefficients (reported within 1.2x of the measured error,
// mean and 95th percentile over probes, on every shared DEM), and more replicates make each
// lattice smaller and the bake noisier.
constexpr int kReplicates = 2;
// The rays that choose how a probe counts the glow's (traceProbeRounds).
constexpr int kGlowPilotRays = 16;

// Per luminance SH coefficient, an estimate and the variance of that estimate.
struct CoefficientMoments {
    std::array<double, sh::kCoeffCount> mean{}, variance{};

    // The relative standard error of the irradiance the coefficients stand for:
    // sqrt(Σ_k A_l² Var(L_k)) / sqrt(Σ_k A_l² L_k²).
    float relativeError() const {
        double num = 0.0, den = 0.0;
        for (int j = 0; j < sh::kCoeffCount; ++j) {
            const double a = sh::kCosineLobe[size_t(sh::bandOf(j))];
            num += a * a * variance[size_t(j)];
            den += a * a * mean[size_t(j)] * mean[size_t(j)];
        }
        return den > 0.0 ? float(std::sqrt(num / den)) : 0.0f;
    }
};

// Accumulates each replicate's luminance SH (radiance projections with the replicate's own weight
// 4π / its rays); their mean and its variance from the spread of the replicates.
struct Replicates {
    std::array<std::array<double, sh::kCoeffCount>, kReplicates> lum{};
    std::array<int, kReplicates> count{};

    // `counted`: a ray of the replicate's lattice (a glow ray adds to its sum, already scaled).
    void add(int k, const glm::vec3& radiance, const glm::vec3& d, bool counted = true) {
        float y[sh::kCoeffCount];
        sh::evalBasis(d, y);
        const double l = double(glsl::rec709Luminance(radiance));
        for (int j = 0; j < sh::kCoeffCount; ++j) lum[size_t(k)][size_t(j)] += l * double(y[j]);
        count[size_t(k)] += counted;
    }
    // With fewer than two replicates traced the variance is unknown and reads 0.
    CoefficientMoments moments() const {
        CoefficientMoments m;
        int k = 0;
        for (int r = 0; r < kReplicates; ++r) k += count[size_t(r)] > 0;
        if (k == 0) return m;
        for (int j = 0; j < sh::kCoeffCount; ++j) {
            double mean = 0.0, sq = 0.0;
            for (int r = 0; r < kReplicates; ++r) {
                if (count[size_t(r)] == 0) continue;
                const double e = 4.0 * std::numbers::pi * lum[size_t(r)][size_t(j)] / count[size_t(r)];
                mean += e;
                sq += e * e;
            }
            mean /= k;
            m.mean[size_t(j)] = mean;
            m.variance[size_t(j)] = k < 2 ? 0.0 : std::max(0.0, sq / k - mean * mean) / (k - 1);
        }
        return m;
    }
};

// The rounds of one probe with a target (ProbeRays), in two stages (Stein 1945, "A two-sample
// test for a linear hypothesis whose power is independent of the variance"): the first round
// (half the lower count) only decides how many rays the probe gets; the rounds after it are traced
// whatever they show. The probe is the mean of all its rays (round r weighs N_r / N), and its
// variance Σ_r (N_r / N)² Var_r takes each round's variance from its own replicates, except the
// first's, which is the second round's (the same size, and independent of the decision). A figure
// that also decided when to stop would be optimistic: the probes that stop are those whose
// estimate came out low (on a mountain crop, 0.36 % reported against 1.26 % measured).
struct Rounds {
    std::vector<std::pair<int, CoefficientMoments>> rounds;
    int rays = 0;

    void add(int n, const CoefficientMoments& m) {
        rounds.emplace_back(n, m);
        rays += n;
    }
    float relativeError() const {
        CoefficientMoments c;
        for (size_t r = 0; r < rounds.size(); ++r) {
            const double w = double(rounds[r].first) / double(rays);
            const CoefficientMoments& m = rounds[r].second;
            const CoefficientMoments& v = r == 0 && rounds.size() > 1 ? rounds[1].second : m;
            for (size_t j = 0; j < c.mean.size(); ++j) {
                c.mean[j] += w * m.mean[j];
                c.variance[j] += w * w * v.variance[j];
            }
        }
        return c.relativeError();
    }
    // The rays a probe gets from its first round's error `first` over `n` rays: the lower count
    // doubled until the error, falling as 1/sqrt(rays), is at most the target, within the cap.
    static int planned(const ProbeRays& schedule, int n, float first) {
        const double need = double(n) * std::pow(double(first) / double(schedule.target), 2.0);
        int total = schedule.rays;
        while (double(total) < need && 2 * total <= schedule.maxRays) total *= 2;
        return total;
    }
};

// Ray r of a probe's `rays` is point r / kReplicates of replicate r mod kReplicates, a lattice of
// rays / kReplicates points (one more for the first rays % kReplicates replicates).
struct ReplicateLattices {
    int rays;
    std::array<float, kReplicates> azimuth{};
    ReplicateLattices(int rays, Rng& rng) : rays(rays) {
        for (float& a : azimuth) a = rng.next();
    }
    int replicateOf(int r) const { return r % kReplicates; }
    glm::vec3 direction(int r) const {
        const int k = replicateOf(r);
        const int n = rays / kReplicates + (k < rays % kReplicates);
        return fibonacciSphere(uint32_t(r / kReplicates), uint32_t(n), azimuth[size_t(k)]);
    }
};

// Lift off the surface by more than the tracer's self-hit distance, scaled with the coordinates.
glm::vec3 liftOff(const glm::vec3& p, const glm::vec3& n) {
    const float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    return p + n * (1e-5f * m + 1e-2f);
}

// Runs body(i) for i in [0, n) in chunks, reporting progress and honouring cancel. Results go
// to per-index slots, so the chunking does not change any value.
template <typename Body>
void parallelIndices(size_t n, const BakeControl& control, Body body) {
    std::atomic<size_t> done{0};
    const size_t grain = 16;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, grain), [&](const tbb::blocked_range<size_t>& r) {
        if (control.cancelled()) return;
        for (size_t i = r.begin(); i != r.end(); ++i) body(i);
        const size_t d = done.fetch_add(r.size()) + r.size();
        if (control.progress) control.progress(double(d) / double(n));
    });
    if (control.cancelled()) throw BakeCancelled();
}

glm::vec3 sunIrradiance(const BakeLighting& L, const glm::vec3& p, const glm::vec3& n, int samples,
                        Rng& rng) {
    const float cosine = glm::dot(n, L.sun.direction);
    if (cosine <= 0.0f || samples <= 0 || L.sun.illuminance == glm::vec3(0.0f)) return glm::vec3(0.0f);
    return L.sun.illuminance * cosine * sunVisibility(*L.tracer, L.sun, p, n, samples, rng);
}

// Where a ray meets the water before `tMax` (the terrain's hit, or +∞), seen from above. A ray
// that meets the terrain first never reaches water over it: from above the level, the terrain
// under water lies beyond the plane.
bool hitsWater(const BakeLighting& L, const glm::vec3& o, const glm::vec3& d, float tMax, glm::vec3& at) {
    if (!L.water || !(o.y > L.water->level) || !(d.y < 0.0f)) return false;
    const float t = (L.water->level - o.y) / d.y;
    if (!(t < tMax)) return false;
    at = glm::vec3(o.x + t * d.x, L.water->level, o.z + t * d.z);
    // Without the skirt nothing continues beyond the ground, the water neither.
    return L.tracer->reaches(at.x, at.z);
}

// A direction about `n` with density cos θ / π, from two fresh random numbers.
glm::vec3 randomCosineDirection(const glm::vec3& n, Rng& rng) {
    const float u1 = rng.next(), u2 = rng.next();
    const float rr = std::sqrt(u1), phi = 2.0f * kPi * u2;
    glm::vec3 t, bt;
    basisAround(n, t, bt);
    return glm::normalize(rr * std::cos(phi) * t + rr * std::sin(phi) * bt + std::sqrt(std::max(0.0f, 1.0f - u1)) * n);
}

// The sun at a hit: one shadow ray across the disc; the skirt is unshadowed by definition.
glm::vec3 sunAtHit(const BakeLighting& L, const RayHit& hit, Rng& rng) {
    return hit.onTerrain ? sunIrradiance(L, hit.position, hit.normal, 1, rng)
                         : L.sun.illuminance * std::max(0.0f, L.sun.direction.y);
}

// The irradiance the sky's glow (Sky::hasGlow) puts on a surface at o with normal n, by one ray
// drawn from the glow's luminance (next-event estimation, as the sun's shadow ray): the glow over
// its density, times the cosine, where the terrain does not hide it. 0 without glow, drawing no
// numbers, so a sky without one bakes as before.
glm::vec3 glowIrradiance(const BakeLighting& L, const glm::vec3& o, const glm::vec3& n, int samples, Rng& rng) {
    if (!L.sky.hasGlow() || samples <= 0) return glm::vec3(0.0f);
    glm::vec3 sum(0.0f);
    for (int m = 0; m < samples; ++m) {
        glm::vec3 d;
        const float u0 = (float(m) + rng.next()) / float(samples);
        const float u1 = rng.next(), u2 = rng.next();
        const glm::vec3 overPdf = L.sky.sampleGlow(u0, u1, u2, d);
        const float c = glm::dot(n, d);
        if (c > 0.0f && !L.tracer->occluded(o, d, INFINITY)) sum += overPdf * c;
    }
    return sum / float(samples);
}

// The direct light at a hit: the sun's and, on the terrain, the glow's (a skirt hit's open sky
// holds its glow).
glm::vec3 directAtHit(const BakeLighting& L, const RayHit& hit, Rng& rng) {
    glm::vec3 e = sunAtHit(L, hit, rng);
    if (hit.onTerrain) e += glowIrradiance(L, liftOff(hit.position, hit.normal), hit.normal, 1, rng);
    return e;
}

// What a terrain hit reflects toward the ray: albedo/π × (its indirect light + the sun at the
// hit). With one bounce the indirect light is the cache's, read at the hit. With more (a cache
// with a gather), it is gathered by one cosine-weighted ray from the hit itself, with the hit's
// own normal (a final gather, docs/lighting.md "Irradiance cache"): the sky where it escapes,
// and where it meets the terrain again what that point reflects of the sun and of the cache's
// light one gather earlier. The cache's points stand on a surface smoothed over their spacing, so
// its irradiance read at the hit would light every slope as that smoothed surface; one bounce
// later its error is damped by the albedo. The skirt's light is exact.
glm::vec3 terrainRadiance(const BakeLighting& L, const IrradianceCache* cache, int bounces, const RayHit& hit,
                          Rng& rng) {
    if (!(bounces > 0 && cache)) return glm::vec3(0.0f);
    const glm::vec3 albedo = L.albedoAt(hit) / kPi;
    if (!hit.onTerrain || !cache->gathersAtHits()) return albedo * (cache->indirectAt(hit) + directAtHit(L, hit, rng));
    const glm::vec3 d = randomCosineDirection(hit.normal, rng);
    const glm::vec3 o = liftOff(hit.position, hit.normal);
    RayHit next;
    glm::vec3 gathered;  // radiance along d: the irradiance is π × it under cosine sampling
    // The sky's glow comes by a ray of its own; the cosine ray reads the rest.
    if (!L.tracer->intersect(o, d, INFINITY, next))
        gathered = L.sky.smoothRadiance(d, 0.0f);
    else
        gathered = L.albedoAt(next) / kPi * (cache->earlierIndirectAt(next) + directAtHit(L, next, rng));
    return albedo * (kPi * gathered + directAtHit(L, hit, rng));
}

// The irradiance on the level water surface at `at`: the open sky's (as on the skirt: what the
// terrain hides of the sky is left out) and the sun through one shadow ray.
glm::vec3 waterIrradiance(const BakeLighting& L, const glm::vec3& at, Rng& rng) {
    return L.sky.openIrradianceUp() + sunIrradiance(L, at, glm::vec3(0.0f, 1.0f, 0.0f), 1, rng);
}

// The light the water at `at` sends back along −d: the mirrored ray's light weighted by Fresnel,
// and the scatter of what enters. `mirrored` gives the radiance along the reflected ray.
template <typename Mirrored>
glm::vec3 waterRadiance(const BakeLighting& L, const glm::vec3& at, const glm::vec3& d, Rng& rng,
                        Mirrored mirrored) {
    const float f = waterFresnel(-d.y);
    const glm::vec3 up(0.0f, 1.0f, 0.0f);
    const glm::vec3 reflected = mirrored(liftOff(at, up), glm::vec3(d.x, -d.y, d.z));
    return f * reflected + (1.0f - f) * L.water->scatter / kPi * waterIrradiance(L, at, rng);
}

// probeRayRadiance with the terrain's hit already traced (`hit` null: the ray escapes).
glm::vec3 rayRadiance(const BakeLighting& L, const IrradianceCache* cache, int bounces, const glm::vec3& o,
                      const glm::vec3& d, const RayHit* hit, float skyAngle, Rng& rng,
                      const glm::vec3* ground = nullptr) {
    glm::vec3 at;
    if (hitsWater(L, o, d, hit ? hit->t : INFINITY, at)) {
        if (bounces <= 0) return glm::vec3(0.0f);
        // The mirrored ray rises, so it cannot meet the water again: the sky or lit terrain.
        return waterRadiance(L, at, d, rng, [&](const glm::vec3& ro, const glm::vec3& rd) {
            RayHit h;
            return L.tracer->intersect(ro, rd, INFINITY, h) ? terrainRadiance(L, cache, bounces, h, rng)
                                                            : L.sky.radiance(rd, skyAngle);
        });
    }
    if (hit) return terrainRadiance(L, cache, bounces, *hit, rng);
    if (ground && d.y < 0.0f) return *ground;
    return L.sky.radiance(d, skyAngle);
}

}  // namespace

float waterFresnel(float cosine) {
    // Schlick, "An Inexpensive BRDF Model for Physically-based Rendering", CGF 13(3), 1994.
    const float m = 1.0f - std::clamp(cosine, 0.0f, 1.0f);
    const float m2 = m * m;
    return float(water::kWaterF0) + (1.0f - float(water::kWaterF0)) * m2 * m2 * m;
}

glm::vec3 probeRayRadiance(const BakeLighting& L, const IrradianceCache* cache, int bounces,
                           const glm::vec3& origin, const glm::vec3& dir, float skyAngle, Rng& rng,
                           const glm::vec3* ground) {
    RayHit hit;
    const bool terrain = L.tracer->intersect(origin, dir, INFINITY, hit);
    return rayRadiance(L, cache, bounces, origin, dir, terrain ? &hit : nullptr, skyAngle, rng, ground);
}

float sunVisibility(const HeightfieldTracer& tracer, const SunLight& sun, const glm::vec3& p,
                    const glm::vec3& n, int samples, Rng& rng) {
    if (glm::dot(n, sun.direction) <= 0.0f || samples <= 0) return 0.0f;
    int visible = 0;
    const glm::vec3 o = liftOff(p, n);
    for (int s = 0; s < samples; ++s) {
        // Stratified over the disk's cos-θ range.
        const float u1 = (float(s) + rng.next()) / float(samples);
        const glm::vec3 d = sampleCone(sun.direction, sun.angularRadius, u1, rng.next());
        if (!tracer.occluded(o, d, INFINITY)) ++visible;
    }
    return float(visible) / float(samples);
}

float tracedSkyVisibility(const HeightfieldTracer& tracer, const glm::vec3& p, const glm::vec3& n,
                          uint32_t rays, uint64_t seed) {
    const glm::vec3 o = liftOff(p, n);
    const float offset = hashToUnit(splitmix64(seed));
    uint32_t open = 0;
    for (uint32_t i = 0; i < rays; ++i)
        open += !tracer.occluded(o, cosineHemisphere(i, rays, offset, n), INFINITY);
    return rays ? float(open) / float(rays) : 0.0f;
}

glm::vec3 sunFirstBounce(const BakeLighting& lighting, const glm::vec3& p, const glm::vec3& n, uint32_t rays,
                         uint64_t seed) {
    const glm::vec3 o = liftOff(p, n);
    Rng rng(seed);
    const float offset = rng.next();
    glm::vec3 sum(0.0f);
    for (uint32_t i = 0; i < rays; ++i) {
        RayHit hit;
        if (!lighting.tracer->intersect(o, cosineHemisphere(i, rays, offset, n), INFINITY, hit)) continue;
        const float cosine = glm::dot(hit.normal, lighting.sun.direction);
        if (cosine <= 0.0f) continue;
        const float v = sunVisibility(*lighting.tracer, lighting.sun, hit.position, hit.normal, 4, rng);
        sum += lighting.albedoAt(hit) * lighting.sun.illuminance * (cosine * v);
    }
    return rays ? sum / float(rays) : sum;
}

const char* qualityName(QualityPreset preset) {
    switch (preset) {
        case QualityPreset::Draft: return "draft";
        case QualityPreset::Standard: return "standard";
        case QualityPreset::High: return "high";
        case QualityPreset::Reference: return "reference";
    }
    return "standard";
}

BakeQuality qualityOf(const BakeSettings& bake) {
    BakeQuality q = qualityPreset(bake.quality);
    if (bake.rays) {
        q.rays = *bake.rays;
        q.targetError = 0.0f;
    }
    if (bake.bounces) q.bounces = *bake.bounces;
    return q;
}

BakeQuality qualityPreset(QualityPreset preset) {
    switch (preset) {
        case QualityPreset::Draft: return {96, 1, 64, 32, 2, 0.016f, 6144};
        case QualityPreset::Standard: return {256, 2, 128, 64, 4, 0.004f, 16384};
        case QualityPreset::High: return {1024, 3, 256, 128, 8, 0.002f, 65536};
        case QualityPreset::Reference: return {4096, 16, 0, 0, 1, 0.001f, 65536};
    }
    return {};
}

std::array<int, 2> IrradianceCache::gridPoints(const Heightfield& hf, int resolution) {
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    const float span = std::max(spanX, spanZ);
    resolution = std::max(resolution, 2);
    // Never finer than the DEM itself.
    return {std::clamp(int(std::lround(resolution * (span > 0 ? spanX / span : 1.0f))), 2,
                       std::max(hf.width(), 2)),
            std::clamp(int(std::lround(resolution * (span > 0 ? spanZ / span : 1.0f))), 2,
                       std::max(hf.depth(), 2))};
}

int cacheResolutionFor(const Heightfield& hf, const BakeQuality& q, uint64_t probeRays) {
    int resolution = std::max(q.cacheResolution, 2);
    auto cacheRays = [&](int r) {
        const std::array<int, 2> n = IrradianceCache::gridPoints(hf, r);
        return uint64_t(n[0]) * uint64_t(n[1]) * uint64_t(std::max(q.cacheRays, 1));
    };
    // Twice the probe rays: the cost stays below 3x the probes', under the 4x step in rays per
    // probe between presets, and halves the extra error of a cut cache against a budget of 1x.
    while (resolution > 2 && cacheRays(resolution) > 2 * probeRays) --resolution;
    return resolution;
}

IrradianceCache::IrradianceCache(const BakeLighting& L, int resolution, int rays, int sunSamples,
                                 int bounces, const BakeControl& control)
    : IrradianceCache(L, resolution, rays, sunSamples, bounces, control, nullptr) {}

std::vector<IrradianceCache> IrradianceCache::byGathers(const BakeLighting& L, int resolution, int rays,
                                                        int sunSamples, int gathers, const BakeControl& control) {
    std::vector<std::vector<glm::vec3>> levels;
    IrradianceCache last(L, resolution, rays, sunSamples, gathers, control, &levels);
    std::vector<IrradianceCache> out;
    for (size_t g = 0; g < levels.size(); ++g) {
        out.push_back(last);
        out.back().irradiance_ = levels[g];
        out.back().earlier_ = g > 0 ? levels[g - 1] : std::vector<glm::vec3>();
    }
    return out;
}

IrradianceCache::IrradianceCache(const BakeLighting& L, int resolution, int rays, int sunSamples,
                                 int bounces, const BakeControl& control,
                                 std::vector<std::vector<glm::vec3>>* levels)
    : lighting_(&L) {
    const Heightfield& hf = L.tracer->heightfield();
    skirt_ = L.sky.openIrradianceUp() + L.sun.illuminance * std::max(0.0f, L.sun.direction.y);
    const float spanX = hf.maxX() - hf.minX(), spanZ = hf.maxZ() - hf.minZ();
    const std::array<int, 2> n = gridPoints(hf, resolution);
    nx_ = n[0];
    nz_ = n[1];
    x0_ = hf.minX();
    z0_ = hf.minZ();
    dx_ = spanX > 0 ? spanX / float(nx_ - 1) : 1.0f;
    dz_ = spanZ > 0 ? spanZ / float(nz_ - 1) : 1.0f;
    const size_t points = size_t(nx_) * nz_;
    rays = std::max(rays, 1);
    rays_ = rays;

    std::vector<glm::vec3> direct(points);
    sunDirect_.assign(points, glm::vec3(0.0f));
    skirtSun_ = L.sun.illuminance * std::max(0.0f, L.sun.direction.y);
    // Hits per point: (x, z) of terrain hits; NaN x marks a skirt hit.
    std::vector<float> hitXZ(points * size_t(rays) * 2);
    // A varying albedo: per point, the sum of the albedos its skirt hits reflect with (the skirt's
    // irradiance is one constant, so this is all the gathers need of those hits).
    const bool varying = L.variesOverTerrain();
    std::vector<glm::vec3> skirtAlbedoSum(varying ? points : 0);
    BakeControl phase = control;
    phase.progress = control.progress ? [&](double f) { control.progress(0.8 * f); }
                                      : std::function<void(double)>();
    parallelIndices(points, phase, [&](size_t i) {
        const int ix = int(i % nx_), iz = int(i / nx_);
        const float x = x0_ + dx_ * float(ix), z = z0_ + dz_ * float(iz);
        const glm::vec3 p(x, hf.surfaceHeight(x, z), z);
        // Cache-scale normal: central differences over one cache spacing.
        const float hx = 0.5f * dx_, hz = 0.5f * dz_;
        const glm::vec3 n = glm::normalize(glm::vec3(
            -(hf.surfaceHeight(x + hx, z) - hf.surfaceHeight(x - hx, z)) / (2 * hx), 1.0f,
            -(hf.surfaceHeight(x, z + hz) - hf.surfaceHeight(x, z - hz)) / (2 * hz)));
        Rng rng(splitmix64(0x5EEDCACEull ^ uint64_t(i)));
        const glm::vec3 o = liftOff(p, n);
        glm::vec3 sky(0.0f), skirtAlbedo(0.0f);
        const float offset = rng.next();
        const float solidAngle = 2.0f * kPi / float(rays);
        float* hits = &hitXZ[i * size_t(rays) * 2];
        for (int r = 0; r < rays; ++r) {
            const glm::vec3 d = cosineHemisphere(uint32_t(r), uint32_t(rays), offset, n);
            RayHit hit;
            if (L.tracer->intersect(o, d, INFINITY, hit)) {
                hits[2 * r] = hit.onTerrain ? hit.position.x : NAN;
                hits[2 * r + 1] = hit.position.z;
                if (!hit.onTerrain && varying) skirtAlbedo += L.albedoAt(hit);
            } else {
                sky += L.sky.smoothRadiance(d, solidAngle);
                hits[2 * r] = NAN;
                hits[2 * r + 1] = INFINITY;  // escaped: contributes sky only
            }
        }
        sunDirect_[i] = sunIrradiance(L, p, n, sunSamples, rng) + glowIrradiance(L, o, n, std::max(1, rays / 4), rng);
        direct[i] = sky * (kPi / float(rays)) + sunDirect_[i];
        if (varying) skirtAlbedoSum[i] = skirtAlbedo;
    });

    // Gathers: E_b = E_0 + albedo / N × Σ E_{b-1}(hit) (cosine-weighted estimator of
    // ∫ albedo/π E cos dω).
    irradiance_ = direct;
    std::vector<glm::vec3> next(points);
    for (int b = 0; b < bounces; ++b) {
        if (levels) levels->push_back(irradiance_);
        if (b + 1 == bounces) earlier_ = irradiance_;
        BakeControl gather = control;
        gather.progress = control.progress
                              ? [&](double f) { control.progress(0.8 + 0.2 * (b + f) / bounces); }
                              : std::function<void(double)>();
        if (varying) {
            // The light a hit reflects is its own albedo times its irradiance.
            parallelIndices(points, gather, [&](size_t i) {
                const float* hits = &hitXZ[i * size_t(rays) * 2];
                glm::vec3 sum = skirt_ * skirtAlbedoSum[i];
                for (int r = 0; r < rays; ++r)
                    if (!std::isnan(hits[2 * r]))
                        sum += L.surface->at(hf, hits[2 * r], hits[2 * r + 1]) *
                               interpolate(irradiance_, hits[2 * r], hits[2 * r + 1]);
                next[i] = direct[i] + sum / float(rays);
            });
            irradiance_.swap(next);
            continue;
        }
        parallelIndices(points, gather, [&](size_t i) {
            const float* hits = &hitXZ[i * size_t(rays) * 2];
            glm::vec3 sum(0.0f);
            for (int r = 0; r < rays; ++r) {
                if (!std::isnan(hits[2 * r])) sum += interpolate(irradiance_, hits[2 * r], hits[2 * r + 1]);
                else if (std::isfinite(hits[2 * r + 1])) sum += skirt_;
            }
            next[i] = direct[i] + L.albedo * sum / float(rays);
        });
        irradiance_.swap(next);
    }
    if (levels) levels->push_back(irradiance_);
}

glm::vec3 IrradianceCache::interpolate(const std::vector<glm::vec3>& e, float x, float z) const {
    const float fx = std::clamp((x - x0_) / dx_, 0.0f, float(nx_ - 1));
    const float fz = std::clamp((z - z0_) / dz_, 0.0f, float(nz_ - 1));
    const int ix = std::min(int(fx), nx_ - 2), iz = std::min(int(fz), nz_ - 2);
    const float tx = fx - float(ix), tz = fz - float(iz);
    const size_t i00 = size_t(iz) * nx_ + ix;
    return (1 - tz) * ((1 - tx) * e[i00] + tx * e[i00 + 1]) +
           tz * ((1 - tx) * e[i00 + nx_] + tx * e[i00 + nx_ + 1]);
}

glm::vec3 IrradianceCache::at(const RayHit& hit) const {
    return hit.onTerrain ? interpolate(irradiance_, hit.position.x, hit.position.z) : skirt_;
}

glm::vec3 IrradianceCache::indirectAt(const RayHit& hit) const {
    if (!hit.onTerrain) return skirt_ - skirtSun_;
    return glm::max(interpolate(irradiance_, hit.position.x, hit.position.z) -
                        interpolate(sunDirect_, hit.position.x, hit.position.z),
                    glm::vec3(0.0f));
}

glm::vec3 IrradianceCache::earlierIndirectAt(const RayHit& hit) const {
    if (!hit.onTerrain) return skirt_ - skirtSun_;
    return glm::max(interpolate(earlier_, hit.position.x, hit.position.z) -
                        interpolate(sunDirect_, hit.position.x, hit.position.z),
                    glm::vec3(0.0f));
}

std::vector<uint64_t> positionSeeds(const std::vector<glm::vec3>& positions, uint64_t seed) {
    std::vector<uint64_t> seeds(positions.size());
    for (size_t i = 0; i < positions.size(); ++i) {
        // To the centimetre: the same place computed in another engine space (a tile's, placed in
        // its region's) differs by float rounding, far below that.
        uint64_t h = 0;
        for (int c = 0; c < 3; ++c) h = splitmix64(h ^ uint64_t(std::llround(double(positions[i][c]) * 100.0)));
        seeds[i] = seed ^ h;
    }
    return seeds;
}

// Traces one probe's rays (ProbeRays) into slot i of `out`: `ray(d, weight)` is the radiance
// along direction d, weight the solid angle one ray of the round stands for. Returns the rays.
// With `base`, the rays estimate what the probe differs from it: the probe is `base` plus their
// projection, and ray(d, weight) is the radiance less base's own along d.
// With `glow` (a sky with a glow, Sky::sampleGlow), each round also draws a quarter as many rays
// from the glow's luminance, split evenly between the replicates, and ray(d, weight) leaves the
// glow out; sees(d) says whether the probe sees the sky along d. The glow the probe sees, V, is
// estimated one of two ways, each exact at one end: as the glow's whole projection less what the
// rays find hidden (exact for a glow in full view), or as what the rays find seen (exact for a
// glow hidden whole, where the first way would leave the spread of the glow's texels as noise
// many times the probe's own light). Sixteen rays drawn before the rounds choose, so the choice
// does not depend on the rays it weighs. A ray's value is projected at the centre of its glow
// texel, as Sky::sh() projects the texel. The rays add V to `base`, which holds none of the glow
// (the bake's base is the smooth part's projection, Sky::smoothSh).
template <typename Ray, typename Sees>
int traceProbeRounds(const ProbeRays& schedule, Rng& rng, ProbeBake& out, size_t i, const sh::ShRgb* base,
                     Ray&& ray, const Sky* glow, Sees&& sees) {
    std::array<double, sh::kCoeffCount> baseLuminance{};
    if (base)
        for (int j = 0; j < sh::kCoeffCount; ++j) baseLuminance[size_t(j)] = double(glsl::rec709Luminance(base->c[size_t(j)]));
    Rounds rounds;
    sh::ShRgb total;
    int glowRays = 0;
    // The glow's constant part of each round and whether its rays count what they find hidden.
    sh::ShRgb glowConstant;
    bool countHidden = false;
    if (glow) {
        constexpr int kPilot = kGlowPilotRays;
        int hidden = 0;
        for (int m = 0; m < kPilot; ++m) {
            glm::vec3 d;
            const float u0 = (float(m) + rng.next()) / float(kPilot);
            const float u1 = rng.next(), u2 = rng.next();
            glow->sampleGlow(u0, u1, u2, d);
            hidden += !sees(d);
        }
        glowRays += kPilot;
        countHidden = 2 * hidden <= kPilot;
        // V = glow − hidden (rays count hidden) or V = seen.
        if (countHidden) glowConstant = glow->glowSh();
    }
    std::array<double, sh::kCoeffCount> constantLuminance{};
    for (int j = 0; j < sh::kCoeffCount; ++j) constantLuminance[size_t(j)] = double(glsl::rec709Luminance(glowConstant.c[size_t(j)]));
    auto round = [&](int n) {
        const ReplicateLattices lattices(n, rng);
        const float weight = 4.0f * kPi / float(n);
        sh::ShRgb acc;
        Replicates replicates;
        for (int r = 0; r < n; ++r) {
            const glm::vec3 d = lattices.direction(r);
            const glm::vec3 radiance = ray(d, weight);
            sh::accumulate(acc, d, radiance, weight);
            replicates.add(lattices.replicateOf(r), radiance, d);
        }
        if (glow) {
            // Each replicate's glow rays are stratified over the glow's distribution by their
            // first number; in the replicate's estimate a ray's value is scaled from its
            // lattice's weight (4π over its rays) to 1 over its glow rays.
            const int perReplicate = std::max(1, n / (4 * kReplicates));
            for (int k = 0; k < kReplicates; ++k) {
                const int latticeRays = n / kReplicates + (k < n % kReplicates);
                const float toLattice = float(latticeRays) / (4.0f * kPi * float(perReplicate));
                for (int m = 0; m < perReplicate; ++m) {
                    glm::vec3 d, centre;
                    const float u0 = (float(m) + rng.next()) / float(perReplicate);
                    const float u1 = rng.next(), u2 = rng.next();
                    const glm::vec3 overPdf = glow->sampleGlow(u0, u1, u2, d, &centre);
                    ++glowRays;
                    if (sees(d) == countHidden) continue;
                    const glm::vec3 value = countHidden ? -overPdf : overPdf;
                    sh::accumulate(acc, centre, value, 1.0f / float(perReplicate * kReplicates));
                    replicates.add(k, value * toLattice, centre, false);
                }
            }
            for (int j = 0; j < sh::kCoeffCount; ++j) acc.c[size_t(j)] += glowConstant.c[size_t(j)];
        }
        // Earlier rounds' share shrinks as this one adds its rays.
        const float share = float(n) / float(rounds.rays + n);
        total *= 1.0f - share;
        acc *= share;
        total += acc;
        CoefficientMoments m = replicates.moments();
        for (size_t j = 0; j < m.mean.size(); ++j) m.mean[j] += baseLuminance[j] + constantLuminance[j];
        rounds.add(n, m);
    };
    if (!schedule.adaptive()) {
        round(std::max(schedule.rays, 1));
    } else {
        // The two halves differ by a few rays, so that their lattices put their height bands
        // apart (both stay even, keeping flat ground's horizon on a band edge): the heights are
        // not randomised, and two rounds of one size would share their height quadrature's error.
        const int half = schedule.rays / 2 - (schedule.rays >= 64 ? 4 : 0);
        round(half);
        const int planned = Rounds::planned(schedule, half, rounds.relativeError());
        round(schedule.rays - half);
        while (rounds.rays < planned) round(rounds.rays);
    }
    out.standardError[i] = rounds.relativeError();
    if (base) total += *base;  // the rounds' shares add up to one
    out.sh[i] = total;
    out.raysPerProbe[i] = uint32_t(rounds.rays + glowRays);
    return rounds.rays + glowRays;
}

bool probesSampleGlow(const BakeLighting& L) { return L.sky.hasGlow() && !L.water; }

double probeRaysWithGlow(double latticeRays, bool glow) {
    return glow ? latticeRays + latticeRays / 4.0 + double(kGlowPilotRays) : latticeRays;
}

ProbeBake bakeProbes(const BakeLighting& L, const IrradianceCache* cache, int bounces,
                     const std::vector<glm::vec3>& positions, const std::vector<uint8_t>& valid,
                     const ProbeRays& rays, uint64_t seed, const BakeControl& control) {
    return bakeProbesSeeded(L, cache, bounces, positions, valid, rays, positionSeeds(positions, seed), control);
}

ProbeBake bakeProbesSeeded(const BakeLighting& L, const IrradianceCache* cache, int bounces,
                           const std::vector<glm::vec3>& positions,
                           const std::vector<uint8_t>& valid, const ProbeRays& schedule,
                           const std::vector<uint64_t>& seeds, const BakeControl& control) {
    ProbeBake out(positions.size());
    std::atomic<uint64_t> traced{0};
    parallelIndices(positions.size(), control, [&](size_t i) {
        if (!valid[i]) return;
        Rng rng(splitmix64(seeds[i]));
        int fromBelow = 0;
        // The sky as a control variate (Glasserman 2003, "Monte Carlo Methods in Financial
        // Engineering", 4.1): its projection is exact (Sky::sh), so the rays only estimate how
        // the probe's light differs from the open sky's. A ray that escapes adds nothing, and the
        // sky's bright spots (an HDR's sun glow, the physical sky's circumsolar light) add noise
        // only where the terrain hides them.
        // Where the sky has a glow (Sky::hasGlow) the lattice's rays take only the smooth part
        // as their control variate and the glow the probe sees is estimated by rays of its own,
        // so a glow a few pixels wide does not ride on the few lattice rays that fall on it.
        // Water reflects the sky, so there every ray would need the glow: it keeps the whole sky.
        const Sky* glow = probesSampleGlow(L) ? &L.sky : nullptr;
        int latticeRays = 0;
        traceProbeRounds(
            schedule, rng, out, i, glow ? &L.sky.smoothSh() : &L.sky.sh(),
            [&](const glm::vec3& d, float weight) {
                ++latticeRays;
                RayHit hit;
                const bool terrain = L.tracer->intersect(positions[i], d, INFINITY, hit);
                if (terrain) fromBelow += glm::dot(d, hit.normal) > 0.0f;
                if (!terrain && !L.water) return glm::vec3(0.0f);
                return rayRadiance(L, cache, bounces, positions[i], d, terrain ? &hit : nullptr, weight, rng) -
                       (glow ? L.sky.smoothRadiance(d, weight) : L.sky.radiance(d, weight));
            },
            glow, [&](const glm::vec3& d) { return !L.tracer->occluded(positions[i], d, INFINITY); });
        const int rays = int(out.raysPerProbe[i]);
        out.fromBelowShare[i] = float(fromBelow) / float(latticeRays);
        traced.fetch_add(uint64_t(rays), std::memory_order_relaxed);
    });
    out.rays = traced.load();
    return out;
}

std::string raysDescription(const ProbeRays& r) {
    if (!r.adaptive()) return std::to_string(r.rays) + " rays";
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.2f %% standard error per probe (%d to %d rays)", 100.0 * r.target, r.rays,
                  r.maxRays);
    return buf;
}

RaySpread raySpreadOf(const ProbeBake& bake, const std::vector<uint8_t>& valid) {
    std::vector<uint32_t> rays;
    for (size_t i = 0; i < valid.size() && i < bake.raysPerProbe.size(); ++i)
        if (valid[i]) rays.push_back(bake.raysPerProbe[i]);
    RaySpread s;
    if (rays.empty()) return s;
    std::sort(rays.begin(), rays.end());
    s.min = rays.front();
    s.max = rays.back();
    s.median = rays[(rays.size() - 1) / 2];
    double sum = 0.0;
    for (uint32_t r : rays) sum += r;
    s.mean = sum / double(rays.size());
    return s;
}

int referencePathLength(const glm::vec3& albedo) {
    const float a = std::max({albedo.x, albedo.y, albedo.z});
    if (a <= 0.0f) return 1;
    if (a >= 0.999f) return 64;
    return std::clamp(int(std::ceil(std::log(1e-3f) / std::log(a))), 1, 64);
}

ProbeBake referenceProbes(const BakeLighting& L, int bounces, const std::vector<glm::vec3>& positions,
                          const std::vector<uint8_t>& valid, const ProbeRays& rays, uint64_t seed,
                          const BakeControl& control) {
    return referenceProbesSeeded(L, bounces, positions, valid, rays, positionSeeds(positions, seed), control);
}

ProbeBake referenceProbesSeeded(const BakeLighting& L, int bounces,
                                const std::vector<glm::vec3>& positions,
                                const std::vector<uint8_t>& valid, const ProbeRays& schedule,
                                const std::vector<uint64_t>& seeds, const BakeControl& control) {
    ProbeBake out(positions.size());
    const int depth = bounces == 0 ? 0 : referencePathLength(L.maxAlbedo());
    const glm::vec3 skirt = L.sky.openIrradianceUp() + L.sun.illuminance * std::max(0.0f, L.sun.direction.y);
    std::atomic<uint64_t> traced{0};
    parallelIndices(positions.size(), control, [&](size_t i) {
        if (!valid[i]) return;
        Rng rng(splitmix64(seeds[i] ^ 0xBADC0FFEEull));
        uint64_t count = 0;
        int fromBelow = 0;
        // The light a path from terrain hit `hit` brings back: at each terrain vertex, sun by a
        // shadow ray plus one cosine-weighted continuation; throughput albedo per bounce. A sky
        // with a glow (and no water, as for the bake) gives the glow by a ray of its own at each
        // vertex, as the sun, and the continuation reads the rest of the sky: a sun in an HDR
        // found only by the paths that happen to escape toward it would leave the reference
        // itself noisier than the bake it checks.
        const bool glow = probesSampleGlow(L);
        auto path = [&](RayHit hit) {
            glm::vec3 radiance(0.0f);
            glm::vec3 throughput = L.albedoAt(hit) / kPi;
            for (int b = 0; b < depth; ++b) {
                if (!hit.onTerrain) {
                    radiance += throughput * skirt;
                    break;
                }
                const glm::vec3 n = hit.normal;
                radiance += throughput * sunIrradiance(L, hit.position, n, 1, rng);
                const glm::vec3 dir = randomCosineDirection(n, rng);
                const glm::vec3 o = liftOff(hit.position, n);
                if (glow) {
                    radiance += throughput * glowIrradiance(L, o, n, 1, rng);
                    ++count;
                }
                ++count;
                RayHit next;
                // E = π × mean radiance under cosine sampling: the π cancels albedo's 1/π.
                if (!L.tracer->intersect(o, dir, INFINITY, next)) {
                    radiance += throughput * kPi * (glow ? L.sky.smoothRadiance(dir, 0.0f) : L.sky.radiance(dir, 0.0f));
                    break;
                }
                if (b + 1 == depth) break;
                hit = next;
                throughput *= L.albedoAt(hit);
            }
            return radiance;
        };
        int latticeRays = 0;
        traceProbeRounds(schedule, rng, out, i, nullptr, [&](const glm::vec3& d0, float weight) {
            RayHit hit;
            ++count;
            ++latticeRays;
            glm::vec3 radiance(0.0f);
            const bool hitSomething = L.tracer->intersect(positions[i], d0, INFINITY, hit);
            if (hitSomething) fromBelow += glm::dot(d0, hit.normal) > 0.0f;
            glm::vec3 at;
            if (hitsWater(L, positions[i], d0, hitSomething ? hit.t : INFINITY, at)) {
                // The bake's water model, with the mirrored ray followed as a path of its own.
                if (depth > 0)
                    radiance = waterRadiance(L, at, d0, rng, [&](const glm::vec3& ro, const glm::vec3& rd) {
                        RayHit h;
                        ++count;
                        return L.tracer->intersect(ro, rd, INFINITY, h) ? path(h) : L.sky.radiance(rd, weight);
                    });
            } else if (!hitSomething) {
                radiance = glow ? L.sky.smoothRadiance(d0, weight) : L.sky.radiance(d0, weight);
            } else if (depth > 0) {
                radiance = path(hit);
            }
            return radiance;
        }, glow ? &L.sky : nullptr, [&](const glm::vec3& d) {
            ++count;
            return !L.tracer->occluded(positions[i], d, INFINITY);
        });
        out.fromBelowShare[i] = float(fromBelow) / float(latticeRays);
        traced.fetch_add(count, std::memory_order_relaxed);
    });
    out.rays = traced.load();
    return out;
}

namespace {
const std::vector<glm::vec3>& metricNormals() {
    static const std::vector<glm::vec3> normals = [] {
        std::vector<glm::vec3> n;
        for (uint32_t i = 0; i < 256; ++i) n.push_back(fibonacciSphere(i, 256, 0.0f));
        return n;
    }();
    return normals;
}
}  // namespace

float relativeIrradianceError(const sh::ShRgb& value, const sh::ShRgb& reference, double floor) {
    const auto& normals = metricNormals();
    double num = 0, den = 0;
    for (const auto& n : normals) {
        const double e = glsl::rec709Luminance(sh::evalIrradiance(value, n));
        const double r = glsl::rec709Luminance(sh::evalIrradiance(reference, n));
        num += (e - r) * (e - r);
        den += r * r;
    }
    den = std::max(den, floor * floor * double(normals.size()));
    return den > 0 ? float(std::sqrt(num / den)) : 0.0f;
}

double rmsIrradiance(const sh::ShRgb& sh) {
    const auto& normals = metricNormals();
    double sq = 0;
    for (const auto& n : normals) {
        const double r = glsl::rec709Luminance(sh::evalIrradiance(sh, n));
        sq += r * r;
    }
    return std::sqrt(sq / double(normals.size()));
}

double interpolationErrorFloor(const std::vector<sh::ShRgb>& truths) {
    if (truths.empty()) return 0.0;
    double sum = 0;
    for (const auto& t : truths) sum += rmsIrradiance(t);
    return kInterpolationErrorFloor * sum / double(truths.size());
}

ErrorStats compareToReference(const std::vector<sh::ShRgb>& bake,
                              const std::vector<sh::ShRgb>& reference,
                              const std::vector<uint8_t>& valid) {
    ErrorStats s;
    for (size_t i = 0; i < bake.size() && i < reference.size(); ++i) {
        if (!valid[i]) continue;
        s.perProbe.push_back(relativeIrradianceError(bake[i], reference[i]));
    }
    const Spread d = spreadOf(s.perProbe);
    s.mean = d.mean;
    s.p95 = d.p95;
    s.max = d.max;
    return s;
}

Spread spreadOf(std::vector<float> values) {
    Spread s;
    if (values.empty()) return s;
    std::sort(values.begin(), values.end());
    double sum = 0;
    for (float e : values) sum += e;
    s.mean = sum / double(values.size());
    s.p95 = values[std::min(values.size() - 1, size_t(std::ceil(0.95 * double(values.size()))) - 1)];
    s.max = values.back();
    return s;
}

}  // namespace terralux
