#pragma once
// The CPU bake of diffuse SH probes over a heightfield (docs/lighting.md "Light transport for bakes").
//
// Probe radiance L(p, ω) is the sky where a ray escapes and, where it hits the terrain, the
// light that point reflects: albedo/π × its irradiance from the sun (shadowed), the sky
// (occluded) and, with more bounces, the terrain. The direct sun is not in the probes: engines
// draw it as a light with shadows. Bounces go through a terrain irradiance cache (a regular grid
// of surface points whose hemisphere rays are traced once and re-gathered per bounce), not
// recursive rays per probe.

#include <array>
#include <cmath>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "bake/HeightfieldTracer.h"
#include "bake/SphericalHarmonics.h"
#include "bake/Sky.h"
#include "scene/SceneDescription.h"
#include "terrain/SurfaceAlbedo.h"

namespace terralux {

// The rays one probe traces (docs/lighting.md "Rays per probe"): `rays`, or, with a target, at
// least `rays` and as many more, doubling up to `maxRays`, as its first half says the probe needs
// for a standard error of `target`. Open ground stops at `rays`; probes whose light varies more
// (valleys, slopes below bright snow) trace on.
struct ProbeRays {
    int rays = 256;        // all of them when fixed; the least a probe traces with a target
    float target = 0.0f;   // relative standard error a probe's rays are chosen for; 0: fixed
    int maxRays = 0;       // no probe's lattice traces more (a sky's glow adds rays of its own, Sky::hasGlow)

    ProbeRays() = default;
    ProbeRays(int fixed) : rays(fixed) {}  // NOLINT(google-explicit-constructor): a count is a fixed schedule
    ProbeRays(int least, float target, int maxRays) : rays(least), target(target), maxRays(maxRays) {}
    bool adaptive() const { return target > 0.0f && rays >= 4 && maxRays >= rays; }
    int most() const { return adaptive() ? maxRays : rays; }
    // What a bake plans for before it knows, which sizes the irradiance cache: the count, or with
    // a target twice the least (what a probe that traces on gets at least).
    int planned() const { return adaptive() ? std::min(2 * rays, maxRays) : rays; }
};

struct BakeQuality {
    int rays = 256;            // per probe, whole sphere: the least with a target
    int bounces = 2;           // 0 = sky visibility only
    int cacheResolution = 128; // irradiance-cache points along the longer footprint side
    int cacheRays = 64;        // hemisphere rays per cache point
    int sunSamples = 4;        // shadow rays per cache point across the sun's disk
    float targetError = 0.0f;  // each probe's standard error to reach (0: `rays` exactly)
    int maxRays = 0;           // the most rays a probe traces for targetError

    ProbeRays probeRays() const { return {rays, targetError, maxRays}; }
};
// "256 rays", or "0.40 % standard error per probe (256 to 4096 rays)".
std::string raysDescription(const ProbeRays& rays);

// A volume's rays: its ray_count as a fixed count, else the bake's schedule `q`.
inline ProbeRays volumeRays(const BakeQuality& q, const ProbeVolumeSettings& v) {
    return v.rayCount ? ProbeRays(*v.rayCount) : q.probeRays();
}
BakeQuality qualityPreset(QualityPreset preset);
// The preset of bake.quality with bake.rays and bake.bounces applied where set.
BakeQuality qualityOf(const BakeSettings& bake);
const char* qualityName(QualityPreset preset);

// The irradiance-cache resolution a bake uses (docs/lighting.md "Irradiance cache"): the
// preset's, lowered until the cache traces no more than twice the bake's `probeRays`.
// The cache only serves the probe rays' terrain hits, so a few probes need no dense cache, and
// a bake's cost then grows with its rays per probe: presets stay ordered by cost at any size.
int cacheResolutionFor(const Heightfield& hf, const BakeQuality& q, uint64_t probeRays);

// Water as the probe rays see it (docs/lighting.md, "Water"): a level plane that hides the
// terrain below it, seen from above. A ray that meets it first brings back the Fresnel-weighted
// (Schlick, F0 = 0.02) reflection of what the mirrored ray meets, plus the water's scatter,
// (1 − F)·scatter·E/π, E the irradiance on the level surface from the open sky and the sun.
struct BakeWater {
    float level = 0.0f;         // engine y of the plane at rest
    glm::vec3 scatter{0.0f};    // deep-water scatter albedo (water.color)
};

struct BakeLighting {
    const HeightfieldTracer* tracer = nullptr;
    Sky sky = Sky::uniform(glm::vec3(0.0f));
    SunLight sun;
    glm::vec3 albedo{0.3f};
    // Albedo that varies over the terrain (a map or the ramp), over the tracer's heightfield;
    // null or empty: `albedo` everywhere. Shared: lightings are copied, the field is not.
    std::shared_ptr<const SurfaceAlbedo> surface;
    // Unset: no water. With the skirt off it ends at the footprint, like the ground.
    std::optional<BakeWater> water;

    bool variesOverTerrain() const { return surface && !surface->empty(); }
    // The albedo a ray hit reflects with.
    glm::vec3 albedoAt(const RayHit& hit) const {
        return variesOverTerrain() ? surface->at(tracer->heightfield(), hit.position.x, hit.position.z)
                                   : albedo;
    }
    // Per channel, the largest albedo anywhere on the terrain.
    glm::vec3 maxAlbedo() const { return variesOverTerrain() ? surface->maximum() : albedo; }
};

// Progress in [0, 1] of the current phase, and a cancel flag polled between work chunks.
struct BakeControl {
    std::function<void(double)> progress;
    const std::atomic<bool>* cancel = nullptr;
    bool cancelled() const { return cancel && cancel->load(std::memory_order_relaxed); }
};

class BakeCancelled : public std::runtime_error {
public:
    BakeCancelled() : std::runtime_error("bake cancelled") {}
};

// Terrain irradiance after `bounces` gathers (0 = direct sun + occluded sky only).
class IrradianceCache {
public:
    IrradianceCache(const BakeLighting& lighting, int resolution, int rays, int sunSamples,
                    int bounces, const BakeControl& control);
    // The caches after 0, 1, ..., `gathers` gathers, from one set of traced rays: what a search
    // over bounces compares (only the gathers differ, so their differences carry no ray noise).
    static std::vector<IrradianceCache> byGathers(const BakeLighting& lighting, int resolution, int rays,
                                                  int sunSamples, int gathers, const BakeControl& control);
    // Irradiance arriving at a hit point: bilinear over the cache on the terrain; on the skirt,
    // the open sky and the unshadowed sun (docs/lighting.md).
    glm::vec3 at(const RayHit& hit) const;
    // The same without the direct sun at the hit: callers that trace the sun themselves add it
    // exactly (sun shadows are the sharpest part of terrain irradiance, too sharp for the cache).
    glm::vec3 indirectAt(const RayHit& hit) const;
    // Whether a probe ray's terrain hit gathers its indirect light with a ray of its own (a cache
    // with at least one gather, i.e. two bounces or more) rather than read it here.
    bool gathersAtHits() const { return !earlier_.empty(); }
    // indirectAt one gather earlier, with gathersAtHits: what that ray reads where it meets the
    // terrain again.
    glm::vec3 earlierIndirectAt(const RayHit& hit) const;
    int pointsX() const { return nx_; }
    int pointsZ() const { return nz_; }
    // Hemisphere rays traced (shadow rays toward the sun not counted, as for probes).
    uint64_t rays() const { return uint64_t(nx_) * uint64_t(nz_) * uint64_t(rays_); }
    // The (x, z) point counts a cache of `resolution` gets over `hf`, without building it.
    static std::array<int, 2> gridPoints(const Heightfield& hf, int resolution);

private:
    // `levels`, when given, receives the irradiance after each gather count, 0 to `bounces`.
    IrradianceCache(const BakeLighting& lighting, int resolution, int rays, int sunSamples, int bounces,
                    const BakeControl& control, std::vector<std::vector<glm::vec3>>* levels);
    glm::vec3 interpolate(const std::vector<glm::vec3>& e, float x, float z) const;
    const BakeLighting* lighting_;
    int nx_ = 0, nz_ = 0, rays_ = 0;
    float x0_ = 0, z0_ = 0, dx_ = 1, dz_ = 1;
    glm::vec3 skirt_{0.0f};
    std::vector<glm::vec3> irradiance_;
    std::vector<glm::vec3> earlier_;  // the irradiance before the last gather; empty with none
    std::vector<glm::vec3> sunDirect_;  // the direct light of the sun and of the sky's glow (Sky::hasGlow)
    glm::vec3 skirtSun_{0.0f};
};

struct ProbeBake {
    std::vector<sh::ShRgb> sh;          // radiance projections per probe (zero when invalid)
    std::vector<float> standardError;   // relative Monte Carlo standard error per probe (RMS over normals)
    // docs/lighting.md probe validity: the share of a probe's rays whose first hit is the terrain seen
    // from below (dot(dir, normal) > 0; the surface normals face up). A heightfield can only be
    // reached from below by a probe inside it, so any valid probe has 0.
    std::vector<float> fromBelowShare;
    std::vector<uint32_t> raysPerProbe; // rays each probe traced (0 when invalid)
    uint64_t rays = 0;                  // rays traced for the probes themselves

    ProbeBake() = default;
    // n probes, all zero.
    explicit ProbeBake(size_t n) : sh(n), standardError(n, 0.0f), fromBelowShare(n, 0.0f), raysPerProbe(n, 0) {}
};

// Rays per valid probe over a bake: what a target's rounds spent, probe by probe.
struct RaySpread {
    uint32_t min = 0, median = 0, max = 0;
    double mean = 0.0;
};
RaySpread raySpreadOf(const ProbeBake& bake, const std::vector<uint8_t>& valid);

// The seed of each probe of bakeProbes and referenceProbes: `seed` mixed with its position
// rounded to the centimetre.
std::vector<uint64_t> positionSeeds(const std::vector<glm::vec3>& positions, uint64_t seed);

// Bakes the probes at `positions` (skipping those with valid[i] == 0). Deterministic: each probe's
// directions and rounds depend only on its position and `seed` (positionSeeds), so a probe at the
// same place in two bakes (a tile's border probe and the untiled bake's) traces the same rays.
// Whether a probe samples the sky's glow by rays of its own (docs/lighting.md, "The sky's glow"):
// an image sky with a glow, and no water (water reflects the sky into every ray).
bool probesSampleGlow(const BakeLighting& lighting);
// About the rays a probe traces for `latticeRays` of its lattice: with the glow sampled, a
// quarter more and the sixteen that choose how to count them.
double probeRaysWithGlow(double latticeRays, bool glow);

ProbeBake bakeProbes(const BakeLighting& lighting, const IrradianceCache* cache, int bounces,
                     const std::vector<glm::vec3>& positions, const std::vector<uint8_t>& valid,
                     const ProbeRays& rays, uint64_t seed, const BakeControl& control);
// The same with one seed per probe (seeds[i]), for probes whose identity is not their index (an
// octree leaf keeps its seed whatever order the leaves are baked in).
ProbeBake bakeProbesSeeded(const BakeLighting& lighting, const IrradianceCache* cache, int bounces,
                           const std::vector<glm::vec3>& positions,
                           const std::vector<uint8_t>& valid, const ProbeRays& rays,
                           const std::vector<uint64_t>& seeds, const BakeControl& control);

// Brute-force reference: path tracing from each probe, sun by shadow rays at every vertex, bounces
// until the albedo-weighted energy a path can still add is below 0.1 % (0 bounces stays sky
// visibility only, the same model as such a bake).
ProbeBake referenceProbes(const BakeLighting& lighting, int bounces,
                          const std::vector<glm::vec3>& positions,
                          const std::vector<uint8_t>& valid, const ProbeRays& rays, uint64_t seed,
                          const BakeControl& control);
ProbeBake referenceProbesSeeded(const BakeLighting& lighting, int bounces,
                                const std::vector<glm::vec3>& positions,
                                const std::vector<uint8_t>& valid, const ProbeRays& rays,
                                const std::vector<uint64_t>& seeds, const BakeControl& control);
int referencePathLength(const glm::vec3& albedo);

// Mean, 95th percentile (nearest rank) and max of a set of errors; zeros when it is empty.
struct Spread {
    double mean = 0, p95 = 0, max = 0;
};
Spread spreadOf(std::vector<float> values);

// docs/lighting.md probe error: relative RMS of irradiance (luminance) over 256 fixed normals against
// the reference, per valid probe; with mean, 95th percentile and max over probes.
struct ErrorStats {
    std::vector<float> perProbe;
    double mean = 0, p95 = 0, max = 0;
};
ErrorStats compareToReference(const std::vector<sh::ShRgb>& bake,
                              const std::vector<sh::ShRgb>& reference,
                              const std::vector<uint8_t>& valid);

class Rng;
// Schlick's approximation of the Fresnel reflectance of water (F0 = 0.02) for light arriving at
// cos θ = `cosine` from the normal: F0 + (1 − F0)·(1 − cos θ)^5.
float waterFresnel(float cosine);
// The radiance one probe ray brings back (docs/lighting.md, "The bake", "Water"): the sky where
// it escapes (read for `skyAngle` steradians, the solid angle the ray stands for); where it meets
// the terrain, albedo/π × (the cache's indirect irradiance + the sun through one shadow ray),
// black without bounces or a cache; where it meets the water first, the water's reflection and
// scatter (black without bounces: 0 bounces is sky visibility only). Shadow rays draw from `rng`.
// `ground`: the radiance a ray heading down brings back where it escapes (null: the sky's).
glm::vec3 probeRayRadiance(const BakeLighting& lighting, const IrradianceCache* cache, int bounces,
                           const glm::vec3& origin, const glm::vec3& dir, float skyAngle, Rng& rng,
                           const glm::vec3* ground = nullptr);
// Share of the sun's disc visible from surface point p with normal n: `samples` shadow rays,
// stratified over the disc, against the traced surface (0 where the sun is behind the surface).
// The bake's sun term is this × cos θ × E_sun; the sun-visibility debug view draws it.
float sunVisibility(const HeightfieldTracer& tracer, const SunLight& sun, const glm::vec3& p,
                    const glm::vec3& n, int samples, Rng& rng);
// Cosine-weighted sky visibility at surface point p (normal n): the share of `rays` stratified
// cosine-weighted rays that escape the traced surface. What horizon AO approximates (the AO
// benchmark and the study measure it against this).
float tracedSkyVisibility(const HeightfieldTracer& tracer, const glm::vec3& p, const glm::vec3& n,
                          uint32_t rays, uint64_t seed);
// The sun's light reflected once by the terrain onto surface point p (normal n), the sky black:
// the cosine-weighted estimator of ∫ (ρE/π)·cos dω over `rays` rays, at each terrain hit
// albedo × E_sun·cos θ·V with V from 4 shadow rays over the sun's disc. What a light propagation
// volume carries, so the LPV's exact counterpart.
glm::vec3 sunFirstBounce(const BakeLighting& lighting, const glm::vec3& p, const glm::vec3& n, uint32_t rays,
                         uint64_t seed);
// The per-probe term of that metric: relative RMS of irradiance luminance over the 256 fixed
// normals of `value` against `reference` (0 when the reference is black). With `floor` > 0 the
// difference is relative to at least that RMS irradiance: the interpolation error's floor.
float relativeIrradianceError(const sh::ShRgb& value, const sh::ShRgb& reference, double floor = 0.0);
// RMS irradiance luminance of `sh` over the same 256 normals: the metric's denominator.
double rmsIrradiance(const sh::ShRgb& sh);
// Where the true light is nearly black a relative error explodes (a mean of 73 000 % with a black
// sky and the sun on the horizon), so the interpolation error of each point is relative to at least
// kInterpolationErrorFloor of the mean RMS irradiance over the points measured (docs/lighting.md,
// "Metrics").
inline constexpr double kInterpolationErrorFloor = 0.05;
double interpolationErrorFloor(const std::vector<sh::ShRgb>& truths);

}  // namespace terralux
