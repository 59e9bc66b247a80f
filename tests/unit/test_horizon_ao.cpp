#include <algorithm>
#include <cstdio>
#include <string>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "DemImport.h"
#include "MountainDems.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/Sky.h"
#include "bake/SphereSampling.h"
#include "terrain/HorizonAO.h"

using namespace terralux;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A long groove along X whose floor is row `floorRow` and whose walls rise at `alphaDeg` to the
// grid's edges.
Heightfield vGroove(double alphaDeg, int size, double cell) {
    const int floorRow = size / 2;
    std::vector<float> h(size_t(size) * size_t(size));
    for (int r = 0; r < size; ++r)
        for (int c = 0; c < size; ++c)
            h[size_t(r) * size + c] = float(std::abs(r - floorRow) * cell * std::tan(alphaDeg * kDeg));
    return Heightfield(size, size, cell, cell, std::move(h));
}

// Smooth hills with valleys and ridges (no symmetry the sweep could get lucky with).
Heightfield hills(int w, int d, double cx, double cz) {
    std::vector<float> h(size_t(w) * size_t(d));
    for (int r = 0; r < d; ++r)
        for (int c = 0; c < w; ++c)
            h[size_t(r) * w + c] = float(120.0 * std::sin(0.11 * c + 0.3) * std::cos(0.07 * r) +
                                         60.0 * std::sin(0.23 * r - 0.05 * c) + 0.8 * c);
    return Heightfield(w, d, cx, cz, std::move(h));
}

size_t centre(const Heightfield& hf) { return size_t(hf.depth() / 2) * hf.width() + hf.width() / 2; }

}  // namespace

// The floor of an infinitely long V-groove sees the sky through a wedge from α to 180° − α; in 2-D
// the cosine-weighted view factor of such an opening is (cos α + cos α)/2 = cos α (the crossed
// strings of Hottel, 1954).
TEST(HorizonAo, VGrooveFloorSeesCosAlpha) {
    for (const double alpha : {15.0, 30.0, 45.0, 60.0}) {
        const Heightfield hf = vGroove(alpha, 513, 10.0);
        const std::vector<float> ao = horizonSkyVisibility(hf, {64, 0.0});
        ASSERT_EQ(ao.size(), size_t(513 * 513));
        const double expected = std::cos(alpha * kDeg);
        EXPECT_NEAR(ao[centre(hf)], expected, 0.002 * expected) << "alpha " << alpha;
        // Off the centre line's column too: every floor vertex away from the ends sees the same.
        EXPECT_NEAR(ao[size_t(256) * 513 + 200], expected, 0.002 * expected) << "alpha " << alpha;
        // A point on a wall of an infinite groove sees (1 + cos 2α)/2 = cos² α (its normal is
        // tilted by α toward the opposite wall, whose far end rises to α); the finite walls here
        // hide less, so that is a lower bound, and the wall is darker than open ground.
        const float wall = ao[size_t(256 + 60) * 513 + 256];
        EXPECT_LT(wall, 0.999f) << "alpha " << alpha;
        EXPECT_GT(wall, expected * expected - 1e-3) << "alpha " << alpha;
    }
}

TEST(HorizonAo, FlatPlaneSeesTheWholeSky) {
    const Heightfield hf(64, 48, 5.0, 7.0, std::vector<float>(64 * 48, 812.5f));
    for (const int k : {8, 32, 64}) {
        const std::vector<float> ao = horizonSkyVisibility(hf, {k, 0.0});
        for (const float v : ao) ASSERT_NEAR(v, 1.0f, 1e-5f) << k << " directions";
        const std::vector<float> bounded = horizonSkyVisibility(hf, {k, 40.0});
        for (const float v : bounded) ASSERT_NEAR(v, 1.0f, 1e-5f) << k << " directions, bounded";
    }
    EXPECT_NEAR(horizonSkyVisibilityAt(hf, {}, 13.7f, -40.2f), 1.0f, 1e-5f);
}

// A tilted plane does not rise above its own tangent plane, so with the plane's normal nothing
// of the hemisphere is hidden: every vertex, border included, sees 1. (With the world up as the
// normal it would see (1 + cos t)/2; the measure here uses the surface normal.)
TEST(HorizonAo, TiltedPlaneSeesItsWholeHemisphere) {
    for (const double tilt : {10.0, 35.0, 60.0}) {
        const double sx = std::tan(tilt * kDeg) * std::cos(0.4), sz = std::tan(tilt * kDeg) * std::sin(0.4);
        const int w = 90, d = 70;
        const double cx = 12.0, cz = 9.0;
        std::vector<float> h(size_t(w) * d);
        for (int r = 0; r < d; ++r)
            for (int c = 0; c < w; ++c) h[size_t(r) * w + c] = float(c * cx * sx + r * cz * sz);
        const Heightfield hf(w, d, cx, cz, std::move(h));
        const std::vector<float> ao = horizonSkyVisibility(hf, {32, 0.0});
        const auto [lo, hi] = std::minmax_element(ao.begin(), ao.end());
        EXPECT_NEAR(*lo, 1.0f, 1e-4f) << "tilt " << tilt;
        EXPECT_NEAR(*hi, 1.0f, 1e-4f) << "tilt " << tilt;
        EXPECT_NEAR(horizonSkyVisibilityAt(hf, {32, 0.0}, 31.0f, -7.5f), 1.0f, 1e-4f) << "tilt " << tilt;
    }
}

// A 200 m wall 500 m east of the centre of a plain: out of reach at 300 m, in reach at 800 m.
TEST(HorizonAo, MaxDistanceBoundsTheSearch) {
    const int n = 161;
    const double cell = 10.0;
    std::vector<float> h(size_t(n) * n, 0.0f);
    for (int r = 0; r < n; ++r)
        for (int c = 80 + 50; c < n; ++c) h[size_t(r) * n + c] = 200.0f;
    const Heightfield hf(n, n, cell, cell, std::move(h));
    const size_t i = size_t(80) * n + 80;  // at x = 0, z = 0

    const float unbounded = horizonSkyVisibility(hf, {32, 0.0})[i];
    const float near = horizonSkyVisibility(hf, {32, 300.0})[i];
    const float far = horizonSkyVisibility(hf, {32, 800.0})[i];
    EXPECT_NEAR(near, 1.0f, 1e-5f);
    EXPECT_LT(far, 0.97f);
    EXPECT_LT(unbounded, far + 1e-6f);
    EXPECT_NEAR(horizonSkyVisibilityAt(hf, {32, 300.0}, 0.0f, 0.0f), 1.0f, 1e-5f);
    EXPECT_LT(horizonSkyVisibilityAt(hf, {32, 800.0}, 0.0f, 0.0f), 0.97f);
    // The wall seen whole from the centre: in the slice facing it (azimuth 90°) the horizon is
    // atan(200/500); the other slices see less of it, none more.
    EXPECT_NEAR(far, unbounded, 0.01f);
}

TEST(HorizonAo, HugeMaxDistanceEqualsUnbounded) {
    const Heightfield hf = hills(97, 131, 20.0, 25.0);
    const std::vector<float> unbounded = horizonSkyVisibility(hf, {24, 0.0});
    const std::vector<float> huge = horizonSkyVisibility(hf, {24, 1.0e7});
    const std::vector<float> shortReach = horizonSkyVisibility(hf, {24, 60.0});
    ASSERT_EQ(unbounded.size(), huge.size());
    double maxDiff = 0.0, meanShort = 0.0, meanUnbounded = 0.0;
    for (size_t i = 0; i < huge.size(); ++i) {
        maxDiff = std::max(maxDiff, double(std::fabs(huge[i] - unbounded[i])));
        meanShort += shortReach[i];
        meanUnbounded += unbounded[i];
    }
    EXPECT_LT(maxDiff, 1e-5);
    // And the bound is not a no-op: three cells of reach miss most of the hills' occlusion.
    EXPECT_GT(meanShort, meanUnbounded + 0.01 * huge.size());
    for (const float x : {-300.0f, 0.0f, 411.0f})
        EXPECT_NEAR(horizonSkyVisibilityAt(hf, {24, 1.0e7}, x, 100.0f),
                    horizonSkyVisibilityAt(hf, {24, 0.0}, x, 100.0f), 1e-6f);
}

// The point version searches from the point itself and the field interpolates between lines;
// at the vertices of smooth terrain the two agree closely.
TEST(HorizonAo, PointAndFieldAgreeOnSmoothTerrain) {
    const Heightfield hf = hills(120, 100, 30.0, 30.0);
    const std::vector<float> ao = horizonSkyVisibility(hf, {32, 0.0});
    double worst = 0.0;
    for (int r = 10; r < 90; r += 7)
        for (int c = 10; c < 110; c += 9) {
            const float at = horizonSkyVisibilityAt(hf, {32, 0.0}, hf.xOf(c), hf.zOf(r));
            worst = std::max(worst, double(std::fabs(at - ao[size_t(r) * 120 + c])));
        }
    EXPECT_LT(worst, 0.03);
}

TEST(HorizonAo, ValleysAreDarkerThanRidgesOnARealDem) {
    const Heightfield hf = importDem(std::string(TERRALUX_TEST_DATA) + "/dem/bigtujunga_utm11_crop.tif").heightfield;
    const std::vector<float> ao = horizonSkyVisibility(hf, {32, 0.0});
    ASSERT_EQ(ao.size(), hf.heights().size());
    // Compare the lowest and highest tenth of the interior (a border vertex sees nothing beyond
    // the footprint, so it is too bright).
    const int mw = hf.width() / 8, md = hf.depth() / 8;
    std::vector<std::pair<float, float>> interior;  // (height, ao)
    for (int r = md; r < hf.depth() - md; ++r)
        for (int c = mw; c < hf.width() - mw; ++c) interior.push_back({hf.at(c, r), ao[size_t(r) * hf.width() + c]});
    std::sort(interior.begin(), interior.end());
    const size_t tenth = interior.size() / 10;
    double low = 0.0, high = 0.0;
    for (size_t i = 0; i < tenth; ++i) {
        low += interior[i].second;
        high += interior[interior.size() - 1 - i].second;
    }
    low /= double(tenth);
    high /= double(tenth);
    EXPECT_LT(low, high - 0.03) << "valley " << low << ", ridge " << high;
    for (const float v : ao) ASSERT_TRUE(v >= 0.0f && v <= 1.0f);
}

TEST(HorizonAo, ProgressCanCancel) {
    const Heightfield hf = hills(60, 40, 10.0, 10.0);
    std::vector<double> seen;
    const std::vector<float> done = horizonSkyVisibility(hf, {16, 0.0}, [&](double f) {
        seen.push_back(f);
        return true;
    });
    EXPECT_EQ(done.size(), hf.heights().size());
    ASSERT_FALSE(seen.empty());
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_DOUBLE_EQ(seen.back(), 1.0);

    int calls = 0;
    EXPECT_TRUE(horizonSkyVisibility(hf, {16, 0.0}, [](double) { return false; }).empty());
    EXPECT_TRUE(horizonSkyVisibility(hf, {16, 500.0}, [&](double) { return ++calls < 5; }).empty());
    EXPECT_EQ(calls, 5);
}

TEST(HorizonAo, DegenerateGridsGiveNoNan) {
    const Heightfield one(1, 1, 30.0, 30.0, {5.0f});
    EXPECT_EQ(horizonSkyVisibility(one, {}), std::vector<float>{1.0f});
    EXPECT_NEAR(horizonSkyVisibilityAt(one, {}, 0.0f, 0.0f), 1.0f, 1e-6f);
    // A single row and a single column with a bump: finite, in range, and the valley darker.
    const std::vector<float> profile = {0, 50, 100, 50, 0, 0, 0, 50, 100};
    for (const bool column : {false, true}) {
        const Heightfield line(column ? 1 : 9, column ? 9 : 1, 10.0, 10.0, profile);
        for (const double reach : {0.0, 25.0}) {
            const std::vector<float> ao = horizonSkyVisibility(line, {8, reach});
            ASSERT_EQ(ao.size(), 9u);
            for (const float v : ao) ASSERT_TRUE(v >= 0.0f && v <= 1.0f) << v;
            EXPECT_LT(ao[5], 1.0f);
        }
    }
    const Heightfield flatLine(7, 1, 10.0, 10.0, std::vector<float>(7, 3.0f));
    for (const float v : horizonSkyVisibility(flatLine, {})) EXPECT_NEAR(v, 1.0f, 1e-6f);
}

TEST(HorizonAo, RejectsBadSettings) {
    const Heightfield hf(4, 4, 1.0, 1.0, std::vector<float>(16, 0.0f));
    EXPECT_THROW(horizonSkyVisibility(hf, {7, 0.0}), std::invalid_argument);
    EXPECT_THROW(horizonSkyVisibility(hf, {65, 0.0}), std::invalid_argument);
    EXPECT_THROW(horizonSkyVisibility(hf, {32, -1.0}), std::invalid_argument);
    EXPECT_THROW(horizonSkyVisibility(hf, {32, NAN}), std::invalid_argument);
    EXPECT_THROW(horizonSkyVisibilityAt(hf, {}, 100.0f, 0.0f), std::invalid_argument);
}

// The disc's share above a horizon, against counting a fine grid over the disc.
TEST(SunHorizon, DiscShareAboveTheHorizonIsTheCircularSegment) {
    const float e = float(10.0 * kDeg), r = float(0.27 * kDeg);
    for (const double y : {-1.2, -1.0, -0.6, -0.1, 0.0, 0.3, 0.9, 1.0, 1.5}) {
        const int n = 2000;
        int above = 0, inside = 0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double px = (i + 0.5) / n * 2.0 - 1.0, py = (j + 0.5) / n * 2.0 - 1.0;
                if (px * px + py * py > 1.0) continue;
                ++inside;
                above += py > y;
            }
        EXPECT_NEAR(sunDiscAboveHorizon(e + float(y) * r, e, r), double(above) / inside, 1e-3) << "y " << y;
    }
    EXPECT_EQ(sunDiscAboveHorizon(0.1f, 0.2f, 0.0f), 1.0f);
    EXPECT_EQ(sunDiscAboveHorizon(0.3f, 0.2f, 0.0f), 0.0f);
}

// Every vertex of the committed mountain crops (and of the whole N42E001 tile where the shared
// data is), against the bake's own traced sun visibility at the vertex: 256 shadow rays over the
// disc against the exact triangles and the skirt. Low, middle and high suns, off the grid's axes.
TEST(SunHorizon, MatchesTheTracedSunAtEveryVertexOfAMountain) {
    for (const test::MountainDem& dem : test::mountainDems()) {
        const std::string name = dem.file.filename().string();
        const Heightfield hf = importDem(dem.file.string()).heightfield;
        const HeightfieldTracer tracer(hf);
        const size_t stride = dem.shared ? 97 : 1;  // a sample of the 1.4 M vertices of the whole tile
        for (const double elevation : {3.0, 5.0, 12.0, 35.0})
            for (const double azimuth : {135.0, 17.0, 270.0}) {
                SunLight sun;
                sun.direction = sunDirection(azimuth, elevation);
                sun.angularRadius = float(0.27 * kDeg);
                const std::vector<float> swept = sunHorizonVisibility(hf, sun.direction, sun.angularRadius, true);
                double sum = 0.0, worst = 0.0;
                size_t n = 0, apart = 0, shaded = 0;
                for (size_t i = 0; i < swept.size(); i += stride) {
                    const int c = int(i % size_t(hf.width())), r = int(i / size_t(hf.width()));
                    const glm::vec3 nrm = hf.vertexNormal(c, r);
                    if (glm::dot(nrm, sun.direction) <= 0.05f) continue;  // the terminator: not the horizon's
                    Rng rng(0x5eed0000ull + i);
                    const float traced = sunVisibility(tracer, sun, hf.vertex(c, r), nrm, 256, rng);
                    const double d = std::abs(double(swept[i]) - traced);
                    sum += d;
                    worst = std::max(worst, d);
                    apart += d > 0.5;
                    shaded += traced < 0.5f;
                    ++n;
                }
                std::printf("%s sun %.0f° az %.0f°: %zu vertices (%zu in shadow), mean |Δ| %.4f, apart %.3f %%, worst %.2f\n",
                            name.c_str(), elevation, azimuth, n, shaded, sum / double(n), 100.0 * double(apart) / double(n), worst);
                // Off the grid's axes and diagonals a vertex between two sweep lines takes their
                // horizons interpolated: up to 0.73 % of the vertices 0.5 apart there (measured;
                // 1.37 % with one sweep), 0.04 % or none on the axes and diagonals.
                EXPECT_LE(sum / double(n), 0.012) << name << " sun " << elevation << " az " << azimuth;
                EXPECT_LE(double(apart) / double(n), 0.01) << name << " sun " << elevation << " az " << azimuth;
                if (elevation <= 5.0) {
                    EXPECT_GT(double(shaded) / double(n), 0.05) << name << ": a low sun casts shadows";
                }
            }
    }
}
