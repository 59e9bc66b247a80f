// Placement from an accuracy (bake/TargetSearch.h): the search against a field whose
// interpolation error is known in closed form, and the validation of both target_error settings.

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "Project.h"
#include "ProjectErrors.h"
#include "TestScenes.h"
#include "bake/TargetSearch.h"

using namespace terralux;
using terralux::test::fieldBaker;
using terralux::test::flat;
using terralux::test::projectErrorFor;

namespace {

// A sinusoidal ridge field over a flat 640 m square: every probe sees a constant sky of radiance
// f(x) = a + b·sin(2πx/λ), so the relative interpolation error at a point is |f − lerp f| / f and
// depends on x and the probe spacing alone.
constexpr double kA = 1.0, kB = 0.5, kLambda = 400.0;
constexpr int kMapResolution = 64;

double field(double x) { return kA + kB * std::sin(2.0 * std::numbers::pi * x / kLambda); }

// Closed form of the map's p95 for an n × n auto-spanned grid: the map's points sit at the centres
// of 64 equal columns over the footprint, probes at x_j = minX + j·s; between two probes the
// engine's bilinear blend is the straight line through f(x_j) and f(x_j + s).
double analyticP95(const Heightfield& hf, int n) {
    const double x0 = hf.minX(), w = hf.maxX() - hf.minX(), s = w / double(n - 1);
    const double step = w / kMapResolution;
    std::vector<float> e;
    for (int i = 0; i < kMapResolution; ++i) {
        const double x = x0 + (double(i) + 0.5) * step;
        const int j = std::min(int((x - x0) / s), n - 2);
        const double xj = x0 + s * j, t = (x - xj) / s;
        const double lerp = (1.0 - t) * field(xj) + t * field(xj + s);
        // Every row of the map repeats the same x values.
        for (int row = 0; row < kMapResolution; ++row) e.push_back(float(std::abs(lerp - field(x)) / field(x)));
    }
    return spreadOf(e).p95;
}

ProbeVolumeSettings terrainVolume() {
    ProbeVolumeSettings v;
    v.placement = ProbePlacement::Terrain;
    v.heightOffset = 5.0;  // the map measures at the probes' own height: horizontal blend alone
    return v;
}

}  // namespace

TEST(TargetSearch, TerrainGridMeetsAnalyticSpacingWithinOneStep) {
    const Heightfield hf = flat(65, 10.0, 100.0f);
    const ProbeBaker baker = fieldBaker([](const glm::vec3& p) { return float(field(p.x)); });
    const ProbeVolumeSettings v = terrainVolume();
    for (double target : {0.03, 0.01, 0.004}) {
        int analytic = 0;
        for (int n = 2; n <= 64 && !analytic; ++n)
            if (analyticP95(hf, n) <= target) analytic = n;
        ASSERT_GT(analytic, 2) << "target " << target;
        size_t trials = 0;
        const PlacementSearch s = searchTerrainGrid(hf, target, kMaxTerrainGridProbes, 8, [&](const std::array<int, 3>& d) {
            ++trials;
            return measureGridTrial(v, hf, d, baker, kMapResolution, 1);
        });
        EXPECT_TRUE(s.met) << "target " << target;
        EXPECT_FALSE(s.capped);
        EXPECT_LE(s.chosen.p95, target);
        EXPECT_EQ(s.chosen.dims[0], s.chosen.dims[2]);  // a square footprint, square grid
        EXPECT_NEAR(s.chosen.dims[0], analytic, 1) << "target " << target;
        // The measured map is the closed form: the pipeline interpolates as the model says.
        EXPECT_NEAR(s.chosen.p95, analyticP95(hf, s.chosen.dims[0]), 1e-4);
        EXPECT_EQ(s.chosen.probes, size_t(s.chosen.dims[0]) * size_t(s.chosen.dims[2]));
        // Bisection, not a scan of every count.
        EXPECT_LE(trials, 9u) << "target " << target;
        EXPECT_EQ(trials, s.trials.size());
    }
}

TEST(TargetSearch, TerrainGridStopsAtTheProbeLimit) {
    const Heightfield hf = flat(65, 10.0, 100.0f);
    const ProbeBaker baker = fieldBaker([](const glm::vec3& p) { return float(field(p.x)); });
    // 1e-5 needs far more than 100 probes (10 a side gives 4 %).
    const PlacementSearch s = searchTerrainGrid(hf, 1e-5, 100, 8, [&](const std::array<int, 3>& d) {
        return measureGridTrial(terrainVolume(), hf, d, baker, kMapResolution, 1);
    });
    EXPECT_FALSE(s.met);
    EXPECT_TRUE(s.capped);
    EXPECT_EQ(s.chosen.dims[0], 10);
    EXPECT_EQ(s.chosen.dims[2], 10);
    EXPECT_GT(s.chosen.p95, 1e-5);
    for (const auto& t : s.trials) EXPECT_LE(t.dims[0] * t.dims[2], 100);
}

TEST(TargetSearch, DimsFollowTheFootprint) {
    // 960 x 640 m: 49 a side along x is 20 m spacing, 33 along z.
    const Heightfield hf(97, 65, 10.0, 10.0, std::vector<float>(97 * 65, 0.0f));
    EXPECT_EQ(terrainDimsFor(hf, 49), (std::array<int, 3>{49, 1, 33}));
    EXPECT_EQ(terrainDimsFor(hf, 2), (std::array<int, 3>{2, 1, 2}));
    const int top = maxPerSide(hf, kMaxTerrainGridProbes);
    const auto d = terrainDimsFor(hf, top), next = terrainDimsFor(hf, top + 1);
    EXPECT_LE(d[0] * d[2], kMaxTerrainGridProbes);
    EXPECT_GT(next[0] * next[2], kMaxTerrainGridProbes);
}

TEST(TargetSearch, AdaptiveToleranceIsTheLargestOnTheLadderThatMeets) {
    // A model volume whose map p95 is 2.5 × its tolerance: the target needs tolerance <= 0.4 ·
    // target, and the ladder target·2^(k/2) first gets there at k = -3.
    const double target = 0.03;
    size_t trials = 0;
    const PlacementSearch s = searchAdaptiveTolerance(target, [&](double tolerance) {
        ++trials;
        PlacementTrial t;
        t.tolerance = tolerance;
        t.p95 = 2.5 * tolerance;
        return t;
    });
    EXPECT_TRUE(s.met);
    EXPECT_NEAR(s.chosen.tolerance, target * std::exp2(-1.5), 1e-12);
    EXPECT_LE(s.chosen.p95, target);
    EXPECT_LE(trials, 5u);
    // A volume that never gets there: the closest trial, marked capped.
    const PlacementSearch never = searchAdaptiveTolerance(target, [](double tolerance) {
        PlacementTrial t;
        t.tolerance = tolerance;
        t.p95 = 0.05 + tolerance;
        return t;
    });
    EXPECT_FALSE(never.met);
    EXPECT_TRUE(never.capped);
    EXPECT_NEAR(never.chosen.tolerance, target * std::exp2(-6.0), 1e-12);
}

TEST(TargetSearch, TargetErrorSettingsAreValidated) {
    for (const char* path : {"probe_volumes[0].target_error", "bake.target_error"}) {
        EXPECT_EQ(projectErrorFor(path, 0.03), "") << path;
        EXPECT_EQ(projectErrorFor(path, nullptr), "") << path;
        for (const nlohmann::json& bad : {nlohmann::json(-0.1), nlohmann::json(0.0), nlohmann::json(1.0),
                                          nlohmann::json(2.5)}) {
            const std::string e = projectErrorFor(path, bad);
            EXPECT_NE(e.find(path), std::string::npos) << path << " = " << bad << ": " << e;
            EXPECT_NE(e.find("(0, 1)"), std::string::npos) << path << " = " << bad << ": " << e;
            EXPECT_EQ(e.find('\n'), std::string::npos) << e;
        }
        EXPECT_NE(projectErrorFor(path, "abc").find("must be a number"), std::string::npos);
        // NaN cannot be JSON; --set spells it as a bare word.
        nlohmann::json doc = defaultProjectJson();
        try {
            applyOverride(doc, std::string(path) + "=NaN");
            sceneFromJson(doc, "--set", nullptr);
            ADD_FAILURE() << path << " accepted NaN";
        } catch (const ProjectError& e) {
            EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
        }
    }
}
