// Bake time and error against the reference for each quality preset on a 64 x 64 terrain grid
// (4096 probes) over a real DEM (the shared N42E001 SRTM tile, reprojected to UTM). Needs the
// shared data beside the repository; exits 0 with a note when it is absent.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <benchmark/benchmark.h>

#include "DemImport.h"
#include "TestScenes.h"
#include "bake/AdaptivePlacement.h"
#include "bake/DiffuseBake.h"
#include "bake/ProbeDiagnostics.h"
#include "bake/ProbePlacement.h"

using namespace terralux;

namespace {

struct Fixture {
    DemImportResult dem;
    std::unique_ptr<HeightfieldTracer> tracer;
    BakeLighting lighting;
    ProbeLayout layout;
    ProbeBake reference;
    double referenceSeconds = 0;
};

Fixture* fixture() {
    static std::unique_ptr<Fixture> f = [] {
        const std::filesystem::path dem =
            std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
        if (!std::filesystem::exists(dem)) return std::unique_ptr<Fixture>();
        auto x = std::make_unique<Fixture>();
        x->dem = importDem(dem.string());
        x->tracer = std::make_unique<HeightfieldTracer>(x->dem.heightfield);
        x->lighting = test::skyAndSun(*x->tracer);
        ProbeVolumeSettings v;
        v.gridDims = {64, 1, 64};
        x->layout = placeProbes(v, x->dem.heightfield);
        const auto t = std::chrono::steady_clock::now();
        x->reference = referenceProbes(x->lighting, 16, x->layout.positions, x->layout.valid,
                                       qualityPreset(QualityPreset::Reference).rays, 1234, {});
        x->referenceSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        std::fprintf(stderr, "reference: %zu probes, %llu rays, %.1f s\n", x->layout.positions.size(),
                     (unsigned long long)x->reference.rays, x->referenceSeconds);
        return x;
    }();
    return f.get();
}

void BM_BakePreset(benchmark::State& state) {
    Fixture* f = fixture();
    if (!f) {
        state.SkipWithError("shared DEM N42E001.hgt not present");
        return;
    }
    const auto preset = QualityPreset(state.range(0));
    const BakeQuality q = qualityPreset(preset);
    ProbeBake bake;
    for (auto _ : state) {
        const IrradianceCache cache(f->lighting, q.cacheResolution, q.cacheRays, q.sunSamples,
                                    q.bounces - 1, {});
        bake = bakeProbes(f->lighting, &cache, q.bounces, f->layout.positions, f->layout.valid,
                          q.rays, 99, {});
        benchmark::DoNotOptimize(bake.sh.data());
    }
    const ErrorStats e = compareToReference(bake.sh, f->reference.sh, f->layout.valid);
    state.SetLabel(qualityName(preset));
    state.counters["probes"] = double(f->layout.validCount());
    state.counters["err_mean_pct"] = 100.0 * e.mean;
    state.counters["err_p95_pct"] = 100.0 * e.p95;
    state.counters["err_max_pct"] = 100.0 * e.max;
    state.counters["ref_s"] = f->referenceSeconds;
}
BENCHMARK(BM_BakePreset)
    ->Arg(int(QualityPreset::Draft))
    ->Arg(int(QualityPreset::Standard))
    ->Arg(int(QualityPreset::High))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->UseRealTime();

// The ground interpolation-error map of debug view 56 (bake.error_map_resolution points a side)
// over the same grid: what it costs on top of the bake, and what it finds.
void BM_ErrorMap(benchmark::State& state) {
    Fixture* f = fixture();
    if (!f) {
        state.SkipWithError("shared DEM N42E001.hgt not present");
        return;
    }
    const QualityPreset preset = QualityPreset::Standard;
    const BakeQuality q = qualityPreset(preset);
    const int resolution = int(state.range(0));
    const IrradianceCache cache(f->lighting, q.cacheResolution, q.cacheRays, q.sunSamples,
                                q.bounces - 1, {});
    const ProbeBake bake = bakeProbes(f->lighting, &cache, q.bounces, f->layout.positions,
                                      f->layout.valid, q.rays, 99, {});
    const ProbeBaker baker = seededBaker(f->lighting, &cache, q.bounces, q.rays, 99, {});
    ErrorMap map;
    for (auto _ : state) {
        map = measureErrorMap(f->layout, bake.sh, f->dem.heightfield, baker, resolution, 5.0f, 99);
        benchmark::DoNotOptimize(map.error.data());
    }
    const ErrorMapStats s = errorMapStats(map);
    state.SetLabel(qualityName(preset));
    state.counters["points"] = double(s.points);
    state.counters["map_mean_pct"] = 100.0 * s.mean;
    state.counters["map_p95_pct"] = 100.0 * s.p95;
    state.counters["map_max_pct"] = 100.0 * s.max;
}
BENCHMARK(BM_ErrorMap)->Arg(32)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond)->Iterations(1)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
