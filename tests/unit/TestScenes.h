#pragma once
// Scenes the bake tests and benchmarks share.

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/Sky.h"

namespace terralux::test {

// A flat n × n terrain of `cell` metres at height h.
inline Heightfield flat(int n, double cell, float h) {
    return Heightfield(n, n, cell, cell, std::vector<float>(size_t(n) * n, h));
}

// A baker whose probes see a constant sky of radiance f(p): interpolation error is then the
// spatial error of the blend alone. `baked` (optional) counts the probes it bakes.
inline ProbeBaker fieldBaker(std::function<float(const glm::vec3&)> f, size_t* baked = nullptr) {
    return [f, baked](const std::vector<glm::vec3>& p, const std::vector<uint64_t>&) {
        ProbeBake b(p.size());
        for (size_t i = 0; i < p.size(); ++i) b.sh[i] = sh::projectConstant(glm::vec3(f(p[i])));
        b.rays = p.size();
        if (baked) *baked += p.size();
        return b;
    };
}

// A Gaussian bump of light: 1 at c, falling off over `radius`.
inline float bump(const glm::vec3& p, const glm::vec3& c, float radius) {
    const glm::vec3 d = (p - c) / radius;
    return std::exp(-glm::dot(d, d));
}

// An unbudgeted error-driven refinement that split something, kept every tested leaf within the
// tolerance, and baked nothing beyond the geometric layout's probes and its children trials: each
// split adds its `children` (8 octants, 4 quadrants), all baked already as trials.
inline void expectRefinementKeptItsTrials(const AdaptiveBake& a, size_t geometricProbes, size_t baked,
                                          size_t children, double tolerance) {
    ASSERT_TRUE(a.refinement.has_value());
    const AdaptiveRefinement& r = *a.refinement;
    EXPECT_GT(r.leavesSplit, 0u);
    EXPECT_FALSE(r.budgetReached);
    EXPECT_LE(r.worstKeptError, tolerance);
    EXPECT_EQ(a.layout.validCount(), geometricProbes + (children - 1) * r.leavesSplit);
    EXPECT_EQ(r.octantProbesKept, children * r.leavesSplit);
    EXPECT_EQ(baked, geometricProbes + r.octantProbes);
}

// A uniform sky (0.6, 0.75, 1.0), a sun of illuminance (3, 2.88, 2.7) from azimuth 135° at 35°
// with the real sun's 0.27° radius, albedo 0.3.
inline BakeLighting skyAndSun(const HeightfieldTracer& tracer) {
    BakeLighting L;
    L.tracer = &tracer;
    L.sky = Sky::uniform(glm::vec3(0.6f, 0.75f, 1.0f));
    L.sun.direction = sunDirection(135.0, 35.0);
    L.sun.illuminance = glm::vec3(3.0f, 2.88f, 2.7f);
    L.sun.angularRadius = 0.27f * std::numbers::pi_v<float> / 180.0f;
    L.albedo = glm::vec3(0.3f);
    return L;
}

}  // namespace terralux::test
