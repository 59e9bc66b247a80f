// The surface maps the viewport shades with: the mean-normal mip chain whose shortening is the
// normals' variance (Toksvig), the roughness it widens, the AO it carries and the filled share.
#include <cmath>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "terrain/SurfaceMaps.h"

using namespace terralux;

namespace {

Heightfield grid(int n, double cell, float (*h)(int, int)) {
    std::vector<float> v(size_t(n) * size_t(n));
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) v[size_t(r) * size_t(n) + size_t(c)] = h(c, r);
    return Heightfield(n, n, cell, cell, std::move(v));
}

}  // namespace

TEST(Toksvig, VarianceOfAMeanNormal) {
    EXPECT_EQ(toksvigVariance(1.0f), 0.0f);
    // σ² = (1 − |N̄|) / |N̄| (Toksvig 2005, eq. 3).
    EXPECT_FLOAT_EQ(toksvigVariance(0.5f), 1.0f);
    EXPECT_FLOAT_EQ(toksvigVariance(0.8f), 0.25f);
    // A degenerate mean (opposite normals cancelling) gives a large, finite variance.
    EXPECT_TRUE(std::isfinite(toksvigVariance(0.0f)));
    EXPECT_GT(toksvigVariance(0.0f), 1000.0f);
}

TEST(Toksvig, WidenedRoughness) {
    // No variance: the roughness as authored, bit for bit.
    for (float r : {0.25f, 0.6f, 1.0f}) EXPECT_EQ(widenedRoughness(r, 0.0f), r);
    // r' = sqrt(r² + σ²(1 − r²)).
    EXPECT_FLOAT_EQ(widenedRoughness(0.6f, 0.25f), std::sqrt(0.36f + 0.25f * 0.64f));
    EXPECT_FLOAT_EQ(widenedRoughness(0.0f, 0.09f), 0.3f);
    // Never past 1, and growing with the variance.
    EXPECT_LE(widenedRoughness(0.25f, 1.0e6f), 1.0f);
    float last = 0.25f;
    for (float v : {0.01f, 0.1f, 0.5f, 2.0f}) {
        const float r = widenedRoughness(0.25f, v);
        EXPECT_GT(r, last);
        last = r;
    }
}

TEST(SurfaceMaps, APlaneHasUnitNormalsAtEveryLevel) {
    const Heightfield plane = grid(33, 10.0, [](int, int) { return 120.0f; });
    const SurfaceMaps m = buildSurfaceMaps(plane, {});
    ASSERT_EQ(m.width, 33);
    ASSERT_EQ(m.height, 33);
    ASSERT_EQ(m.normalAo.size(), 6u);  // 33, 16, 8, 4, 2, 1
    EXPECT_EQ(m.normalAo.back().size(), 1u);
    for (const auto& level : m.normalAo)
        for (const glm::vec4& t : level) {
            EXPECT_NEAR(t.x, 0.0f, 1e-6f);
            EXPECT_NEAR(t.y, 1.0f, 1e-6f);
            EXPECT_NEAR(t.z, 0.0f, 1e-6f);
            EXPECT_EQ(t.w, 1.0f);  // no AO given: open sky
        }
    for (uint8_t f : m.filled) EXPECT_EQ(f, 0);
}

TEST(SurfaceMaps, RidgesFinerThanATexelShortenTheMeanNormal) {
    // Ridges six cells apart: unit normals at level 0, their spread in the shortening beyond.
    const Heightfield ridges = grid(65, 2.0, [](int c, int) {
        return 1.2f * std::sin(float(c) * 2.0f * std::numbers::pi_v<float> / 6.0f);
    });
    const SurfaceMaps m = buildSurfaceMaps(ridges, {});
    for (const glm::vec4& t : m.normalAo[0]) EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-5f);
    auto meanVariance = [&](size_t level) {
        double v = 0.0;
        for (const glm::vec4& t : m.normalAo[level]) v += toksvigVariance(glm::length(glm::vec3(t)));
        return v / double(m.normalAo[level].size());
    };
    // Once a texel spans a whole ridge (level 3: 8 vertices), the mean normal points up and is
    // shortened by the slopes' spread: about the mean squared slope tangent / 2 for small slopes.
    const double v3 = meanVariance(3);
    EXPECT_GT(v3, 0.05);
    EXPECT_GT(meanVariance(4), 0.8 * v3);
    EXPECT_GT(v3, 4.0 * meanVariance(0) + 0.01);
    const glm::vec4 top = m.normalAo.back()[0];
    EXPECT_NEAR(top.x / glm::length(glm::vec3(top)), 0.0f, 0.05f);
}

TEST(SurfaceMaps, CarriesTheAoAndTheFilledShare) {
    Heightfield hf = grid(9, 5.0, [](int c, int r) { return float(c + r); });
    std::vector<float> ao(81, 1.0f);
    std::vector<uint8_t> mask(81, 0);
    for (int r = 3; r <= 5; ++r)
        for (int c = 3; c <= 5; ++c) {
            ao[size_t(r) * 9 + size_t(c)] = 0.25f;
            mask[size_t(r) * 9 + size_t(c)] = 1;
        }
    hf.setNodataMask(mask);
    const SurfaceMaps m = buildSurfaceMaps(hf, ao);
    EXPECT_EQ(m.normalAo[0][4 * 9 + 4].w, 0.25f);
    EXPECT_EQ(m.normalAo[0][0].w, 1.0f);
    EXPECT_EQ(m.filled[4 * 9 + 4], 255);
    EXPECT_EQ(m.filled[0], 0);
    // A 5-texel cap averages 2 × 2 or so vertices a texel: the filled share becomes a fraction.
    const SurfaceMaps small = buildSurfaceMaps(hf, ao, 5);
    ASSERT_EQ(small.width, 5);
    int partial = 0;
    for (uint8_t f : small.filled) partial += f > 0 && f < 255 ? 1 : 0;
    EXPECT_GT(partial, 0);
    double mean = 0.0;
    for (const glm::vec4& t : small.normalAo[0]) mean += t.w;
    EXPECT_LT(mean / 25.0, 1.0);
}
