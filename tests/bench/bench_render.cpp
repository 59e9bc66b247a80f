// Frame time per debug view at 1280 x 720 over a 1201^2 real DEM (the shared N42E001 tile), and
// the cost of probe lighting against none. Draw + readback, wall clock, on whatever device
// TERRALUX_VK_DEVICE picks (lavapipe here; a GPU where there is one).
#include <filesystem>
#include <memory>

#include <benchmark/benchmark.h>

#include "RenderJob.h"
#include "TerrainLoading.h"
#include "render/DebugViews.h"

using namespace terralux;

namespace {

struct Fixture {
    std::unique_ptr<vk::VulkanContext> ctx;
    std::unique_ptr<ProjectRenderer> renderer;
    std::string error;
};

Fixture& fixture() {
    static Fixture f = [] {
        Fixture x;
        const auto dem = std::filesystem::path(TERRALUX_SHARED_DATA) / "dem" / "N42E001.hgt";
        if (!std::filesystem::exists(dem)) {
            x.error = "shared DEM N42E001.hgt not present";
            return x;
        }
        try {
            x.ctx = std::make_unique<vk::VulkanContext>();
        } catch (const std::exception& e) {
            x.error = e.what();
            return x;
        }
        Project p = loadEffectiveProject("", {"bake.quality=draft", "probe_volumes[0].grid_dims=64,64"},
                                         dem.string(), nullptr);
        p.scene.exportSettings.outDir = (std::filesystem::temp_directory_path() / "terralux_bench_render").string();
        x.renderer = std::make_unique<ProjectRenderer>(*x.ctx, p);
        x.renderer->loadProbes(true);
        // The first frame builds the pipelines (lavapipe compiles them then): not a frame time.
        RenderRequest warm;
        warm.width = 1280;
        warm.height = 720;
        x.renderer->render(warm);
        return x;
    }();
    return f;
}

void BM_Frame(benchmark::State& state) {
    Fixture& f = fixture();
    if (!f.renderer) {
        state.SkipWithError(f.error.c_str());
        return;
    }
    RenderRequest q;
    q.width = 1280;
    q.height = 720;
    q.debugView = int(state.range(0));
    q.probes = state.range(1) != 0;
    double ms = 0;
    for (auto _ : state) {
        const RenderedImage img = f.renderer->render(q);
        ms += img.milliseconds;
        benchmark::DoNotOptimize(img.rgba.data());
    }
    const auto view = findDebugView(std::to_string(q.debugView));
    state.SetLabel(std::string(view->name) + (q.probes ? "" : " (no probes)") + " on " + f.ctx->deviceName());
    state.counters["frame_ms"] = ms / double(state.iterations());
    state.counters["vertices"] = double(f.renderer->renderer().vertexCount());
    state.counters["stride"] = f.renderer->renderer().meshStride();
}

void views(benchmark::internal::Benchmark* b) {
    for (const auto& v : debugViews()) b->Args({v.number, 1});
    b->Args({0, 0});
}
BENCHMARK(BM_Frame)->Apply(views)->Unit(benchmark::kMillisecond)->Iterations(5)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
