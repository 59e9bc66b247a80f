// Whole bakes through runBake on the committed Big Tujunga crop: what the exported probes and
// bake_report.json say (non-negative irradiance, ray counts, reference comparison, preset costs)
// and whether the reported Monte Carlo standard error is the error a bake really has.
#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "BakeJob.h"
#include "DemImport.h"
#include "ShProbeFile.h"
#include "TestScenes.h"
#include "bake/DiffuseBake.h"
#include "bake/ProbePlacement.h"

using namespace terralux;
namespace fs = std::filesystem;

namespace {

const fs::path kCrop = fs::path(TERRALUX_TEST_DATA) / "dem" / "bigtujunga_utm11_crop.tif";

fs::path tempDir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() /
                       ("terralux_bake_job_" + name + "_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
    fs::remove_all(d);
    return d;
}

Project cropProject(const fs::path& out, int grid) {
    Project p;
    p.scene.terrain.dem = kCrop.string();
    p.scene.exportSettings.outDir = out.string();
    p.scene.exportSettings.gltf = false;
    p.scene.bake.errorMapResolution = 0;
    p.scene.probeVolumes[0].gridDims = {grid, 1, grid};
    return p;
}

float minIrradianceOf(const ShProbeGrid& g) {
    float lo = INFINITY;
    for (const ShProbeRecord& r : g.probes) {
        sh::ShRgb s;
        s.c = r.coeffs;
        for (int ch = 0; ch < 3; ++ch) lo = std::min(lo, sh::minIrradiance(s, ch));
    }
    return lo;
}

}  // namespace

// Issue: black sky, sun on the horizon. The light is the sunlit slopes' bounce, strongly
// directional, and its L2 projection rings below zero for some normals.
TEST(BakeDefaults, NoExportedProbeHasNegativeIrradiance) {
    const fs::path dir = tempDir("negative");
    Project p = cropProject(dir / "on", 16);
    p.scene.sky.color = glm::vec3(0.0f);
    p.scene.sun.elevationDeg = 0.0;
    const BakeOutcome on = runBake(BakeRequest{p, 0, false}, {}, nullptr);
    const ShProbeGrid g = readShProbeFile(dir / "on" / "sh_coeffs/probes.shprobe");
    ASSERT_GT(g.probes.size(), 200u);
    EXPECT_GE(minIrradianceOf(g), 0.0f);
    EXPECT_GT(on.report["volumes"][0]["deringing"]["probes_windowed"].get<int>(), 0);
    // Without the window the same bake has negative irradiance: the case is a real one.
    p.scene.bake.deringing = false;
    p.scene.exportSettings.outDir = (dir / "off").string();
    runBake(BakeRequest{p, 0, false}, {}, nullptr);
    EXPECT_LT(minIrradianceOf(readShProbeFile(dir / "off" / "sh_coeffs/probes.shprobe")), 0.0f);
    fs::remove_all(dir);
}

// The reported standard error against the error each preset really has: the same probes at
// 16384 rays on the same irradiance cache leave only the sampling error of the preset's rays.
// Compared as root mean squares over the probes (a standard error is the RMS of the error).
TEST(StandardError, MatchesTheMeasuredSamplingErrorOfEachPreset) {
    const DemImportResult dem = importDem(kCrop.string());
    const HeightfieldTracer tracer(dem.heightfield);
    const BakeLighting L = test::skyAndSun(tracer);
    ProbeVolumeSettings v;
    v.gridDims = {8, 1, 8};
    const ProbeLayout layout = placeProbes(v, dem.heightfield);
    auto upLuminance = [](const sh::ShRgb& s) {
        return double(luminance(sh::evalIrradiance(s, glm::vec3(0, 1, 0))));
    };
    for (QualityPreset preset : {QualityPreset::Draft, QualityPreset::Standard, QualityPreset::High,
                                 QualityPreset::Reference}) {
        const BakeQuality q = qualityPreset(preset);
        ProbeBake bake, fine;
        if (preset == QualityPreset::Reference) {
            bake = referenceProbes(L, q.bounces, layout.positions, layout.valid, q.rays, 5, {});
            fine = referenceProbes(L, q.bounces, layout.positions, layout.valid, 16384, 6, {});
        } else {
            const IrradianceCache cache(L, q.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1, {});
            bake = bakeProbes(L, &cache, q.bounces, layout.positions, layout.valid, q.rays, 5, {});
            fine = bakeProbes(L, &cache, q.bounces, layout.positions, layout.valid, 16384, 6, {});
        }
        double measured = 0, reported = 0;
        int n = 0;
        for (size_t i = 0; i < layout.positions.size(); ++i) {
            if (!layout.valid[i]) continue;
            const double e = (upLuminance(bake.sh[i]) - upLuminance(fine.sh[i])) / upLuminance(fine.sh[i]);
            measured += e * e;
            reported += double(bake.standardError[i]) * bake.standardError[i];
            ++n;
        }
        ASSERT_GT(n, 50);
        measured = std::sqrt(measured / n);
        reported = std::sqrt(reported / n);
        RecordProperty(std::string(qualityName(preset)) + "_measured_pct", std::to_string(100 * measured));
        RecordProperty(std::string(qualityName(preset)) + "_reported_pct", std::to_string(100 * reported));
        std::printf("%s: standard error reported %.3f %%, measured %.3f %%\n", qualityName(preset),
                    100 * reported, 100 * measured);
        EXPECT_LT(reported, 1.5 * measured) << qualityName(preset);
        EXPECT_GT(reported, measured / 1.5) << qualityName(preset);
    }
}
