// The water model (renderer/water/Water.h, docs/lighting.md "Water"): Gerstner waves against
// their defining properties and finite differences, the dispersion relation's limits, the
// steepness rule, the distance to shore against brute force, the auto level and the presets.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "water/Water.h"

using namespace terralux;
using namespace terralux::water;

namespace {

constexpr double kPi = std::numbers::pi;

GerstnerWave wave(double directionDeg, double wavelength, std::optional<double> amplitude,
                  std::optional<double> steepness, double phase = 0.0) {
    GerstnerWave w;
    w.directionDeg = directionDeg;
    w.wavelength = wavelength;
    w.amplitude = amplitude;
    w.steepness = steepness;
    w.phase = phase;
    return w;
}

std::vector<WaveTerms> terms(const std::vector<GerstnerWave>& waves) {
    std::vector<WaveTerms> out;
    for (const GerstnerWave& w : waves) out.push_back(waveTerms(w));
    return out;
}

// The displaced surface point of rest position (x, z), the level at 0.
glm::dvec3 surfaceAt(const std::vector<WaveTerms>& w, double x, double z, double t,
                     std::optional<double> depth = std::nullopt, double fade = 1.0) {
    return glm::dvec3(x, 0.0, z) + gerstner(w, {x, z}, t, depth, fade).displacement;
}

// Five waves from several directions, summed steepness 0.90: steep crests, no loops.
std::vector<GerstnerWave> steepSet() {
    return {wave(10.0, 23.0, std::nullopt, 0.25, 0.3), wave(75.0, 11.0, 0.3, std::nullopt, 1.1),
            wave(-40.0, 7.5, std::nullopt, 0.2, 2.0), wave(160.0, 4.0, std::nullopt, 0.15, 4.0),
            wave(230.0, 2.3, std::nullopt, 0.13, 5.5)};
}

}  // namespace

TEST(WaterWaves, TermsFollowTheAzimuthConventionAndResolveTheAmplitude) {
    // Clockwise from north (−Z) toward east (+X), like the sun's azimuth.
    const WaveTerms east = waveTerms(wave(90.0, 10.0, 0.5, std::nullopt));
    EXPECT_NEAR(east.direction.x, 1.0, 1e-15);
    EXPECT_NEAR(east.direction.y, 0.0, 1e-15);
    const WaveTerms north = waveTerms(wave(0.0, 10.0, 0.5, std::nullopt));
    EXPECT_NEAR(north.direction.y, -1.0, 1e-15);
    const WaveTerms south = waveTerms(wave(180.0, 10.0, 0.5, std::nullopt));
    EXPECT_NEAR(south.direction.y, 1.0, 1e-15);
    EXPECT_NEAR(east.k, 2.0 * kPi / 10.0, 1e-15);
    EXPECT_EQ(east.amplitude, 0.5);
    EXPECT_NEAR(east.omegaDeep, std::sqrt(kGravity * 2.0 * kPi / 10.0), 1e-15);
    // Steepness is k·A.
    const WaveTerms steep = waveTerms(wave(0.0, 20.0, std::nullopt, 0.3, 1.25));
    EXPECT_NEAR(steep.amplitude, 0.3 * 20.0 / (2.0 * kPi), 1e-15);
    EXPECT_EQ(steep.phase, 1.25);
}

TEST(WaterWaves, NormalsAreTheFiniteDifferenceNormalsOfTheDisplacedSurface) {
    const std::vector<WaveTerms> w = terms(steepSet());
    ASSERT_NEAR(summedSteepness(steepSet()), 0.9, 0.05);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(-60.0, 60.0), time(0.0, 20.0), fade(0.2, 1.0);
    const double h = 1e-5;
    int checked = 0;
    for (int i = 0; i < 400; ++i) {
        const double x = pos(rng), z = pos(rng), t = time(rng);
        const std::optional<double> depth = i % 2 ? std::optional<double>(3.0 + 0.01 * i) : std::nullopt;
        const double f = i % 3 ? 1.0 : fade(rng);
        const glm::dvec3 dx = (surfaceAt(w, x + h, z, t, depth, f) - surfaceAt(w, x - h, z, t, depth, f)) / (2 * h);
        const glm::dvec3 dz = (surfaceAt(w, x, z + h, t, depth, f) - surfaceAt(w, x, z - h, t, depth, f)) / (2 * h);
        const glm::dvec3 expected = glm::normalize(glm::cross(dz, dx));
        const glm::dvec3 n = gerstner(w, {x, z}, t, depth, f).normal;
        EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
        EXPECT_GT(n.y, 0.0);
        EXPECT_LT(glm::length(n - expected), 1e-7) << "at (" << x << ", " << z << "), t " << t;
        ++checked;
    }
    EXPECT_EQ(checked, 400);
}

TEST(WaterWaves, APointMovesOnACircleAtTheOrbitalSpeed) {
    // One Gerstner wave moves each water particle on a circle of radius A at angular speed ω:
    // |displacement| = A, and its time derivative (finite differences) has length ω·A and is
    // perpendicular to it.
    const GerstnerWave g = wave(30.0, 12.0, 0.9, std::nullopt, 0.4);
    const std::vector<WaveTerms> w = terms({g});
    const double omega = w[0].omegaDeep, dt = 1e-5;
    for (double x : {-7.0, 0.0, 3.3})
        for (double t : {0.0, 1.7, 9.2}) {
            const glm::dvec3 d = gerstner(w, {x, 2.0}, t).displacement;
            EXPECT_NEAR(glm::length(d), 0.9, 1e-12);
            const glm::dvec3 v = (gerstner(w, {x, 2.0}, t + dt).displacement -
                                  gerstner(w, {x, 2.0}, t - dt).displacement) / (2 * dt);
            EXPECT_NEAR(glm::length(v), omega * 0.9, 1e-6);
            EXPECT_NEAR(glm::dot(v, d), 0.0, 1e-6);
            // The circle stands in the vertical plane of the travel direction.
            const glm::dvec3 side(-w[0].direction.y, 0.0, w[0].direction.x);
            EXPECT_NEAR(glm::dot(d, side), 0.0, 1e-12);
        }
}

TEST(WaterWaves, CrestsTravelAlongTheDirectionAtThePhaseSpeed) {
    // A wave toward the east (90°): the surface at (x + c·t, t) is the surface at (x, 0),
    // with c = ω/k the phase speed.
    const std::vector<WaveTerms> w = terms({wave(90.0, 16.0, 0.6, std::nullopt, 0.7)});
    const double c = w[0].omegaDeep / w[0].k;
    EXPECT_NEAR(c, std::sqrt(kGravity * 16.0 / (2.0 * kPi)), 1e-12);
    for (double x : {-5.0, 1.0, 6.5}) {
        const glm::dvec3 at0 = gerstner(w, {x, 4.0}, 0.0).displacement;
        const glm::dvec3 later = gerstner(w, {x + c * 3.0, 4.0}, 3.0).displacement;
        EXPECT_LT(glm::length(later - at0), 1e-12);
        // And not westward.
        const glm::dvec3 west = gerstner(w, {x - c * 3.0, 4.0}, 3.0).displacement;
        EXPECT_GT(glm::length(west - at0), 0.1);
    }
}

TEST(WaterWaves, CrestsAreNarrowerThanTroughs) {
    // A trochoid of k·A = 0.8: the part above the level spans λ/2 − 2A of the displaced x, the
    // part below λ/2 + 2A (the points gather at the crests). Measured on the displaced surface.
    const double lambda = 10.0, a = 0.8 * lambda / (2.0 * kPi);
    const std::vector<WaveTerms> w = terms({wave(90.0, lambda, a, std::nullopt)});
    const int n = 200000;
    double above = 0.0;
    glm::dvec3 prev = surfaceAt(w, 0.0, 0.0, 0.0);
    for (int i = 1; i <= n; ++i) {
        const glm::dvec3 p = surfaceAt(w, lambda * i / n, 0.0, 0.0);
        ASSERT_GT(p.x, prev.x);  // no loop below k·A = 1
        if (0.5 * (p.y + prev.y) > 0.0) above += p.x - prev.x;
        prev = p;
    }
    EXPECT_NEAR(above / lambda, 0.5 - 2.0 * a / lambda, 1e-4);
}

TEST(WaterWaves, FadeScalesTheAmplitudes) {
    const std::vector<WaveTerms> w = terms(steepSet());
    const SurfacePoint full = gerstner(w, {3.0, -2.0}, 1.5);
    const SurfacePoint half = gerstner(w, {3.0, -2.0}, 1.5, std::nullopt, 0.5);
    EXPECT_LT(glm::length(half.displacement - 0.5 * full.displacement), 1e-12);
    const SurfacePoint none = gerstner(w, {3.0, -2.0}, 1.5, std::nullopt, 0.0);
    EXPECT_EQ(none.displacement, glm::dvec3(0.0));
    EXPECT_EQ(none.normal, glm::dvec3(0.0, 1.0, 0.0));
    // No waves: the level plane.
    EXPECT_EQ(gerstner({}, {1.0, 1.0}, 2.0).normal, glm::dvec3(0.0, 1.0, 0.0));
}

TEST(WaterWaves, ShoreFadeIsASmoothstepOverTheFadeDistance) {
    EXPECT_EQ(shoreFade(0.0, 50.0), 0.0);
    EXPECT_EQ(shoreFade(25.0, 50.0), 0.5);
    EXPECT_NEAR(shoreFade(10.0, 50.0), 0.2 * 0.2 * (3.0 - 0.4), 1e-15);
    EXPECT_EQ(shoreFade(50.0, 50.0), 1.0);
    EXPECT_EQ(shoreFade(std::numeric_limits<double>::infinity(), 50.0), 1.0);
    EXPECT_EQ(shoreFade(0.0, 0.0), 1.0);  // no fade
}

TEST(WaterDispersion, DeepAndShallowLimits) {
    const double k = 2.0 * kPi / 20.0;
    // Unset depth: deep water.
    EXPECT_EQ(angularFrequency(k, std::nullopt), std::sqrt(kGravity * k));
    // Deep: k·h = 20 leaves tanh within 1e-17 of 1.
    EXPECT_NEAR(angularFrequency(k, 20.0 / k), std::sqrt(kGravity * k), 1e-14);
    // Shallow: ω → k·√(g·h); tanh(x) = x − x³/3 + … puts the relative error at (k·h)²/6.
    for (double kh : {1e-2, 1e-3}) {
        const double h = kh / k;
        const double shallow = k * std::sqrt(kGravity * h);
        const double omega = angularFrequency(k, h);
        EXPECT_NEAR(omega / shallow - 1.0, -kh * kh / 6.0, kh * kh * kh * kh);
    }
    // In between, the relation itself.
    EXPECT_NEAR(angularFrequency(k, 2.0), std::sqrt(kGravity * k * std::tanh(2.0 * k)), 1e-15);
    // Dry ground holds a wave still; it never gives NaN.
    EXPECT_EQ(angularFrequency(k, 0.0), 0.0);
    EXPECT_EQ(angularFrequency(k, -3.0), 0.0);
}

TEST(WaterDispersion, ShallowWavesTravelAtTheShallowWaterSpeed) {
    // With a depth, the waves move at ω(k, h)/k, which is √(g·h) where k·h is small.
    const double h = 0.05;
    const std::vector<WaveTerms> w = terms({wave(0.0, 40.0, 0.01, std::nullopt, 0.2)});
    const double c = angularFrequency(w[0].k, h) / w[0].k;
    EXPECT_NEAR(c / std::sqrt(kGravity * h), 1.0, 1e-4);
    const glm::dvec2 travel = w[0].direction * (c * 2.0);  // northward
    const glm::dvec3 at0 = gerstner(w, {1.0, 1.0}, 0.0, h).displacement;
    EXPECT_LT(glm::length(gerstner(w, glm::dvec2(1.0, 1.0) + travel, 2.0, h).displacement - at0), 1e-12);
    // Deep-water waves of that length are much faster.
    EXPECT_GT(glm::length(gerstner(w, glm::dvec2(1.0, 1.0) + travel, 2.0).displacement - at0), 1e-3);
}

TEST(WaterSteepness, TheSumOfKTimesAIsAtMostOne) {
    // Amplitude and steepness add the same way: k·A.
    const std::vector<GerstnerWave> two = {wave(0.0, 2.0 * kPi, 0.3, std::nullopt),
                                           wave(45.0, 3.0, std::nullopt, 0.5)};
    EXPECT_NEAR(summedSteepness(two), 0.8, 1e-15);
    EXPECT_EQ(checkWaves(two), "");
    EXPECT_EQ(checkWaves({}), "");
    // Exactly 1 is allowed; just above is not, with the rule and the value.
    std::vector<GerstnerWave> one = {wave(0.0, 10.0, std::nullopt, 0.6), wave(0.0, 5.0, std::nullopt, 0.4)};
    EXPECT_EQ(checkWaves(one), "");
    one[1].steepness = 0.45;
    EXPECT_EQ(checkWaves(one), "summed steepness Σ k·A must be <= 1, or the crests loop (is 1.05)");
    std::vector<GerstnerWave> big = {wave(0.0, 2.0 * kPi, 1.2, std::nullopt)};
    EXPECT_EQ(checkWaves(big), "summed steepness Σ k·A must be <= 1, or the crests loop (is 1.2)");
}

TEST(WaterSteepness, EachWaveAndTheCountAreChecked) {
    const GerstnerWave ok = wave(0.0, 10.0, std::nullopt, 0.05);
    EXPECT_EQ(checkWaves(std::vector<GerstnerWave>(8, ok)), "");
    EXPECT_EQ(checkWaves(std::vector<GerstnerWave>(9, ok)), "must hold at most 8 waves (has 9)");
    GerstnerWave both = ok;
    both.amplitude = 0.1;
    EXPECT_EQ(checkWaves({ok, both}), "wave 1: must set exactly one of amplitude and steepness");
    GerstnerWave neither = ok;
    neither.steepness.reset();
    EXPECT_EQ(checkWaves({neither}), "wave 0: must set exactly one of amplitude and steepness");
    GerstnerWave flat = ok;
    flat.wavelength = 0.0;
    EXPECT_EQ(checkWaves({flat}), "wave 0: wavelength must be > 0 (is 0)");
    GerstnerWave negative = wave(0.0, 10.0, -0.5, std::nullopt);
    EXPECT_EQ(checkWaves({negative}), "wave 0: amplitude must be >= 0 (is -0.5)");
    GerstnerWave tooSteep = wave(0.0, 10.0, std::nullopt, 1.5);
    EXPECT_EQ(checkWaves({tooSteep}), "wave 0: steepness must be in [0, 1] (is 1.5)");
    GerstnerWave nan = ok;
    nan.phase = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(checkWaves({nan}), "wave 0: phase must be finite");
    GerstnerWave nanSteep = wave(0.0, 10.0, std::nullopt, std::numeric_limits<double>::quiet_NaN());
    EXPECT_NE(checkWaves({nanSteep}), "");
}

namespace {

// Brute force: the distance from each vertex to the nearest land vertex (height >= level).
std::vector<double> bruteForceShore(const Heightfield& hf, double level) {
    std::vector<double> out(size_t(hf.width()) * hf.depth(), std::numeric_limits<double>::infinity());
    for (int r = 0; r < hf.depth(); ++r)
        for (int c = 0; c < hf.width(); ++c)
            for (int rr = 0; rr < hf.depth(); ++rr)
                for (int cc = 0; cc < hf.width(); ++cc) {
                    if (!(double(hf.at(cc, rr)) >= level)) continue;
                    const double dx = (c - cc) * hf.cellSizeX(), dz = (r - rr) * hf.cellSizeZ();
                    double& d = out[size_t(r) * hf.width() + c];
                    d = std::min(d, std::sqrt(dx * dx + dz * dz));
                }
    return out;
}

Heightfield randomIslands(int w, int d, double cx, double cz, double landShare, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> h(size_t(w) * d);
    for (float& v : h) v = u(rng) < landShare ? float(1.0 + u(rng)) : float(-1.0 - u(rng));
    return Heightfield(w, d, cx, cz, std::move(h));
}

}  // namespace

TEST(WaterShore, DistanceIsTheBruteForceEuclideanDistanceToLand) {
    int cases = 0;
    for (const auto& [cx, cz] : {std::pair{1.0, 1.0}, std::pair{1.5, 4.0}, std::pair{30.0, 7.25}}) {
        for (double share : {0.02, 0.1, 0.5}) {
            const Heightfield hf = randomIslands(23, 17, cx, cz, share, unsigned(cases + 1));
            const std::vector<float> got = shoreDistance(hf, 0.0);
            const std::vector<double> want = bruteForceShore(hf, 0.0);
            ASSERT_EQ(got.size(), want.size());
            for (size_t i = 0; i < got.size(); ++i) {
                if (std::isinf(want[i])) {
                    EXPECT_TRUE(std::isinf(got[i])) << i;
                    continue;
                }
                EXPECT_NEAR(got[i], want[i], 1e-6 * std::max(1.0, want[i])) << "vertex " << i << ", cells " << cx << " x " << cz;
                if (hf.heights()[i] >= 0.0f) {
                    EXPECT_EQ(got[i], 0.0f);
                }
            }
            ++cases;
        }
    }
    EXPECT_EQ(cases, 9);
}

TEST(WaterShore, OneIslandAndTheEdgeCases) {
    // One land vertex at column 2, row 5 of a 9 x 7 grid of 2 x 3 m cells.
    std::vector<float> h(9 * 7, -10.0f);
    h[5 * 9 + 2] = 0.0f;  // exactly at the level counts as land
    const Heightfield island(9, 7, 2.0, 3.0, h);
    const std::vector<float> d = shoreDistance(island, 0.0);
    EXPECT_EQ(d[5 * 9 + 2], 0.0f);
    EXPECT_FLOAT_EQ(d[0], float(std::hypot(2 * 2.0, 5 * 3.0)));
    EXPECT_FLOAT_EQ(d[6 * 9 + 8], float(std::hypot(6 * 2.0, 1 * 3.0)));
    // No land anywhere: every vertex is infinitely far from shore; all land: 0 everywhere.
    for (float v : shoreDistance(island, 1.0)) EXPECT_TRUE(std::isinf(v));
    for (float v : shoreDistance(island, -20.0)) EXPECT_EQ(v, 0.0f);
    // One row and one column.
    const Heightfield row(5, 1, 2.0, 2.0, {1.0f, -1.0f, -1.0f, -1.0f, -1.0f});
    EXPECT_EQ(shoreDistance(row, 0.0), (std::vector<float>{0.0f, 2.0f, 4.0f, 6.0f, 8.0f}));
    const Heightfield column(1, 4, 2.0, 5.0, {-1.0f, -1.0f, -1.0f, 1.0f});
    EXPECT_EQ(shoreDistance(column, 0.0), (std::vector<float>{15.0f, 10.0f, 5.0f, 0.0f}));
}

// The auto level is kept under the grid's serial: asked again it is the same, and a grid of the
// same size built where the last one lay in memory gets its own level, not the one kept.
TEST(WaterLevel, TheAutoLevelKeptIsTheGridsOwn) {
    const int w = 40, d = 30;
    auto floodedTo = [&](float level) {
        std::vector<float> h(size_t(w) * d);
        for (int z = 0; z < d; ++z)
            for (int x = 0; x < w; ++x)
                h[size_t(z) * w + size_t(x)] = std::max(float(0.03 * (x - 20) * (x - 20) + 0.5 * z + 400.0), level);
        return h;
    };
    for (float level : {408.0f, 411.0f, 408.0f}) {
        const auto hf = std::make_unique<Heightfield>(w, d, 30.0, 30.0, floodedTo(level));
        ASSERT_EQ(autoLevel(*hf).level, double(level));
        EXPECT_EQ(autoLevel(*hf).level, double(level));
        EXPECT_EQ(autoLevel(Heightfield(*hf)).level, double(level));  // a copy: the same grid
    }
}

// "auto" is the water the DEM shows: a sea or lake is stored as one height over the water body,
// so the level is the largest flat area that is a local minimum; a dry DEM gets no water at all
// (the lowest decile of a dry Pyrenean tile put a lake over 10 % of it).
TEST(WaterLevel, AutoFindsTheWaterTheDemShowsOrNone) {
    // A valley sloping down to the south-east: no flat area, no water.
    const int w = 60, d = 50;
    std::vector<float> valley(size_t(w) * d);
    for (int z = 0; z < d; ++z)
        for (int x = 0; x < w; ++x) valley[size_t(z) * w + size_t(x)] = float(0.02 * (x - 30) * (x - 30) + 0.7 * z + 400.0);
    const Heightfield dry(w, d, 30.0, 30.0, valley);
    const AutoLevel none = autoLevel(dry);
    EXPECT_FALSE(none.level.has_value());
    EXPECT_EQ(none.summary, "the DEM shows no water surface (no flat area of at least 64 cells that is a local minimum)");
    WaterSettings s;
    EXPECT_FALSE(waterLevel(s, dry).has_value());
    s.level = -3.5;
    EXPECT_EQ(waterLevel(s, dry), -3.5);

    // A reservoir: the valley's floor flooded to 412 m, stored flat (to the centimetre).
    std::vector<float> lake = valley;
    for (float& v : lake) v = std::max(v, 412.0f);
    const Heightfield reservoir(w, d, 30.0, 30.0, lake);
    AutoLevel found = autoLevel(reservoir);
    ASSERT_TRUE(found.level.has_value());
    EXPECT_EQ(*found.level, 412.0);
    size_t flooded = 0;
    for (float v : lake) flooded += v == 412.0f;
    EXPECT_EQ(found.cells, flooded);
    EXPECT_NE(found.summary.find("a flat water surface at 412 m over "), std::string::npos) << found.summary;
    EXPECT_EQ(waterLevel(WaterSettings{}, reservoir), 412.0);

    // A sea along the south edge at 0 m (SRTM's sea), land rising from it: level 0.
    std::vector<float> coast(size_t(w) * d);
    for (int z = 0; z < d; ++z)
        for (int x = 0; x < w; ++x) coast[size_t(z) * w + size_t(x)] = z >= 40 ? 0.0f : float(3.0 * (40 - z) + 0.1 * x);
    EXPECT_EQ(autoLevel(Heightfield(w, d, 90.0, 90.0, coast)).level, 0.0);

    // A mountain tarn above a dry valley: a flat corner at 421 m behind a 430 m rim. A plane at its
    // level would flood the valley below it, so it is not the water level.
    std::vector<float> tarn = valley;
    for (int z = 0; z <= 10; ++z)
        for (int x = 0; x <= 10; ++x) tarn[size_t(z) * w + size_t(x)] = x == 10 || z == 10 ? 430.0f : 421.0f;
    const AutoLevel high = autoLevel(Heightfield(w, d, 30.0, 30.0, tarn));
    EXPECT_FALSE(high.level.has_value()) << high.summary;
    EXPECT_NE(high.summary.find("without flooding dry land below it; 1 would"), std::string::npos) << high.summary;
}

TEST(WaterPresets, EveryPresetIsAValidWaveSet) {
    const std::vector<std::string> names = wavePresetNames();
    EXPECT_EQ(names, (std::vector<std::string>{"calm lake", "choppy lake", "open sea"}));
    double previousLargest = 0.0;
    for (const std::string& name : names) {
        const std::vector<GerstnerWave> waves = wavePreset(name);
        ASSERT_FALSE(waves.empty()) << name;
        EXPECT_LE(waves.size(), size_t(WaterSettings::kMaxWaves)) << name;
        EXPECT_EQ(checkWaves(waves), "") << name;
        EXPECT_LT(summedSteepness(waves), 1.0) << name;
        // Rougher water each: the largest amplitude grows from preset to preset.
        double largest = 0.0;
        for (const GerstnerWave& w : waves) largest = std::max(largest, waveTerms(w).amplitude);
        EXPECT_GT(largest, previousLargest) << name;
        previousLargest = largest;
    }
    EXPECT_TRUE(wavePreset("stormy pond").empty());
}
