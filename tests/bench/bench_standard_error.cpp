// The reported Monte Carlo standard error against the sampling error it stands for, on every
// shared DEM and the embedded sample, with the project's default lighting (physical sky, the
// height ramp's albedo, the terrain's own bounce): a 16 x 16 terrain grid baked with each preset's
// rounds (each probe to the preset's standard error) and again at 16 384 rays over the same
// irradiance cache, so the difference is the probes'
// own sampling, measured with the metric every error figure uses (relative RMS of irradiance over
// 256 normals, docs/lighting.md "Metrics"). Counters: the reported and measured RMS and mean over
// the valid probes, their ratios, and the ratio of the 95th percentiles (what bake.target_error
// judges). A ratio measured / reported above 1 means the reported error is optimistic. The third
// argument 1 lights with the shared HDR whose sun holds most of its light (rustig_koppie_puresky)
// instead, on N42E001: the glow's own rays (docs/lighting.md, "The sky's glow").
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "SceneLighting.h"
#include "TerrainLoading.h"
#include "bake/DiffuseBake.h"
#include "bake/HeightfieldTracer.h"
#include "bake/ProbePlacement.h"

using namespace terralux;

namespace {

const char* const kDems[] = {"", "N42E001.hgt", "mt_rainier_90m.tif", "srtm_bigtujunga30m_utm11.tif",
                             "topotoolbox_exampleDEM.asc"};

void BM_StandardError(benchmark::State& state) {
    const std::string name = kDems[state.range(0)];
    const std::filesystem::path dem = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / name;
    if (!name.empty() && !std::filesystem::exists(dem)) {
        state.SkipWithError(("shared DEM " + name + " not present").c_str());
        return;
    }
    const auto preset = QualityPreset(state.range(1));
    std::vector<std::string> sets;
    if (state.range(2) == 1) {
        const std::filesystem::path hdr =
            std::filesystem::path(TERRALUX_SHARED_DATA) / "hdri" / "rustig_koppie_puresky_1k.hdr";
        if (!std::filesystem::exists(hdr)) {
            state.SkipWithError("shared HDR rustig_koppie_puresky_1k.hdr not present");
            return;
        }
        sets = {"sky.mode=hdr", "sky.hdr=" + hdr.string()};
    }
    Project p = loadEffectiveProject("", sets, name.empty() ? "" : dem.string(), nullptr);
    const DemImportResult terrain = loadProjectTerrain(p);
    const Heightfield& hf = terrain.heightfield;
    const HeightfieldTracer tracer(hf, HeightfieldTracer::Options{p.scene.terrain.skirt});
    BakeLighting L = lightingOf(p, hf);
    L.tracer = &tracer;
    L.water = bakeWaterOf(p, hf);
    L.surface = surfaceAlbedoOf(p, hf);
    ProbeVolumeSettings v;
    v.gridDims = {16, 1, 16};
    const ProbeLayout layout = placeProbes(v, hf);
    const BakeQuality q = qualityPreset(preset);
    double reported = 0, reportedAbs = 0, full = 0, fullAbs = 0;
    int n = 0;
    std::vector<float> reportedAll, fullAll;
    for (auto _ : state) {
        const IrradianceCache cache(L, q.cacheResolution, q.cacheRays, q.sunSamples, q.bounces - 1, {});
        const ProbeBake bake =
            bakeProbes(L, &cache, q.bounces, layout.positions, layout.valid, q.probeRays(), 5, {});
        state.counters["rays_per_probe_mean"] = raySpreadOf(bake, layout.valid).mean;
        const ProbeBake fine = bakeProbes(L, &cache, q.bounces, layout.positions, layout.valid, 16384, 6, {});
        for (size_t i = 0; i < layout.positions.size(); ++i) {
            if (!layout.valid[i]) continue;
            const double f = relativeIrradianceError(bake.sh[i], fine.sh[i]);
            const double s = bake.standardError[i];
            reported += s * s, reportedAbs += s;
            full += f * f, fullAbs += f;
            ++n;
            reportedAll.push_back(float(s));
            fullAll.push_back(float(f));
        }
    }
    if (n == 0) return;
    const double rRms = std::sqrt(reported / n), rMean = reportedAbs / n;
    state.SetLabel((name.empty() ? std::string("sample") : name) + " " + qualityName(preset) +
                   (state.range(2) == 1 ? " rustig_koppie_puresky" : ""));
    state.counters["reported_rms_pct"] = 100.0 * rRms;
    state.counters["full_rms_pct"] = 100.0 * std::sqrt(full / n);
    state.counters["full_mean_pct"] = 100.0 * fullAbs / n;
    state.counters["full_p95_over_reported_p95"] = spreadOf(fullAll).p95 / spreadOf(reportedAll).p95;
    state.counters["full_rms_over_reported"] = std::sqrt(full / n) / rRms;
    state.counters["full_mean_over_reported"] = (fullAbs / n) / rMean;
}
BENCHMARK(BM_StandardError)
    ->ArgsProduct({{0, 1, 2, 3, 4},
                   {int(QualityPreset::Draft), int(QualityPreset::Standard), int(QualityPreset::High)},
                   {0}})
    ->ArgsProduct({{1}, {int(QualityPreset::Draft), int(QualityPreset::Standard), int(QualityPreset::High)}, {1}})
    ->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
